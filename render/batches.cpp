#include "render/batches.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace flexure::render {

namespace {

void copyColor(float* out, const Color& c) {
  out[0] = c.r, out[1] = c.g, out[2] = c.b, out[3] = c.a;
}

// The Newell normal of a polygon (not normalised: its length is twice the area).
std::array<double, 3> newellNormal(const std::vector<Point3>& points) {
  std::array<double, 3> normal{0, 0, 0};
  const size_t n = points.size();
  for (size_t k = 0; k < n; ++k) {
    const Point3& p = points[k];
    const Point3& q = points[(k + 1) % n];
    normal[0] += (p[1] - q[1]) * (p[2] + q[2]);
    normal[1] += (p[2] - q[2]) * (p[0] + q[0]);
    normal[2] += (p[0] - q[0]) * (p[1] + q[1]);
  }
  return normal;
}

}  // namespace

Color polygonColor(const Polygon& poly, const Projector& project, bool depth) {
  Color col = poly.fill;
  if (!poly.shaded || !depth) return col;
  const std::array<double, 3> n = newellNormal(poly.points);
  const double nn = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  if (!(nn > 0)) return col;
  const auto ne = project.toEye({n[0] / nn, n[1] / nn, n[2] / nn});
  const double lit = std::abs(-0.35 * ne[0] + 0.45 * ne[1] + 0.82 * ne[2]);
  const float f = static_cast<float>(0.55 + 0.45 * std::min(1.0, lit));
  col.r *= f, col.g *= f, col.b *= f;
  return col;
}

// Ear clipping of a simple polygon given in 2D (indices into pts); returns triangles.
std::vector<int> triangulate(const std::vector<std::array<double, 2>>& pts) {
  const int n = static_cast<int>(pts.size());
  std::vector<int> out, idx(n);
  if (n < 3) return out;
  double area = 0;
  for (int i = 0; i < n; ++i) {
    const auto& p = pts[i];
    const auto& q = pts[(i + 1) % n];
    area += p[0] * q[1] - q[0] * p[1];
  }
  for (int i = 0; i < n; ++i) idx[i] = area >= 0 ? i : n - 1 - i;
  auto cross = [&](int a, int b, int c) {
    return (pts[b][0] - pts[a][0]) * (pts[c][1] - pts[a][1]) - (pts[b][1] - pts[a][1]) * (pts[c][0] - pts[a][0]);
  };
  int guard = 0;
  while (idx.size() > 3 && guard++ < 4 * n * n) {
    bool clipped = false;
    const int m = static_cast<int>(idx.size());
    for (int i = 0; i < m; ++i) {
      const int a = idx[(i + m - 1) % m], b = idx[i], c = idx[(i + 1) % m];
      if (cross(a, b, c) <= 0) continue;
      bool inside = false;
      for (int j : idx) {
        if (j == a || j == b || j == c) continue;
        if (cross(a, b, j) >= 0 && cross(b, c, j) >= 0 && cross(c, a, j) >= 0) {
          inside = true;
          break;
        }
      }
      if (inside) continue;
      out.insert(out.end(), {a, b, c});
      idx.erase(idx.begin() + i);
      clipped = true;
      break;
    }
    if (!clipped) break;  // degenerate: fan the rest
  }
  for (size_t i = 1; i + 1 < idx.size(); ++i) out.insert(out.end(), {idx[0], idx[i], idx[i + 1]});
  return out;
}

double fogAmount(double depth, double fog) { return fog > 0 ? fog * std::clamp((depth + 0.8) / 1.6, 0.0, 1.0) : 0.0; }

Color fogged(const Color& c, double depth, const Color& background, double fog) {
  if (fog <= 0) return c;
  const float t = static_cast<float>(fogAmount(depth, fog));
  return {c.r + t * (background.r - c.r), c.g + t * (background.g - c.g), c.b + t * (background.b - c.b), c.a};
}

Color haloColor(const Color& text, const Color& background) {
  const double luminance = 0.2126 * text.r + 0.7152 * text.g + 0.0722 * text.b;
  return luminance > 0.5 ? Color{0.1f, 0.1f, 0.1f, text.a} : Color{background.r, background.g, background.b, text.a};
}

