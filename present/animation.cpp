#include "present/animation.h"

#include <algorithm>
#include <cmath>

#include "present/frames.h"
#include "present/surface_mesh.h"

namespace flexure::present {

Animation::Animation(const Scene& scene, const engine::DeformationPath& path, int width, int height,
                     const Projection* projection, double size_scale)
    : scene_(scene), path_(path), width_(width), height_(height) {
  const auto& sys = scene.model->system();
  const scenes::AnimationSettings& as = scene.render.animation;
  const auto& samples = path.samples;
  samples_ = frameSamples(static_cast<int>(samples.size()), as.frame_step);
  for (const auto& x : samples) positions_.push_back(sys.vertexPositions(x));
  if (const std::vector<int> simplex = fixedSimplex(scene); !simplex.empty())
    normalizeEquiAffine(positions_, simplex, as.target_stretch, as.tip_value, &maps_);
  else
    alignConfigurations(positions_, fixedVertices(scene), as.fixed_direction, &maps_);
  const bool side = as.side_by_side && projection;
  panel_width_ = side ? width / 2 : width;
  style_ = scene.render.style;
  style_.width = panel_width_;
  style_.height = height;
  style_.unit_px *= size_scale;
  if (style_.ghost >= 0 && style_.ghost < static_cast<int>(positions_.size())) ghost_ = positions_[style_.ghost];
  const engine::Geometry geometry = scene.model->geometry();
  view_ = fitAdapted(geometry, positions_, style_);
  view_.turntable = as.rotate && view_.three_d;
  surface_ = surfaceMesh(geometry, view_, style_);
  if (side) {
    plot_.emplace(projection->plot, projectionStyle(scene, width - panel_width_, height));
    if (!projection->curves.empty())
      cursor_path_.assign(projection->curves[0].begin() + projection->starts[0], projection->curves[0].end());
  }
}

render::DrawList Animation::figureAt(int k, const FigureStyle& style, bool flex, const engine::Matrix* field,
                                     bool caption) const {
  const scenes::AnimationSettings& as = scene_.render.animation;
  const auto at = [&](int j) -> const engine::Matrix& { return positions_[static_cast<size_t>(j)]; };
  FigureExtras extras;
  if (style.trace)
    for (int j = 0; j <= k; ++j) extras.trace.push_back(at(j));
  extras.ghost = ghost_;
  extras.surface = &surface_;
  const int last = static_cast<int>(positions_.size()) - 1;
  if (field) {
    extras.flex = *field;
  } else if (flex && last > 0) {
    // The velocity of the picture: a central difference of the aligned positions (one-sided at
    // the ends); figure() scales the longest arrow to flex_scale of the extent.
    const int a = std::max(0, k - 1), b = std::min(last, k + 1);
    extras.flex = at(b) - at(a);
    if (extras.flex.norm() == 0) extras.flex.resize(0, 0);
  }
  render::DrawList list = figure(path_.geometryAt(k), at(k), style, extras);
  if (caption && as.mark_events) {
    // A caption for half a second after each singular point or new contact.
    const int hold = std::max(1, scene_.render.fps / 2) * std::max(1, as.frame_step);
    for (auto it = path_.events.rbegin(); it != path_.events.rend(); ++it)
      if (k >= it->sample && k < it->sample + hold) {
        render::Label l;
        const double px = pixelScale(style);
        l.screen = true;
        l.at = {30 * px, 45 * px, 0};
        l.align = -1;
        l.size = static_cast<float>(style.font_size * px);
        l.color = render::Color{0xCD / 255.f, 0, 0, 1};
        l.role = "caption";
        l.text = (it->kind != engine::EventKind::Singularity ? it->detail : "singular point") + " (sample " + std::to_string(it->sample) + ")";
        list.labels.push_back(l);
        break;
      }
  }
  return list;
}

render::View Animation::viewFor(const FrameOptions& o) const {
  render::View view = view_;
  view.turntable = false;
  if (o.azimuth) view.azimuth = *o.azimuth;
  if (o.elevation) view.elevation = *o.elevation;
  view.zoom = o.zoom;
  view.pan_x = o.pan_x;
  view.pan_y = -o.pan_y;
  return view;
}

Animation::Still Animation::still(int k, const engine::Matrix* flex, const FigureStyle* style) const {
  k = clampSample(k);
  Still s;
  // The path's alignment and camera, framed on this sample alone (and its arrows): a still does
  // not depend on where the rest of the path goes. No event caption: a still has no time.
  std::vector<engine::Matrix> frames{positions_[static_cast<size_t>(k)]};
  engine::Matrix field;
  if (flex && flex->size() > 0) {
    // Velocities move with the linear part of the display map.
    field = maps_[static_cast<size_t>(k)].A * *flex;
    frames.push_back(flexTips(frames.front(), field, style_));
  }
  s.list = figureAt(k, style ? *style : style_, false, field.size() > 0 ? &field : nullptr, false);
  s.view = view_;
  s.view.turntable = false;
  const render::View fitted = fitView(path_.geometryAt(k), frames, style_);
  s.view.lo = fitted.lo, s.view.hi = fitted.hi;
  return s;
}

Animation::Still Animation::sampleDrawing(int k, const FrameOptions& o) const {
  k = clampSample(k);
  FigureStyle style = style_;
  if (o.labels) style.labels = *o.labels;
  if (o.trace) style.trace = *o.trace;
  return {figureAt(k, style, o.flex), viewFor(o)};
}

void Animation::sample(int k, const FrameOptions& o, render::Renderer& renderer, render::Image& out) const {
  const Still s = sampleDrawing(k, o);
  renderer.render(s.list, s.view, out);
}

Animation::Still Animation::configurationDrawing(int k, const engine::Matrix& shown, const FrameOptions& o,
                                                 const std::vector<FigureExtras::Highlight>& highlight) const {
  FigureStyle style = style_;
  if (o.labels) style.labels = *o.labels;
  FigureExtras extras;
  extras.surface = &surface_;
  extras.highlight = highlight;
  return {figure(path_.geometryAt(clampSample(k)), shown, style, extras), viewFor(o)};
}

void Animation::configuration(int k, const engine::Matrix& shown, const FrameOptions& o,
                              const std::vector<FigureExtras::Highlight>& highlight, render::Renderer& renderer,
                              render::Image& out) const {
  const Still s = configurationDrawing(k, shown, o, highlight);
  renderer.render(s.list, s.view, out);
}

void Animation::frame(int i, render::Renderer& renderer, render::Image& out) const {
  const scenes::AnimationSettings& as = scene_.render.animation;
  const int k = samples_[static_cast<size_t>(i)];
  render::DrawList list = figureAt(k, style_, false);
  render::View view = view_;
  if (as.rotate && view.three_d) view.azimuth = style_.azimuth + 2 * M_PI * i / as.rotation_frames;
  if (!plot_) {
    renderer.render(list, view, out);
    return;
  }
  renderer.render(list, view, left_);
  std::optional<render::Point2> cursor;
  if (static_cast<size_t>(k) < cursor_path_.size()) cursor = cursor_path_[static_cast<size_t>(k)];
  renderer.render(plot_->draw(cursor), plot_->view(), right_);
  out.width = width_, out.height = height_;
  out.rgba.resize(static_cast<size_t>(width_) * height_ * 4);
  for (int y = 0; y < height_; ++y) {
    std::copy_n(left_.pixel(0, y), static_cast<size_t>(left_.width) * 4, &out.rgba[static_cast<size_t>(y) * width_ * 4]);
    std::copy_n(right_.pixel(0, y), static_cast<size_t>(right_.width) * 4,
                &out.rgba[(static_cast<size_t>(y) * width_ + left_.width) * 4]);
  }
}

}  // namespace flexure::present
