// Dragging a vertex of the configuration shown (engine::dragVertex), the dragged configuration
// as the new start, and the path continued along a chosen branch at a singular point.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include <Eigen/LU>

#include "engine/drag.h"
#include "render/camera.h"
#include "viewer/session.h"
#include "viewer/session_internal.h"

namespace flexure::viewer {

using session_detail::animationFor;
using session_detail::Clock;
using session_detail::rows;

nlohmann::ordered_json Session::drag(int vertex, double px, double py, std::uint64_t seq) {
  std::lock_guard<std::mutex> one_at_a_time(drag_mutex_);
  // Answered when this returns or throws: a frame waiting for it goes on.
  struct Answered {
    Session& s;
    std::uint64_t seq;
    ~Answered() {
      if (!seq) return;
      {
        std::lock_guard<std::mutex> lock(s.mutex_);
        s.drag_seq_ = std::max(s.drag_seq_, seq);
      }
      s.changed_.notify_all();
    }
  } answered{*this, seq};
  const auto t0 = Clock::now();
  std::shared_ptr<const Computed> c;
  FrameRequest v;
  std::optional<Dragged> from;
  snapshot(c, v, from, true);
  if (!c) throw std::invalid_argument("nothing to drag: the scene has not loaded");
  if (!std::isfinite(px) || !std::isfinite(py)) throw std::invalid_argument("the target must be finite pixels");
  Dragged next;
  {
    const auto animation = animationFor(*c, v.width, v.height);
    const present::Animation& a = *animation;
    const engine::DeformationPath& path = c->motion.path;
    const int k = from ? from->sample : std::clamp(v.sample, 0, static_cast<int>(path.samples.size()) - 1);
    const engine::Model& model = path.modelAt(k);
    const engine::ConstraintSystem& sys = model.system();
    const int base = c->scene.index_base, i = vertex - base;
    if (i < 0 || i >= sys.numVertices())
      throw std::invalid_argument("vertex " + std::to_string(vertex) + " does not exist (" + std::to_string(base) +
                                  ".." + std::to_string(sys.numVertices() - 1 + base) + ")");
    if (sys.isPinned(i)) throw std::invalid_argument("vertex " + std::to_string(vertex) + " is pinned");
    const engine::Vector& x = from ? from->result.x : path.samples[static_cast<size_t>(k)];
    const present::DisplayMap map = from ? from->map : a.displayMap(k);
    const engine::Matrix drawn = map.apply(sys.vertexPositions(x));
    const int d = sys.dimension();
    const render::Projector projector(a.viewFor(v.options));
    const render::Point3 through{drawn(0, i), drawn(1, i), d > 2 ? drawn(2, i) : 0.0};
    const render::Point3 w = projector.unproject(px, v.height - py, through);
    engine::Vector target(d);
    for (int r = 0; r < d; ++r) target[r] = w[static_cast<size_t>(r)] - map.b[r];
    target = map.A.fullPivLu().solve(target);
    engine::DragOptions o;
    // A quarter pixel, in the model's units.
    o.tolerance = 0.25 / projector.pixelsPerUnitAt(through) / std::max(map.A.norm() / std::sqrt(double(d)), 1e-300);
    o.regular_flexes = c->regular_flexes;
    // An answer in time for the next pointer move (the page asks again from where it stopped):
    // a move of a large system costs a sparse factorization or more.
    o.max_moves = sys.numVariables() <= 500 ? 12 : 3;
    o.factorization.rank_tolerance = c->scene.analysis.rank_tolerance;
    next.result = engine::dragVertex(model, x, i, target, o);
    {
      const engine::Vector p = sys.vertexPositions(next.result.x).col(i);
      const engine::Matrix shownp = map.apply(p);
      const render::Point3 at{shownp(0, 0), shownp(1, 0), d > 2 ? shownp(2, 0) : 0.0};
      const auto q = projector(at);
      next.remaining_px = std::hypot(q[0] - px, (v.height - q[1]) - py);
    }
    next.generation = c->generation;
    next.sample = k;
    next.map = map;
    next.vertex = i;
  }
  next.target_px[0] = px, next.target_px[1] = py;
  next.milliseconds = 1e3 * std::chrono::duration<double>(Clock::now() - t0).count();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (computed_ != c) throw std::invalid_argument("the scene changed during the drag; drag again");
    dragged_ = std::make_unique<Dragged>(std::move(next));
    view_.dragged = true;
    ++revision_;
  }
  return state();
}

void Session::startFromDragged() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!dragged_ || !computed_ || dragged_->generation != computed_->generation)
    throw std::invalid_argument("drag a vertex first: its configuration becomes the start");
  MotionControls next = controls_;
  next.vertices = rows(computed_->motion.path.modelAt(dragged_->sample).system().vertexPositions(dragged_->result.x));
  // A new start has its own flexes: the form's coefficients may not fit it.
  if (next.flex && !next.flex->empty()) next.flex = std::vector<double>{};
  std::vector<std::string> o = options_.overrides;
  for (auto& a : next.assignments()) o.push_back(std::move(a));
  const MotionControls old = controls_;
  controls_ = next;
  try {
    (void)scenes::loadSceneFromString(jobText(), path_, o);
  } catch (const scenes::SceneError& e) {
    controls_ = old;
    throw std::invalid_argument("this scene cannot start from the dragged configuration: " + e.message);
  }
  submitLocked();
}

void Session::followBranch(int sample, int direction) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!computed_) throw std::invalid_argument("nothing loaded");
  for (const auto& b : computed_->branches)
    if (b.sample == sample) {
      if (direction < 0 || direction >= static_cast<int>(b.cone.directions.size()))
        throw std::invalid_argument("sample " + std::to_string(sample) + " has " +
                                    std::to_string(b.cone.directions.size()) + " branch direction(s)");
      pipeline::StudyOptions::Branch br;
      br.sample = sample;
      br.direction = b.cone.directions[static_cast<size_t>(direction)];
      br.point = b.cone.point;
      br.note = "branch direction " + std::to_string(direction) + " (" + b.cone.kinds[static_cast<size_t>(direction)] + ")";
      pending_ = Job{computed_->text, computed_->overrides, next_job_++, br};
      cancel_below_ = pending_->id;
      ++revision_;
      changed_.notify_all();
      return;
    }
  throw std::invalid_argument("sample " + std::to_string(sample) + " is not a singular point of the path");
}

}  // namespace flexure::viewer
