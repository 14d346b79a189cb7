// The catalog meta-type: [system] type = "catalog" builds the named entry's system, the entry's
// title and settings become the defaults of the scene's own, and a command's SCENE argument may
// name an entry instead of a file.
#include <algorithm>
#include <filesystem>

#include "scenes/catalog.h"
#include "scenes/keys.h"
#include "scenes/loader_parts.h"
#include "scenes/scene.h"

namespace flexure::scenes {

namespace detail {

std::unique_ptr<engine::Model> buildCatalog(const Reader& r, const toml::table& sys, int outer_base,
                                            std::string& type_out, int depth, toml::table* resolved) {
  r.checkKeys(sys, keysOf("system", "catalog"), "[system] (catalog)");
  const toml::node& nn = r.require(sys, "name", "[system]");
  const std::string name = r.string(nn, "name");
  const CatalogEntry* entry = findCatalogEntry(name);
  if (!entry) r.fail(nn, unknownCatalogName(name));
  if (depth > 4) r.fail(nn, "catalog entries refer to each other in a loop");
  const std::string src = "catalog:" + entry->name;
  toml::table doc;
  try {
    doc = toml::parse(entry->text, src);
  } catch (const toml::parse_error& e) {
    r.fail(e.source(), std::string(e.description()));
  }
  Reader inner(src);
  int base = 1;
  if (const toml::node* b = doc.get("index_base")) base = static_cast<int>(inner.integer(*b, "index_base"));
  const toml::table& entry_system = inner.table(inner.require(doc, "system", "the scene"), "[system]");
  // The scene's own text (a path JSON's scene, a viewer's moved start) holds the entry's system
  // where it numbers vertices as the scene does.
  if (resolved && base == outer_base && !entry_system.contains("from")) *resolved = entry_system;
  return buildModel(inner, entry_system, base, type_out, depth + 1);
}

// [system] type = "catalog": the entry's title and its [motion], [analysis], [render] and
// [projection] keys are the defaults of the scene's own (the scene's keys win, key by key; its
// [[output]] are its own). The settings that name vertices are read with the scene's
// index_base, so they are taken only when the entry counts vertices the same way.
namespace {
// The [motion] keys that drive a motion instead of a flex direction.
constexpr const char* kDrives[] = {"contract_edge", "target_length", "fold_crease", "fold_angle", "fold_percent"};
}  // namespace

void mergeCatalogEntry(toml::table& doc) {
  const toml::table* sys = doc["system"].as_table();
  if (!sys || (*sys)["type"].value_or(std::string()) != "catalog") return;
  const CatalogEntry* entry = findCatalogEntry((*sys)["name"].value_or(std::string()));
  if (!entry) return;  // buildCatalog reports it at the name
  toml::table e;
  try {
    e = toml::parse(entry->text, "catalog:" + entry->name);
  } catch (const toml::parse_error&) {
    return;  // buildCatalog reports it
  }
  if (!doc.contains("title") && e.contains("title")) doc.insert("title", *e.get("title"));
  if (doc["index_base"].value_or(int64_t{1}) != e["index_base"].value_or(int64_t{1})) return;
  for (const char* key : {"motion", "analysis", "render", "projection"}) {
    const toml::table* from = e[key].as_table();
    if (!from) continue;
    if (!doc.contains(key)) {
      doc.insert(key, *from);
      continue;
    }
    toml::table* to = doc[key].as_table();
    if (!to) continue;  // not a table: readScene reports it
    // A scene that drives the motion itself (contracts an edge, drives a fold) does not take
    // the entry's flex direction, nor its own way of driving.
    const bool driven = std::string(key) == "motion" &&
                        std::any_of(std::begin(kDrives), std::end(kDrives), [&](const char* d) { return to->contains(d); });
    for (const auto& [k, v] : *from) {
      if (driven && (k.str() == "flex" || std::find(std::begin(kDrives), std::end(kDrives), k.str()) != std::end(kDrives)))
        continue;
      if (!to->contains(k.str())) to->insert(k.str(), v);
    }
  }
}

}  // namespace detail

std::string unknownCatalogName(const std::string& name) {
  std::string best;
  int best_d = std::max<int>(3, static_cast<int>(name.size()) / 3);
  for (const auto& e : catalog())
    if (const int d = editDistance(name, e.name); d < best_d) best_d = d, best = e.name;
  if (!best.empty()) return "unknown catalog name '" + name + "' (did you mean '" + best + "'?)";
  std::string known;
  for (const auto& e : catalog()) known += (known.empty() ? "" : ", ") + e.name;
  return "unknown catalog name '" + name + "' (see `flexure catalog`: " + known + ")";
}

const CatalogEntry* catalogArgument(const std::string& argument) {
  std::error_code ec;
  if (std::filesystem::exists(argument, ec)) return nullptr;  // a file of that name wins
  const std::string name = argument.rfind("catalog:", 0) == 0 ? argument.substr(8) : argument;
  return findCatalogEntry(name);
}

}  // namespace flexure::scenes
