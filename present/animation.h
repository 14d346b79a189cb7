// The frames of an animation and the viewer's pictures of single samples: aligned
// configurations, one camera for all, optional rotation, event captions and the projection
// plot beside it.
#pragma once

#include <algorithm>
#include <optional>
#include <vector>

#include "engine/deformation_path.h"
#include "present/figure.h"
#include "present/frames.h"
#include "present/projection.h"
#include "render/plot.h"
#include "render/renderer.h"
#include "scenes/scene.h"

namespace flexure::present {

// What the viewer changes per frame; unset keeps the scene's [render] choice.
struct FrameOptions {
  std::optional<bool> labels, trace;
  bool flex = false;                         // arrows: the path's velocity at the sample shown
  std::optional<double> azimuth, elevation;  // 3D camera, radians
  double zoom = 1;
  double pan_x = 0, pan_y = 0;               // pixels, x right and y down as in the image
};

// The frames of an animation: aligned configurations, one camera for all, optional rotation,
// event captions and the projection plot beside it.
class Animation {
 public:
  // `projection`: drawn beside the mechanism with side_by_side; its first path must be the
  // scene's motion (a cursor follows it). `size_scale`: a figure sized in lengths draws its
  // sizes this much larger (a GIF scaled down to gif_size: smaller).
  Animation(const Scene& scene, const engine::DeformationPath& path, int width, int height,
            const Projection* projection = nullptr, double size_scale = 1);
  int frameCount() const { return static_cast<int>(samples_.size()); }
  int width() const { return width_; }
  int height() const { return height_; }
  int sampleCount() const { return static_cast<int>(positions_.size()); }
  // Draws frame i into `out` (reusing its memory).
  void frame(int i, render::Renderer& renderer, render::Image& out) const;
  // Draws sample k of the path (any sample, not only the animation's frames) as the viewer
  // asks for it; no turntable, no side-by-side plot.
  void sample(int k, const FrameOptions& options, render::Renderer& renderer, render::Image& out) const;
  // The camera of sample() with these options.
  render::View viewFor(const FrameOptions& options) const;
  // Sample k as a still: what frame() draws for it (the path's one alignment and camera
  // orientation), framed on the sample itself, without the turntable, the plot beside it and the
  // event caption. With `flex` (d x n velocities in the path's coordinates) its arrows are
  // drawn, and the framing holds them too.
  struct Still {
    render::DrawList list;
    render::View view;
  };
  // `style`: another look (the path's own, style(), with parts styled: a stress drawn).
  Still still(int k, const engine::Matrix* flex = nullptr, const FigureStyle* style = nullptr) const;
  // The look the frames are drawn in (sizes adapted to the path).
  const FigureStyle& style() const { return style_; }
  // How sample k is shown: its positions as drawn, and the map from the path's positions.
  const engine::Matrix& shownPositions(int k) const { return positions_[static_cast<size_t>(clampSample(k))]; }
  const DisplayMap& displayMap(int k) const { return maps_[static_cast<size_t>(clampSample(k))]; }
  // Draws `shown` (d x n, positions as drawn) with the structure of sample k, as sample() draws
  // a sample (the viewer's dragged configuration); `highlight` as in FigureExtras.
  void configuration(int k, const engine::Matrix& shown, const FrameOptions& options,
                     const std::vector<FigureExtras::Highlight>& highlight, render::Renderer& renderer,
                     render::Image& out) const;
  // What sample() and configuration() draw, as a drawing and its camera (for vector output).
  Still sampleDrawing(int k, const FrameOptions& options) const;
  Still configurationDrawing(int k, const engine::Matrix& shown, const FrameOptions& options,
                             const std::vector<FigureExtras::Highlight>& highlight) const;

 private:
  const Scene& scene_;
  const engine::DeformationPath& path_;
  std::vector<int> samples_;               // sample index per frame
  std::vector<engine::Matrix> positions_;  // aligned, per sample of the path
  std::vector<DisplayMap> maps_;           // path positions -> positions_
  int clampSample(int k) const { return std::clamp(k, 0, static_cast<int>(positions_.size()) - 1); }
  std::optional<engine::Matrix> ghost_;
  std::vector<render::Polygon> surface_;  // a framework's surface, meshed once for the view
  FigureStyle style_;
  // `flex`: arrows from the path's velocity at k; `field`: these velocities instead (display frame).
  // `caption`: the event caption of an animation (mark_events).
  render::DrawList figureAt(int k, const FigureStyle& style, bool flex, const engine::Matrix* field = nullptr,
                            bool caption = true) const;
  render::View view_;
  int width_, height_, panel_width_;
  std::optional<render::PlotCanvas> plot_;
  std::vector<render::Point2> cursor_path_;  // the projected motion, from its start
  mutable render::Image left_, right_;       // the two panels side by side
};

}  // namespace flexure::present
