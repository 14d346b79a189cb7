#include "render/vector.h"
#include "render/reproducible.h"
#include "render/utf8.h"

#include <cairo-pdf.h>
#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <map>
#include <cerrno>
#include <stdexcept>

#include "render/batches.h"
#include "render/camera.h"
#include "render/text.h"

namespace flexure::render {

namespace {

using P2 = std::array<double, 2>;

// A primitive in figure pixels (origin top left, y down), in painting order.
struct Prim {
  enum Kind { Fill, Line, Circle, Text } kind = Fill;
  std::string role;
  std::vector<P2> pts;  // Fill: the outline; Line: the two ends; Circle and Text: the centre/anchor
  Color fill, stroke;
  double width = 0;     // Line: full width; Circle: outline width (inside the disc)
  double radius = 0;    // Circle
  double dash = 0, gap = 0;
  bool shaded = false;  // Line: a lit tube; Circle: a lit ball
  bool butt = false;    // Line: square ends (it ends at a ball's rim)
  // Text
  std::string text;
  double size = 14;
  int align = 0;
  bool bold = true;
  double halo = 0;  // 3D labels: an outline this wide in the background colour under the text
};

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
    Prim p;
    p.role = s.role ? s.role : s.kind == ShapeKind::Segment ? "line" : s.kind == ShapeKind::Disc ? "disc" : "marker";
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
  std::vector<size_t> placed = placedLabels(list, project, view.height, depth, approxWidth);
  if (depth)  // far ones first, as the raster renderer draws them
    std::stable_sort(placed.begin(), placed.end(), [&](size_t a, size_t b) {
      const auto depthOf = [&](const Label& l) { return l.screen ? -2.0 : project(l.at)[2]; };
      return depthOf(list.labels[a]) > depthOf(list.labels[b]);
    });
  for (size_t index : placed) {
    const Label& l = list.labels[index];
    if (l.text.empty()) continue;
    Prim p;
    p.kind = Prim::Text;
    p.role = l.role ? l.role : "text";
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
P2 normalOf(const Prim& p, double* length = nullptr) {
  const double dx = p.pts[1][0] - p.pts[0][0], dy = p.pts[1][1] - p.pts[0][1], len = std::hypot(dx, dy);
  if (length) *length = len;
  return len > 0 ? P2{-dy / len, dx / len} : P2{0, 1};
}

// A tube's colour across its width: s from -1 to 1 along `n` (figure pixels, y down).
Color tubeColor(const Color& c, const P2& n, double s) {
  const double h = std::sqrt(std::max(0.0, 1 - s * s));
  return lit(c, n[0] * s, -n[1] * s, h);
}

constexpr double kTubeStops[] = {-1, -0.6, -0.2, 0.2, 0.6, 1};
constexpr double kBallStops[] = {0, 0.35, 0.7, 1};
// The ball's colour at fraction t of the way from its highlight to its rim.
Color ballColor(const Color& c, double t) {
  const double l[3] = {-0.35, 0.45, 0.82};
  const double ln = std::sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
  // The normal turns from the light direction (t = 0) to the rim (t = 1), away from the light.
  const double a0 = std::acos(l[2] / ln), a = a0 + t * (M_PI / 2 - a0 + 0.25);
  const double q = std::hypot(l[0], l[1]);
  return lit(c, l[0] / q * std::sin(a), l[1] / q * std::sin(a), std::max(0.0, std::cos(a)));
}
// Where the highlight is, as a fraction of the radius from the centre (y down).
constexpr double kHighlightX = -0.35 * 0.8, kHighlightY = -0.45 * 0.8;

// ---------------------------------------------------------------------------------- SVG

std::string xmlEscape(const std::string& s) {
  std::string o;
  for (char ch : cleanText(s)) {
    switch (ch) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      default: o += ch;
    }
  }
  return o;
}

std::string svgClass(const std::string& role) {
  std::string c;
  for (char ch : role) c += ch == ' ' ? '-' : ch;
  return c;
}

std::string svgFill(const Color& c) {
  std::string s = "fill=\"" + hex(c) + "\"";
  if (c.a < 1) s += " fill-opacity=\"" + num(c.a) + "\"";
  return s;
}

std::string svg(const VectorFigure& fig, const std::vector<std::vector<Prim>>& panels) {
  std::string defs, body;
  int gradients = 0;
  std::map<std::string, std::string> balls;  // colour -> gradient id
  for (size_t k = 0; k < panels.size(); ++k) {
    const VectorPanel& panel = fig.panels[k];
    body += "<g class=\"panel\" clip-path=\"url(#panel" + std::to_string(k) + ")\">\n";
    defs += "<clipPath id=\"panel" + std::to_string(k) + "\"><rect x=\"" + num(panel.x) + "\" y=\"" + num(panel.y) +
            "\" width=\"" + num(panel.view.width) + "\" height=\"" + num(panel.view.height) + "\"/></clipPath>\n";
    for (const Prim& p : panels[k]) {
      const std::string cls = "class=\"" + svgClass(p.role) + "\"";
      switch (p.kind) {
        case Prim::Fill: {
          body += "<polygon " + cls + " points=\"";
          for (size_t i = 0; i < p.pts.size(); ++i) body += (i ? " " : "") + num(p.pts[i][0]) + "," + num(p.pts[i][1]);
          body += "\" " + svgFill(p.fill) + "/>\n";
          break;
        }
        case Prim::Line: {
          std::string stroke = hex(p.fill);
          if (p.shaded) {
            double len = 0;
            const P2 n = normalOf(p, &len);
            const P2 m{0.5 * (p.pts[0][0] + p.pts[1][0]), 0.5 * (p.pts[0][1] + p.pts[1][1])};
            const double r = 0.5 * p.width;
            const std::string id = "tube" + std::to_string(gradients++);
            defs += "<linearGradient id=\"" + id + "\" gradientUnits=\"userSpaceOnUse\" x1=\"" + num(m[0] - r * n[0]) +
                    "\" y1=\"" + num(m[1] - r * n[1]) + "\" x2=\"" + num(m[0] + r * n[0]) + "\" y2=\"" +
                    num(m[1] + r * n[1]) + "\">";
            for (double s : kTubeStops)
              defs += "<stop offset=\"" + num(0.5 * (s + 1)) + "\" stop-color=\"" + hex(tubeColor(p.fill, n, s)) + "\"/>";
            defs += "</linearGradient>\n";
            stroke = "url(#" + id + ")";
          }
          body += "<line " + cls + " x1=\"" + num(p.pts[0][0]) + "\" y1=\"" + num(p.pts[0][1]) + "\" x2=\"" +
                  num(p.pts[1][0]) + "\" y2=\"" + num(p.pts[1][1]) + "\" stroke=\"" + stroke + "\"";
          if (p.fill.a < 1) body += " stroke-opacity=\"" + num(p.fill.a) + "\"";
          body += " stroke-width=\"" + num(p.width) + "\"";
          if (p.dash > 0)
            body += " stroke-linecap=\"butt\" stroke-dasharray=\"" + num(p.dash) + " " + num(p.gap) + "\"";
          else
            body += p.butt ? " stroke-linecap=\"butt\"" : " stroke-linecap=\"round\"";
          body += "/>\n";
          break;
        }
        case Prim::Circle: {
          std::string fill = svgFill(p.fill);
          if (p.shaded) {
            const std::string key = hex(p.fill);
            auto it = balls.find(key);
            if (it == balls.end()) {
              const std::string id = "ball" + std::to_string(gradients++);
              defs += "<radialGradient id=\"" + id + "\" cx=\"0.5\" cy=\"0.5\" r=\"0.5\" fx=\"" +
                      num(0.5 + 0.5 * kHighlightX) + "\" fy=\"" + num(0.5 + 0.5 * kHighlightY) + "\">";
              for (double t : kBallStops)
                defs += "<stop offset=\"" + num(t) + "\" stop-color=\"" + hex(ballColor(p.fill, t)) + "\"/>";
              defs += "</radialGradient>\n";
              it = balls.emplace(key, id).first;
            }
            fill = "fill=\"url(#" + it->second + ")\"";
            if (p.fill.a < 1) fill += " fill-opacity=\"" + num(p.fill.a) + "\"";
          }
          body += "<circle " + cls + " cx=\"" + num(p.pts[0][0]) + "\" cy=\"" + num(p.pts[0][1]) + "\" r=\"" +
                  num(p.radius) + "\" " + fill + "/>\n";
          if (p.width > 0)  // the outline, inside the disc
            body += "<circle " + cls + " cx=\"" + num(p.pts[0][0]) + "\" cy=\"" + num(p.pts[0][1]) + "\" r=\"" +
                    num(std::max(0.0, p.radius - 0.5 * p.width)) + "\" fill=\"none\" stroke=\"" + hex(p.stroke) +
                    "\"" + (p.stroke.a < 1 ? " stroke-opacity=\"" + num(p.stroke.a) + "\"" : std::string()) +
                    " stroke-width=\"" + num(p.width) + "\"/>\n";
          break;
        }
        case Prim::Text: {
          const char* anchor = p.align < 0 ? "start" : p.align > 0 ? "end" : "middle";
          body += "<text " + cls + " x=\"" + num(p.pts[0][0]) + "\" y=\"" + num(p.pts[0][1]) + "\" font-size=\"" +
                  num(p.size) + "\" text-anchor=\"" + anchor + "\" dominant-baseline=\"central\"" +
                  (p.bold ? " font-weight=\"bold\"" : "") + " " + svgFill(p.fill) +
                  (p.halo > 0 ? " stroke=\"" + hex(p.stroke) + "\" stroke-width=\"" + num(p.halo) +
                                    "\" stroke-linejoin=\"round\" paint-order=\"stroke\""
                              : std::string()) +
                  ">" + xmlEscape(p.text) +
                  "</text>\n";
          break;
        }
      }
    }
    body += "</g>\n";
  }
  std::string o = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  o += "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"" + std::to_string(fig.width) +
       "\" height=\"" + std::to_string(fig.height) + "\" viewBox=\"0 0 " + std::to_string(fig.width) + " " +
       std::to_string(fig.height) + "\" font-family=\"" + xmlEscape(fontFamily(defaultFont())) + ", sans-serif\">\n";
  if (!fig.title.empty()) o += "<title>" + xmlEscape(fig.title) + "</title>\n";
  o += "<defs>\n" + defs + "</defs>\n";
  o += "<rect class=\"background\" width=\"100%\" height=\"100%\" " + svgFill(fig.background) + "/>\n";
  return o + body + "</svg>\n";
}

// ---------------------------------------------------------------------------------- PDF

void cairoColor(cairo_t* cr, const Color& c) { cairo_set_source_rgba(cr, c.r, c.g, c.b, c.a); }

cairo_status_t appendToString(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

std::string pdf(const VectorFigure& fig, const std::vector<std::vector<Prim>>& panels) {
  std::string bytes;
  constexpr double kPt = 0.75;  // points per pixel
  cairo_surface_t* surface =
      cairo_pdf_surface_create_for_stream(appendToString, &bytes, fig.width * kPt, fig.height * kPt);
  if (!fig.title.empty()) cairo_pdf_surface_set_metadata(surface, CAIRO_PDF_METADATA_TITLE, cleanText(fig.title).c_str());
  cairo_pdf_surface_set_metadata(surface, CAIRO_PDF_METADATA_CREATOR, "flexure");
  // The creation date is the clock's, unless SOURCE_DATE_EPOCH fixes it (reproducible files).
  if (const long long t = sourceDateEpoch(); t >= 0) {
    const std::time_t tt = static_cast<std::time_t>(t);
    std::tm utc{};
    gmtime_r(&tt, &utc);
    char date[32];
    std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", &utc);
    cairo_pdf_surface_set_metadata(surface, CAIRO_PDF_METADATA_CREATE_DATE, date);
  }
  cairo_t* cr = cairo_create(surface);
  const std::string family = fontFamily(defaultFont());
  cairo_scale(cr, kPt, kPt);
  cairoColor(cr, fig.background);
  cairo_paint(cr);
  for (size_t k = 0; k < panels.size(); ++k) {
    const VectorPanel& panel = fig.panels[k];
    cairo_save(cr);
    cairo_rectangle(cr, panel.x, panel.y, panel.view.width, panel.view.height);
    cairo_clip(cr);
    for (const Prim& p : panels[k]) {
      switch (p.kind) {
        case Prim::Fill:
          cairo_new_path(cr);
          for (const P2& q : p.pts) cairo_line_to(cr, q[0], q[1]);
          cairo_close_path(cr);
          cairoColor(cr, p.fill);
          cairo_fill(cr);
          break;
        case Prim::Line: {
          cairo_new_path(cr);
          cairo_move_to(cr, p.pts[0][0], p.pts[0][1]);
          cairo_line_to(cr, p.pts[1][0], p.pts[1][1]);
          cairo_set_line_width(cr, p.width);
          if (p.dash > 0) {
            const double d[2] = {p.dash, p.gap};
            cairo_set_dash(cr, d, 2, 0);
            cairo_set_line_cap(cr, CAIRO_LINE_CAP_BUTT);
          } else {
            cairo_set_dash(cr, nullptr, 0, 0);
            cairo_set_line_cap(cr, p.butt ? CAIRO_LINE_CAP_BUTT : CAIRO_LINE_CAP_ROUND);
          }
          cairo_pattern_t* pattern = nullptr;
          if (p.shaded) {
            const P2 n = normalOf(p);
            const P2 m{0.5 * (p.pts[0][0] + p.pts[1][0]), 0.5 * (p.pts[0][1] + p.pts[1][1])};
            const double r = 0.5 * p.width;
            pattern = cairo_pattern_create_linear(m[0] - r * n[0], m[1] - r * n[1], m[0] + r * n[0], m[1] + r * n[1]);
            for (double s : kTubeStops) {
              const Color c = tubeColor(p.fill, n, s);
              cairo_pattern_add_color_stop_rgba(pattern, 0.5 * (s + 1), c.r, c.g, c.b, c.a);
            }
            cairo_set_source(cr, pattern);
          } else {
            cairoColor(cr, p.fill);
          }
          cairo_stroke(cr);
          if (pattern) cairo_pattern_destroy(pattern);
          break;
        }
        case Prim::Circle: {
          const double x = p.pts[0][0], y = p.pts[0][1];
          cairo_new_path(cr);
          cairo_arc(cr, x, y, p.radius, 0, 2 * M_PI);
          cairo_pattern_t* pattern = nullptr;
          if (p.shaded) {
            pattern = cairo_pattern_create_radial(x + kHighlightX * p.radius, y + kHighlightY * p.radius, 0, x, y, p.radius);
            for (double t : kBallStops) {
              const Color c = ballColor(p.fill, t);
              cairo_pattern_add_color_stop_rgba(pattern, t, c.r, c.g, c.b, c.a);
            }
            cairo_set_source(cr, pattern);
          } else {
            cairoColor(cr, p.fill);
          }
          cairo_fill(cr);
          if (pattern) cairo_pattern_destroy(pattern);
          if (p.width > 0) {
            cairo_new_path(cr);
            cairo_arc(cr, x, y, std::max(0.0, p.radius - 0.5 * p.width), 0, 2 * M_PI);
            cairo_set_line_width(cr, p.width);
            cairo_set_dash(cr, nullptr, 0, 0);
            cairoColor(cr, p.stroke);
            cairo_stroke(cr);
          }
          break;
        }
        case Prim::Text: {
          const std::string text = cleanText(p.text);
          cairo_select_font_face(cr, family.c_str(), CAIRO_FONT_SLANT_NORMAL,
                                 p.bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
          cairo_set_font_size(cr, p.size);
          cairo_text_extents_t e;
          cairo_text_extents(cr, text.c_str(), &e);
          // As the raster renderer lays labels out: the ink centred vertically on the anchor,
          // its left end, centre or right end at the anchor.
          const double x = p.pts[0][0] - e.x_bearing - 0.5 * (1 + p.align) * e.width;
          const double y = p.pts[0][1] - (e.y_bearing + 0.5 * e.height);
          if (p.halo > 0) {
            cairo_move_to(cr, x, y);
            cairo_text_path(cr, text.c_str());
            cairoColor(cr, p.stroke);
            cairo_set_line_width(cr, p.halo);
            cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
            cairo_set_dash(cr, nullptr, 0, 0);
            cairo_stroke(cr);
          }
          cairo_move_to(cr, x, y);
          cairoColor(cr, p.fill);
          cairo_show_text(cr, text.c_str());
          break;
        }
      }
    }
    cairo_restore(cr);
  }
  cairo_destroy(cr);
  cairo_surface_finish(surface);
  const cairo_status_t status = cairo_surface_status(surface);
  cairo_surface_destroy(surface);
  if (status != CAIRO_STATUS_SUCCESS) throw std::runtime_error(std::string("cairo: ") + cairo_status_to_string(status));
  return bytes;
}

// --------------------------------------------------------------------------------- TikZ

std::string texEscape(const std::string& s) {
  std::string o;
  for (char ch : cleanText(s)) {
    switch (ch) {
      case '\\': o += "\\textbackslash{}"; break;
      case '{': o += "\\{"; break;
      case '}': o += "\\}"; break;
      case '$': o += "\\$"; break;
      case '&': o += "\\&"; break;
      case '#': o += "\\#"; break;
      case '%': o += "\\%"; break;
      case '_': o += "\\_"; break;
      case '~': o += "\\textasciitilde{}"; break;
      case '^': o += "\\textasciicircum{}"; break;
      default: o += ch;
    }
  }
  return o;
}

// A TikZ style: what a part looks like. Parts whose look equals their role's style use the
// style alone; others add what differs.
struct TikzLook {
  std::string color;  // a defined colour's name
  double opacity = 1, width = 0, dash = 0, gap = 0, size = 0, outline = 0;
  std::string outline_color;
  bool shaded = false, bold = true, butt = false;
  int align = 0;
  bool operator==(const TikzLook& o) const {
    return color == o.color && opacity == o.opacity && width == o.width && dash == o.dash && gap == o.gap &&
           size == o.size && outline == o.outline && outline_color == o.outline_color && shaded == o.shaded &&
           bold == o.bold && align == o.align && butt == o.butt;
  }
};

std::string bp(double px) { return num(0.75 * px) + "bp"; }

std::string tikzOptions(Prim::Kind kind, const TikzLook& l) {
  std::string o;
  const auto add = [&](const std::string& s) { o += (o.empty() ? "" : ", ") + s; };
  switch (kind) {
    case Prim::Fill:
      add("fill=" + l.color);
      if (l.opacity < 1) add("fill opacity=" + num(l.opacity));
      break;
    case Prim::Line:
      add("draw=" + l.color), add("line width=" + bp(l.width));
      if (l.opacity < 1) add("draw opacity=" + num(l.opacity));
      if (l.dash > 0) add("dash pattern=on " + bp(l.dash) + " off " + bp(l.gap) + ", line cap=butt");
      else add(l.butt ? "line cap=butt" : "line cap=round");
      break;
    case Prim::Circle:
      if (l.shaded) add("ball color=" + l.color);
      else add("fill=" + l.color);
      if (l.opacity < 1) add("opacity=" + num(l.opacity));
      if (l.outline > 0) add("draw=" + l.outline_color), add("line width=" + bp(l.outline));
      break;
    case Prim::Text:
      add("text=" + l.color);
      if (l.opacity < 1) add("text opacity=" + num(l.opacity));
      add("inner sep=0pt");
      add(std::string("anchor=") + (l.align < 0 ? "west" : l.align > 0 ? "east" : "center"));
      add("font=\\fontsize{" + num(0.75 * l.size) + "}{" + num(0.9 * l.size) + "}\\selectfont" +
          (l.bold ? "\\bfseries" : ""));
      break;
  }
  return o;
}

std::string tikz(const VectorFigure& fig, const std::vector<std::vector<Prim>>& panels) {
  std::map<std::string, std::string> colors;  // hex -> name
  std::string color_defs;
  const auto colorName = [&](const Color& c) {
    const std::string h = hex(c);
    auto it = colors.find(h);
    if (it == colors.end()) {
      const std::string name = "flexure" + std::string(1, static_cast<char>('A' + colors.size() % 26)) +
                               (colors.size() >= 26 ? std::to_string(colors.size() / 26) : "");
      char rgb[64];
      std::snprintf(rgb, sizeof rgb, "%d,%d,%d", channel(c.r), channel(c.g), channel(c.b));
      color_defs += "\\definecolor{" + name + "}{RGB}{" + rgb + "}\n";
      it = colors.emplace(h, name).first;
    }
    return it->second;
  };
  const std::string background = colorName(fig.background);
  const auto lookOf = [&](const Prim& p) {
    TikzLook l;
    l.color = colorName(p.fill);
    l.opacity = std::round(p.fill.a * 100) / 100;
    if (p.kind == Prim::Line) l.width = p.width, l.dash = p.dash, l.gap = p.gap, l.butt = p.butt;
    if (p.kind == Prim::Circle) {
      l.shaded = p.shaded;
      l.outline = p.width;
      if (p.width > 0) l.outline_color = colorName(p.stroke);
    }
    if (p.kind == Prim::Text) l.size = p.size, l.bold = p.bold, l.align = p.align;
    return l;
  };
  // One style per (role, kind): the first part's look.
  std::map<std::pair<std::string, int>, TikzLook> styles;
  std::vector<std::pair<std::string, int>> style_order;
  std::map<std::string, int> kinds_of_role;
  for (const auto& prims : panels)
    for (const Prim& p : prims) {
      const auto key = std::make_pair(p.role, static_cast<int>(p.kind));
      if (styles.emplace(key, lookOf(p)).second) {
        style_order.push_back(key);
        ++kinds_of_role[p.role];
      }
    }
  static const char* kKindNames[] = {"fill", "line", "disc", "text"};
  const auto styleName = [&](const std::pair<std::string, int>& key) {
    return "flexure " + key.first + (kinds_of_role[key.first] > 1 ? std::string(" ") + kKindNames[key.second] : "");
  };
  std::string body;
  for (size_t k = 0; k < panels.size(); ++k) {
    const VectorPanel& panel = fig.panels[k];
    body += "  \\begin{scope}\n    \\clip (" + num(panel.x) + "," + num(panel.y) + ") rectangle (" +
            num(panel.x + panel.view.width) + "," + num(panel.y + panel.view.height) + ");\n";
    for (const Prim& p : panels[k]) {
      const auto key = std::make_pair(p.role, static_cast<int>(p.kind));
      const TikzLook look = lookOf(p);
      std::string opt = styleName(key);
      if (!(look == styles[key])) opt += ", " + tikzOptions(p.kind, look);
      const auto at = [&](const P2& q) { return "(" + num(q[0]) + "," + num(q[1]) + ")"; };
      switch (p.kind) {
        case Prim::Fill: {
          body += "    \\fill[" + opt + "] ";
          for (const P2& q : p.pts) body += at(q) + " -- ";
          body += "cycle;\n";
          break;
        }
        case Prim::Line:
          body += "    \\draw[" + opt + "] " + at(p.pts[0]) + " -- " + at(p.pts[1]) + ";\n";
          break;
        case Prim::Circle:
          // The radius in the picture's units (x = 0.75bp): as the pixels.
          body += std::string(look.shaded ? "    \\shade[" : "    \\path[") + opt + "] " + at(p.pts[0]) +
                  " circle[radius=" + num(p.radius) + "];\n";
          break;
        case Prim::Text:
          body += "    \\node[" + opt + "] at " + at(p.pts[0]) + " {" + texEscape(p.text) + "};\n";
          break;
      }
    }
    body += "  \\end{scope}\n";
  }
  std::string o = "% " + (fig.title.empty() ? std::string("A figure") : texEscape(fig.title)) +
                  ", drawn by flexure. Compile with pdflatex (lualatex or xelatex for text beyond Latin-1).\n"
                  "% Every part has a named style (\\tikzset below): restyle the bars, joints, ... there.\n"
                  "% Coordinates are the PNG's pixels (y down); 1 px = 0.75 bp.\n";
  // Latin Modern with T1 where installed; else the Type 1 Computer Modern that every TeX has
  // (T1 without Latin Modern or cm-super would make METAFONT draw bitmap fonts).
  o += "\\documentclass[tikz]{standalone}\n\\IfFileExists{lmodern.sty}{\\usepackage[T1]{fontenc}\\usepackage{lmodern}}{}\n"
       "\\usepackage[utf8]{inputenc}\n"
       "\\renewcommand{\\familydefault}{\\sfdefault}\n";
  o += color_defs;
  o += "\\tikzset{\n";
  for (const auto& key : style_order)
    o += "  " + styleName(key) + "/.style={" + tikzOptions(static_cast<Prim::Kind>(key.second), styles[key]) + "},\n";
  o += "}\n\\begin{document}\n\\begin{tikzpicture}[x=0.75bp, y=-0.75bp]\n";
  o += "  \\fill[" + background + "] (0,0) rectangle (" + std::to_string(fig.width) + "," +
       std::to_string(fig.height) + ");\n";
  return o + body + "\\end{tikzpicture}\n\\end{document}\n";
}

}  // namespace

bool vectorFormatOf(const std::string& extension, VectorFormat& format) {
  if (extension == "svg") format = VectorFormat::Svg;
  else if (extension == "pdf") format = VectorFormat::Pdf;
  else if (extension == "tex") format = VectorFormat::Tikz;
  else return false;
  return true;
}

VectorFigure singlePanel(const DrawList& list, const View& view, const std::string& title) {
  VectorFigure f;
  f.width = view.width, f.height = view.height;
  f.background = view.background;
  f.panels.push_back({&list, view, 0, 0});
  f.title = title;
  return f;
}

std::string vectorDocument(const VectorFigure& figure, VectorFormat format) {
  std::vector<std::vector<Prim>> panels;
  for (const VectorPanel& p : figure.panels) panels.push_back(flatten(p));
  switch (format) {
    case VectorFormat::Svg: return svg(figure, panels);
    case VectorFormat::Pdf: return pdf(figure, panels);
    case VectorFormat::Tikz: return tikz(figure, panels);
  }
  throw std::logic_error("unknown vector format");
}

}  // namespace flexure::render
