// What the renderer draws: a list of primitives in world coordinates (2D or 3D) with sizes in
// pixels. It knows nothing of constraint systems; present/figure.cpp builds it from a
// configuration. Primitives are drawn in the order of their layer (polygons, then shapes in
// insertion order, then labels); in 3D the depth test orders the opaque ones, and translucent
// shapes are drawn after them, back to front.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "render/color.h"

namespace flexure::render {

using Point3 = std::array<double, 3>;  // 2D scenes leave z = 0

enum class ShapeKind { Segment, Disc, Triangle, Pentagon };

// One anti-aliased shape, drawn with a signed distance in pixels (no MSAA needed).
struct Shape {
  ShapeKind kind = ShapeKind::Disc;
  Point3 a{}, b{};           // segment ends; a disc's or triangle's centre is a
  float radius = 1;          // half width (segment), radius (disc), circumradius (triangle), px
  float outline = 0;         // outline width in px (disc, triangle), drawn inside the shape
  Color fill, stroke;
  float dash = 0, gap = 0;   // segments: dash pattern in px (0: solid)
  float inset = 0;           // segments: stop this many px short of b (under an arrow head)
  // Triangle: with a == b, centred at a (plus offset) with its tip towards `pointing` on
  // screen; with a != b, an arrow head: tip at b, pointing along a -> b as seen on screen.
  // Pentagon: a regular pentagon marker centred at a (radius: circumradius), tip to `pointing`.
  float pointing[2] = {1, 0};
  float offset[2] = {0, 0};    // screen offset in px of a disc's or triangle's centre
  bool shaded = false;       // 3D: lit as a ball (disc) or a tube (segment)
  double world_radius = 0;   // disc: when > 0, the radius in world units (a disk, a sphere)
  bool on_top = false;       // 3D: drawn over everything, unfaded (flex arrows along tubes)
  // What the shape is ("bar", "joint", "pin", ...): the class in SVG and the named style in
  // TikZ, so that a figure can be restyled by its parts. Raster output ignores it.
  const char* role = nullptr;
  // The vertices it stands for, as the scene numbers them (a bar's two, a joint's one; -1:
  // none): its id in SVG ("bar-1-2") and TikZ (a comment).
  int element[2] = {-1, -1};
};

// A filled planar polygon (a facet, a simplex, a disk drawn as an n-gon), translucent or not.
struct Polygon {
  std::vector<Point3> points;
  Color fill;
  bool shaded = false;  // 3D: lit by its normal
  const char* role = nullptr;  // as Shape::role
};

struct Label {
  Point3 at{};
  std::string text;
  float size = 14;  // font size in px
  Color color;
  float offset[2] = {0, 0};  // px
  int align = 0;             // the anchor is the text's -1: left end, 0: centre, 1: right end
  bool regular = false;      // regular weight instead of bold
  bool screen = false;       // `at` is in pixels from the image's top-left corner, not world
  // Moved beside its anchor (in `aside_color`, as it leaves the vertex disc) where it would
  // overlap a declutter label already placed (nearer ones first in 3D), left out where no place
  // beside it is free: vertex labels never print over each other, and the label of a vertex
  // that projects onto another one's is still shown.
  bool declutter = false;
  Color aside_color{0, 0, 0, 1};
  int element[2] = {-1, -1};  // as Shape::element
  const char* role = nullptr;  // as Shape::role
};

struct DrawList {
  int dimension = 2;
  std::vector<Polygon> polygons;
  std::vector<Shape> shapes;
  std::vector<Label> labels;

  // The role of the shape added last (see Shape::role).
  void tag(const char* role) { shapes.back().role = role; }
  void segment(const Point3& a, const Point3& b, float width, const Color& c) {
    Shape s;
    s.kind = ShapeKind::Segment;
    s.a = a, s.b = b, s.radius = 0.5f * width, s.fill = c;
    shapes.push_back(s);
  }
  void disc(const Point3& a, float radius, const Color& fill, float outline = 0, const Color& stroke = {}) {
    Shape s;
    s.kind = ShapeKind::Disc;
    s.a = s.b = a, s.radius = radius, s.fill = fill, s.outline = outline, s.stroke = stroke;
    shapes.push_back(s);
  }
  // A shaft and a triangular head whose tip is at `to`, pointing along the segment as it
  // appears on screen.
  void arrow(const Point3& from, const Point3& to, float width, float head, const Color& c,
             const char* role = nullptr) {
    segment(from, to, width, c);
    tag(role);
    shapes.back().inset = 0.6f * head;  // the shaft ends inside the head, not at its tip
    Shape tip;
    tip.kind = ShapeKind::Triangle;
    tip.a = from, tip.b = to, tip.radius = 0.5f * head, tip.fill = c;
    tip.role = role;
    shapes.push_back(tip);
  }
};

// How the world is mapped to the image.
struct View {
  int width = 1000, height = 1000;
  Color background{1, 1, 1, 1};
  // World window: 2D, [x0, x1] x [y0, y1] mapped with equal aspect into the image. 3D: the
  // box [lo, hi] is fitted into the image after rotating by azimuth/elevation.
  Point3 lo{0, 0, 0}, hi{1, 1, 1};
  bool three_d = false;
  double azimuth = 0.7853981633974483, elevation = 0.39269908169744;  // pi/4, pi/8
  bool perspective = false;
  // 3D orthographic: fit the box seen from every azimuth (same scale and centre for all), so a
  // turning camera does not zoom in and out.
  bool turntable = false;
  double field_of_view = 0.6;  // radians, perspective only
  double zoom = 1;             // magnification about the centre of the fitted view (the viewer's wheel)
  double pan_x = 0, pan_y = 0; // pixels the picture is moved by (x right, y up; the viewer's pan)
  // 3D: colours fade toward the background with depth, by this fraction at the far side of the
  // box (render::fogged); 0: none.
  double fog = 0;
};

}  // namespace flexure::render
