#include <catch2/catch.hpp>
#include <cmath>

#include "render/batches.h"
#include "render/camera.h"
#include "render/image.h"
#include "render/renderer.h"

using namespace flexure::render;

namespace {

// One renderer for the whole test binary: a context costs tens of milliseconds.
Renderer& renderer() {
  static Renderer r;
  return r;
}

View window(int w, int h) {
  View v;
  v.width = w, v.height = h;
  v.lo = {0, 0, 0}, v.hi = {10, 10, 0};
  return v;
}

// Pixel (x, y) with y counted from the top.
std::array<int, 4> at(const Image& im, int x, int y) {
  const auto* p = im.pixel(x, y);
  return {p[0], p[1], p[2], p[3]};
}

bool near(const std::array<int, 4>& p, const Color& c, int tol = 3) {
  return std::abs(p[0] - std::lround(255 * c.r)) <= tol && std::abs(p[1] - std::lround(255 * c.g)) <= tol &&
         std::abs(p[2] - std::lround(255 * c.b)) <= tol;
}

const Color kBlue{0x46 / 255.f, 0x82 / 255.f, 0xB4 / 255.f, 1};
const Color kWhite{1, 1, 1, 1};
const Color kBlack{0, 0, 0, 1};

}  // namespace

TEST_CASE("render: a bar has its colour along it and the background around it", "[render]") {
  DrawList list;
  list.segment({2, 5, 0}, {8, 5, 0}, 10, kBlue);
  const Image im = renderer().render(list, window(100, 100));
  REQUIRE(im.width == 100);
  REQUIRE(im.height == 100);
  for (auto [x, y] : {std::pair{0, 0}, {99, 0}, {0, 99}, {99, 99}}) REQUIRE(near(at(im, x, y), kWhite));
  REQUIRE(near(at(im, 50, 50), kBlue));
  REQUIRE(near(at(im, 25, 50), kBlue));
  REQUIRE(near(at(im, 50, 40), kWhite));  // 10 px above the axis, the bar is 10 px wide
  REQUIRE(near(at(im, 5, 50), kWhite));   // beyond the round cap
  REQUIRE(at(im, 50, 50)[3] == 255);
}

TEST_CASE("render: edges are anti-aliased with intermediate shades", "[render]") {
  DrawList list;
  list.disc({5, 5, 0}, 30.3f, kBlack);
  const Image im = renderer().render(list, window(100, 100));
  REQUIRE(near(at(im, 50, 50), kBlack));
  int partial = 0;
  for (int x = 0; x < 100; ++x) {
    const int v = at(im, x, 50)[0];
    partial += v > 20 && v < 235;
  }
  REQUIRE(partial >= 2);  // one at each side of the disc
  REQUIRE(partial <= 4);  // and no blur
}

TEST_CASE("render: labels are drawn centred on their anchor", "[render]") {
  DrawList list;
  Label l;
  l.at = {5, 5, 0};
  l.text = "18";
  l.size = 30;
  l.color = kBlack;
  list.labels.push_back(l);
  const Image im = renderer().render(list, window(100, 100));
  int dark = 0, sx = 0, sy = 0;
  for (int y = 0; y < 100; ++y)
    for (int x = 0; x < 100; ++x)
      if (at(im, x, y)[0] < 128) ++dark, sx += x, sy += y;
  REQUIRE(dark > 50);
  REQUIRE(std::abs(sx / dark - 50) <= 4);
  REQUIRE(std::abs(sy / dark - 50) <= 4);
}

TEST_CASE("render: a pin triangle sits left of its vertex and points at it", "[render]") {
  DrawList list;
  Shape t;
  t.kind = ShapeKind::Triangle;
  t.a = t.b = {5, 5, 0};
  t.radius = 20;
  t.offset[0] = -25;
  t.fill = Color{0.8f, 0, 0, 1};
  list.shapes.push_back(t);
  const Image im = renderer().render(list, window(100, 100));
  REQUIRE(near(at(im, 25, 50), t.fill));     // its centroid
  REQUIRE(near(at(im, 41, 50), t.fill));     // towards the tip (at x = 45)
  REQUIRE(near(at(im, 41, 40), kWhite));     // the tip is narrow
  REQUIRE(near(at(im, 60, 50), kWhite));     // nothing right of the tip
}

