// The facets layer: planar polygons (polytopes, bodies, origami panels), translucent, under the bars.
#include "present/layers/layers.h"

namespace flexure::present::layers {

void drawFacets(render::DrawList& out, const engine::Facets& facets, const engine::Matrix& p, const Pen& pen) {
  const FigureStyle& s = pen.s;
  const bool three_d = pen.three_d;
  for (const auto& f : facets.polygons) {
    render::Polygon poly;
    for (int i : f) poly.points.push_back(point(p, i));
    poly.fill = !facets.panels ? s.facet_color : s.panel_color;
    poly.shaded = three_d;
    poly.role = !facets.panels ? "facet" : "face";  // ("panel" is a filmstrip panel)
    out.polygons.push_back(poly);
  }
}

}  // namespace flexure::present::layers
