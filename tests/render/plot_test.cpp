// Plots: tick choice and labels, and rendered plots checked by their pixels.
#include <catch2/catch.hpp>

#include <cmath>

#include "render/plot.h"
#include "render/renderer.h"

using namespace flexure::render;

namespace {

bool near(const std::uint8_t* p, const Color& c, int tol = 40) {
  return std::abs(p[0] - c.r * 255) <= tol && std::abs(p[1] - c.g * 255) <= tol && std::abs(p[2] - c.b * 255) <= tol;
}

// Image rows are top to bottom; plot pixels count from the bottom.
const std::uint8_t* at(const Image& im, const Point2& px) {
  return im.pixel(static_cast<int>(std::lround(px[0])), im.height - 1 - static_cast<int>(std::lround(px[1])));
}

}  // namespace

TEST_CASE("plot: nice ticks and their labels", "[render][plot]") {
  CHECK(niceTicks(0, 1, 5) == std::vector<double>{0, 0.25, 0.5, 0.75, 1});
  const auto t = niceTicks(-2.93, -1.41, 6);
  REQUIRE(t.size() >= 4);
  CHECK(t.front() >= -2.93);
  CHECK(t.back() <= -1.41);
  CHECK(tickLabels(t) == std::vector<std::string>{"-2.75", "-2.50", "-2.25", "-2.00", "-1.75", "-1.50"});
  CHECK(tickLabels(niceTicks(-1, 1, 5)) == std::vector<std::string>{"-1.0", "-0.5", "0", "0.5", "1.0"});
  CHECK(tickLabels({0, 1000, 2000}) == std::vector<std::string>{"0", "1000", "2000"});
  CHECK(tickLabels(niceTicks(1e-4, 5e-4, 4)) == std::vector<std::string>{"0.0001", "0.0002", "0.0003", "0.0004", "0.0005"});
  // Degenerate ranges do not loop or explode.
  CHECK(niceTicks(1, 1).size() == 1);
  CHECK(niceTicks(0, NAN).size() == 1);
}

TEST_CASE("plot: curves, axes, start marker, legend and cursor are drawn where they belong", "[render][plot]") {
  Plot plot;
  plot.title = "A circle";
  plot.xlabel = "x";
  plot.ylabel = "y";
  PlotSeries circle, line;
  for (int i = 0; i <= 200; ++i) circle.points.push_back({std::cos(i * 0.0314159), std::sin(i * 0.0314159)});
  circle.color = Color{0.8f, 0, 0, 1};
  circle.label = "circle";
  circle.marks = {50};
  line.points = {{-1, -1}, {-0.5, -1}};
  line.color = Color{0, 0, 0.8f, 1};
  line.label = "line";
  plot.series = {circle, line};
  plot.start = Point2{1, 0};
  PlotStyle style;
  style.width = 800, style.height = 600;
  const PlotCanvas canvas(plot, style);
  Renderer r;
  const Image im = r.render(canvas.draw(), canvas.view());
  REQUIRE(im.width == 800);
  // Equal aspect: the data window has the frame's shape.
  const auto f = canvas.frame();
  const auto l = canvas.limits();
  CHECK((l[2] - l[0]) / (f[2] - f[0]) == Approx((l[3] - l[1]) / (f[3] - f[1])));
  // Every curve point is inside the frame.
  for (const auto& p : circle.points) {
    const Point2 px = canvas.toPixels(p);
    CHECK(px[0] > f[0]);
    CHECK(px[0] < f[2]);
    CHECK(px[1] > f[1]);
    CHECK(px[1] < f[3]);
  }
  // Curve pixels in the curve's colour, away from the marks.
  CHECK(near(at(im, canvas.toPixels(circle.points[20])), circle.color));
  CHECK(near(at(im, canvas.toPixels({-0.75, -1})), line.color));
  // The start pentagon (steelblue) and the mark (red3) on top of the curve.
  CHECK(near(at(im, canvas.toPixels({1, 0})), style.start_color));
  CHECK(near(at(im, canvas.toPixels(circle.points[50])), style.mark_color));
  // The frame: dark pixels along its left edge, between ticks; white inside, away from curves.
  const Point2 edge{f[0], 0.5 * (f[1] + f[3]) + 7};
  CHECK(near(at(im, edge), style.axis_color, 80));
  CHECK(near(at(im, canvas.toPixels({0, 0.5})), Color{1, 1, 1, 1}, 30));
  // Tick labels: dark pixels left of the frame and below it; the legend right of the frame.
  auto darkIn = [&](int x0, int y0, int x1, int y1) {  // image rows, top to bottom
    int n = 0;
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) n += im.pixel(x, y)[0] < 140 && im.pixel(x, y)[2] < 140;
    return n;
  };
  CHECK(darkIn(0, 0, static_cast<int>(f[0]) - 12, im.height) > 30);
  CHECK(darkIn(0, im.height - static_cast<int>(f[1]) + 12, im.width, im.height) > 30);
  int legend_red = 0;
  for (int y = 0; y < im.height; ++y)
    for (int x = static_cast<int>(f[2]) + 5; x < im.width; ++x) legend_red += near(im.pixel(x, y), circle.color, 30);
  CHECK(legend_red > 20);
  // A cursor changes the picture only around it.
  const Image with = r.render(canvas.draw(Point2{0, 1}), canvas.view());
  CHECK(near(at(with, canvas.toPixels({0, 1})), style.cursor_color));
  CHECK(with.rgba != im.rgba);
  CHECK(std::equal(with.rgba.begin(), with.rgba.begin() + 800 * 4 * 20, im.rgba.begin()));
}