TEST_CASE("render: in 3D the nearer ball covers the farther one whatever the order", "[render]") {
  View v;
  v.width = v.height = 100;
  v.three_d = true;
  v.azimuth = 0, v.elevation = 0;  // looking along -x: +x is towards the viewer
  v.lo = {-1, -1, -1}, v.hi = {1, 1, 1};
  const Color red{1, 0, 0, 1}, green{0, 1, 0, 1};
  for (int order = 0; order < 2; ++order) {
    DrawList list;
    list.dimension = 3;
    if (order == 0) list.disc({1, 0, 0}, 20, red), list.disc({-1, 0, 0}, 20, green);
    else list.disc({-1, 0, 0}, 20, green), list.disc({1, 0, 0}, 20, red);
    const Image im = renderer().render(list, v);
    REQUIRE(near(at(im, 50, 50), red));
  }
}

TEST_CASE("render: the same list renders to identical bytes and PNG round-trips", "[render]") {
  DrawList list;
  list.segment({1, 1, 0}, {9, 7, 0}, 6, kBlue);
  list.disc({3, 3, 0}, 12, kBlack, 3, kBlue);
  const Image a = renderer().render(list, window(64, 48));
  const Image b = renderer().render(list, window(64, 48));
  REQUIRE(a.rgba == b.rgba);
  const auto png = encodePng(a);
  REQUIRE(png == encodePng(b));
  const Image c = decodePng(png);
  REQUIRE(c.width == 64);
  REQUIRE(c.height == 48);
  REQUIRE(c.rgba == a.rgba);
  REQUIRE_THROWS(decodePng({1, 2, 3}));
}

TEST_CASE("render: the 2D projector keeps equal aspect and centres the window", "[render]") {
  View v = window(200, 100);
  const Projector p(v);
  const auto c = p({5, 5, 0});
  REQUIRE(c[0] == Approx(100));
  REQUIRE(c[1] == Approx(50));
  const auto e = p({10, 5, 0});
  REQUIRE(e[0] - c[0] == Approx(50));  // 10 px per unit on both axes
  REQUIRE(p({5, 10, 0})[1] - c[1] == Approx(50));
}

TEST_CASE("render: zoom magnifies about the centre of the view, in 2D and 3D", "[render]") {
  for (bool three_d : {false, true}) {
    INFO(three_d);
    View v = window(200, 100);
    v.three_d = three_d;
    v.lo = {0, 0, 0}, v.hi = {10, 10, 10};
    View z = v;
    z.zoom = 2.5;
    const Projector p(v), q(z);
    const Point3 centre{5, 5, 5}, x{7, 4, 6};
    const auto pc = p(centre), qc = q(centre), px = p(x), qx = q(x);
    CHECK(qc[0] == Approx(pc[0]));
    CHECK(qc[1] == Approx(pc[1]));
    CHECK(qx[0] - qc[0] == Approx(2.5 * (px[0] - pc[0])));
    CHECK(qx[1] - qc[1] == Approx(2.5 * (px[1] - pc[1])));
    CHECK(q.pixelsPerUnit() == Approx(2.5 * p.pixelsPerUnit()));
  }
}

TEST_CASE("Projector: unproject inverts the projection within the view plane, with pan and zoom", "[render]") {
  for (int three_d = 0; three_d < 2; ++three_d)
    for (int perspective = 0; perspective < 1 + three_d; ++perspective) {
      flexure::render::View v;
      v.width = 640, v.height = 480;
      v.lo = {-1, -2, -0.5}, v.hi = {3, 1, 2};
      v.three_d = three_d;
      v.perspective = perspective;
      v.azimuth = 0.7, v.elevation = 0.3;
      v.zoom = 1.7, v.pan_x = 25, v.pan_y = -13;
      const flexure::render::Projector P(v);
      const flexure::render::Point3 p{0.4, -0.3, three_d ? 1.1 : 0.0};
      const auto q = P(p);
      const flexure::render::Point3 back = P.unproject(q[0], q[1], p);
      INFO("3D " << three_d << " perspective " << perspective);
      for (int i = 0; i < 3; ++i) CHECK(back[i] == Approx(p[i]).margin(1e-12));
      // A pixel to the right lands in the view plane through p: the same depth, and the
      // projection of the point found is that pixel.
      const flexure::render::Point3 moved = P.unproject(q[0] + 10, q[1] - 4, p);
      const auto q2 = P(moved);
      CHECK(q2[0] == Approx(q[0] + 10).margin(1e-9));
      CHECK(q2[1] == Approx(q[1] - 4).margin(1e-9));
      if (three_d) CHECK(P.toEye({moved[0] - p[0], moved[1] - p[1], moved[2] - p[2]})[2] == Approx(0).margin(1e-12));
    }
}

