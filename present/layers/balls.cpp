// The balls layer (sphere and disk packings): a ball of its radius at every point, over the
// contact graph (the bars layer, role Contact), translucent so that the graph shows through.
#include "present/layers/layers.h"

namespace flexure::present::layers {

using render::Color;

void drawBalls(render::DrawList& out, const engine::Balls& balls, int points, const engine::Matrix& p, const Pen& pen) {
  if (balls.empty()) return;
  const FigureStyle& s = pen.s;
  const bool three_d = pen.three_d;
  const double px = pen.px;
  Color fill = s.ball_color.value_or(Color{0x46 / 255.f, 0x82 / 255.f, 0xB4 / 255.f, three_d ? 0.25f : 0.1f});
  Color stroke = fill;
  stroke.a = 1;
  for (int i = 0; i < points; ++i) {
    out.disc(point(p, i), 1, fill, three_d ? 0.f : static_cast<float>(s.ball_outline * px), stroke);
    out.shapes.back().world_radius = balls.radii[static_cast<size_t>(i)];
    out.shapes.back().shaded = three_d;
    out.tag("ball");
  }
}

}  // namespace flexure::present::layers
