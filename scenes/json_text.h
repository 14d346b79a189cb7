// JSON read by the scene language (node-link graphs, path files): a text parsed as JSON, its
// syntax errors as SceneError at their line and column. Inside scenes/ only (nlohmann is a
// private dependency of the scene library).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace flexure::scenes {

nlohmann::json parseJsonText(const std::string& text, const std::string& file);

}  // namespace flexure::scenes