TEST_CASE("render: declutter labels never overlap, the nearer one in place in 3D, others always drawn", "[render]") {
  DrawList d;
  const auto label = [&](Point3 at, const char* text, bool declutter) {
    Label l;
    l.at = at, l.text = text, l.size = 20, l.declutter = declutter;
    d.labels.push_back(l);
  };
  label({0, 0, 0}, "far", true);      // behind: larger depth
  label({0, 0, 1}, "near", true);     // the same spot on screen, nearer
  label({5, 5, 0}, "alone", true);
  label({0, 0, 0.5}, "caption", false);
  View v;
  v.width = v.height = 400;
  v.three_d = true;
  v.azimuth = 0, v.elevation = M_PI / 2;  // looking down the z axis: (0,0,z) all project to one point
  v.lo = {-6, -6, -1}, v.hi = {6, 6, 2};
  const Projector project(v);
  const auto width = [](const Label& l) { return 10.0 * static_cast<double>(l.text.size()); };
  const auto texts = [](const std::vector<Label>& labels) {
    std::vector<std::string> out;
    for (const Label& l : labels) out.push_back(l.text);
    return out;
  };
  // Boxes as placedLabels documents them (width by size about the anchor plus the offset): the
  // declutter ones must not overlap.
  const auto disjoint = [&](const std::vector<Label>& labels, const Projector& P) {
    std::vector<std::array<double, 4>> boxes;
    for (const Label& l : labels) {
      if (!l.declutter) continue;
      const auto a = P(l.at);
      const double x = a[0] + l.offset[0] - 0.5 * width(l), y = a[1] + l.offset[1];
      boxes.push_back({x, y - 0.5 * l.size, x + width(l), y + 0.5 * l.size});
    }
    for (size_t i = 0; i < boxes.size(); ++i)
      for (size_t j = 0; j < i; ++j)
        if (boxes[i][0] < boxes[j][2] && boxes[j][0] < boxes[i][2] && boxes[i][1] < boxes[j][3] && boxes[j][1] < boxes[i][3])
          return false;
    return true;
  };
  // "far" projects onto "near": the nearer stays in place, the other moves beside it in its
  // aside colour; the caption stays.
  const std::vector<Label> kept = placedLabels(d, project, v.height, true, width);
  CHECK(texts(kept) == std::vector<std::string>{"far", "near", "alone", "caption"});
  CHECK((kept[0].offset[0] != 0 && kept[0].offset[1] != 0));
  CHECK((kept[0].color.r == 0 && kept[0].color.a == 1));  // aside_color: black by default
  CHECK((kept[1].offset[0] == 0 && kept[1].offset[1] == 0));
  CHECK(disjoint(kept, project));
  // 2D: the first one placed stays, the second moves.
  v.three_d = false;
  v.lo = {-6, -6, 0}, v.hi = {6, 6, 0};
  const Projector flat(v);
  const std::vector<Label> kept2 = placedLabels(d, flat, v.height, false, width);
  CHECK(texts(kept2) == std::vector<std::string>{"far", "near", "alone", "caption"});
  CHECK((kept2[0].offset[0] == 0 && kept2[1].offset[0] != 0));
  CHECK(disjoint(kept2, flat));
  // Labels that overlap without projecting together (anchors 0.3 apart, 10 px at this scale,
  // more than half the size) are left out, as before: moving them would not say more.
  d.labels.clear();
  label({0, 0, 0}, "one", true);
  label({0.3, 0, 0}, "two", true);
  CHECK(texts(placedLabels(d, flat, v.height, false, width)) == std::vector<std::string>{"one"});
}

