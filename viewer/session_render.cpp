// The session's render thread and what it renders: frames (PNG, or SVG, PDF and TikZ text)
// and the projection plot, each request made the current frame first.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "render/image.h"
#include "render/plot.h"
#include "render/renderer.h"
#include "viewer/session.h"
#include "viewer/session_internal.h"

namespace flexure::viewer {

using session_detail::animationFor;

namespace {

// A vertex this close to the pointer is shown as following it: what holds it back is drawn
// only beyond (the pointer is rarely exactly on the vertex's curve).
constexpr double kHeldPixels = 1.5;

}  // namespace

void Session::renderLoop() {
  std::unique_ptr<render::Renderer> renderer;
  try {
    renderer = std::make_unique<render::Renderer>();
  } catch (const std::exception& e) {
    std::lock_guard<std::mutex> lock(render_mutex_);
    render_error_ = std::string("cannot render: ") + e.what();
  }
  for (;;) {
    std::vector<std::packaged_task<void(render::Renderer&)>> tasks;
    {
      std::unique_lock<std::mutex> lock(render_mutex_);
      render_cv_.wait(lock, [&] { return stopping_ || !render_queue_.empty(); });
      if (render_queue_.empty()) return;  // stopping
      tasks.swap(render_queue_);
    }
    for (auto& t : tasks) {
      if (renderer) t(*renderer);
      else t = {};  // the future reports a broken promise
    }
  }
}

std::future<void> Session::onRenderThread(std::function<void(render::Renderer&)> task) const {
  std::packaged_task<void(render::Renderer&)> t(std::move(task));
  std::future<void> f = t.get_future();
  {
    std::lock_guard<std::mutex> lock(render_mutex_);
    if (!render_error_.empty()) throw std::runtime_error(render_error_);
    render_queue_.push_back(std::move(t));
  }
  render_cv_.notify_one();
  return f;
}

bool Session::takeFrameRequest(const std::shared_ptr<const Computed>& c, const FrameRequest& q,
                               std::optional<Dragged>& dragged) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (q.after > drag_seq_)
    changed_.wait_for(lock, std::chrono::seconds(1), [&] { return drag_seq_ >= q.after || stopping_; });
  if (c != computed_) return false;  // replaced meanwhile
  view_ = q;
  view_.dragged = q.dragged && dragged_;
  if (view_.dragged) dragged = *dragged_;
  return true;
}

// What frame.png draws for `q`: the sample, or the dragged configuration on screen.
present::Animation::Still Session::frameDrawing(const Computed& c, const FrameRequest& q,
                                                const std::optional<Dragged>& dragged) const {
  const auto animation = animationFor(c, q.width, q.height);
  const present::Animation& a = *animation;
  if (dragged) {
    const engine::Matrix p = c.motion.path.modelAt(dragged->sample).system().vertexPositions(dragged->result.x);
    std::vector<present::FigureExtras::Highlight> held;
    if (dragged->remaining_px >= kHeldPixels)
      for (const auto& h : dragged->result.held) held.push_back({h.vertices, std::abs(h.weight)});
    return a.configurationDrawing(dragged->sample, dragged->map.apply(p), q.options, held);
  }
  return a.sampleDrawing(q.sample, q.options);
}

std::vector<std::uint8_t> Session::framePng(const FrameRequest& q) {
  const std::shared_ptr<const Computed> c = current();
  std::optional<Dragged> dragged;
  if (!c || !takeFrameRequest(c, q, dragged)) return {};
  std::vector<std::uint8_t> png;
  onRenderThread([&](render::Renderer& r) {
    const present::Animation::Still d = frameDrawing(*c, q, dragged);
    r.render(d.list, d.view, c->image);
    png = render::encodePng(c->image, options_.png_level);
  }).get();
  return png;
}

std::string Session::frameVector(const FrameRequest& q, render::VectorFormat format) {
  const std::shared_ptr<const Computed> c = current();
  std::optional<Dragged> dragged;
  if (!c || !takeFrameRequest(c, q, dragged)) return {};
  std::string text;
  onRenderThread([&](render::Renderer&) {
    const present::Animation::Still d = frameDrawing(*c, q, dragged);
    text = render::vectorDocument(render::singlePanel(d.list, d.view, c->scene.title), format);
  }).get();
  return text;
}

std::vector<std::uint8_t> Session::projectionPng(int sample, int width, int height) {
  const std::shared_ptr<const Computed> c = current();
  if (!c) return {};
  std::vector<std::uint8_t> png;
  onRenderThread([&](render::Renderer& r) {
    if (!c->canvas || c->canvas_width != width || c->canvas_height != height) {
      c->canvas = std::make_unique<render::PlotCanvas>(c->projection.plot,
                                                       present::projectionStyle(c->scene, width, height));
      c->canvas_width = width, c->canvas_height = height;
    }
    std::optional<render::Point2> cursor;
    if (!c->projection.curves.empty()) {
      const auto& curve = c->projection.curves[0];
      const long at = static_cast<long>(c->projection.starts[0]) + std::max(sample, 0);
      if (!curve.empty()) cursor = curve[static_cast<size_t>(std::min<long>(at, static_cast<long>(curve.size()) - 1))];
    }
    r.render(c->canvas->draw(cursor), c->canvas->view(), c->image);
    png = render::encodePng(c->image, options_.png_level);
  }).get();
  return png;
}

}  // namespace flexure::viewer
