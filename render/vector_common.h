// The vector writers' shared primitives, private to render/ (the interface is render/vector.h):
// a panel flattened into primitives in figure pixels and painting order (vector_common.cpp),
// numbers and colours as the files spell them, tubes and balls shaded as the raster renderer
// lights them; and the three writers, one file each (svg.cpp, pdf.cpp, tikz.cpp).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "render/vector.h"

namespace flexure::render::vector_detail {

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
  std::string id;   // the part's element ("bar-1-2", "joint-3", "label-3"), empty for others
  // 3D: how far fill and stroke were faded toward the background by depth (0..1), from these.
  double fog = 0;
  Color own_fill, own_stroke;
};

// "ROLE-A(-B)" for a part that stands for vertices (Shape::element), else "".
std::string elementId(const std::string& role, const int (&element)[2]);

// The panel's primitives in painting order: 2D as given (polygons, shapes, labels); 3D with
// polygons and shapes back to front, labels on top.
std::vector<Prim> flatten(const VectorPanel& panel);

// A number as the files write it: 2 decimals at most, no trailing zeros, never "-0"; 0 if it
// is not finite.
std::string num(double v);
// A colour channel as 0..255 (clamped).
int channel(float v);
// "#RRGGBB" (the alpha aside).
std::string hex(const Color& c);

// The unit normal of a line on screen (figure pixels, y down) and its length.
P2 normalOf(const Prim& p, double* length = nullptr);

// A tube's colour across its width: s from -1 to 1 along `n` (figure pixels, y down).
Color tubeColor(const Color& c, const P2& n, double s);

// The gradients' stops: across a tube (s of tubeColor), from a ball's highlight to its rim (t).
inline constexpr double kTubeStops[] = {-1, -0.6, -0.2, 0.2, 0.6, 1};
inline constexpr double kBallStops[] = {0, 0.35, 0.7, 1};
// The ball's colour at fraction t of the way from its highlight to its rim.
Color ballColor(const Color& c, double t);
// Where the highlight is, as a fraction of the radius from the centre (y down).
inline constexpr double kHighlightX = -0.35 * 0.8, kHighlightY = -0.45 * 0.8;

// The writers, one file each: the whole file's bytes from the figure and its panels' primitives
// (flatten's, in the order of fig.panels). pdf throws std::runtime_error if cairo fails.
std::string svg(const VectorFigure& fig, const std::vector<std::vector<Prim>>& panels);   // svg.cpp
std::string pdf(const VectorFigure& fig, const std::vector<std::vector<Prim>>& panels);   // pdf.cpp
std::string tikz(const VectorFigure& fig, const std::vector<std::vector<Prim>>& panels);  // tikz.cpp

}  // namespace flexure::render::vector_detail
