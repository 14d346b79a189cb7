// The bars layer: segments between two vertices, drawn by their role (engine::Bars::Role).
#include "present/layers/layers.h"

#include <algorithm>

namespace flexure::present::layers {

using render::Color;
using Role = engine::Bars::Role;

void drawBars(render::DrawList& out, const engine::Bars& bars, const engine::Matrix& p, const Pen& pen) {
  const FigureStyle& s = pen.s;
  const bool three_d = pen.three_d;
  const double px = pen.px;
  const float line = pen.line;
  // The shape added last stands for bar b (its id in SVG and TikZ).
  const auto mark = [&](const std::array<int, 2>& b) {
    out.shapes.back().element[0] = b[0] + s.label_base, out.shapes.back().element[1] = b[1] + s.label_base;
  };
  switch (bars.role) {
    case Role::Apex:  // the contact graph of caps, thin, over the unit sphere
      for (const auto& b : bars.edges) {
        out.segment(point(p, b[0]), point(p, b[1]), 0.5f * line, s.apex_color);
        out.tag("bar");
        mark(b);
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
        mark(b);
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
        mark(b);
      }
      break;
    }
    case Role::Plain:
      for (const auto& b : bars.edges) {
        const auto own = s.edge_styles.find({std::min(b[0], b[1]), std::max(b[0], b[1])});
        if (own == s.edge_styles.end()) {
          out.segment(point(p, b[0]), point(p, b[1]), line, s.edge_color);
          out.shapes.back().shaded = three_d;
          out.tag("bar");
        mark(b);
          continue;
        }
        // Its own look: colour, width, dash, and a label at its middle.
        const PartStyle& e = own->second;
        const float w = e.width ? static_cast<float>(*e.width * px) : line;
        out.segment(point(p, b[0]), point(p, b[1]), w, e.color.value_or(s.edge_color));
        out.shapes.back().shaded = three_d;
        if (e.dash) out.shapes.back().dash = 2.5f * std::max(w, 1.f), out.shapes.back().gap = 1.5f * std::max(w, 1.f);
        out.tag("bar");
        mark(b);
        if (!e.label.empty()) {
          render::Label l;
          const render::Point3 a = point(p, b[0]), c = point(p, b[1]);
          l.at = {0.5 * (a[0] + c[0]), 0.5 * (a[1] + c[1]), 0.5 * (a[2] + c[2])};
          l.text = e.label;
          l.size = static_cast<float>(0.8 * s.font_size * px);
          l.offset[1] = static_cast<float>(0.5 * w + 0.7 * l.size);  // beside the bar
          l.color = s.vertex_color;
          l.regular = true;
          l.role = "edge-label";
          l.element[0] = b[0] + s.label_base, l.element[1] = b[1] + s.label_base;
          out.labels.push_back(l);
        }
      }
      break;
  }
}

}  // namespace flexure::present::layers
