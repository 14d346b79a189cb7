// The bars layer: segments between two vertices, drawn by their role (engine::Bars::Role).
#include "present/layers/layers.h"

namespace flexure::present::layers {

using render::Color;
using Role = engine::Bars::Role;

void drawBars(render::DrawList& out, const engine::Bars& bars, const engine::Matrix& p, const Pen& pen) {
  const FigureStyle& s = pen.s;
  const bool three_d = pen.three_d;
  const double px = pen.px;
  const float line = pen.line;
  switch (bars.role) {
    case Role::Apex:  // the contact graph of caps, thin, over the unit sphere
      for (const auto& b : bars.edges) {
        out.segment(point(p, b[0]), point(p, b[1]), 0.5f * line, s.apex_color);
        out.tag("bar");
      }
      break;
    case Role::Outline:
      // The dashed outlines of the simplices are the bars.
      break;
    case Role::Contact: {
      // The contact graph, under the balls (translucent: the graph shows through).
      const Color contact = s.contact_color.value_or(three_d ? Color{0x7F / 255.f, 0x7F / 255.f, 0x7F / 255.f, 1}
                                                             : Color{0xCC / 255.f, 0xCC / 255.f, 0xCC / 255.f, 1});
      for (const auto& b : bars.edges) {
        out.segment(point(p, b[0]), point(p, b[1]), static_cast<float>(s.contact_width * px), contact);
        out.shapes.back().shaded = three_d;
        out.tag("bar");
      }
      break;
    }
    case Role::Crease: {
      // Origami: creases by assignment, mountains solid, valleys dashed, flat and unassigned ones
      // thin and grey; the boundary dark grey.
      const Color grey{0.55f, 0.55f, 0.55f, 1};
      for (size_t k = 0; k < bars.edges.size(); ++k) {
        const auto& b = bars.edges[k];
        const char kind = bars.kinds[k];
        const bool border = kind == 'B';
        const Color dark{0.25f, 0.25f, 0.25f, 1};
        const Color c = kind == 'M' ? s.mountain_color : kind == 'V' ? s.valley_color : border ? dark : grey;
        out.segment(point(p, b[0]), point(p, b[1]), (kind == 'M' || kind == 'V' || border ? 0.6f : 0.35f) * line, c);
        if (kind == 'V') out.shapes.back().dash = 2.5f * line, out.shapes.back().gap = 1.5f * line;
        out.tag(kind == 'M' ? "mountain" : kind == 'V' ? "valley" : border ? "boundary" : "crease");
      }
      break;
    }
    case Role::Plain:
      for (const auto& b : bars.edges) {
        out.segment(point(p, b[0]), point(p, b[1]), line, s.edge_color);
        out.shapes.back().shaded = three_d;
        out.tag("bar");
      }
      break;
  }
}

}  // namespace flexure::present::layers
