// The vector writers' shared primitives (render/vector_common.h): panels flattened into
// primitives, numbers and colours as the files spell them, the shading of tubes and balls.
#include "render/vector_common.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <utility>

#include "render/batches.h"
#include "render/camera.h"
#include "render/text.h"

namespace flexure::render::vector_detail {

namespace {

// The light of the raster renderer's shader (eye space, y up): colour at unit normal n.
Color lit(const Color& c, double nx, double ny, double nz) {
  const double l[3] = {-0.35, 0.45, 0.82};
  const double ln = std::sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
  const double diffuse = std::max(0.0, (nx * l[0] + ny * l[1] + nz * l[2]) / ln);
  // reflect(-l, n) . (0, 0, 1) = 2 (n . l) n_z - l_z
  const double spec = std::pow(std::max(0.0, 2 * (nx * l[0] + ny * l[1] + nz * l[2]) / ln * nz - l[2] / ln), 24.0);
  const auto ch = [&](float v) { return static_cast<float>(std::min(1.0, v * (0.45 + 0.6 * diffuse) + 0.25 * spec)); };
  return {ch(c.r), ch(c.g), ch(c.b), c.a};
}

// Regular polygon of `corners` corners, circumradius r, centre c, first corner towards
// `dir` (unit, y up).
std::vector<P2> regular(const P2& c, double r, const P2& dir, int corners) {
  std::vector<P2> out;
  for (int k = 0; k < corners; ++k) {
    const double t = 2 * M_PI * k / corners, ct = std::cos(t), st = std::sin(t);
    out.push_back({c[0] + r * (ct * dir[0] - st * dir[1]), c[1] + r * (st * dir[0] + ct * dir[1])});
  }
  return out;
}

}  // namespace

// The panel's primitives in painting order: 2D as given (polygons, shapes, labels); 3D with
// polygons and shapes back to front, labels on top.
std::vector<Prim> flatten(const VectorPanel& panel) {
  const DrawList& list = *panel.list;
  const View& view = panel.view;
  const Projector project(view);
  const bool depth = view.three_d;
  const double H = view.height;
  // Pixels with y up (the projector's) to figure pixels.
  const auto out = [&](double x, double y) { return P2{panel.x + x, panel.y + H - y}; };
  std::vector<std::pair<double, Prim>> body;  // (depth, primitive)
  for (const Polygon& poly : list.polygons) {
    if (poly.points.size() < 3) continue;
    Prim p;
    p.kind = Prim::Fill;
    p.role = poly.role ? poly.role : "polygon";
    double z = 0;
    for (const Point3& q : poly.points) {
      const auto s = project(q);
      p.pts.push_back(out(s[0], s[1]));
      z += s[2];
    }
    z /= static_cast<double>(poly.points.size());
    p.fill = polygonColor(poly, project, depth);  // as the raster renderer lights it
    body.push_back({z, std::move(p)});
  }
  const double depth_per_px = depth ? project.depthPerUnit() / std::max(project.pixelsPerUnit(), 1e-300) : 0.0;
  // 3D: the balls (opaque discs) by centre. A line that ends inside one is drawn from its rim:
  // the raster renderer's depth test hides that part inside the ball, and painting by depth
  // alone would draw a bar coming towards the viewer over the ball it starts in.
  std::map<Point3, double> balls;
  if (depth)
    for (const Shape& s : list.shapes)
      if (s.kind == ShapeKind::Disc && s.fill.a >= 1 && s.world_radius <= 0 && s.offset[0] == 0 && s.offset[1] == 0)
        balls[s.a] = std::max(balls[s.a], static_cast<double>(s.radius));
  for (const Shape& s0 : list.shapes) {
    Shape s = s0;
    if (s.kind == ShapeKind::Disc && s.world_radius > 0)
      s.radius = static_cast<float>(s.world_radius * project.pixelsPerUnitAt(s.a));
    auto pa = project(s.a), pb = project(s.b);
    if (s.on_top) pa[2] = pb[2] = -1;  // painted last, unfaded
    Prim p;
    p.role = s.role ? s.role : s.kind == ShapeKind::Segment ? "line" : s.kind == ShapeKind::Disc ? "disc" : "marker";
    p.id = elementId(p.role, s.element);
    p.fill = s.fill;
    p.stroke = s.stroke;
    p.shaded = s.shaded && depth;
    double z = 0.5 * (pa[2] + pb[2]);
    if (s.kind == ShapeKind::Segment) {
      if (s.inset > 0) {
        const double dx = pb[0] - pa[0], dy = pb[1] - pa[1], len = std::hypot(dx, dy);
        const double keep = std::max(0.0, len - s.inset) / std::max(len, 1e-300);
        pb[0] = pa[0] + keep * dx, pb[1] = pa[1] + keep * dy;
      }
      bool trimmed = false;
      const double hw = s.radius;
      for (int end = 0; end < 2 && !balls.empty(); ++end) {
        const auto it = balls.find(end == 0 ? s.a : s.b);
        if (it == balls.end() || it->second <= hw) continue;
        auto& from = end == 0 ? pa : pb;
        const auto& to = end == 0 ? pb : pa;
        const double dx = to[0] - from[0], dy = to[1] - from[1], len = std::hypot(dx, dy);
        const double cut = std::sqrt(it->second * it->second - hw * hw);
        if (len <= cut) {
          trimmed = true;
          from = to;  // all of it inside the ball (on screen)
          continue;
        }
        from[0] += cut * dx / len, from[1] += cut * dy / len;
        trimmed = true;
      }
      if (trimmed && std::hypot(pb[0] - pa[0], pb[1] - pa[1]) < 1e-9) continue;
      p.kind = Prim::Line;
      p.pts = {out(pa[0], pa[1]), out(pb[0], pb[1])};
      p.width = 2.0 * s.radius;
      p.butt = trimmed;
      p.dash = s.dash, p.gap = s.gap;
    } else if (s.kind == ShapeKind::Disc) {
      p.kind = Prim::Circle;
      p.pts = {out(pa[0] + s.offset[0], pa[1] + s.offset[1])};
      p.radius = s.radius;
      p.width = s.outline;
      z = pa[2] - s.radius * depth_per_px;  // its front
    } else {
      P2 dir{s.pointing[0], s.pointing[1]};
      P2 c{pa[0] + s.offset[0], pa[1] + s.offset[1]};
      if (s.kind == ShapeKind::Triangle && s.a != s.b) {  // an arrow head with its tip at b
        const double dx = pb[0] - pa[0], dy = pb[1] - pa[1], len = std::hypot(dx, dy);
        if (len < 1e-9) continue;
        dir = {dx / len, dy / len};
        c = {pb[0] - s.radius * dir[0], pb[1] - s.radius * dir[1]};
        z = pb[2];
      } else {
        const double len = std::hypot(dir[0], dir[1]);
        dir = len > 0 ? P2{dir[0] / len, dir[1] / len} : P2{1, 0};
      }
      p.kind = Prim::Fill;
      for (const P2& q : regular(c, s.radius, dir, s.kind == ShapeKind::Triangle ? 3 : 5)) p.pts.push_back(out(q[0], q[1]));
      p.width = s.outline;
    }
    body.push_back({z, std::move(p)});
  }
  // 3D: fog as the raster renderer's (by the primitive's mean depth); farther (larger depth)
  // first; 2D keeps the order (polygons under shapes).
  if (depth) {
    for (auto& [z, p] : body) {
      p.own_fill = p.fill, p.own_stroke = p.stroke;
      p.fog = fogAmount(z, view.fog);
      p.fill = fogged(p.fill, z, view.background, view.fog);
      p.stroke = fogged(p.stroke, z, view.background, view.fog);
    }
    std::stable_sort(body.begin(), body.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  }
  std::vector<Prim> prims;
  prims.reserve(body.size() + list.labels.size());
  for (auto& [z, p] : body) prims.push_back(std::move(p));
  // Text widths as DejaVu Sans Bold's average advance (0.62 em) for the declutter test.
  const auto approxWidth = [](const Label& l) { return 0.62 * l.size * static_cast<double>(utf8Characters(l.text)); };
  std::vector<Label> placed = placedLabels(list, project, view.height, depth, approxWidth);
  if (depth)  // far ones first, as the raster renderer draws them
    std::stable_sort(placed.begin(), placed.end(), [&](const Label& a, const Label& b) {
      const auto depthOf = [&](const Label& l) { return l.screen ? -2.0 : project(l.at)[2]; };
      return depthOf(a) > depthOf(b);
    });
  for (const Label& l : placed) {
    if (l.text.empty()) continue;
    Prim p;
    p.kind = Prim::Text;
    p.role = l.role ? l.role : "text";
    p.id = elementId(p.role, l.element);
    const auto at = l.screen ? std::array<double, 3>{l.at[0], H - l.at[1], 0.0} : project(l.at);
    p.pts = {out(at[0] + l.offset[0], at[1] + l.offset[1])};
    p.text = l.text;
    p.size = l.size;
    p.fill = l.color;
    p.align = l.align;
    p.bold = !l.regular;
    if (depth && !l.screen) p.halo = 2 * haloWidth(l.size), p.stroke = haloColor(l.color, view.background);
    prims.push_back(std::move(p));
  }
  return prims;
}

std::string elementId(const std::string& role, const int (&element)[2]) {
  if (element[0] < 0) return "";
  return role + "-" + std::to_string(element[0]) + (element[1] >= 0 ? "-" + std::to_string(element[1]) : "");
}

std::string num(double v) {
  if (!std::isfinite(v)) v = 0;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", v);
  std::string s = buf;
  while (!s.empty() && s.back() == '0') s.pop_back();
  if (!s.empty() && s.back() == '.') s.pop_back();
  if (s == "-0") s = "0";
  return s;
}

int channel(float v) { return static_cast<int>(std::lround(255.0 * std::clamp(v, 0.f, 1.f))); }

std::string hex(const Color& c) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "#%02X%02X%02X", channel(c.r), channel(c.g), channel(c.b));
  return buf;
}

