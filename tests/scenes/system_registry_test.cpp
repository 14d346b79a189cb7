// The registry of system types (scenes/system_types.cpp) against the key table and the files
// that list types or keys: every type a key names is registered; every registered type takes
// vertices and pins and refuses vertices of another dimension; an unknown type is told with the
// registry's list; the vertex-number keys come from the key table; and the scene fuzzer's
// dictionary holds every type name and every key.
#include <catch2/catch.hpp>

#include <algorithm>
#include <set>
#include <sstream>

#include "scenes/keys.h"
#include "scenes/scene.h"
#include "scenes/system_types.h"
#include "scene_test_common.h"
#include "../test_common.h"

using namespace flexure;
using scenes::KeySpec;

namespace {

bool contains(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

std::string joined(const std::vector<std::string>& v) {
  std::string out;
  for (const auto& s : v) out += (out.empty() ? "" : ", ") + s;
  return out;
}

}  // namespace

TEST_CASE("system types: the registry, the type names of the key table and the loader agree", "[scenes]") {
  const auto& types = scenes::detail::systemTypes();
  const std::vector<std::string> names = scenes::systemTypeNames();
  REQUIRE(names.size() == types.size() + 1);
  CHECK(names.back() == "catalog");
  std::set<std::string> seen;
  for (size_t i = 0; i < types.size(); ++i) {
    const auto& t = types[i];
    INFO(t.name);
    CHECK(names[i] == t.name);
    CHECK(seen.insert(t.name).second);
    CHECK(scenes::detail::findSystemType(t.name) == &t);
    CHECK(t.build != nullptr);
    CHECK(!t.doc.empty());
    REQUIRE(!t.dimensions.empty());
    for (int d : t.dimensions) CHECK((d == 2 || d == 3));
    // Every type takes vertices and pins; its vertex-number keys are among its keys.
    const std::vector<std::string> keys = scenes::keysOf("system", t.name);
    CHECK(contains(keys, "vertices"));
    CHECK(contains(keys, "pinned"));
    CHECK(contains(scenes::indexKeysOf("system", t.name), "pinned"));
    for (const auto& k : scenes::indexKeysOf("system", t.name)) CHECK(contains(keys, k));
    // A vertex of 1 coordinate is refused with the dimensions the type takes.
    std::string dims;
    for (size_t k = 0; k < t.dimensions.size(); ++k) dims += (k ? " or " : "") + std::to_string(t.dimensions[k]);
    try {
      scenes::loadSceneFromString("[system]\ntype = \"" + t.name + "\"\nvertices = [[0]]\n", "t.toml");
      FAIL("no error");
    } catch (const scenes::SceneError& e) {
      CHECK(e.line == 3);
      CHECK_THAT(e.message, Catch::Equals("a vertex has 1 coordinates; this system type needs " + dims));
    }
  }
  CHECK(scenes::detail::findSystemType("catalog") == nullptr);
  CHECK(scenes::detail::findSystemType("frameworks") == nullptr);
  // The types a [system] key names (scenes/keys.cpp) are registered ("from": the keys of
  // [system] from = FILE).
  for (const KeySpec& k : scenes::sceneKeys()) {
    if (k.table != "system") continue;
    std::istringstream words(k.types);
    for (std::string w; words >> w;) {
      INFO(k.key << ": " << w);
      CHECK((w == "from" || contains(names, w)));
    }
  }
  // An unknown type is told with the registry's list, in its order.
  test::requireSceneError("[system]\ntype = \"frameworks\"\n", 2, 8,
                          "unknown or unsupported system type 'frameworks' (this version supports: " + joined(names) +
                              ")");
}

TEST_CASE("system types: the keys that hold vertex numbers come from the key table", "[scenes]") {
  std::vector<std::string> all;
  for (const KeySpec& k : scenes::sceneKeys())
    if (k.vertex_indices) all.push_back(k.table + "." + k.key);
  CHECK(contains(all, "system.edges"));
  CHECK(contains(all, "system.creases"));
  CHECK(contains(all, "motion.contract_edge"));
  CHECK(contains(all, "render.fixed_simplex"));
  CHECK(!contains(all, "system.vertices"));
  CHECK(!contains(all, "system.radii"));
  CHECK(scenes::indexKeysOf("system", "framework") == std::vector<std::string>{"edges", "pinned", "attached"});
  CHECK(scenes::indexKeysOf("system", "catalog").empty());
  CHECK(scenes::indexKeysOf("motion") == std::vector<std::string>{"contract_edge", "fold_crease"});
  CHECK(scenes::indexKeysOf("analysis").empty());
}

TEST_CASE("system types: the scene fuzzer's dictionary holds every type name and every key", "[scenes]") {
  const std::string dict = test::readProjectFile(FLEXURE_SOURCE_DIR, "tests/fuzz/scene.dict");
  // One entry per line: "text" (libFuzzer's format; # starts a comment).
  std::set<std::string> entries;
  std::istringstream lines(dict);
  for (std::string line; std::getline(lines, line);) {
    const size_t a = line.find('"'), b = line.rfind('"');
    if (line.empty() || line[0] == '#' || a == std::string::npos || b <= a) continue;
    entries.insert(line.substr(a + 1, b - a - 1));
  }
  REQUIRE(entries.size() > 50);
  for (const std::string& t : scenes::systemTypeNames()) {
    INFO("type " << t);
    CHECK(entries.count(t));
  }
  for (const KeySpec& k : scenes::sceneKeys()) {
    INFO("[" << k.table << "] " << k.key);
    // A table of the top level may be there as its header instead: "[motion]", "[[output]]".
    CHECK((entries.count(k.key) || entries.count("[" + k.key + "]") || entries.count("[[" + k.key + "]]")));
  }
}
