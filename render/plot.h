// A 2D line plot drawn by the renderer: fitted axes with "nice" ticks, grid, labels (FreeType),
// one or more curves with a legend, marked points, a start marker (a pentagon, as in the paper's
// figures) and arrows. Used for the random projections of deformation paths. The layout is
// computed once, so an animation can redraw the same axes with a moving cursor.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "render/draw_list.h"

namespace flexure::render {

using Point2 = std::array<double, 2>;

struct PlotSeries {
  std::vector<Point2> points;  // the curve
  Color color;
  std::string label;           // legend entry (the legend appears with two or more labels)
  std::vector<int> marks;      // indices of points to mark (e.g. singular points)
};

struct PlotArrow {
  Point2 from, to;
  Color color;
};

struct PlotStyle {
  int width = 1000, height = 1000;
  Color background{1, 1, 1, 1};
  // Sizes in pixels of a 1000-pixel image; they scale with min(width, height).
  double line_width = 8, marker_size = 45, arrow_size = 40, font_size = 28, tick_font_size = 22;
  double unit_px = 0;  // > 0: pixels per size unit, whatever the size (a figure sized in lengths)
  Color axis_color{0.2f, 0.2f, 0.2f, 1};
  Color grid_color{0.9f, 0.9f, 0.9f, 1};
  Color start_color{0x46 / 255.f, 0x82 / 255.f, 0xB4 / 255.f, 1};  // steelblue, black outline
  Color mark_color{0xCD / 255.f, 0, 0, 1};                          // red3
  Color cursor_color{0xCD / 255.f, 0, 0, 1};
  bool equal_aspect = true;  // one unit is the same length on both axes
};

struct Plot {
  std::string title, subtitle, xlabel, ylabel;
  std::vector<PlotSeries> series;
  std::optional<Point2> start;  // drawn as a pentagon
  std::vector<PlotArrow> arrows;
};

// Ticks at 1, 2, 2.5 or 5 times a power of ten, about `target` of them over [lo, hi].
std::vector<double> niceTicks(double lo, double hi, int target = 6);
// The tick labels: the fewest decimals that tell the ticks apart ("-0" shown as "0").
std::vector<std::string> tickLabels(const std::vector<double>& ticks);

class PlotCanvas {
 public:
  PlotCanvas(Plot plot, PlotStyle style);
  // The plot (with a cursor disc at `cursor` in data coordinates, if given).
  DrawList draw(const std::optional<Point2>& cursor = std::nullopt) const;
  View view() const;
  // Data coordinates to pixels (origin bottom left), and the plot frame in pixels.
  Point2 toPixels(const Point2& p) const;
  std::array<double, 4> frame() const { return {x0_, y0_, x1_, y1_}; }
  std::array<double, 4> limits() const { return {lo_[0], lo_[1], hi_[0], hi_[1]}; }

 private:
  Plot plot_;
  PlotStyle style_;
  double s_ = 1;                       // pixel scale: min(width, height) / 1000
  double x0_ = 0, y0_ = 0, x1_ = 1, y1_ = 1;  // the frame, px
  Point2 lo_{0, 0}, hi_{1, 1};         // data window
  std::vector<double> xticks_, yticks_;
  DrawList fixed_;                     // everything but the cursor
};

}  // namespace flexure::render
