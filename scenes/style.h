// How a scene looks: the [render] keys of colours, sizes, toggles and the camera, as plain
// data. The presentation layer (present/figure.h) draws with it; the scene language only reads it.
#pragma once

#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "render/color.h"

namespace flexure::scenes {

// "#RRGGBB", "#RRGGBBAA", or a name of the reference's palette (steelblue, black, white,
// lightgrey, red3, green3, grey80, grey50, grey98, gray35, teal, coral, ...).
std::optional<render::Color> parseColor(const std::string& text);

// One edge's or vertex's own look, over the figure's ([render] edge_styles, vertex_styles, and
// the stress drawn by [render] stress).
struct PartStyle {
  std::optional<render::Color> color;
  std::optional<double> width;  // edges: the bar width; vertices: the disc diameter (size units)
  bool dash = false;            // edges: dashed
  std::string label;            // edges: written at the middle; vertices: instead of the number
};

// A figure sized in lengths draws its sizes as a 1000-pixel image does at 11.3 cm: the default
// labels (28) are 9 pt.
constexpr double kPointsPerSizeUnit = 9.0 / 28.0;

struct FigureStyle {
  int width = 1000, height = 1000;
  render::Color background{1, 1, 1, 1};
  render::Color edge_color{0x46 / 255.f, 0x82 / 255.f, 0xB4 / 255.f, 1};   // steelblue
  render::Color vertex_color{0, 0, 0, 1};                                   // black
  render::Color label_color{0xD3 / 255.f, 0xD3 / 255.f, 0xD3 / 255.f, 1};  // lightgrey
  render::Color pin_color{0xCD / 255.f, 0, 0, 0.4f};                        // red3, alpha 0.4
  render::Color flex_color{0, 0xCD / 255.f, 0, 1};                          // green3
  render::Color trace_color{0xE0 / 255.f, 0x7B / 255.f, 0, 1};              // dark orange: not a flex
  render::Color ghost_color{0xD3 / 255.f, 0xD3 / 255.f, 0xD3 / 255.f, 1};  // lightgrey
  render::Color facet_color{0xFA / 255.f, 0xFA / 255.f, 0xFA / 255.f, 0.6f};  // grey98
  // Origami: panels shaded in a paper colour; creases: mountains solid, valleys dashed.
  render::Color panel_color{0xF2 / 255.f, 0xE6 / 255.f, 0xC9 / 255.f, 0.92f};
  render::Color mountain_color{0xD6 / 255.f, 0x27 / 255.f, 0x28 / 255.f, 1};  // red
  render::Color valley_color{0x1F / 255.f, 0x77 / 255.f, 0xB4 / 255.f, 1};    // blue
  // Sizes in pixels of a 1000-pixel image; they scale with min(width, height). A figure sized in
  // lengths ([render] width = "8cm") has them in units of kPointsPerSizeUnit at its dpi instead,
  // whatever its size: unit_px pixels each.
  double vertex_size = 55, line_width = 12, font_size = 28, arrow_size = 40;
  double unit_px = 0;  // > 0: pixels per size unit (a figure sized in lengths); 0: min(width, height) / 1000
  bool labels = true, pins = true;
  // Not given in [render]: vertex_size, line_width, font_size and arrow_size shrink (never
  // grow) to the figure's typical bar on screen, and labels are left out when unreadable
  // (present::adaptStyle).
  bool auto_size = true, auto_labels = true;
  int label_base = 1;  // vertex labels count from this: the scene's index_base
  // World units around the figure (the notes' padding rule). Not given in [render]: 0.15 times
  // the power of ten nearest the figure's typical length (its median bar), so that a scene in
  // millimetres is padded as the same scene in metres (present::fitView).
  double padding = 0.15;
  bool auto_padding = true;
  // [render] view: the box shown, fixed by hand (3D: the box the camera fits); no padding.
  std::optional<std::array<std::array<double, 3>, 2>> view_box;
  double flex_scale = 0.15;    // the longest flex arrow, as a fraction of the figure's extent
  double azimuth = 0.7853981633974483, elevation = 0.39269908169744;  // 3D, radians
  bool perspective = false;
  double fog = 0.35;           // 3D: colours fade toward the background by this much at the far side
  bool trace = false;          // draw each moving vertex's trajectory up to the sample
  int ghost = -1;              // draw this sample underneath, in ghost_color (-1: none)
  // Sphere packings: disks (2D, with an outline) or shaded spheres (3D), and the contact graph.
  // Unset colours take the reference's: steelblue at alpha 0.1 (2D) or 0.25 (3D); contacts
  // grey80 (2D) or grey50 (3D).
  std::optional<render::Color> ball_color, contact_color;
  double ball_outline = 8.5, contact_width = 7;  // px of a 1000-pixel image
  // Angular frameworks: the constrained angles as sectors (0.3 of the shorter arm).
  render::Color angle_color{0xD3 / 255.f, 0xD3 / 255.f, 0xD3 / 255.f, 0.5f};  // lightgrey, alpha 0.5
  // Volume hypergraphs: simplex i is filled with simplex_colors[i % size] at alpha 0.25 and
  // outlined with it, dashed.
  std::vector<render::Color> simplex_colors = {
      {0xCD / 255.f, 0, 0, 1},                 {0x22 / 255.f, 0x8B / 255.f, 0x22 / 255.f, 1},
      {0x41 / 255.f, 0x69 / 255.f, 0xE1 / 255.f, 1}, {0, 0xA5 / 255.f, 0xA8 / 255.f, 1},
      {0xDA / 255.f, 0xA5 / 255.f, 0x20 / 255.f, 1}, {0x8B / 255.f, 0x3A / 255.f, 0x9B / 255.f, 1}};
  // Spherical disk packings: the caps' circles, the unit sphere, and the contact graph through
  // the cones' apices.
  render::Color cap_color{0x46 / 255.f, 0x82 / 255.f, 0xB4 / 255.f, 1};     // steelblue
  render::Color sphere_color{0xD3 / 255.f, 0xD3 / 255.f, 0xD3 / 255.f, 0.15f};
  render::Color apex_color{0xCD / 255.f, 0, 0, 0.45f};                       // red3, alpha 0.45
  // Frameworks on surfaces: the surface, meshed in the view's box with this many cells per axis.
  render::Color surface_color{0xCC / 255.f, 0xCC / 255.f, 0xCC / 255.f, 0.45f};  // grey80, alpha 0.45
  int surface_samples = 40;
  // Parts drawn in their own look (0-based vertices; an edge as its smaller vertex first).
  std::map<std::pair<int, int>, PartStyle> edge_styles;
  std::map<int, PartStyle> vertex_styles;
  int stress = -1;  // >= 0: draw stress `stress` of the stress basis (tension red, compression blue)
};

}  // namespace flexure::scenes
