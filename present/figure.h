// The bridge from engine geometry to drawables: one configuration (plus optional flex arrows,
// a trace of the path and a ghost of another sample) becomes a render::DrawList, in 2D and 3D
// alike. The look follows the reference package (notes section 4); every colour, size and
// toggle is a [render] key (FigureStyle).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "engine/constraint_system.h"
#include "engine/geometry.h"
#include "render/draw_list.h"
#include "scenes/style.h"

namespace flexure::present {

using scenes::FigureStyle;

struct FigureExtras {
  engine::Matrix flex;                   // d x n velocity field to draw as arrows (empty: none)
  std::vector<engine::Matrix> trace;     // positions of the samples to trace through
  std::optional<engine::Matrix> ghost;   // positions drawn underneath
  const std::vector<render::Polygon>* surface = nullptr;  // surfaceMesh(), drawn translucent
  // Groups of vertices drawn over the bars in the alert colour (the viewer's drag: the
  // constraints that hold a vertex back), consecutive vertices joined (single ones ringed), the
  // stronger (0..1) the wider.
  struct Highlight {
    std::vector<int> vertices;
    double strength = 1;
  };
  std::vector<Highlight> highlight;
};

// The geometry's surface (if any) as shaded translucent triangles clipped to the view's box;
// empty without a surface. Computed once per view (it does not move with the framework).
std::vector<render::Polygon> surfaceMesh(const engine::Geometry& g, const render::View& view, const FigureStyle& style);

// The view that fits every one of `frames` (d x n positions) with the padding rule, so that an
// animation's camera stays put.
render::View fitView(const engine::Geometry& g, const std::vector<engine::Matrix>& frames, const FigureStyle& style);

// The style the figure is drawn with: with auto_size, the vertex discs (and with them bars,
// arrows and labels) shrink so that a disc is at most 0.6 of the median bar on screen (never
// below a 2-pixel disc and 1-pixel bars); with auto_labels, labels are left out when they would
// be under 6 pixels or there are more than 200 vertices. `frames` and `view` as fitView's.
FigureStyle adaptStyle(const FigureStyle& style, const engine::Geometry& g, const std::vector<engine::Matrix>& frames,
                       const render::View& view);
// fitView, adaptStyle, then fitView again with the adapted sizes (the 2D margin holds the discs).
render::View fitAdapted(const engine::Geometry& g, const std::vector<engine::Matrix>& frames, FigureStyle& style);

// Pixels per size unit (vertex_size, line_width, font_size, ...): min(width, height) / 1000, or
// the style's unit_px in a figure sized in lengths.
double pixelScale(const FigureStyle& style);

// Where the flex arrows end: positions + k * flex with the longest arrow flex_scale times the
// figure's extent (empty when there is nothing to draw). fitView should include them.
engine::Matrix flexTips(const engine::Matrix& positions, const engine::Matrix& flex, const FigureStyle& style);

render::DrawList figure(const engine::Geometry& g, const engine::Matrix& positions, const FigureStyle& style,
                        const FigureExtras& extras = {});

}  // namespace flexure::present
