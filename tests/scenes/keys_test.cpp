// The key table (scenes/keys.h) against the loader and the documentation: every simple key is
// read into its field and range-checked at its position, every table's keys are accepted and
// no other, and docs/scene-format.md holds exactly the generated reference.
#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>
#include <sstream>

#include "scenes/keys.h"
#include "scenes/system_types.h"
#include "scenes/scene.h"
#include "scene_test_common.h"
#include "../test_common.h"

using namespace flexure;
using scenes::KeyKind;
using scenes::KeySpec;

namespace {

const std::string kFramework = "[system]\ntype = \"framework\"\nvertices = [[0,0],[1,0],[0,2]]\nedges = [[1,2],[2,3]]\n";
const std::string kHypergraph =
    "[system]\ntype = \"volume_hypergraph\"\nvertices = [[0,0],[1,0],[0,1]]\nsimplices = [[1,2,3]]\n";

// The scene with `table` holding `key = value`, the value on the returned line at `column`.
std::string sceneWith(const KeySpec& k, const std::string& value, int& line, int& column) {
  const bool hyper = k.key == "target_stretch" || k.key == "tip_value";
  std::string text = hyper ? kHypergraph : kFramework;
  text += "[" + k.table + "]\n";
  line = static_cast<int>(std::count(text.begin(), text.end(), '\n')) + 1;
  column = static_cast<int>(k.key.size()) + 4;
  return text + k.key + " = " + value + "\n";
}

std::string tomlNumber(double v) {
  std::ostringstream o;
  o.precision(17);
  o << v;
  std::string s = o.str();
  if (s.find_first_of(".e") == std::string::npos) s += ".0";
  return s;
}

}  // namespace

TEST_CASE("keys: every simple key is read into its field and checked against its range", "[scenes]") {
  int simple = 0;
  for (const KeySpec& k : scenes::sceneKeys()) {
    if (k.kind == KeyKind::Custom) continue;
    ++simple;
    INFO("[" << k.table << "] " << k.key);
    int line = 0, column = 0;
    scenes::Scene s;
    switch (k.kind) {
      case KeyKind::Integer: {
        const long long v = static_cast<long long>(k.lo) + (k.hi > k.lo ? 1 : 0);
        s = scenes::loadSceneFromString(sceneWith(k, std::to_string(v), line, column), "t.toml");
        CHECK(std::get<int& (*)(scenes::Scene&)>(k.field)(s) == v);
        test::requireSceneError(sceneWith(k, std::to_string(static_cast<long long>(k.hi) + 1), line, column), line,
                                column, k.range_message.empty() ? k.key + " must be between" : k.range_message);
        test::requireSceneError(sceneWith(k, "\"many\"", line, column), line, column, k.key + " must be an integer");
        break;
      }
      case KeyKind::Number: {
        const bool lo = std::isfinite(k.lo), hi = std::isfinite(k.hi);
        const double v = lo && hi ? 0.5 * (k.lo + k.hi) : lo ? k.lo + 0.75 : hi ? k.hi - 0.75 : 0.25;
        s = scenes::loadSceneFromString(sceneWith(k, tomlNumber(v), line, column), "t.toml");
        CHECK(std::get<double& (*)(scenes::Scene&)>(k.field)(s) == v);
        if (hi || lo) {
          const double bad = hi ? 2 * k.hi + 1 : k.open_lo ? k.lo : k.lo - 1;
          test::requireSceneError(sceneWith(k, tomlNumber(bad), line, column), line, column,
                                  k.range_message.empty() ? k.key + " must be between" : k.range_message);
        }
        // An expression is a number too.
        s = scenes::loadSceneFromString(sceneWith(k, "\"" + tomlNumber(v) + " + 0*pi\"", line, column), "t.toml");
        CHECK(std::get<double& (*)(scenes::Scene&)>(k.field)(s) == Approx(v));
        break;
      }
      case KeyKind::Flag: {
        const bool before = std::get<bool& (*)(scenes::Scene&)>(k.field)(s);
        s = scenes::loadSceneFromString(sceneWith(k, before ? "false" : "true", line, column), "t.toml");
        CHECK(std::get<bool& (*)(scenes::Scene&)>(k.field)(s) == !before);
        test::requireSceneError(sceneWith(k, "1", line, column), line, column, k.key + " must be true or false");
        break;
      }
      case KeyKind::Color:
      case KeyKind::OptionalColor: {
        s = scenes::loadSceneFromString(sceneWith(k, "\"#10203040\"", line, column), "t.toml");
        const render::Color c = k.kind == KeyKind::Color ? std::get<render::Color& (*)(scenes::Scene&)>(k.field)(s)
                                                         : *std::get<std::optional<render::Color>& (*)(scenes::Scene&)>(k.field)(s);
        CHECK(std::lround(c.r * 255) == 0x10);
        CHECK(std::lround(c.a * 255) == 0x40);
        test::requireSceneError(sceneWith(k, "\"chartreusey\"", line, column), line, column, "unknown colour");
        break;
      }
      case KeyKind::Seed:
      case KeyKind::OptionalSeed: {
        s = scenes::loadSceneFromString(sceneWith(k, "77", line, column), "t.toml");
        const std::uint64_t v = k.kind == KeyKind::Seed ? std::get<std::uint64_t& (*)(scenes::Scene&)>(k.field)(s)
                                                        : *std::get<std::optional<std::uint64_t>& (*)(scenes::Scene&)>(k.field)(s);
        CHECK(v == 77);
        test::requireSceneError(sceneWith(k, "-3", line, column), line, column, "seed must be a nonnegative integer");
        break;
      }
      case KeyKind::Custom: break;
    }
  }
  CHECK(simple >= 50);
}