TEST_CASE("render: fog fades 3D shapes and facets toward the background with depth", "[render]") {
  // fogged(): none at the near side of the box, `fog` at the far side, clamped beyond.
  const Color black{0, 0, 0, 1};
  CHECK(fogged(black, -0.8, kWhite, 0.5).r == Approx(0));
  CHECK(fogged(black, 0.0, kWhite, 0.5).r == Approx(0.25));
  CHECK(fogged(black, 0.8, kWhite, 0.5).r == Approx(0.5));
  CHECK(fogged(black, 5.0, kWhite, 0.5).r == Approx(0.5));
  CHECK(fogged(black, 0.8, kWhite, 0).r == 0);
  // Two flat (unshaded) black discs, one near, one far; and a far facet.
  View v;
  v.width = v.height = 120;
  v.three_d = true;
  v.azimuth = 0, v.elevation = 0;  // looking along -x
  v.lo = {-1, -1, -1}, v.hi = {1, 1, 1};
  DrawList list;
  list.dimension = 3;
  list.disc({1, -0.5, 0}, 8, black);
  list.disc({-1, 0.5, 0}, 8, black);
  Polygon far;
  far.points = {{-1, -0.6, 0.4}, {-1, -0.4, 0.4}, {-1, -0.4, 0.6}, {-1, -0.6, 0.6}};
  far.fill = black;
  list.polygons.push_back(far);
  const Projector project(v);
  const auto pixel = [&](const Image& im, const Point3& p) {
    const auto q = project(p);
    return at(im, static_cast<int>(std::lround(q[0])), static_cast<int>(std::lround(v.height - q[1])));
  };
  const double near_depth = project({1, -0.5, 0})[2], far_depth = project({-1, 0.5, 0})[2];
  REQUIRE(near_depth < far_depth);
  for (double fog : {0.0, 0.6}) {
    INFO(fog);
    v.fog = fog;
    const Image im = renderer().render(list, v);
    const auto expected = [&](double depth) { return 255 * fogged(black, depth, kWhite, fog).r; };
    // A ball's depth at its centre is its front (nearer by its radius): a little less fog.
    CHECK(pixel(im, {1, -0.5, 0})[0] == Approx(expected(near_depth)).margin(12));
    CHECK(pixel(im, {-1, 0.5, 0})[0] == Approx(expected(far_depth)).margin(12));
    CHECK(pixel(im, {-1, -0.5, 0.5})[0] == Approx(expected(project({-1, -0.5, 0.5})[2])).margin(3));
    if (fog > 0) CHECK(pixel(im, {-1, 0.5, 0})[0] > pixel(im, {1, -0.5, 0})[0] + 60);
  }
}

TEST_CASE("render: 3D labels have a halo, 2D labels none, and far labels are drawn first", "[render]") {
  // White text on a white background: only a halo makes dark pixels.
  const auto darkPixels = [](const Image& im) {
    long n = 0;
    for (int y = 0; y < im.height; ++y)
      for (int x = 0; x < im.width; ++x) n += im.pixel(x, y)[0] < 100;
    return n;
  };
  DrawList list;
  Label l;
  l.at = {0, 0, 0}, l.text = "12", l.size = 24, l.color = kWhite;
  list.labels.push_back(l);
  View v2 = window(100, 100);
  v2.lo = {-1, -1, 0}, v2.hi = {1, 1, 0};
  CHECK(darkPixels(renderer().render(list, v2)) == 0);
  View v3;
  v3.width = v3.height = 100;
  v3.three_d = true;
  v3.lo = {-1, -1, -1}, v3.hi = {1, 1, 1};
  list.dimension = 3;
  CHECK(darkPixels(renderer().render(list, v3)) > 40);
  // Dark text gets a halo of the background: over a black bar, white around the glyphs.
  CHECK(haloColor(kBlack, kWhite).r == 1);
  CHECK(haloColor(kWhite, kWhite).r < 0.2f);
  // Two labels at one spot: the nearer one is drawn last, over the farther one.
  v3.azimuth = 0, v3.elevation = 0;  // +x towards the viewer
  for (int order = 0; order < 2; ++order) {
    DrawList two;
    two.dimension = 3;
    Label near_label = l, far_label = l;
    near_label.at = {1, 0, 0}, near_label.text = "8", near_label.color = {1, 0, 0, 1};
    far_label.at = {-1, 0, 0}, far_label.text = "8", far_label.color = {0, 0, 1, 1};
    if (order == 0) two.labels = {near_label, far_label};
    else two.labels = {far_label, near_label};
    const Image im = renderer().render(two, v3);
    long red = 0, blue = 0;
    for (int y = 0; y < im.height; ++y)
      for (int x = 0; x < im.width; ++x) {
        const auto* p = im.pixel(x, y);
        red += p[0] > 200 && p[2] < 60;
        blue += p[2] > 200 && p[0] < 60;
      }
    CHECK(red > 20);
    CHECK(blue == 0);
  }
}
