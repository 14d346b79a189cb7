#include <catch2/catch.hpp>
#include <cmath>
#include <Eigen/Geometry>
#include <fstream>
#include <iterator>

#include "render/renderer.h"
#include "scenes/catalog.h"
#include "present/figure.h"
#include "present/surface_mesh.h"
#include "scenes/scene.h"

using namespace flexure;

namespace {

render::Renderer& renderer() {
  static render::Renderer r;
  return r;
}

render::Image draw(const scenes::Scene& scene, int size, present::FigureExtras extras = {}) {
  scenes::FigureStyle style = scene.render.style;
  style.width = style.height = size;
  const engine::Matrix p = scene.model->startPositions();
  const engine::Geometry g = scene.model->geometry();
  return renderer().render(present::figure(g, p, style, extras), present::fitView(g, {p}, style));
}

int count(const render::Image& im, const render::Color& c, int tol) {
  int n = 0;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      const auto* q = im.pixel(x, y);
      n += std::abs(q[0] - std::lround(255 * c.r)) <= tol && std::abs(q[1] - std::lround(255 * c.g)) <= tol &&
           std::abs(q[2] - std::lround(255 * c.b)) <= tol;
    }
  return n;
}

}  // namespace

TEST_CASE("figure: colours parse as hex or by name and bad ones are refused", "[scenes][render]") {
  const auto a = scenes::parseColor("steelblue");
  REQUIRE(a);
  REQUIRE(a->r == Approx(0x46 / 255.0));
  const auto b = scenes::parseColor("#FF800080");
  REQUIRE(b);
  REQUIRE(b->g == Approx(128 / 255.0));
  REQUIRE(b->a == Approx(128 / 255.0));
  REQUIRE_FALSE(scenes::parseColor("#12345"));
  REQUIRE_FALSE(scenes::parseColor("#GG0000"));
  REQUIRE_FALSE(scenes::parseColor("steelbleu"));
}

TEST_CASE("figure: every example scene renders inside the frame with bars labels and pins", "[scenes][render]") {
  for (const auto& e : scenes::catalog()) {
    INFO(e.name);
    const scenes::Scene scene = scenes::loadSceneFromString(e.text, "catalog:" + e.name);
    const render::Image im = draw(scene, 240);
    const scenes::FigureStyle& s = scene.render.style;
    // Nothing touches the border: every border pixel is the background.
    int border = 0;
    for (int i = 0; i < 240; ++i)
      for (auto [x, y] : {std::pair{i, 0}, {i, 239}, {0, i}, {239, i}}) {
        const auto* q = im.pixel(x, y);
        border += q[0] != 255 || q[1] != 255 || q[2] != 255;
      }
    REQUIRE(border == 0);
    const bool flat = scene.model->system().dimension() == 2;
    const int n = scene.model->system().numVertices();
    if (!scene.model->geometry().balls.empty()) {
      // Packings: translucent blue balls (outlined in 2D) and dark labels, no vertex discs.
      int blue = 0;
      for (int y = 0; y < 240; ++y)
        for (int x = 0; x < 240; ++x) blue += im.pixel(x, y)[2] > im.pixel(x, y)[0] + 6;
      REQUIRE(blue > 240 * 240 / 10);
      if (flat) REQUIRE(count(im, render::Color{0x46 / 255.f, 0x82 / 255.f, 0xB4 / 255.f, 1}, 2) > 100);
      REQUIRE(count(im, s.vertex_color, 60) > 2 * n);
    } else if (scene.model->geometry().caps.on) {
      // Spherical caps: their circles, dark labels on the sphere, no vertex discs.
      REQUIRE(count(im, s.cap_color, 30) > 100);
      REQUIRE(count(im, s.vertex_color, 60) > 2 * n);
    } else if (!scene.model->geometry().simplices.empty()) {
      // Simplices: dashed outlines in the first palette colours, vertex discs and labels.
      REQUIRE(count(im, s.simplex_colors[0], 2) > 50);
      REQUIRE(count(im, s.simplex_colors[1], 2) > 50);
      REQUIRE(count(im, s.vertex_color, 2) > 50);
    } else {
      REQUIRE(count(im, s.edge_color, flat ? 2 : 60) > (flat ? 100 : 60));  // 3D bars are shaded (and fewer at 240 px)
      // Labels that would overlap a nearer one are left out (3D solids seen edge-on): at least
      // half of them are drawn.
      if (s.labels) REQUIRE(count(im, s.label_color, 2) > n);
      else REQUIRE(count(im, s.label_color, 2) < 2 * n);
      REQUIRE(count(im, s.vertex_color, flat ? 2 : 40) > 50);
    }
    if (!scene.model->geometry().pinned.empty()) {
      // red3 at alpha 0.4 over white (over a light ball for packings)
      const int tol = scene.model->geometry().balls.empty() ? 4 : 40;
      REQUIRE(count(im, render::Color{1.0f - 0.4f * (1 - 0xCD / 255.f), 0.6f, 0.6f, 1}, tol) > 20);
    }
  }
}