double haloWidth(double size) { return std::max(1.0, std::round(size / 14.0)); }

// Polygons: opaque ones first; translucent ones back to front without depth writes.
void buildPolygonBatches(const DrawList& list, const Projector& project, bool depth, FrameBatches& out) {
  std::vector<std::pair<double, size_t>> order;
  for (size_t i = 0; i < list.polygons.size(); ++i) {
    double zsum = 0;  // 2D: all zero, so the order given stays
    if (depth)
      for (const Point3& p : list.polygons[i].points) zsum += project(p)[2];
    order.push_back({-zsum / std::max<size_t>(1, list.polygons[i].points.size()), i});
  }
  std::stable_sort(order.begin(), order.end(), [](auto& a, auto& b) { return a.first < b.first; });
  for (const auto& [key, i] : order) {
    const Polygon& poly = list.polygons[i];
    const size_t n = poly.points.size();
    if (n < 3) continue;
    // Triangulate in the polygon's own plane (Newell normal), so edge-on views stay right.
    std::array<double, 3> normal = newellNormal(poly.points), c{0, 0, 0};
    for (const Point3& p : poly.points)
      for (int j = 0; j < 3; ++j) c[j] += p[j] / static_cast<double>(n);
    const double nn = std::sqrt(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]);
    std::array<double, 3> e1{1, 0, 0}, e2{0, 1, 0};
    if (nn > 0) {
      for (double& x : normal) x /= nn;
      const std::array<double, 3> t = std::abs(normal[0]) < 0.9 ? std::array<double, 3>{1, 0, 0}
                                                                 : std::array<double, 3>{0, 1, 0};
      e1 = {normal[1] * t[2] - normal[2] * t[1], normal[2] * t[0] - normal[0] * t[2], normal[0] * t[1] - normal[1] * t[0]};
      const double l = std::sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
      for (double& x : e1) x /= l;
      e2 = {normal[1] * e1[2] - normal[2] * e1[1], normal[2] * e1[0] - normal[0] * e1[2], normal[0] * e1[1] - normal[1] * e1[0]};
    }
    static const std::vector<int> kTriangle = {0, 1, 2};  // meshes: no triangulation needed
    std::vector<int> triangles;
    if (n > 3) {
      std::vector<std::array<double, 2>> flat(n);
      for (size_t k = 0; k < n; ++k) {
        double u = 0, v = 0;
        for (int j = 0; j < 3; ++j) {
          u += (poly.points[k][j] - c[j]) * e1[j];
          v += (poly.points[k][j] - c[j]) * e2[j];
        }
        flat[k] = {u, v};
      }
      triangles = triangulate(flat);
    }
    const Color col = polygonColor(poly, project, depth);
    std::vector<FlatVertex>& tris = col.a >= 1.0f ? out.opaque_polygons : out.translucent_polygons;
    for (int k : n > 3 ? triangles : kTriangle) {
      const auto q = project(poly.points[static_cast<size_t>(k)]);
      FlatVertex fv{};
      fv.pos[0] = static_cast<float>(q[0]), fv.pos[1] = static_cast<float>(q[1]), fv.pos[2] = static_cast<float>(q[2]);
      copyColor(fv.rgba, fogged(col, q[2], out.background, out.fog));
      tris.push_back(fv);
    }
  }
}

