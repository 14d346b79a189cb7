#include "present/figure.h"

#include "engine/terms.h"
#include "present/surface_mesh.h"
#include "render/camera.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <map>

#include <Eigen/Geometry>

namespace flexure::present {

using render::Color;
using render::Point3;

namespace {

Point3 point(const engine::Matrix& p, int i) {
  return {p(0, i), p(1, i), p.rows() > 2 ? p(2, i) : 0.0};
}

double pixelScale(const FigureStyle& s) { return std::min(s.width, s.height) / 1000.0; }

}  // namespace

engine::Matrix flexTips(const engine::Matrix& p, const engine::Matrix& flex, const FigureStyle& s) {
  if (flex.size() == 0 || flex.cols() != p.cols()) return engine::Matrix(p.rows(), 0);
  double extent = 0, vmax = 0;
  for (int k = 0; k < p.rows(); ++k) extent = std::max(extent, p.row(k).maxCoeff() - p.row(k).minCoeff());
  for (int i = 0; i < flex.cols(); ++i) vmax = std::max(vmax, flex.col(i).norm());
  if (vmax <= 0 || extent <= 0) return engine::Matrix(p.rows(), 0);
  engine::Matrix tips = p;
  const double k = s.flex_scale * extent / vmax;
  for (int i = 0; i < p.cols(); ++i)
    if (flex.col(i).norm() > 1e-6 * vmax) tips.col(i) += k * flex.col(i);  // others stay (no arrow)
  return tips;
}

namespace {

// The power of ten nearest x (in logarithm): 1 for x in [0.316, 3.16).
double decade(double x) { return x > 0 && std::isfinite(x) ? std::pow(10.0, std::round(std::log10(x))) : 1.0; }

// A figure's typical length: its median bar in `p`; without bars, half its extent.
double typicalLength(const engine::Geometry& g, const engine::Matrix* p, double extent) {
  if (!p || g.bars.empty()) return 0.5 * extent;
  std::vector<double> lengths;
  for (const auto& b : g.bars)
    if (b[0] < p->cols() && b[1] < p->cols()) lengths.push_back((p->col(b[0]) - p->col(b[1])).norm());
  if (lengths.empty()) return 0.5 * extent;
  std::nth_element(lengths.begin(), lengths.begin() + static_cast<long>(lengths.size() / 2), lengths.end());
  return lengths[lengths.size() / 2] > 0 ? lengths[lengths.size() / 2] : 0.5 * extent;
}

}  // namespace

render::View fitView(const engine::Geometry& g, const std::vector<engine::Matrix>& frames, const FigureStyle& s) {
  render::View v;
  v.width = s.width, v.height = s.height;
  v.background = s.background;
  v.three_d = g.dimension == 3;
  v.azimuth = s.azimuth, v.elevation = s.elevation, v.perspective = s.perspective;
  v.fog = s.fog;
  const int d = g.dimension;
  double L = std::numeric_limits<double>::infinity(), U = -L;
  std::vector<double> lo(d, L), hi(d, -L);
  for (const engine::Matrix& p : frames)
    for (int i = 0; i < p.cols(); ++i)
      for (int k = 0; k < d; ++k) {
        lo[k] = std::min(lo[k], p(k, i)), hi[k] = std::max(hi[k], p(k, i));
        L = std::min(L, p(k, i)), U = std::max(U, p(k, i));
      }
  if (!(U >= L)) L = 0, U = 1;
  // Caps: the whole unit sphere is in view.
  if (g.caps) {
    L = std::min(L, -1.0), U = std::max(U, 1.0);
    for (int k = 0; k < d; ++k) lo[k] = std::min(lo[k], -1.0), hi[k] = std::max(hi[k], 1.0);
  }
  // Disks and spheres: room for the largest radius (the reference's rule for packings).
  if (!g.radii.empty()) {
    const double r = *std::max_element(g.radii.begin(), g.radii.end());
    L -= r, U += r;
    for (int k = 0; k < d; ++k) lo[k] -= r, hi[k] += r;
  }
  if (U - L < 1e-12) L -= 0.5, U += 0.5;
  if (s.view_box) {  // fixed by hand
    for (int k = 0; k < 3; ++k) v.lo[k] = (*s.view_box)[0][k], v.hi[k] = (*s.view_box)[1][k];
    if (d == 2) v.lo[2] = v.hi[2] = 0;
    return v;
  }
  const double pad = s.auto_padding ? s.padding * decade(typicalLength(g, frames.empty() ? nullptr : &frames.front(), U - L))
                                    : s.padding;
  for (int k = 0; k < d; ++k) {
    if (d == 3 && !g.surface) {
      // The data's own box: the camera fits its projection. (The reference takes the cube
      // [L - pad, U + pad]^3, which leaves flat figures small and off centre.)
      v.lo[k] = lo[k] - pad, v.hi[k] = hi[k] + pad;
    } else {  // a window (a cube on surfaces: the surface fills it) of common width centred on each axis' data
      const double t = lo[k] + hi[k] - L - U;
      v.lo[k] = L - pad + 0.5 * t, v.hi[k] = U + pad + 0.5 * t;
    }
  }
  if (d == 2) {
    // Room for the vertex discs and pins, in pixels, on top of the world padding.
    const double margin = pixelScale(s) * (0.5 * s.vertex_size + 0.5 * s.vertex_size) + 2;
    const double span = U - L + 2 * pad;
    const double scale = (std::min(s.width, s.height) - 2 * margin) / span;
    for (int k = 0; k < 2; ++k) v.lo[k] -= margin / scale, v.hi[k] += margin / scale;
    v.lo[2] = v.hi[2] = 0;
  }
  return v;
}

FigureStyle adaptStyle(const FigureStyle& style, const engine::Geometry& g, const std::vector<engine::Matrix>& frames,
                       const render::View& view) {
  FigureStyle s = style;
  if (frames.empty()) return s;
  const double px = pixelScale(s);
  if (s.auto_size && !g.bars.empty() && g.radii.empty() && !g.caps) {
    // The median bar on screen, over the first frame.
    const render::Projector project(view);
    const engine::Matrix& p = frames.front();
    std::vector<double> lengths;
    for (const auto& b : g.bars) {
      const auto a = project(point(p, b[0])), c = project(point(p, b[1]));
      lengths.push_back(std::hypot(a[0] - c[0], a[1] - c[1]));
    }
    std::nth_element(lengths.begin(), lengths.begin() + static_cast<long>(lengths.size() / 2), lengths.end());
    const double bar = lengths[lengths.size() / 2], disc = s.vertex_size * px;
    if (bar > 0 && disc > 0.6 * bar) {
      const double f = std::max(0.6 * bar, 2.0) / disc;
      s.vertex_size *= f, s.font_size *= f, s.arrow_size *= f;
      s.line_width = std::max(s.line_width * f, 1.0 / px);
    }
  }
  // Origami: the sheet reads better without vertex numbers (labels = true brings them back).
  if (s.auto_labels && s.labels && (s.font_size * px < 6 || g.points > 200 || !g.bar_kinds.empty())) s.labels = false;
  return s;
}

render::View fitAdapted(const engine::Geometry& g, const std::vector<engine::Matrix>& frames, FigureStyle& style) {
  render::View view = fitView(g, frames, style);
  const FigureStyle adapted = adaptStyle(style, g, frames, view);
  if (adapted.vertex_size == style.vertex_size && adapted.labels == style.labels) return view;
  style = adapted;
  return fitView(g, frames, style);
}

std::vector<render::Polygon> surfaceMesh(const engine::Geometry& g, const render::View& view, const FigureStyle& s) {
  std::vector<render::Polygon> out;
  if (!g.surface || g.dimension != 3) return out;
  const engine::ScalarField* f = g.surface;
  // A little inside the view's box, so that the cut edges stay off the image's border.
  std::array<double, 3> lo = view.lo, hi = view.hi;
  for (int k = 0; k < 3; ++k) {
    const double c = 0.5 * (lo[k] + hi[k]), r = 0.47 * (hi[k] - lo[k]);
    lo[k] = c - r, hi[k] = c + r;
  }
  for (const Triangle3& t : meshImplicitSurface([f](const double* x) { return f->value(x); }, lo, hi,
                                                s.surface_samples)) {
    render::Polygon p;
    p.points.assign(t.begin(), t.end());
    p.fill = s.surface_color;
    p.shaded = true;
    out.push_back(std::move(p));
  }
  return out;
}

render::DrawList figure(const engine::Geometry& g, const engine::Matrix& p, const FigureStyle& s,
                        const FigureExtras& extras) {
  render::DrawList out;
  out.dimension = g.dimension;
  const bool three_d = g.dimension == 3;
  const double px = pixelScale(s);
  const float line = static_cast<float>(s.line_width * px), vr = static_cast<float>(0.5 * s.vertex_size * px);
  // Ghost: another sample underneath, in one colour.
  if (extras.ghost) {
    for (const auto& b : g.bars) {
      out.segment(point(*extras.ghost, b[0]), point(*extras.ghost, b[1]), line, s.ghost_color);
      out.tag("ghost");
    }
    for (int i = 0; i < g.points; ++i) {
      out.disc(point(*extras.ghost, i), vr, s.ghost_color);
      out.tag("ghost");
    }
  }
  if (extras.surface)
    for (render::Polygon poly : *extras.surface) {
      poly.role = "surface";
      out.polygons.push_back(std::move(poly));
    }
  // Facets (polytopes and bodies), translucent, under the bars.
  for (const auto& f : g.facets) {
    render::Polygon poly;
    for (int i : f) poly.points.push_back(point(p, i));
    poly.fill = g.bar_kinds.empty() ? s.facet_color : s.panel_color;
    poly.shaded = three_d;
    poly.role = g.bar_kinds.empty() ? "facet" : "face";  // ("panel" is a filmstrip panel)
    out.polygons.push_back(poly);
  }
  // Trajectories of the vertices that move, with an arrow head at the end.
  if (extras.trace.size() >= 2) {
    const engine::Matrix& first = extras.trace.front();
    const engine::Matrix& last = extras.trace.back();
    for (int i = 0; i < g.points; ++i) {
      double moved = 0;
      for (const auto& q : extras.trace) moved = std::max(moved, (q.col(i) - first.col(i)).norm());
      if (moved < 1e-6) continue;
      const size_t n = extras.trace.size();
      for (size_t k = 0; k + 2 < n; ++k) {
        out.segment(point(extras.trace[k], i), point(extras.trace[k + 1], i), 0.5f * line, s.trace_color);
        out.tag("trace");
      }
      out.arrow(point(extras.trace[n - 2], i), point(last, i), 0.5f * line, static_cast<float>(s.arrow_size * px),
                s.trace_color, "trace");
    }
  }
  // Flex arrows.
  const engine::Matrix tips = flexTips(p, extras.flex, s);
  for (int i = 0; i < tips.cols(); ++i)
    if ((tips.col(i) - p.col(i)).norm() > 0)
      out.arrow(point(p, i), point(tips, i), line, static_cast<float>(s.arrow_size * px), s.flex_color, "flex");
  // Angle sectors (angular frameworks), under the bars: the normalised lerp of the reference.
  for (const auto& [i, j, k] : g.angles) {
    const Eigen::Vector3d c(point(p, j).data()), u = Eigen::Vector3d(point(p, i).data()) - c,
                                                  w = Eigen::Vector3d(point(p, k).data()) - c;
    const double r = 0.3 * std::min(u.norm(), w.norm());
    if (!(r > 0)) continue;
    render::Polygon sector;
    sector.points.push_back({c[0], c[1], c[2]});
    std::vector<Point3> arc;
    for (int t = 0; t <= 20; ++t) {
      const double f = t / 20.0;
      Eigen::Vector3d q = (1 - f) * u.normalized() + f * w.normalized();
      if (q.norm() < 1e-9) continue;  // a straight angle: the lerp passes the centre
      q = c + r * q.normalized();
      arc.push_back({q[0], q[1], q[2]});
    }
    sector.points.insert(sector.points.end(), arc.begin(), arc.end());
    sector.fill = s.angle_color;
    sector.role = "angle";
    out.polygons.push_back(sector);
    Color stroke = s.angle_color;
    stroke.a = 1;
    for (size_t t = 0; t + 1 < arc.size(); ++t) {
      out.segment(arc[t], arc[t + 1], 0.5f * line, stroke);
      out.tag("angle");
    }
  }
  // Simplices (volume hypergraphs): translucent faces and dashed outlines in one colour each.
  for (size_t f = 0; f < g.simplices.size() && !s.simplex_colors.empty(); ++f) {
    const auto& sv = g.simplices[f];
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
  const bool balls = !g.radii.empty();
  if (g.caps) {
    // The unit sphere, each cap's circle (centre a / |a|^2, radius sqrt(1 - 1/|a|^2), in the
    // plane a . y = 1) and the contact graph joining the cones' apices a.
    out.disc({0, 0, 0}, 1, s.sphere_color);
    out.tag("sphere");
    out.shapes.back().world_radius = 0.99;  // just inside the circles on its front: no z-fighting
    out.shapes.back().shaded = true;
    for (const auto& b : g.bars) {
      out.segment(point(p, b[0]), point(p, b[1]), 0.5f * line, s.apex_color);
      out.tag("bar");
    }
    for (int i = 0; i < g.points; ++i) {
      const Eigen::Vector3d a(point(p, i).data());
      const double n2 = a.squaredNorm();
      if (!(n2 > 1)) continue;
      const Eigen::Vector3d c = a / n2, e = a.normalized();
      const Eigen::Vector3d e1 = e.unitOrthogonal(), e2 = e.cross(e1);
      const double rho = std::sqrt(1 - 1 / n2);
      Point3 prev{};
      for (int t = 0; t <= 64; ++t) {
        const double phi = 2 * M_PI * t / 64;
        const Eigen::Vector3d q = c + rho * (std::cos(phi) * e1 + std::sin(phi) * e2);
        const Point3 cur{q[0], q[1], q[2]};
        // Drawn as (barely) translucent: sorted with the sphere and not writing depth, so the
        // anti-aliased fringe of one piece never hides the next one behind it.
        Color cap = s.cap_color;
        cap.a = std::min(cap.a, 0.99f);
        if (t > 0) {
          out.segment(prev, cur, 0.75f * line, cap);
          out.tag("cap");
        }
        prev = cur;
      }
    }
  } else if (!g.simplices.empty()) {
    // The dashed outlines are the bars.
  } else if (balls) {
    // The contact graph, then the balls over it (translucent: the graph shows through).
    const Color contact = s.contact_color.value_or(three_d ? Color{0x7F / 255.f, 0x7F / 255.f, 0x7F / 255.f, 1}
                                                           : Color{0xCC / 255.f, 0xCC / 255.f, 0xCC / 255.f, 1});
    for (const auto& b : g.bars) {
      out.segment(point(p, b[0]), point(p, b[1]), static_cast<float>(s.contact_width * px), contact);
      out.shapes.back().shaded = three_d;
      out.tag("bar");
    }
    Color fill = s.ball_color.value_or(Color{0x46 / 255.f, 0x82 / 255.f, 0xB4 / 255.f, three_d ? 0.25f : 0.1f});
    Color stroke = fill;
    stroke.a = 1;
    for (int i = 0; i < g.points; ++i) {
      out.disc(point(p, i), 1, fill, three_d ? 0.f : static_cast<float>(s.ball_outline * px), stroke);
      out.shapes.back().world_radius = g.radii[static_cast<size_t>(i)];
      out.shapes.back().shaded = three_d;
      out.tag("ball");
    }
  } else if (!g.bar_kinds.empty()) {
    // Origami: creases by assignment, mountains solid, valleys dashed, flat and unassigned ones
    // thin and grey; the boundary dark grey.
    const Color grey{0.55f, 0.55f, 0.55f, 1};
    for (size_t k = 0; k < g.bars.size(); ++k) {
      const auto& b = g.bars[k];
      const char kind = g.bar_kinds[k];
      const bool border = kind == 'B';
      const Color dark{0.25f, 0.25f, 0.25f, 1};
      const Color c = kind == 'M' ? s.mountain_color : kind == 'V' ? s.valley_color : border ? dark : grey;
      out.segment(point(p, b[0]), point(p, b[1]), (kind == 'M' || kind == 'V' || border ? 0.6f : 0.35f) * line, c);
      if (kind == 'V') out.shapes.back().dash = 2.5f * line, out.shapes.back().gap = 1.5f * line;
      out.tag(kind == 'M' ? "mountain" : kind == 'V' ? "valley" : border ? "boundary" : "crease");
    }
  } else {
    for (const auto& b : g.bars) {
      out.segment(point(p, b[0]), point(p, b[1]), line, s.edge_color);
      out.shapes.back().shaded = three_d;
      out.tag("bar");
    }
  }
  const Color alert{0xCD / 255.f, 0x26 / 255.f, 0x1E / 255.f, 1};
  for (const auto& h : extras.highlight) {
    const auto& group = h.vertices;
    const float w = static_cast<float>(1.0 + 1.2 * std::clamp(h.strength, 0.0, 1.0));
    for (size_t k = 0; k + 1 < group.size(); ++k) {
      out.segment(point(p, group[k]), point(p, group[k + 1]), w * line, alert);
      out.tag("holding");
    }
    if (group.size() == 1) {
      out.disc(point(p, group[0]), w * vr, alert);
      out.tag("holding");
    }
  }
  if (s.pins) {
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
  const bool origami = !g.bar_kinds.empty();
  if (!balls && !g.caps)
    for (int i = 0; i < g.points; ++i) {
      out.disc(point(p, i), origami ? 0.3f * vr : vr, s.vertex_color);  // origami: the sheet, not its vertices
      out.shapes.back().shaded = three_d;
      out.tag("joint");
    }
  if (s.labels)
    for (int i = 0; i < g.points; ++i) {
      render::Label l;
      l.at = point(p, i);
      if (g.caps) {  // at the cap's centre on the sphere
        const Eigen::Vector3d e = Eigen::Vector3d(point(p, i).data()).normalized();
        l.at = {e[0], e[1], e[2]};
      }
      l.text = std::to_string(i + s.label_base);
      l.size = static_cast<float>(s.font_size * px * (l.text.size() > 1 ? 0.8 : 1.0));
      l.color = balls || g.caps ? s.vertex_color : s.label_color;  // packings: dark labels on the light balls
      l.role = "label";
      l.declutter = true;
      out.labels.push_back(l);
    }
  return out;
}

}  // namespace flexure::present