TEST_CASE("figure: flex arrows are drawn in the flex colour and fit the view", "[scenes][render]") {
  const scenes::Scene scene = scenes::loadSceneFromString(scenes::findCatalogEntry("square")->text, "catalog:square");
  const engine::Matrix p = scene.model->startPositions();
  engine::Matrix flex = engine::Matrix::Zero(2, 4);
  flex.col(2) << 1, 0;  // vertex 3 moves right
  present::FigureExtras extras;
  extras.flex = flex;
  scenes::FigureStyle style = scene.render.style;
  style.width = style.height = 240;
  const engine::Geometry g = scene.model->geometry();
  const engine::Matrix tips = present::flexTips(p, flex, style);
  REQUIRE(tips(0, 2) > p(0, 2));
  REQUIRE(tips.col(0) == p.col(0));
  const render::Image im = renderer().render(present::figure(g, p, style, extras), present::fitView(g, {p, tips}, style));
  REQUIRE(count(im, style.flex_color, 2) > 20);
  const render::Image plain = draw(scene, 240);
  REQUIRE(count(plain, style.flex_color, 2) == 0);
}

TEST_CASE("figure: the double Watt matches its reference image", "[scenes][render]") {
  const scenes::Scene scene = scenes::loadSceneFromString(scenes::findCatalogEntry("double_watt")->text, "catalog:double_watt");
  const render::Image im = draw(scene, 300);
  std::ifstream f(FLEXURE_ASSETS_DIR "/reference/double_watt_300.png", std::ios::binary);
  REQUIRE(f.good());
  const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  const render::Image ref = render::decodePng(bytes);
  REQUIRE(ref.width == im.width);
  REQUIRE(ref.height == im.height);
  // Tolerant: another Mesa may round edges differently, not move a bar.
  double sum = 0;
  int far = 0;
  for (size_t i = 0; i < im.rgba.size(); ++i) {
    const int d = std::abs(int(im.rgba[i]) - int(ref.rgba[i]));
    sum += d;
    far += d > 64;
  }
  REQUIRE(sum / im.rgba.size() < 1.0);
  REQUIRE(far < static_cast<int>(im.rgba.size() / 200));
}

TEST_CASE("figure: render keys are read and bad ones answered with their position", "[scenes][render]") {
  const std::string base = scenes::findCatalogEntry("square")->text;
  const scenes::Scene s = scenes::loadSceneFromString(base + "\n[render]\nedge_color = \"#112233\"\nlabels = false\nline_width = 6\n", "t.toml");
  REQUIRE(s.render.style.edge_color.r == Approx(0x11 / 255.0));
  REQUIRE_FALSE(s.render.style.labels);
  REQUIRE(s.render.style.line_width == 6);
  try {
    scenes::loadSceneFromString(base + "\n[render]\nedge_color = \"bleu\"\n", "t.toml");
    FAIL("no error");
  } catch (const scenes::SceneError& e) {
    REQUIRE(std::string(e.what()).find("unknown colour 'bleu'") != std::string::npos);
    REQUIRE(e.column == 14);
  }
  REQUIRE_THROWS_AS(scenes::loadSceneFromString(base + "\n[render]\nlabels = 1\n", "t.toml"), scenes::SceneError);
  // The per-type colours.
  const scenes::Scene t = scenes::loadSceneFromString(
      base + "\n[render]\nsimplex_colors = [\"black\", \"#00FF00\"]\nball_color = \"red\"\napex_color = \"navy\"\n", "t.toml");
  REQUIRE(t.render.style.simplex_colors.size() == 2);
  REQUIRE(t.render.style.simplex_colors[1].g == Approx(1.0));
  REQUIRE(t.render.style.ball_color->r == Approx(1.0));
  REQUIRE(t.render.style.apex_color.b == Approx(0x80 / 255.0));
  try {
    scenes::loadSceneFromString(base + "\n[render]\nsimplex_colors = [\"red\", \"rouge\"]\n", "t.toml");
    FAIL("no error");
  } catch (const scenes::SceneError& e) {
    REQUIRE(std::string(e.what()).find("unknown colour 'rouge'") != std::string::npos);
    REQUIRE(e.column == 26);
  }
  REQUIRE_THROWS_AS(scenes::loadSceneFromString(base + "\n[render]\nsimplex_colors = []\n", "t.toml"), scenes::SceneError);
}