// Shapes: one quad each, in pixels.
void buildShapeBatch(const DrawList& list, const Projector& project, bool depth, FrameBatches& out) {
  std::vector<ShapeVertex>& shapes = out.shapes;
  shapes.reserve(list.shapes.size() * 6);
  const double depth_per_px = depth ? project.depthPerUnit() / std::max(project.pixelsPerUnit(), 1e-300) : 0.0;
  // In 3D, translucent shapes go after the opaque ones, back to front (larger depth first).
  std::vector<size_t> shape_order(list.shapes.size());
  size_t opaque_shapes = list.shapes.size();  // 2D: all in order, depth plays no part
  for (size_t i = 0; i < shape_order.size(); ++i) shape_order[i] = i;
  if (depth) {
    std::vector<double> z(shape_order.size());
    for (size_t i = 0; i < shape_order.size(); ++i) z[i] = 0.5 * (project(list.shapes[i].a)[2] + project(list.shapes[i].b)[2]);
    auto clear = [&](size_t i) { return list.shapes[i].fill.a < 1.0f; };
    const auto mid = std::stable_partition(shape_order.begin(), shape_order.end(), [&](size_t i) { return !clear(i); });
    std::stable_sort(mid, shape_order.end(), [&](size_t i, size_t j) { return z[i] > z[j]; });
    opaque_shapes = static_cast<size_t>(mid - shape_order.begin());
  }
  size_t& opaque_vertices = out.opaque_shape_vertices;
  opaque_vertices = 0;
  for (size_t pos = 0; pos < shape_order.size(); ++pos) {
    if (pos == opaque_shapes) opaque_vertices = shapes.size();
    Shape s = list.shapes[shape_order[pos]];
    if (s.kind == ShapeKind::Disc && s.world_radius > 0)
      s.radius = static_cast<float>(s.world_radius * project.pixelsPerUnitAt(s.a));
    auto pa = project(s.a), pb = project(s.b);
    if (s.on_top) pa[2] = pb[2] = -1;  // the nearest depth
    float pointing[2] = {s.pointing[0], s.pointing[1]};
    if (s.kind == ShapeKind::Triangle && s.a != s.b) {  // an arrow head at b
      const double dx = pb[0] - pa[0], dy = pb[1] - pa[1], len = std::hypot(dx, dy);
      if (len < 1e-9) continue;
      pointing[0] = static_cast<float>(dx / len), pointing[1] = static_cast<float>(dy / len);
      pa = pb;
      pa[0] -= s.radius * dx / len, pa[1] -= s.radius * dy / len;
    }
    if (s.kind != ShapeKind::Segment) {
      pa[0] += s.offset[0], pa[1] += s.offset[1];
      pb = pa;
    } else if (s.inset > 0) {
      const double dx = pb[0] - pa[0], dy = pb[1] - pa[1], len = std::hypot(dx, dy);
      const double keep = std::max(0.0, len - s.inset) / std::max(len, 1e-300);
      pb[0] = pa[0] + keep * dx, pb[1] = pa[1] + keep * dy, pb[2] = pa[2] + keep * (pb[2] - pa[2]);
    }
    ShapeVertex base{};
    base.ends[0] = static_cast<float>(pa[0]), base.ends[1] = static_cast<float>(pa[1]);
    base.ends[2] = static_cast<float>(pb[0]), base.ends[3] = static_cast<float>(pb[1]);
    base.params[0] = static_cast<float>(s.kind == ShapeKind::Segment ? 0 : s.kind == ShapeKind::Disc ? 1
                                        : s.kind == ShapeKind::Triangle ? 2 : 3);
    base.params[1] = s.radius;
    base.params[2] = s.outline;
    base.params[3] = static_cast<float>(s.radius * depth_per_px);
    copyColor(base.fill, s.fill);
    copyColor(base.stroke, s.stroke);
    if (s.kind == ShapeKind::Segment) {
      base.extra[0] = s.dash, base.extra[1] = s.gap;
    } else {
      base.extra[0] = pointing[0], base.extra[1] = pointing[1];
    }
    base.depths[0] = static_cast<float>(pa[2]), base.depths[1] = static_cast<float>(pb[2]);
    base.depths[2] = s.shaded && depth ? 1.0f : 0.0f;
    // The covering quad.
    const double grow = s.radius + 1.5;
    double dx = pb[0] - pa[0], dy = pb[1] - pa[1];
    const double len = std::hypot(dx, dy);
    if (len > 0) dx /= len, dy /= len;
    else dx = 1, dy = 0;
    const double nx = -dy, ny = dx;
    const double corners[4][2] = {{pa[0] - grow * dx - grow * nx, pa[1] - grow * dy - grow * ny},
                                  {pb[0] + grow * dx - grow * nx, pb[1] + grow * dy - grow * ny},
                                  {pb[0] + grow * dx + grow * nx, pb[1] + grow * dy + grow * ny},
                                  {pa[0] - grow * dx + grow * nx, pa[1] - grow * dy + grow * ny}};
    const float zq = static_cast<float>(std::min(pa[2], pb[2]));
    for (int k : {0, 1, 2, 0, 2, 3}) {
      ShapeVertex v = base;
      v.pos[0] = static_cast<float>(corners[k][0]), v.pos[1] = static_cast<float>(corners[k][1]), v.pos[2] = zq;
      shapes.push_back(v);
    }
  }
  if (opaque_shapes >= shape_order.size()) opaque_vertices = shapes.size();
}

