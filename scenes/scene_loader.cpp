// TOML scene files to Scene. Every problem is a SceneError with the file, line and column of
// the offending node; nothing is guessed. This file holds the entry points and the [system]
// dispatch; the rest of the loader is in toml_reader.cpp (the Reader), system_reader.cpp (the
// readers the system types share), systems/<type>.cpp (one file per system type, listed in
// system_types.cpp), scene_imports.cpp, scene_catalog.cpp and scene_settings.cpp.
#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include "engine/systems/framework.h"
#include "scenes/catalog.h"
#include "scenes/importers.h"
#include "scenes/json_text.h"
#include "scenes/keys.h"
#include "scenes/loader_parts.h"
#include "scenes/npz_file.h"
#include "scenes/path_file.h"
#include "scenes/scene.h"
#include "scenes/scene_document.h"
#include "scenes/scene_edit.h"
#include "scenes/system_reader.h"
#include "scenes/system_types.h"
#include "scenes/toml_text.h"

namespace flexure::scenes {

namespace detail {

std::unique_ptr<engine::Model> buildModel(const Reader& r, const toml::table& sys, int base,
                                          std::string& type_out, int depth, toml::table* resolved) {
  if (const toml::node* from = sys.get("from")) return buildImported(r, sys, *from, base, type_out, depth, resolved);
  const toml::node& tn = r.require(sys, "type", "[system]");
  const std::string type = r.string(tn, "type");
  try {
    if (const SystemType* t = findSystemType(type)) {
      std::vector<std::string> keys = keysOf("system", type);
      keys.insert(keys.end(), t->own_keys.begin(), t->own_keys.end());
      r.checkKeys(sys, keys, "[system] (" + type + ")");
      auto m = t->build(r, sys, base, readVertices(r, sys, t->dimensions));
      type_out = type;
      return m;
    }
    if (type == "catalog") return buildCatalog(r, sys, base, type_out, depth, resolved);
  } catch (const std::invalid_argument& e) {
    r.fail(sys.source(), e.what());
  }
  std::string known;
  for (const auto& t : systemTypeNames()) known += (known.empty() ? "" : ", ") + t;
  r.fail(tn, "unknown or unsupported system type '" + type + "' (this version supports: " + known + ")");
}

}  // namespace detail

using namespace detail;

namespace {

Scene readScene(toml::table& doc, const std::string& file, const std::vector<std::string>& overrides,
                const std::string* text = nullptr, std::shared_ptr<const std::vector<BulkArray>> bulk = nullptr) {
  for (const auto& o : overrides) applyOverride(doc, o);
  mergeCatalogEntry(doc);
  Reader r(file);
  r.setText(text);
  r.setBulk(bulk);
  // The arrays read from the text that the document still has (an override replaces one).
  std::vector<std::string> bulk_keys;
  if (const toml::table* sys = doc["system"].as_table(); sys && bulk)
    for (const BulkArray& a : *bulk)
      if (const toml::node* n = sys->get(a.key); n && r.bulk(*n) == &a) bulk_keys.push_back(a.key);
  // The exact mode reads the vertices as rationals too; known before the system is read (a value
  // that is not a flag is refused with [analysis] below).
  if (const auto exact = doc["analysis"]["exact"].value<bool>()) r.setExact(*exact);
  Scene scene;
  scene.motion.flex_file = file;
  r.checkKeys(doc, keysOf(""), "the scene");
  scene.path = file;
  if (const toml::node* n = doc.get("title")) scene.title = r.string(*n, "title");
  if (const toml::node* n = doc.get("index_base")) {
    const long long b = r.integer(*n, "index_base");
    if (b != 0 && b != 1) r.fail(*n, "index_base must be 0 or 1");
    scene.index_base = static_cast<int>(b);
  }
  const toml::node* sys = doc.get("system");
  if (!sys) throw SceneError(file, 1, 1, "the scene has no [system] table");
  toml::table resolved;
  scene.model = buildModel(r, r.table(*sys, "[system]"), scene.index_base, scene.type, 0, &resolved);
  scene.exact_vertices = r.exactPoints();
  if (const toml::node* n = doc.get("motion")) readMotion(r, r.table(*n, "[motion]"), scene);
  if (const toml::node* n = doc.get("analysis")) readAnalysis(r, r.table(*n, "[analysis]"), scene);
  if (const toml::node* n = doc.get("render")) readRender(r, r.table(*n, "[render]"), scene);
  if (const toml::node* n = doc.get("projection")) readProjection(r, r.table(*n, "[projection]"), scene);
  if (const toml::node* n = doc.get("output")) readOutputs(r, *n, scene.outputs);
  scene.render.style.label_base = scene.index_base;
  auto self = std::make_shared<toml::table>(doc);
  self->erase("output");
  self->erase("sweep");
  if (!resolved.empty()) self->insert_or_assign("system", std::move(resolved));
  scene.document = [self, bulk, bulk_keys] {
    std::ostringstream text;
    if (bulk_keys.empty()) {
      text << toml::toml_formatter(*self);
      return text.str() + "\n";
    }
    toml::table doc = *self;  // small: the large arrays are in `bulk`
    for (const BulkArray& a : *bulk) {
      if (std::find(bulk_keys.begin(), bulk_keys.end(), a.key) == bulk_keys.end()) continue;
      const auto push = [&](toml::array& to, size_t i, size_t k) {
        if (a.isInteger(i, k)) to.push_back(static_cast<std::int64_t>(a.value(i, k)));
        else to.push_back(a.value(i, k));
      };
      toml::array rows;
      rows.reserve(a.rows());
      for (size_t i = 0; i < a.rows(); ++i) {
        if (a.flat) {
          push(rows, i, 0);
          continue;
        }
        toml::array row;
        for (size_t k = 0; k < a.width(i); ++k) push(row, i, k);
        rows.push_back(std::move(row));
      }
      doc["system"].as_table()->insert_or_assign(a.key, std::move(rows));
    }
    text << toml::toml_formatter(doc);
    return text.str() + "\n";
  };
  return scene;
}

}  // namespace

namespace {

// An array given as numbers as a bulk array whose failures are at line and column (with the
// item, and `origin` and the key in the message when it came from a file).
BulkArray bulkOf(SceneArray&& g, int line, int column, const std::string& source_name, const std::string& origin) {
  const size_t width = std::max<size_t>(g.cols, 1);
  if (g.values.size() != g.rows * width)
    throw std::invalid_argument("the array " + g.key + " has " + std::to_string(g.values.size()) + " values, not " +
                                std::to_string(g.rows) + " x " + std::to_string(width));
  BulkArray a;
  a.key = g.key;
  a.flat = g.cols == 0;
  a.given = true;
  a.origin = origin;
  a.line = line;
  a.column = column;
  for (size_t i = 0; i < g.values.size(); ++i) {
    const double v = g.values[i];
    const auto fail = [&](const std::string& why) {
      const std::string where = origin.empty() ? "" : origin + ", " + g.key + "[" + std::to_string(i / width) + "]: ";
      throw SceneError(source_name, a.line, a.column, where + why, static_cast<long>(i / width));
    };
    if (std::isnan(v)) fail("a number is NaN");
    if (std::isinf(v)) fail("a number is infinite");
    if (g.integer && std::abs(v) > 9007199254740992.0) fail("the integer " + fmt(v) + " is beyond 2^53 (not exact as a double)");
  }
  a.row_first.resize(g.rows + 1);
  for (size_t i = 0; i <= g.rows; ++i) a.row_first[i] = i * width;
  a.values = std::move(g.values);
  a.integer.assign(a.values.size(), g.integer ? 1 : 0);
  return a;
}

// A given array as the bulk array of its `KEY = []` in the document's [system].
BulkArray givenArray(SceneArray&& g, const toml::table& doc, const std::string& source_name) {
  const toml::node* n = doc["system"][g.key].node();
  const toml::array* placeholder = n ? n->as_array() : nullptr;
  if (!placeholder || !placeholder->empty())
    throw std::invalid_argument("the scene's [system] has no `" + g.key + " = []` for the array given as numbers");
  BulkArray a = bulkOf(std::move(g), static_cast<int>(n->source().begin.line), static_cast<int>(n->source().begin.column),
                       source_name, "");
  a.node = n;
  return a;
}

bool isNumpyFile(const std::string& name) {
  std::string lower = name;
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return lower.size() > 4 && lower.compare(lower.size() - 4, 4, ".npz") == 0;
}

// [system] from = "FILE.npz" (numpy.savez's file, relative to the scene's folder): its arrays
// are the [system] keys of their names, as if the text held them (placeholders in the document,
// `from` taken out: the document then holds the system it read). Failures at the `from` key.
void npzArrays(toml::table& doc, const std::string& source_name, std::vector<BulkArray>& arrays) {
  toml::table* sys = doc["system"].as_table();
  const toml::node* from = sys ? sys->get("from") : nullptr;
  if (!from || !from->is_string() || !isNumpyFile(from->as_string()->get())) return;
  const std::string name = from->as_string()->get();
  const int line = static_cast<int>(from->source().begin.line), column = static_cast<int>(from->source().begin.column);
  const auto fail = [&](const std::string& message) { throw SceneError(source_name, line, column, message); };
  const std::string path = besideScene(source_name, name);
  std::vector<NumpyArray> got;
  try {
    got = readNumpyFile(path);
  } catch (const SceneError& e) {
    fail("cannot read '" + name + "': " + e.message);
  }
  if (got.empty()) fail(name + " holds no array");
  for (NumpyArray& a : got) {
    bool flat = false;
    if (!bulkKey(a.name, &flat))
      fail(name + " holds the array '" + a.name + "': an .npz gives [system] arrays (vertices, edges, faces, creases, "
                  "bodies, bars, facets, simplices, angles, contacts, attached, pinned, lengths, radii)");
    if (sys->contains(a.name)) fail("[system] " + a.name + " is given both here and in " + name);
    if (a.shape.size() != (flat ? 1u : 2u))
      fail(name + ": " + a.name + " has " + std::to_string(a.shape.size()) + " dimension(s): it is " +
           (flat ? "a flat array, shape (n,)" : "an array of rows, shape (n, k)"));
    if (a.values.empty()) fail(name + ": " + a.name + " is empty");
    SceneArray g{a.name, std::move(a.values), a.shape[0], flat ? 0 : a.shape[1], a.integer};
    BulkArray b = bulkOf(std::move(g), line, column, source_name, name);
    sys->insert(b.key, toml::array{});
    b.node = sys->get(b.key);
    arrays.push_back(std::move(b));
  }
  sys->erase("from");
}

Scene loadText(const std::string& text, const std::string& source_name, const std::vector<std::string>& overrides,
               std::vector<SceneArray> given) {
  // Large [system] arrays (vertices, edges, ...) are read straight from the text (scenes/bulk_arrays.h);
  // toml++ reads the rest, with those arrays blanked. Should the scanner have taken for an
  // array what is not one (text in a multi-line string), the document shows it: toml++ then
  // reads the whole text. Arrays given as numbers (Python's) are bulk arrays at their
  // placeholders, and so are those of `[system] from = "FILE.npz"`.
  const auto withGiven = [&](toml::table& doc, std::vector<BulkArray> arrays) -> std::shared_ptr<const std::vector<BulkArray>> {
    for (SceneArray& g : given) arrays.push_back(givenArray(std::move(g), doc, source_name));
    npzArrays(doc, source_name, arrays);
    return arrays.empty() ? nullptr : std::make_shared<const std::vector<BulkArray>>(std::move(arrays));
  };
  BulkText bulk = extractBulkArrays(text);
  if (!bulk.arrays.empty()) {
    std::optional<toml::table> doc;
    try {
      doc = parseToml(bulk.text, source_name);
    } catch (const SceneError&) {
    }
    bool found = doc.has_value();
    for (size_t i = 0; found && i < bulk.arrays.size(); ++i) {
      const BulkArray& a = bulk.arrays[i];
      const toml::node* n = (*doc)["system"][a.key].node();
      const toml::array* arr = n ? n->as_array() : nullptr;
      found = arr && arr->empty() && static_cast<int>(n->source().begin.line) == a.line &&
              static_cast<int>(n->source().begin.column) == a.column;
    }
    if (found) return readScene(*doc, source_name, overrides, &text, withGiven(*doc, std::move(bulk.arrays)));
  }
  toml::table doc = parseToml(text, source_name);
  return readScene(doc, source_name, overrides, &text, withGiven(doc, {}));
}

}  // namespace

Scene loadSceneFromString(const std::string& text, const std::string& source_name,
                          const std::vector<std::string>& overrides) {
  return loadText(text, source_name, overrides, {});
}

Scene loadSceneFromString(const std::string& text, const std::string& source_name, std::vector<SceneArray> arrays) {
  return loadText(text, source_name, {}, std::move(arrays));
}

std::string readSceneFile(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw SceneError(path, 1, 1, "is a directory, not a scene file");
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int err = errno;
    std::string m = std::string("cannot open the scene file: ") + std::strerror(err);
    if (err == ENOENT && path.find('/') == std::string::npos && path.find('.') == std::string::npos)
      m += "; nor is it a catalog entry: " + unknownCatalogName(path);
    throw SceneError(path, 1, 1, m);
  }
  // Read in pieces up to the limit: /dev/zero or a FIFO has no size to ask for.
  std::string text;
  char buf[1 << 16];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    text.append(buf, static_cast<size_t>(in.gcount()));
    if (text.size() > kMaxSceneBytes)
      throw SceneError(path, 1, 1, "the scene file is larger than " + std::to_string(kMaxSceneBytes >> 20) + " MiB");
  }
  if (in.bad()) throw SceneError(path, 1, 1, "cannot read the scene file");
  return text;
}