TEST_CASE("figure: implicit surfaces are meshed closely and drawn with frameworks on surfaces", "[scenes][render]") {
  // The unit sphere in [-1.3, 1.3]^3: every mesh vertex within the interpolation error of it,
  // and the area within 1 % of 4 pi.
  const auto mesh = present::meshImplicitSurface(
      [](const double* x) { return x[0] * x[0] + x[1] * x[1] + x[2] * x[2] - 1; }, {-1.3, -1.3, -1.3},
      {1.3, 1.3, 1.3}, 40);
  REQUIRE(mesh.size() > 1000);
  double area = 0, worst = 0;
  for (const auto& t : mesh) {
    const Eigen::Vector3d a(t[0].data()), b(t[1].data()), c(t[2].data());
    area += 0.5 * (b - a).cross(c - a).norm();
    for (const auto& p : t) worst = std::max(worst, std::abs(Eigen::Vector3d(p.data()).norm() - 1));
  }
  const double h = 2.6 / 40;
  CHECK(worst < h * h);
  CHECK(std::abs(area - 4 * M_PI) < 0.01 * 4 * M_PI);
  // Nothing where f has no zero; a plane cuts the box in a square of the box's size.
  CHECK(present::meshImplicitSurface([](const double*) { return 1.0; }, {0, 0, 0}, {1, 1, 1}, 8).empty());
  double plane = 0;
  for (const auto& t : present::meshImplicitSurface([](const double* x) { return x[2] - 0.3; }, {0, 0, 0}, {1, 1, 1}, 8)) {
    const Eigen::Vector3d a(t[0].data()), b(t[1].data()), c(t[2].data());
    plane += 0.5 * (b - a).cross(c - a).norm();
    CHECK(std::abs(a[2] - 0.3) < 1e-12);
  }
  CHECK(plane == Approx(1.0));
  // The hyperboloid scene: the surface is meshed in the view and drawn (grey80, translucent).
  const scenes::Scene s = scenes::loadSceneFromString(scenes::findCatalogEntry("square_on_hyperboloid")->text, "h");
  scenes::FigureStyle style = s.render.style;
  style.width = style.height = 240;
  const engine::Geometry g = s.model->geometry();
  const engine::Matrix p = s.model->startPositions();
  const render::View view = present::fitView(g, {p}, style);
  const auto surface = present::surfaceMesh(g, view, style);
  REQUIRE(surface.size() > 500);
  present::FigureExtras extras;
  extras.surface = &surface;
  const render::Image with = renderer().render(present::figure(g, p, style, extras), view);
  const render::Image without = renderer().render(present::figure(g, p, style), view);
  int grey_with = 0, grey_without = 0;
  for (int y = 0; y < 240; ++y)
    for (int x = 0; x < 240; ++x) {
      auto grey = [](const std::uint8_t* q) { return q[0] < 235 && q[0] > 120 && q[0] == q[1] && q[1] == q[2]; };
      grey_with += grey(with.pixel(x, y));
      grey_without += grey(without.pixel(x, y));
    }
  CHECK(grey_with > 240 * 240 / 5);
  CHECK(grey_without < 240 * 240 / 50);
  CHECK(present::surfaceMesh(scenes::loadSceneFromString(scenes::findCatalogEntry("cube")->text, "c").model->geometry(),
                            view, style).empty());
}

