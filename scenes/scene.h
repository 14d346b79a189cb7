// A scene: one geometric constraint system, how to move it and how to show it (SPEC section 2).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/model.h"
#include "scenes/figure.h"

namespace flexure::scenes {

// A scene-file problem, reported as "FILE:LINE:COLUMN: message".
class SceneError : public std::runtime_error {
 public:
  SceneError(std::string file, int line, int column, const std::string& message)
      : std::runtime_error(file + ":" + std::to_string(line) + ":" + std::to_string(column) +
                           ": " + message),
        file(std::move(file)), line(line), column(column), message(message) {}
  std::string file;
  int line;
  int column;
  std::string message;
};

struct MotionSettings {
  int steps = 100;                           // samples to compute after the start
  double step_size = 0.01;                   // predictor step length
  std::optional<std::vector<double>> flex;   // coefficients in the nontrivial-flex basis; unset = "auto"
  std::uint64_t seed = 1;                    // every random choice derives from it
  std::string flex_where;                    // "FILE:LINE:COLUMN" of the flex key, for messages
};

struct AnalysisSettings {
  double rank_tolerance = 1e-9;  // singular values <= rank_tolerance * sigma_max count as zero
};

struct RenderSettings {
  int width = 1000;
  int height = 1000;
  int fps = 25;
  FigureStyle style;  // the look: colours, sizes, toggles, camera (its width/height unused)
};

struct OutputSpec {
  std::string file;
  std::string kind;  // "frame", "animation", "path" or "projection"
};

struct Scene {
  std::string path;        // the file it came from (or "catalog:NAME")
  std::string title;
  std::string type;        // the [system] type after resolving "catalog"
  int index_base = 1;      // vertex numbers in the file count from this
  std::unique_ptr<engine::Model> model;
  MotionSettings motion;
  AnalysisSettings analysis;
  RenderSettings render;
  std::vector<OutputSpec> outputs;
};

// Loads and validates a scene file. `overrides` are "KEY=VALUE" strings (the CLI's --set),
// applied before validation; VALUE is a TOML value (a bare word is taken as a string).
// Throws SceneError for every problem with the input, including an unreadable file.
Scene loadScene(const std::string& path, const std::vector<std::string>& overrides = {});
Scene loadSceneFromString(const std::string& text, const std::string& source_name,
                          const std::vector<std::string>& overrides = {});

}  // namespace flexure::scenes
