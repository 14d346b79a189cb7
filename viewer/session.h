// What `flexure view` shows, apart from HTTP: the scene file watched on disk, its motion
// computed in the background (the last good one stays shown while a new one computes or
// when the file has an error), the viewer's motion controls as --set overrides on top of the
// file, and frames and projection plots rendered on demand on one render thread.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "pipeline/pipeline.h"
#include "present/animation.h"
#include "render/vector.h"
#include "scenes/scene.h"

namespace flexure::viewer {

// The motion controls of the page; unset keeps the scene file's value.
struct MotionControls {
  std::optional<std::vector<double>> flex;  // empty vector: "auto"
  std::optional<double> step_size;
  std::optional<int> steps;
  std::optional<std::uint64_t> seed;
  std::optional<bool> certify;  // motion.certify: the Krawczyk certificate of every sample and step
  // A new start: every vertex's coordinates (a dragged configuration), as system.vertices.
  std::optional<std::vector<std::vector<double>>> vertices;
  // As --set assignments, in this order: motion.flex, motion.step_size, motion.steps,
  // motion.seed, motion.certify, system.vertices.
  std::vector<std::string> assignments() const;
};

// One frame as the page asks for it; the last one asked for is the current frame, in whose
// pixels the API's screen positions and drag targets are.
struct FrameRequest {
  int sample = 0;
  int width = 800, height = 800;
  present::FrameOptions options;
  bool dragged = false;  // the dragged configuration (if there is one) instead of the sample
  // Wait (up to a second) until the drag numbered `after` has been answered: the page asks for
  // the frame of a drag while the drag is still under way, saving a round trip.
  std::uint64_t after = 0;
};

struct SessionOptions {
  std::vector<std::string> overrides;  // the command line's --set, applied before the controls
  int max_steps = 100000;              // the steps control's bound
  int png_level = 1;                   // fast PNG for interactive frames
  // Told one line after each computation ("501 samples, success ... (190 ms)" or the error).
  std::function<void(const std::string&)> log;
};

// A scene that loaded, and everything computed from it; never changed once published.
struct Computed;

class Session {
 public:
  // Reads `scene_path` and starts computing. Throws SceneError when the file cannot be read;
  // a scene error in a readable file is kept and shown (the page waits for a fixed file).
  Session(std::string scene_path, SessionOptions options = {});
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  // Reads the scene file when its time stamp or size changed; when its text changed, starts a
  // recompute (an unfinished one is abandoned). Returns whether it did.
  bool checkFile();
  // Validates the controls at once (throws SceneError with the reason) and recomputes.
  void setControls(const MotionControls& controls);
  // Back to the scene file's motion.
  void resetControls();

  // Everything the page shows except images. `revision` changes whenever any of it changes
  // except the current frame (the configuration shown, its screen positions and residual,
  // which are always as of the call).
  nlohmann::ordered_json state() const;
  std::uint64_t revision() const;
  // Blocks until no computation is pending (tests); false on timeout.
  bool waitIdle(double seconds) const;

  // PNG of a frame / of the projection plot with its marker at `sample`, from the current
  // state (an empty result when nothing has loaded yet). Rendered on the render thread.
  std::vector<std::uint8_t> framePng(const FrameRequest& request);
  // The same frame as SVG, PDF or TikZ text (the exports of the page); "" when nothing is loaded.
  std::string frameVector(const FrameRequest& request, render::VectorFormat format);
  std::vector<std::uint8_t> projectionPng(int sample, int width, int height);

  // Pulls vertex `vertex` (numbered as in the scene file) of the configuration shown towards
  // pixel (px, py) of the current frame (origin at the top left; in 3D within the view plane
  // through the vertex); the mechanism follows on its constraint set (engine::dragVertex). The
  // frame then shows the dragged configuration. Returns the new state. Throws
  // std::invalid_argument for a vertex that does not exist or is pinned, or nothing loaded.
  // `seq` (optional, increasing) numbers the drag for FrameRequest::after; it counts as
  // answered when drag returns or throws.
  nlohmann::ordered_json drag(int vertex, double px, double py, std::uint64_t seq = 0);
  // The dragged configuration becomes the start (the control system.vertices) and the motion
  // is tracked from it. Throws std::invalid_argument when nothing was dragged or the scene
  // does not load with it.
  void startFromDragged();
  // Continues the path from singular sample `sample` along direction `direction` of the
  // state's branches there. Throws std::invalid_argument when there is no such direction.
  void followBranch(int sample, int direction);
  // The path shown, as `track` writes it (JSON or CSV); empty when nothing has loaded.
  std::string pathText(bool csv) const;

