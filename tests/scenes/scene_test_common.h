// Helpers shared by the scene tests: catalog scenes and scene errors with their position.
#pragma once

#include <catch2/catch.hpp>
#include <string>
#include <vector>

#include "scenes/catalog.h"
#include "scenes/scene.h"

namespace flexure::test {

// The catalog entry `name`, with `--set`-style overrides.
inline scenes::Scene example(const std::string& name, const std::vector<std::string>& overrides = {}) {
  const scenes::CatalogEntry* e = scenes::findCatalogEntry(name);
  REQUIRE(e != nullptr);
  return scenes::loadSceneFromString(e->text, "catalog:" + name, overrides);
}

// Loading `toml` fails at line:column with a message containing `text`.
inline void requireSceneError(const std::string& toml, int line, int column, const std::string& text) {
  INFO(toml);
  try {
    scenes::loadSceneFromString(toml, "t.toml");
    FAIL("no error");
  } catch (const scenes::SceneError& e) {
    INFO(e.what());
    CHECK(e.line == line);
    CHECK(e.column == column);
    CHECK_THAT(e.message, Catch::Contains(text));
  }
}

}  // namespace flexure::test