TEST_CASE("figure: vertex labels count from the scene's index_base", "[scenes]") {
  for (int base : {0, 1}) {
    const std::string text = "index_base = " + std::to_string(base) +
                             "\n[system]\ntype = \"framework\"\nvertices = [[0,0],[1,0],[0,1]]\nedges = [[" +
                             std::to_string(base) + "," + std::to_string(base + 1) + "]]\n";
    const scenes::Scene s = scenes::loadSceneFromString(text, "t.toml");
    const engine::Model& m = *s.model;
    const render::DrawList d =
        present::figure(m.geometry(), m.system().vertexPositions(m.startCoordinates()), s.render.style, {});
    REQUIRE(d.labels.size() == 3);
    CHECK(d.labels[0].text == std::to_string(base));
    CHECK(d.labels[2].text == std::to_string(base + 2));
  }
}

namespace {

double meanDifference(const render::Image& a, const render::Image& b) {
  REQUIRE(a.rgba.size() == b.rgba.size());
  double sum = 0;
  for (size_t i = 0; i < a.rgba.size(); ++i) sum += std::abs(int(a.rgba[i]) - int(b.rgba[i]));
  return sum / static_cast<double>(a.rgba.size());
}

render::Image drawScaled(const scenes::Scene& scene, double factor, int size) {
  scenes::FigureStyle style = scene.render.style;
  style.width = style.height = size;
  const engine::Matrix p = factor * scene.model->startPositions();
  const engine::Geometry g = scene.model->geometry();
  std::vector<engine::Matrix> frames{p};
  const render::View view = present::fitAdapted(g, frames, style);
  return renderer().render(present::figure(g, p, style), view);
}

}  // namespace

TEST_CASE("figure: the padding follows the scene's unit: millimetres look like metres", "[scenes][render]") {
  // The double Watt in its units, in hundredths (a linkage in millimetres) and thousandths:
  // the same picture; with the padding given by hand, the millimetre one touches the frame.
  for (const char* name : {"double_watt", "octahedron"}) {
    INFO(name);
    const scenes::Scene scene = scenes::loadSceneFromString(scenes::findCatalogEntry(name)->text, "catalog");
    const render::Image unit = drawScaled(scene, 1, 240);
    for (double f : {100.0, 1e-3, 1e4}) {
      INFO(f);
      CHECK(meanDifference(unit, drawScaled(scene, f, 240)) < 0.15);  // float rounding on the GPU
    }
  }
  const scenes::Scene fixed = scenes::loadSceneFromString(
      "[system]\ntype = \"catalog\"\nname = \"double_watt\"\n[render]\npadding = 0.15\n", "t.toml");
  CHECK_FALSE(fixed.render.style.auto_padding);
  CHECK(meanDifference(drawScaled(fixed, 1, 240), drawScaled(fixed, 100, 240)) > 1);
}

TEST_CASE("figure: [render] view fixes the box shown", "[scenes][render]") {
  const std::string base = "[system]\ntype = \"catalog\"\nname = \"double_watt\"\n";
  const scenes::Scene s = scenes::loadSceneFromString(base + "\n[render]\nview = [[-1, -4], [9, 6]]\n", "t.toml");
  REQUIRE(s.render.style.view_box);
  const engine::Geometry g = s.model->geometry();
  const render::View v = present::fitView(g, {s.model->startPositions()}, s.render.style);
  CHECK(v.lo[0] == -1);
  CHECK(v.lo[1] == -4);
  CHECK(v.hi[0] == 9);
  CHECK(v.hi[1] == 6);
  const auto bad = [&](const std::string& text, int line, int column, const std::string& message) {
    try {
      scenes::loadSceneFromString(base + "\n[render]\n" + text + "\n", "t.toml");
      FAIL("no error for " + text);
    } catch (const scenes::SceneError& e) {
      CHECK_THAT(e.what(), Catch::Contains(message));
      CHECK(e.line == line);
      CHECK(e.column == column);
    }
  };
  const int line = static_cast<int>(std::count(base.begin(), base.end(), '\n')) + 3;
  bad("view = [[0, 0]]", line, 8, "two points");
  bad("view = [[0, 0, 0], [1, 1, 1]]", line, 9, "2 coordinates in this 2D scene, not 3");
  bad("view = [[0, 0], [1, -1]]", line, 17, "upper corner must exceed");
}