  // The scene file's text (of the state shown) with the controls written into it.
  std::string sceneText() const;
  // Writes sceneText() as `name` in the scene file's directory. `name` is a plain file name ending in .toml; an existing file is replaced only
  // with `overwrite`. Returns the path written. Throws std::invalid_argument for a bad name or
  // an existing file, OutputError when writing fails.
  std::string saveAs(const std::string& name, bool overwrite) const;

  const std::string& scenePath() const { return path_; }

 private:
  struct Job {
    std::string text;
    std::vector<std::string> overrides;
    std::uint64_t id;
    std::optional<pipeline::StudyOptions::Branch> branch;
  };
  struct Dragged;
  struct Shown;
  Shown shown(const Computed& c, const FrameRequest& view, const std::optional<Dragged>& dragged) const;
  // The computed state, the current frame and the last drag (only if shown, with shown_only),
  // read together.
  void snapshot(std::shared_ptr<const Computed>& c, FrameRequest& view, std::optional<Dragged>& dragged,
                bool shown_only) const;
  // frame.png's request made current (waiting up to a second for the drag it names); false
  // when `c` was replaced meanwhile. `dragged`: the dragged configuration it shows, if any.
  bool takeFrameRequest(const std::shared_ptr<const Computed>& c, const FrameRequest& q,
                        std::optional<Dragged>& dragged);
  // What the frame shows (on the render thread: the animation is cached per size).
  present::Animation::Still frameDrawing(const Computed& c, const FrameRequest& q,
                                         const std::optional<Dragged>& dragged) const;
  void submitLocked(std::optional<pipeline::StudyOptions::Branch> branch = std::nullopt);
  std::string jobText() const;  // the text a job loads (the system spelled out with a moved start)
  void computeLoop();
  void renderLoop();
  std::future<void> onRenderThread(std::function<void(render::Renderer&)> task) const;
  void submit(std::string text);
  std::shared_ptr<const Computed> current() const;
  std::vector<std::string> overrides() const;

  std::string path_;
  const scenes::CatalogEntry* catalog_;  // a catalog name instead of a file: nothing to watch
  SessionOptions options_;

  mutable std::mutex mutex_;  // everything below until the threads
  mutable std::condition_variable changed_;
  std::shared_ptr<const Computed> computed_;
  std::string text_;                 // the file's text last read
  long long mtime_ns_ = -1, size_ = -1;
  MotionControls controls_;
  std::mutex drag_mutex_;             // one drag at a time (each starts where the last ended)
  std::uint64_t drag_seq_ = 0;        // the largest drag number answered (under mutex_)
  FrameRequest view_;                 // the current frame
  std::unique_ptr<Dragged> dragged_;  // the last drag (of computed_'s generation)
  std::optional<Job> pending_;
  bool computing_ = false;
  std::uint64_t next_job_ = 1;
  std::uint64_t revision_ = 1;
  std::optional<scenes::SceneError> error_;
  std::string read_error_;           // the file could not be read (it may come back)
  std::string error_line_;           // the text of the error's line
  std::string failure_;              // a computation that failed other than by a scene error
  std::atomic<std::uint64_t> cancel_below_{0};  // jobs with a smaller id stop at their next step
  bool stopping_ = false;

  mutable std::mutex render_mutex_;
  mutable std::condition_variable render_cv_;
  mutable std::vector<std::packaged_task<void(render::Renderer&)>> render_queue_;
  std::string render_error_;

  std::thread compute_thread_, render_thread_;
};

}  // namespace flexure::viewer