std::vector<Label> placedLabels(const DrawList& list, const Projector& project, int height, bool depth,
                                const std::function<double(const Label&)>& width) {
  struct Box {
    double x0, y0, x1, y1;
    bool overlaps(const Box& p) const { return x0 < p.x1 && p.x0 < x1 && y0 < p.y1 && p.y0 < y1; }
  };
  const auto anchor = [&](const Label& l) {
    return l.screen ? std::array<double, 3>{l.at[0], height - l.at[1], 0.0} : project(l.at);
  };
  // `w`: the label's width (measured once: laying out text is not free).
  const auto box = [&](const Label& l, double w, const std::array<double, 3>& at, double dx, double dy) {
    const double x = at[0] + l.offset[0] + dx - 0.5 * (1 + l.align) * w, y = at[1] + l.offset[1] + dy;
    return Box{x, y - 0.5 * l.size, x + w, y + 0.5 * l.size};
  };
  std::vector<size_t> order;
  std::vector<std::array<double, 3>> anchors(list.labels.size());
  for (size_t i = 0; i < list.labels.size(); ++i)
    if (list.labels[i].declutter) order.push_back(i), anchors[i] = anchor(list.labels[i]);
  if (depth) std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return anchors[a][2] < anchors[b][2]; });
  std::vector<Label> out = list.labels;
  std::vector<char> keep(list.labels.size(), 1);
  std::vector<Box> placed;
  std::vector<std::array<double, 2>> placed_at;  // their anchors
  for (size_t i : order) {
    const Label& l = list.labels[i];
    const auto free = [&](const Box& b) {
      return std::none_of(placed.begin(), placed.end(), [&](const Box& p) { return b.overlaps(p); });
    };
    // Where it belongs; else, if its anchor is on a placed label's (a vertex seen on another),
    // beside it: upper right, upper left, lower right, lower left.
    const double s = l.size, w = width(l);
    const bool onto = std::any_of(placed_at.begin(), placed_at.end(), [&](const std::array<double, 2>& a) {
      return std::hypot(a[0] - anchors[i][0], a[1] - anchors[i][1]) < 0.5 * s;
    });
    const double shifts[5][2] = {{0, 0}, {0.5 * w + 0.9 * s, 1.1 * s}, {-0.5 * w - 0.9 * s, 1.1 * s},
                                 {0.5 * w + 0.9 * s, -1.1 * s}, {-0.5 * w - 0.9 * s, -1.1 * s}};
    keep[i] = 0;
    for (int k = 0; k < (onto ? 5 : 1); ++k) {
      const Box b = box(l, w, anchors[i], shifts[k][0], shifts[k][1]);
      if (!free(b)) continue;
      placed.push_back(b);
      placed_at.push_back({anchors[i][0], anchors[i][1]});
      keep[i] = 1;
      if (k > 0) {
        out[i].offset[0] += static_cast<float>(shifts[k][0]), out[i].offset[1] += static_cast<float>(shifts[k][1]);
        out[i].color = l.aside_color;
      }
      break;
    }
  }
  std::vector<Label> kept;
  for (size_t i = 0; i < out.size(); ++i)
    if (keep[i]) kept.push_back(std::move(out[i]));
  return kept;
}

