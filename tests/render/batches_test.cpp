// The drawing logic without a GL library: batches built from draw lists, and the renderer's
// stages as the null backend records them (no OpenGL context is made in this executable).
#include <catch2/catch.hpp>

#include <cmath>

#include "present/figure.h"
#include "render/batches.h"
#include "render/draw_backend.h"
#include "render/renderer.h"
#include "../scenes/scene_test_common.h"

using namespace flexure;
using render::Color;

namespace {

double area(const std::vector<std::array<double, 2>>& p, const std::vector<int>& idx, size_t t) {
  const auto& a = p[static_cast<size_t>(idx[t])];
  const auto& b = p[static_cast<size_t>(idx[t + 1])];
  const auto& c = p[static_cast<size_t>(idx[t + 2])];
  return 0.5 * std::abs((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]));
}

render::Renderer nullRenderer(render::NullBackend*& backend) {
  auto b = std::make_unique<render::NullBackend>();
  backend = b.get();
  return render::Renderer(std::move(b));
}

}  // namespace

TEST_CASE("batches: ear clipping covers a concave polygon exactly", "[render]") {
  // An L: area 3, 6 corners, 4 triangles.
  const std::vector<std::array<double, 2>> l = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  const std::vector<int> t = render::triangulate(l);
  REQUIRE(t.size() == 12);
  double total = 0;
  for (size_t i = 0; i < t.size(); i += 3) {
    CHECK(area(l, t, i) > 0);
    total += area(l, t, i);
  }
  CHECK(total == Approx(3.0));
}

TEST_CASE("batches: 2D keeps the given order, and 3D draws translucent shapes last, back to front", "[render]") {
  render::DrawList list;
  list.polygons.push_back({{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, Color{1, 0, 0, 1}});
  list.polygons.push_back({{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, Color{0, 1, 0, 0.5f}});
  list.disc({0.2, 0.2, 0.9}, 10, Color{0, 0, 1, 0.5f});  // translucent, near
  list.disc({0.5, 0.5, 0.0}, 10, Color{0, 0, 0, 1});     // opaque
  list.disc({0.8, 0.8, -0.9}, 10, Color{0, 1, 1, 0.5f}); // translucent, far
  render::View view;
  view.width = 200, view.height = 100;
  view.lo = {0, 0, -1}, view.hi = {1, 1, 1};
  const render::AtlasSource none = [](int) -> render::GlyphAtlas& { throw std::logic_error("no labels"); };
  const render::FrameBatches flat = render::buildFrame(list, view, none);
  CHECK(flat.opaque_polygons.size() == 6);      // the square: two triangles
  CHECK(flat.translucent_polygons.size() == 3);
  REQUIRE(flat.shapes.size() == 18);
  CHECK(flat.opaque_shape_vertices == 18);      // 2D: every shape in the order given
  CHECK(flat.shapes[0].fill[3] == 0.5f);
  view.three_d = true;
  const render::FrameBatches deep = render::buildFrame(list, view, none);
  REQUIRE(deep.shapes.size() == 18);
  CHECK(deep.opaque_shape_vertices == 6);
  CHECK(deep.shapes[0].fill[3] == 1.0f);
  // Larger depth is farther: the far translucent disc before the near one.
  CHECK(deep.shapes[6].depths[0] > deep.shapes[12].depths[0]);
}

TEST_CASE("renderer stages: setup, opaque, translucent, text, readback, in that order", "[render]") {
  render::NullBackend* backend = nullptr;
  render::Renderer renderer = nullRenderer(backend);
  CHECK_THAT(renderer.contextDescription(), Catch::Contains("null"));
  render::DrawList list;
  list.polygons.push_back({{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, Color{0, 1, 0, 0.5f}});
  list.segment({0, 0, 0}, {1, 1, 0}, 4, Color{0, 0, 0, 1});
  render::Label label;
  label.at = {0.5, 0.5, 0};
  label.text = "12";
  label.size = 20;
  list.labels.push_back(label);
  render::View view;
  view.width = 64, view.height = 48;
  view.background = Color{1, 0, 0, 1};
  const render::Image image = renderer.render(list, view);
  CHECK(backend->calls == std::vector<std::string>{"begin 64x48", "polygons 1", "shapes 1 opaque 1",
                                                   "text 2 glyphs at 20 px", "finish"});
  REQUIRE(image.width == 64);
  REQUIRE(image.height == 48);
  CHECK(image.rgba[0] == 255);
  CHECK(image.rgba[1] == 0);
  view.three_d = true;
  renderer.render(list, view);
  CHECK(backend->calls == std::vector<std::string>{"begin 64x48 depth", "shapes 1 opaque 1",
                                                   "polygons 1 no-depth-write", "text 18 glyphs at 20 px", "finish"});
  // (3D: each glyph eight times more, offset all around in the halo colour, under it.)
}

TEST_CASE("renderer stages: a label is centred on its anchor", "[render]") {
  render::DrawList list;
  render::Label label;
  label.at = {0.5, 0.5, 0};
  label.text = "Watt";
  label.size = 30;
  list.labels.push_back(label);
  render::View view;
  view.width = view.height = 400;
  render::GlyphAtlas atlas(render::defaultFont(), true, 30);
  const render::FrameBatches f = render::buildFrame(list, view, [&](int) -> render::GlyphAtlas& { return atlas; });
  REQUIRE(f.text.size() == 1);
  CHECK(f.text[0].vertices.size() == 4 * 6);
  double lo[2] = {1e9, 1e9}, hi[2] = {-1e9, -1e9};
  for (const auto& v : f.text[0].vertices)
    for (int k = 0; k < 2; ++k) lo[k] = std::min(lo[k], double(v.pos[k])), hi[k] = std::max(hi[k], double(v.pos[k]));
  CHECK(0.5 * (lo[0] + hi[0]) == Approx(200).margin(1.0));
  CHECK(0.5 * (lo[1] + hi[1]) == Approx(200).margin(1.0));
}

TEST_CASE("renderer stages: every example scene's figure goes through the null backend", "[render][scenes]") {
  render::NullBackend* backend = nullptr;
  render::Renderer renderer = nullRenderer(backend);
  for (const auto& entry : scenes::catalog()) {
    INFO(entry.name);
    const scenes::Scene s = test::example(entry.name);
    scenes::FigureStyle style = s.render.style;
    style.width = 300, style.height = 200;
    const engine::Geometry g = s.model->geometry();
    const engine::Matrix p = s.model->system().positions(s.model->startCoordinates());
    const render::DrawList list = present::figure(g, p, style);
    const render::Image image = renderer.render(list, present::fitView(g, {p}, style));
    CHECK(image.width == 300);
    REQUIRE(backend->calls.size() >= 3);
    CHECK(backend->calls.front() == std::string(g.dimension == 3 ? "begin 300x200 depth" : "begin 300x200"));
    CHECK(backend->calls.back() == "finish");
    // Every vertex is drawn (a disc each), and labelled unless labels are off.
    bool shapes = false;
    for (const auto& c : backend->calls) shapes = shapes || c.rfind("shapes ", 0) == 0;
    CHECK(shapes);
  }
}