std::string sceneTextOfFile(const std::string& path, const std::string& text) {
  if (isNodeLinkFile(path) && looksLikePathJson(text)) {
    const nlohmann::json j = parseJsonText(text, path);
    if (isPathJson(j)) return j["scene"].is_string() ? j["scene"].get<std::string>() : text;
  }
  if (!isImportable(path) || tomlNamedJson(path)) return text;
  std::ostringstream o;
  o << toml::toml_formatter(importedSceneDocument(path)) << "\n";
  return o.str();
}

Scene loadScene(const std::string& path, const std::vector<std::string>& overrides) {
  if (const CatalogEntry* e = catalogArgument(path))
    return loadSceneFromString(e->text, "catalog:" + e->name, overrides);
  if (isNodeLinkFile(path)) {
    // A path JSON written by track: its scene and samples.
    std::error_code ec;
    if (std::filesystem::is_regular_file(path, ec)) {
      const std::string text = readSceneFile(path);
      if (looksLikePathJson(text)) {
        nlohmann::json j = parseJsonText(text, path);
        if (isPathJson(j)) return loadPathJson(path, j, overrides);
      }
    }
  }
  if (isImportable(path) && !tomlNamedJson(path)) {
    // A graph6/sparse6 file, a mesh or a FOLD file given directly.
    toml::table doc = importedSceneDocument(path);
    return readScene(doc, path, overrides);
  }
  return loadSceneFromString(readSceneFile(path), path, overrides);
}