// The unit normal of a line on screen (figure pixels, y down) and its length.
P2 normalOf(const Prim& p, double* length) {
  const double dx = p.pts[1][0] - p.pts[0][0], dy = p.pts[1][1] - p.pts[0][1], len = std::hypot(dx, dy);
  if (length) *length = len;
  return len > 0 ? P2{-dy / len, dx / len} : P2{0, 1};
}

// A tube's colour across its width: s from -1 to 1 along `n` (figure pixels, y down).
Color tubeColor(const Color& c, const P2& n, double s) {
  const double h = std::sqrt(std::max(0.0, 1 - s * s));
  return lit(c, n[0] * s, -n[1] * s, h);
}

// The ball's colour at fraction t of the way from its highlight to its rim.
Color ballColor(const Color& c, double t) {
  const double l[3] = {-0.35, 0.45, 0.82};
  const double ln = std::sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
  // The normal turns from the light direction (t = 0) to the rim (t = 1), away from the light.
  const double a0 = std::acos(l[2] / ln), a = a0 + t * (M_PI / 2 - a0 + 0.25);
  const double q = std::hypot(l[0], l[1]);
  return lit(c, l[0] / q * std::sin(a), l[1] / q * std::sin(a), std::max(0.0, std::cos(a)));
}

}  // namespace flexure::render::vector_detail
