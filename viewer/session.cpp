// The session's construction and core: the threads started and stopped, the computed state
// and the current frame read under the lock, and the jobs submitted. The rest is in
// session_watch.cpp, session_compute.cpp, session_state.cpp, session_drag.cpp,
// session_render.cpp and session_controls.cpp.
#include "viewer/session.h"

#include "present/path_output.h"
#include "present/text.h"
#include "viewer/session_internal.h"

namespace flexure::viewer {

Session::Session(std::string scene_path, SessionOptions options)
    : path_(std::move(scene_path)), catalog_(scenes::catalogArgument(path_)), options_(std::move(options)) {
  if (!catalog_) (void)scenes::readSceneFile(path_);  // an unreadable file is an error at once
  compute_thread_ = std::thread([this] { computeLoop(); });
  render_thread_ = std::thread([this] { renderLoop(); });
  checkFile();
}

Session::~Session() {
  {
    // Both threads read stopping_ under their own mutex.
    std::lock_guard<std::mutex> lock(mutex_);
    std::lock_guard<std::mutex> render_lock(render_mutex_);
    stopping_ = true;
    cancel_below_ = ~std::uint64_t{0};
  }
  changed_.notify_all();
  render_cv_.notify_all();
  compute_thread_.join();
  render_thread_.join();
}

bool Session::waitIdle(double seconds) const {
  std::unique_lock<std::mutex> lock(mutex_);
  return changed_.wait_for(lock, std::chrono::duration<double>(seconds), [&] { return !pending_ && !computing_; });
}

std::uint64_t Session::revision() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return revision_;
}

std::shared_ptr<const Computed> Session::current() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return computed_;
}

void Session::snapshot(std::shared_ptr<const Computed>& c, FrameRequest& view, std::optional<Dragged>& dragged,
                       bool shown_only) const {
  std::lock_guard<std::mutex> lock(mutex_);
  c = computed_;
  view = view_;
  if (dragged_ && (view.dragged || !shown_only)) dragged = *dragged_;
}

// The text a job loads: the scene's own, or, with a moved start, the scene as one text with
// its system spelled out (`[system] from = FILE` or a catalog entry take no vertices).
std::string Session::jobText() const {
  if (!controls_.vertices) return text_;
  try {
    (void)scenes::loadSceneFromString(text_, path_, overrides());
    return text_;  // the file itself takes the vertices (and keeps its comments when saved)
  } catch (const scenes::SceneError&) {
  }
  try {
    const scenes::Scene s = scenes::loadSceneFromString(text_, path_, options_.overrides);
    if (s.document) return s.document();
  } catch (const scenes::SceneError&) {
  }
  return text_;
}

void Session::submitLocked(std::optional<pipeline::StudyOptions::Branch> branch) {
  pending_ = Job{jobText(), overrides(), next_job_++, std::move(branch)};
  cancel_below_ = pending_->id;
  ++revision_;
  changed_.notify_all();
}

std::string Session::pathText(bool csv) const {
  const std::shared_ptr<const Computed> c = current();
  if (!c) return "";
  return csv ? present::pathCsv(c->scene, c->motion.path) : present::jsonText(present::pathJson(c->scene, c->motion.path));
}

}  // namespace flexure::viewer