Scene loadSceneFromDocument(toml::table doc, const std::string& source_name,
                            const std::vector<std::string>& overrides) {
  return readScene(doc, source_name, overrides);
}

namespace {

// loadGraphScene without a TOML document: a sweep of 20,303 graphs on 9 vertices spent a third of
// its time building, checking and copying one per graph. Taken only where nothing can differ from
// what readScene makes of graphSystem's table: no override, positions drawn from the seed, edges
// in range, no loop, no repeated pair, no edge of length 0 (else nullopt: the document's path
// then says what is wrong, and where). The document is written when asked for.
std::optional<Scene> directGraphScene(const ImportedGraph& g, int dimension, std::uint64_t seed,
                                      const std::string& source_name, const std::string& title) {
  if (!g.positions.empty() || g.vertices < 1) return std::nullopt;
  const engine::Matrix p = graphRealization(g.vertices, dimension, seed);  // graphSystem's vertices
  std::vector<engine::Framework::Edge> edges;
  std::vector<std::pair<int, int>> pairs;
  edges.reserve(g.edges.size());
  pairs.reserve(g.edges.size());
  for (const auto& e : g.edges) {
    if (e[0] == e[1] || std::min(e[0], e[1]) < 0 || std::max(e[0], e[1]) >= g.vertices) return std::nullopt;
    edges.push_back({e[0], e[1]});
    pairs.push_back(std::minmax(e[0], e[1]));
  }
  std::sort(pairs.begin(), pairs.end());
  if (std::adjacent_find(pairs.begin(), pairs.end()) != pairs.end()) return std::nullopt;
  const double scale = (p.rowwise().maxCoeff() - p.rowwise().minCoeff()).norm();
  for (const auto& [a, b] : edges)
    if ((p.col(a) - p.col(b)).norm() <= 1e-12 * scale) return std::nullopt;
  Scene scene;
  scene.path = source_name;
  scene.title = title;
  scene.type = "framework";
  scene.index_base = 1;
  scene.motion.flex_file = source_name;
  scene.render.style.label_base = 1;
  try {
    scene.model = std::make_unique<engine::Framework>(p, std::move(edges), std::vector<int>{});
  } catch (const std::exception&) {
    return std::nullopt;
  }
  scene.document = [g, dimension, seed, title] {
    toml::table doc;
    doc.insert("title", title);
    doc.insert("system", graphSystem(g, dimension, seed, 1));
    std::ostringstream text;
    text << toml::toml_formatter(doc);
    return text.str() + "\n";
  };
  return scene;
}

}  // namespace

Scene loadGraphScene(const ImportedGraph& g, int dimension, std::uint64_t seed, const std::string& source_name,
                     const std::string& title, const std::vector<std::string>& overrides) {
  if (dimension != 2 && dimension != 3) throw std::invalid_argument("a graph's realization has dimension 2 or 3");
  if (g.edges.empty()) throw SceneError(source_name, 1, 1, "the graph has no edge");
  if (overrides.empty())
    if (std::optional<Scene> s = directGraphScene(g, dimension, seed, source_name, title)) return std::move(*s);
  toml::table doc;
  doc.insert("title", title);
  doc.insert("system", graphSystem(g, dimension, seed, 1));
  return readScene(doc, source_name, overrides);
}

}  // namespace flexure::scenes
