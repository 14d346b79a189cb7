// The simplices layer (volume hypergraphs): translucent faces and dashed outlines in one colour
// each. The outlines are the bars (their role is Outline: the bars layer leaves them).
#include "present/layers/layers.h"

namespace flexure::present::layers {

using render::Color;

void drawSimplices(render::DrawList& out, const engine::Simplices& simplices, const engine::Matrix& p, const Pen& pen) {
  const FigureStyle& s = pen.s;
  const bool three_d = pen.three_d;
  const float line = pen.line;
  for (size_t f = 0; f < simplices.list.size() && !s.simplex_colors.empty(); ++f) {
    const auto& sv = simplices.list[f];
    Color edge = s.simplex_colors[f % s.simplex_colors.size()], fill = edge;
    fill.a = 0.25f * edge.a;
    const size_t m = sv.size();
    for (size_t a = 0; a < m; ++a)  // a triangle (2D), or the four faces of a tetrahedron (3D)
      for (size_t b = a + 1; b < m; ++b)
        for (size_t c = b + 1; c < m; ++c) {
          render::Polygon face;
          face.points = {point(p, sv[a]), point(p, sv[b]), point(p, sv[c])};
          face.fill = fill;
          face.shaded = three_d;
          face.role = "simplex";
          out.polygons.push_back(face);
        }
    for (size_t a = 0; a < m; ++a)
      for (size_t b = a + 1; b < m; ++b) {
        out.segment(point(p, sv[a]), point(p, sv[b]), 0.65f * line, edge);
        out.tag("bar");
        out.shapes.back().dash = 2.2f * line, out.shapes.back().gap = 1.4f * line;
      }
  }
}

}  // namespace flexure::present::layers