// Labels on top, centred on their anchors. Glyph quads carry atlas pixels as uv until every
// label is laid out (laying one out may grow the atlas), then they are normalized.
void layoutLabels(const DrawList& list, const Projector& project, int height, const AtlasSource& atlas_for,
                  FrameBatches& out) {
  std::map<int, std::vector<FlatVertex>> text;
  const int H = height;
  const auto keyOf = [](const Label& l) { return 2 * std::max(4, static_cast<int>(std::lround(l.size))) + (l.regular ? 1 : 0); };
  const auto inkWidth = [&](const Label& l) {
    double width = 0;
    for (const PlacedGlyph& p : atlas_for(keyOf(l)).layout(l.text))
      if (p.glyph->w > 0) width = std::max(width, p.x + p.glyph->left + p.glyph->w);
    return width;
  };
  std::vector<Label> placed = placedLabels(list, project, height, out.depth, inkWidth);
  if (out.depth)  // far ones first: nearer labels (and their halos) cover them
    std::stable_sort(placed.begin(), placed.end(), [&](const Label& a, const Label& b) {
      const auto depthOf = [&](const Label& l) { return l.screen ? -2.0 : project(l.at)[2]; };
      return depthOf(a) > depthOf(b);
    });
  for (const Label& l : placed) {
    const int key = keyOf(l);
    const std::vector<PlacedGlyph>& line = atlas_for(key).layout(l.text);
    const auto at = l.screen ? std::array<double, 3>{l.at[0], H - l.at[1], 0.0} : project(l.at);
    double right = -1e9, top = -1e9, bottom = 1e9, left = 1e9;
    for (const PlacedGlyph& p : line) {
      const Glyph& g = *p.glyph;
      if (g.w == 0) continue;
      left = std::min(left, p.x + g.left);
      right = std::max(right, p.x + g.left + g.w);
      top = std::max(top, p.y + g.top);
      bottom = std::min(bottom, p.y + g.top - g.h);
    }
    if (top < bottom) continue;
    const double ox = std::round(at[0] + l.offset[0] - 0.5 * (1 + l.align) * right + 0.5 * (l.align - 1) * left);
    const double oy = std::round(at[1] + l.offset[1] - 0.5 * (top + bottom));
    auto& quads = text[key];
    const auto glyphs = [&](double dx, double dy, const Color& color) {
      for (const PlacedGlyph& p : line) {
        const Glyph& g = *p.glyph;
        if (g.w == 0) continue;
        const double x0 = std::round(ox + p.x) + g.left + dx, y1 = std::round(oy + p.y) + g.top + dy;
        const double x1 = x0 + g.w, y0 = y1 - g.h;
        const double xs[4] = {x0, x1, x1, x0}, ys[4] = {y0, y0, y1, y1};
        const float us[4] = {float(g.x), float(g.x + g.w), float(g.x + g.w), float(g.x)};
        const float vs[4] = {float(g.y + g.h), float(g.y + g.h), float(g.y), float(g.y)};
        for (int k : {0, 1, 2, 0, 2, 3}) {
          FlatVertex fv{};
          fv.pos[0] = static_cast<float>(xs[k]), fv.pos[1] = static_cast<float>(ys[k]), fv.pos[2] = 0;
          copyColor(fv.rgba, color);
          fv.uv[0] = us[k], fv.uv[1] = vs[k];
          quads.push_back(fv);
        }
      }
    };
    // 3D: a halo around labels in the scene, so that a label reads over the bars and balls
    // behind it.
    if (out.depth && !l.screen) {
      const double h = haloWidth(l.size);
      const Color halo = haloColor(l.color, out.background);
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          if (dx || dy) glyphs(dx * h, dy * h, halo);
    }
    glyphs(0, 0, l.color);
  }
  for (auto& [key, quads] : text) {
    const GlyphAtlas& atlas = atlas_for(key);
    for (FlatVertex& v : quads) v.uv[0] /= static_cast<float>(atlas.width()), v.uv[1] /= static_cast<float>(atlas.height());
    out.text.push_back({key, std::move(quads)});
  }
}

FrameBatches buildFrame(const DrawList& list, const View& view, const AtlasSource& atlas) {
  FrameBatches f;
  f.width = view.width, f.height = view.height;
  f.background = view.background;
  f.depth = view.three_d;
  f.fog = view.three_d ? static_cast<float>(view.fog) : 0.0f;
  const Projector project(view);
  buildPolygonBatches(list, project, f.depth, f);
  buildShapeBatch(list, project, f.depth, f);
  layoutLabels(list, project, f.height, atlas, f);
  return f;
}

}  // namespace flexure::render
