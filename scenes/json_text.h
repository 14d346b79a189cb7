// JSON read by the scene language (node-link graphs, path files): a text parsed as JSON, its
// syntax errors as SceneError at their line and column. Inside scenes/ only (nlohmann is a
// private dependency of the scene library).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "scenes/scene.h"

namespace flexure::scenes {

// The deepest nesting of arrays and objects any JSON flexure reads may have: its own files nest
// at most 5 deep. Deeper input is refused before it is parsed (the parser would take it, but
// copying, comparing or printing such a value recurses once per level: 100,000 levels overflow
// the stack).
constexpr int kMaxJsonDepth = 256;

// Throws SceneError at the line and column where `text` nests deeper than kMaxJsonDepth, and
// (engine::ResourceError) when its parsed form would take more memory than the process can
// have (about 32 bytes per value: a 16-byte value and its share of its array's storage).
// `first_line`: the line `text` starts on in `file` (a line of a JSON Lines file).
void checkJsonShape(std::string_view text, const std::string& file, int first_line = 1);

// `text` parsed after checkJsonShape(); syntax errors as SceneError at their line and column.
nlohmann::json parseJsonText(const std::string& text, const std::string& file);

// A path JSON as track writes it: an object with the keys "samples" and "scene" at its top level
// (a node-link graph has "nodes" there, whatever its nodes are named); loadPathJson() says what
// is wrong with their values.
bool isPathJson(const nlohmann::json& j);

// loadPathJson (scenes/path_file.h) of a value already parsed.
Scene loadPathJson(const std::string& file, const nlohmann::json& j, const std::vector<std::string>& overrides);

}  // namespace flexure::scenes
