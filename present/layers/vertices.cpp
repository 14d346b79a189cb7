// The vertices layer: the pins, each vertex's mark (engine::Vertices::Look) and its number.
#include "present/layers/layers.h"

#include <string>

#include <Eigen/Geometry>

namespace flexure::present::layers {

using Look = engine::Vertices::Look;

void drawPins(render::DrawList& out, const engine::Geometry& g, const engine::Matrix& p, const Pen& pen) {
  const FigureStyle& s = pen.s;
  const float vr = pen.vr;
  const bool balls = !g.balls.empty();
  for (int i : g.pinned) {
    render::Shape t;
    t.kind = render::ShapeKind::Triangle;
    t.a = t.b = point(p, i);
    t.radius = vr;
    t.fill = s.pin_color;
    t.role = "pin";
    t.offset[0] = balls ? 0.f : -1.15f * vr;  // just left of the vertex, pointing at it (packings: centred)
    out.shapes.push_back(t);
  }
}

void drawVertices(render::DrawList& out, const engine::Geometry& g, const engine::Matrix& p, const Pen& pen) {
  const FigureStyle& s = pen.s;
  const bool three_d = pen.three_d;
  const float vr = pen.vr;
  const bool dots = g.vertices.look == Look::Dot;
  if (g.vertices.look != Look::None)  // balls and caps show the points themselves
    for (int i = 0; i < g.points; ++i) {
      const auto own = s.vertex_styles.find(i);
      const bool styled = own != s.vertex_styles.end();
      const float r = styled && own->second.width ? static_cast<float>(0.5 * *own->second.width * pen.px) : vr;
      out.disc(point(p, i), dots ? 0.3f * r : r, styled && own->second.color ? *own->second.color : s.vertex_color);
      out.shapes.back().shaded = three_d;
      out.tag("joint");
      out.shapes.back().element[0] = i + s.label_base;
    }
}

void drawLabels(render::DrawList& out, const engine::Geometry& g, const engine::Matrix& p, const Pen& pen) {
  const FigureStyle& s = pen.s;
  const double px = pen.px;
  for (int i = 0; i < g.points; ++i) {
    render::Label l;
    l.at = point(p, i);
    if (!g.caps.empty()) {  // at the cap's centre on the sphere
      const Eigen::Vector3d e = Eigen::Vector3d(point(p, i).data()).normalized();
      l.at = {e[0], e[1], e[2]};
    }
    const auto own = s.vertex_styles.find(i);
    l.text = own != s.vertex_styles.end() && !own->second.label.empty() ? own->second.label : std::to_string(i + s.label_base);
    l.size = static_cast<float>(s.font_size * px * (l.text.size() > 1 ? 0.8 : 1.0));
    // Without vertex marks (balls, caps), dark labels on the light balls and sphere.
    l.color = g.vertices.look == Look::None ? s.vertex_color : s.label_color;
    l.role = "label";
    l.declutter = true;
    l.aside_color = s.vertex_color;  // beside its disc, on the background
    l.element[0] = i + s.label_base;
    out.labels.push_back(l);
  }
}

}  // namespace flexure::present::layers
