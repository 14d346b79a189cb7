#include "present/figure.h"

#include "engine/terms.h"
#include "present/layers/layers.h"
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
using layers::point;

namespace {

}  // namespace

double pixelScale(const FigureStyle& s) { return s.unit_px > 0 ? s.unit_px : std::min(s.width, s.height) / 1000.0; }

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
  for (const auto& b : g.bars.edges)
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
  if (!g.caps.empty()) {
    L = std::min(L, -1.0), U = std::max(U, 1.0);
    for (int k = 0; k < d; ++k) lo[k] = std::min(lo[k], -1.0), hi[k] = std::max(hi[k], 1.0);
  }
  // Disks and spheres: room for the largest radius (the reference's rule for packings).
  if (!g.balls.empty()) {
    const double r = *std::max_element(g.balls.radii.begin(), g.balls.radii.end());
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
    if (d == 3 && g.surface.empty()) {
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
  // Only vertex discs need room (balls and caps are drawn at their own size).
  if (s.auto_size && !g.bars.empty() && g.vertices.look != engine::Vertices::Look::None) {
    // The median bar on screen, over the first frame.
    const render::Projector project(view);
    const engine::Matrix& p = frames.front();
    std::vector<double> lengths;
    for (const auto& b : g.bars.edges) {
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
  // A model may read better without vertex numbers (origami's sheet; labels = true brings them back).
  if (s.auto_labels && s.labels && (s.font_size * px < 6 || g.points > 200 || !g.vertices.numbered)) s.labels = false;
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
  if (g.surface.empty() || g.dimension != 3) return out;
  const engine::ScalarField* f = g.surface.field;
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
  const layers::Pen pen{s, px, line, vr, three_d};
  // Ghost: another sample underneath, in one colour.
  if (extras.ghost) {
    for (const auto& b : g.bars.edges) {
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
  // Facets (polytopes, bodies, origami panels), translucent, under the bars.
  layers::drawFacets(out, g.facets, p, pen);
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
  // The layers, in this order (the order of the primitives decides the picture): angle sectors
  // and simplices under the bars; the sphere of caps under its apex graph, the caps' circles
  // over it; the balls over their contact graph.
  layers::drawAngles(out, g.angles, p, pen);
  layers::drawSimplices(out, g.simplices, p, pen);
  layers::drawSphere(out, g.caps, pen);
  layers::drawBars(out, g.bars, p, pen);
  layers::drawCaps(out, g.caps, g.points, p, pen);
  layers::drawBalls(out, g.balls, g.points, p, pen);
  // Flex arrows over the bars (an arrow along a bar stays visible), under the vertices.
  const engine::Matrix tips = flexTips(p, extras.flex, s);
  for (int i = 0; i < tips.cols(); ++i)
    if ((tips.col(i) - p.col(i)).norm() > 0) {
      out.arrow(point(p, i), point(tips, i), line, static_cast<float>(s.arrow_size * px), s.flex_color, "flex");
      out.shapes.back().on_top = out.shapes[out.shapes.size() - 2].on_top = true;  // 3D: over the tubes
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
  if (s.pins) layers::drawPins(out, g, p, pen);
  layers::drawVertices(out, g, p, pen);
  if (s.labels) layers::drawLabels(out, g, p, pen);
  return out;
}

}  // namespace flexure::present
