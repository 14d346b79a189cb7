// The session's parts shared by its files (viewer/session*.cpp): what a computation publishes
// (Computed), the last drag (Session::Dragged) and the helpers more than one of them uses.
#pragma once

#include <chrono>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "engine/drag.h"
#include "render/image.h"
#include "render/plot.h"
#include "viewer/session.h"

namespace flexure::viewer {

struct Computed {
  std::uint64_t generation = 0;
  std::string text;                    // the scene file's text
  std::vector<std::string> overrides;  // --set, then the controls
  scenes::Scene scene;
  pipeline::Motion motion;
  nlohmann::ordered_json report;
  std::string report_text;
  std::vector<present::ProjectionPath> paths;
  present::Projection projection;
  double seconds = 0;
  // The tangent cone at the path's singular points (pipeline::addBranchDirections).
  struct BranchPoint {
    int sample = 0;
    std::string event;
    engine::BranchDirections cone;
  };
  std::vector<BranchPoint> branches;
  // Nontrivial flexes at a regular point of the path (a drag finds singular points by more).
  int regular_flexes = -1;
  std::string branch_note;            // the path left a singular point along a chosen branch
  // Only the render thread touches these: the views at the last size asked for.
  // The animation (camera, aligned samples) at the last frame size: made by whichever thread
  // needs it first (render thread, drags, the state's screen positions), then only read.
  mutable std::mutex animation_mutex;
  mutable std::shared_ptr<const present::Animation> animation;
  mutable std::unique_ptr<render::PlotCanvas> canvas;
  mutable int canvas_width = 0, canvas_height = 0;
  mutable render::Image image;
};

struct Session::Dragged {
  std::uint64_t generation = 0;
  int sample = 0;  // the sample the drag started from: its model and display map
  present::DisplayMap map;
  engine::DragResult result;  // result.x: the dragged configuration
  int vertex = 0;  // 0-based
  double target_px[2] = {0, 0};
  double remaining_px = 0;  // from the vertex to the pointer, in the frame's pixels
  double milliseconds = 0;
};

namespace session_detail {

using Clock = std::chrono::steady_clock;

// The animation for frames of this size (any thread: its const methods only read).
inline std::shared_ptr<const present::Animation> animationFor(const Computed& c, int width, int height) {
  std::lock_guard<std::mutex> lock(c.animation_mutex);
  if (!c.animation || c.animation->width() != width || c.animation->height() != height)
    c.animation = std::make_shared<const present::Animation>(c.scene, c.motion.path, width, height);
  return c.animation;
}

// The columns of a d x n matrix as rows of numbers (a scene's vertices).
inline std::vector<std::vector<double>> rows(const engine::Matrix& p) {
  std::vector<std::vector<double>> out(static_cast<size_t>(p.cols()));
  for (int i = 0; i < p.cols(); ++i) out[static_cast<size_t>(i)].assign(p.col(i).data(), p.col(i).data() + p.rows());
  return out;
}

}  // namespace session_detail

}  // namespace flexure::viewer
