// Built-in named scenes: every file of scenes/examples/, embedded in the binary at build time.
// A scene file can use one as its system with [system] type = "catalog", name = "...".
#pragma once

#include <string>
#include <vector>

namespace flexure::scenes {

struct CatalogEntry {
  std::string name;  // the example's file stem, e.g. "double_watt"
  std::string text;  // the scene file
};

const std::vector<CatalogEntry>& catalog();
// The entry called `name`, or nullptr.
const CatalogEntry* findCatalogEntry(const std::string& name);
// "unknown catalog name 'NAME'", with the closest name ("did you mean") or the list of names.
std::string unknownCatalogName(const std::string& name);

}  // namespace flexure::scenes