TEST_CASE("keys: each table accepts its keys and names them when a key is unknown", "[scenes]") {
  for (const std::string table : {"motion", "analysis", "render", "projection"}) {
    INFO(table);
    const std::vector<std::string> keys = scenes::keysOf(table);
    REQUIRE(!keys.empty());
    // A key no table has: the message lists the table's keys, in the table's order.
    std::string known;
    for (const auto& k : keys) known += (known.empty() ? "" : ", ") + k;
    test::requireSceneError(kFramework + "[" + table + "]\nzzzzzzzzzzzz = 1\n", 6, 1, "(known: " + known + ")");
  }
  // Every type takes its own [system] keys and refuses another type's.
  CHECK(scenes::keysOf("system", "framework") ==
        std::vector<std::string>{"type", "vertices", "edges", "pinned", "attached", "lengths"});
  CHECK(scenes::keysOf("system", "catalog") == std::vector<std::string>{"type", "name"});
  CHECK(scenes::keysOf("system", "body_bar") == std::vector<std::string>{"type", "vertices", "pinned", "bodies", "bars"});
  test::requireSceneError(kFramework + "facets = [[1,2,3]]\n", 5, 1, "unknown key 'facets' in [system] (framework)");
  test::requireSceneError(kHypergraph + "lengths = [1]\n", 5, 1, "unknown key 'lengths' in [system] (volume_hypergraph)");
  for (const auto& c : scenes::catalog()) {
    const scenes::Scene s = scenes::loadSceneFromString(c.text, "catalog:" + c.name);
    CHECK(!scenes::keysOf("system", s.type).empty());
  }
}

TEST_CASE("keys: docs/scene-format.md holds the generated table of system types", "[scenes]") {
  const std::string doc = test::readProjectFile(FLEXURE_SOURCE_DIR, "docs/scene-format.md");
  const std::string begin =
      "<!-- types: generated by `flexure keys --types`; edit scenes/systems/<type>.cpp, not this table -->\n";
  const std::string end = "<!-- end of types -->";
  const size_t a = doc.find(begin), b = doc.find(end);
  REQUIRE(a != std::string::npos);
  REQUIRE(b != std::string::npos);
  INFO("regenerate with scripts/keys-doc");
  CHECK(doc.substr(a + begin.size(), b - a - begin.size()) == scenes::systemTypesMarkdown());
  for (const std::string& type : scenes::systemTypeNames()) CHECK(doc.find("| `" + type + "` |") != std::string::npos);
}

TEST_CASE("keys: docs/scene-format.md holds the generated key reference", "[scenes]") {
  const std::string doc = test::readProjectFile(FLEXURE_SOURCE_DIR, "docs/scene-format.md");
  const std::string begin = "<!-- keys: generated by `flexure keys`; edit scenes/keys.cpp, not this table -->\n";
  const std::string end = "<!-- end of keys -->";
  const size_t a = doc.find(begin), b = doc.find(end);
  REQUIRE(a != std::string::npos);
  REQUIRE(b != std::string::npos);
  INFO("regenerate with scripts/keys-doc");
  CHECK(doc.substr(a + begin.size(), b - a - begin.size()) == scenes::keyReferenceMarkdown());
  // Every key appears in it, with its documented default.
  for (const KeySpec& k : scenes::sceneKeys()) {
    INFO(k.key);
    CHECK(doc.find("| `" + k.key + "` |") != std::string::npos);
  }
}
