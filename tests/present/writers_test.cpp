// Animation alignment, projections and animation frames (present/frames, projection, animation, writers).
#include <catch2/catch.hpp>

#include <Eigen/Dense>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <random>

#include "scenes/catalog.h"
#include "pipeline/pipeline.h"
#include "present/animation.h"
#include "present/frames.h"
#include "scenes/scene.h"
#include "../scenes/scene_test_common.h"

using namespace flexure;
using test::example;
using test::requireSceneError;
using engine::Matrix;

namespace {

Matrix randomConfiguration(std::mt19937& rng, int d, int n) {
  std::normal_distribution<double> g(0, 2);
  Matrix p(d, n);
  for (int i = 0; i < d; ++i)
    for (int j = 0; j < n; ++j) p(i, j) = g(rng);
  return p;
}

Matrix distances(const Matrix& p) {
  Matrix d(p.cols(), p.cols());
  for (int i = 0; i < p.cols(); ++i)
    for (int j = 0; j < p.cols(); ++j) d(i, j) = (p.col(i) - p.col(j)).norm();
  return d;
}

// Orientation of the simplex on the first d+1 points (a mirror image flips it).
double orientation(const Matrix& p) {
  const int d = static_cast<int>(p.rows());
  Matrix m(d, d);
  for (int k = 0; k < d; ++k) m.col(k) = p.col(k + 1) - p.col(0);
  return m.determinant();
}

render::Renderer& renderer() {
  static render::Renderer r;
  return r;
}


}  // namespace

TEST_CASE("outputs: 2D alignment is a proper rigid motion putting a at 0 and b on the ray", "[scenes][outputs]") {
  std::mt19937 rng(3);
  std::vector<Matrix> frames, original;
  for (int k = 0; k < 20; ++k) frames.push_back(randomConfiguration(rng, 2, 6));
  original = frames;
  const std::vector<double> dir{-1, 2};
  present::alignConfigurations(frames, {2, 4}, dir);
  for (size_t k = 0; k < frames.size(); ++k) {
    const Matrix& p = frames[k];
    CHECK(p.col(2).norm() < 1e-12);
    const Eigen::Vector2d b = p.col(4);
    CHECK(b.x() * dir[1] - b.y() * dir[0] == Approx(0).margin(1e-12));  // on the line
    CHECK(b.x() * dir[0] + b.y() * dir[1] > 0);                          // on the ray, not behind
    CHECK((distances(p) - distances(original[k])).cwiseAbs().maxCoeff() < 1e-12);
    CHECK(orientation(p) * orientation(original[k]) > 0);
  }
}

TEST_CASE("outputs: 3D alignment puts c in the half-plane for any direction, never mirrored", "[scenes][outputs]") {
  std::mt19937 rng(5);
  const std::vector<double> dir{1, 1, 0};  // not e_x (the reference's third-vertex rule assumes e_x)
  const Eigen::Vector3d d = Eigen::Vector3d(1, 1, 0).normalized();
  const Eigen::Vector3d up = (Eigen::Vector3d::UnitY() - d.y() * d).normalized();
  std::vector<Matrix> frames, original;
  for (int k = 0; k < 20; ++k) frames.push_back(randomConfiguration(rng, 3, 5));
  // b exactly opposite to the direction (the reference's antiparallel case is wrong).
  frames[3].col(1) = frames[3].col(0) - 2.0 * d;
  original = frames;
  present::alignConfigurations(frames, {0, 1, 2}, dir);
  for (size_t k = 0; k < frames.size(); ++k) {
    const Matrix& p = frames[k];
    INFO("frame " << k);
    CHECK(p.col(0).norm() < 1e-12);
    const Eigen::Vector3d b = p.col(1), c = p.col(2);
    CHECK(b.normalized().dot(d) == Approx(1).margin(1e-12));
    const Eigen::Vector3d perp = c - c.dot(d) * d;
    CHECK(perp.normalized().dot(up) == Approx(1).margin(1e-9));
    CHECK((distances(p) - distances(original[k])).cwiseAbs().maxCoeff() < 1e-11);
    CHECK(orientation(p) * orientation(original[k]) > 0);
  }
  // A frame where b coincides with a keeps the previous rotation instead of failing.
  std::vector<Matrix> two{original[0], original[0]};
  two[1].col(1) = two[1].col(0);
  present::alignConfigurations(two, {0, 1}, {});
  CHECK(two[1].allFinite());
  CHECK((two[1].col(3) - two[0].col(3)).norm() < 1e-12);
}

TEST_CASE("outputs: default fixed vertices, frame samples, projections", "[scenes][outputs]") {
  CHECK(present::fixedVertices(example("double_watt")).empty());  // pinned: nothing to align
  CHECK(present::fixedVertices(example("square")) == std::vector<int>{0, 1});
  CHECK(present::fixedVertices(example("coned_cube")) == std::vector<int>{0, 1, 2});
  CHECK(present::fixedVertices(example("square", {"render.fixed_vertices=[]"})).empty());
  CHECK(present::fixedVertices(example("square", {"render.fixed_vertices=[3,1]"})) == std::vector<int>{2, 0});

  CHECK(present::frameSamples(11, 1).size() == 11);
  CHECK(present::frameSamples(11, 5) == std::vector<int>{0, 5, 10});
  CHECK(present::frameSamples(12, 5) == std::vector<int>{0, 5, 10, 11});
  CHECK(present::frameSamples(1, 3) == std::vector<int>{0});

  const Matrix q = present::randomProjection(16, 2, 7);
  CHECK((q.transpose() * q - Matrix::Identity(2, 2)).cwiseAbs().maxCoeff() < 1e-14);
  CHECK(present::randomProjection(16, 2, 7) == q);
  CHECK((present::randomProjection(16, 2, 8) - q).norm() > 0.1);
}

TEST_CASE("outputs: projection paths in both directions meet at the start", "[scenes][outputs]") {
  const scenes::Scene scene = example("square_pinned", {"motion.steps=12", "projection.both_directions=true",
                                                         "projection.flexes=[[1],[-1]]"});
  const pipeline::Motion m = pipeline::track(scene, scene.motion.steps);
  const auto paths = pipeline::projectionPaths(scene, m);
  REQUIRE(paths.size() == 2);
  for (const auto& p : paths) {
    CHECK(p.complete);
    REQUIRE(p.samples.size() == 25);
    CHECK(p.start == 12);
    CHECK(p.sample_numbers.front() == -12);
    CHECK(p.sample_numbers.back() == 12);
    CHECK((p.samples[12] - scene.model->startCoordinates()).norm() < 1e-14);
    for (size_t i = 1; i < p.samples.size(); ++i)  // unit speed all along, through the start
      CHECK((p.samples[i] - p.samples[i - 1]).norm() == Approx(scene.motion.step_size).epsilon(0.06));
  }
  // Opposite flexes give the same curve, traversed the other way.
  CHECK((paths[0].samples.front() - paths[1].samples.back()).norm() < 1e-9);
  const present::Projection pr = present::projectPaths(scene, paths, 4);
  CHECK(pr.curves.size() == 2);
  CHECK(pr.plot.series.size() == 2);
  CHECK(pr.plot.start);
  const std::string csv = present::projectionCsv(paths, pr);
  CHECK(csv.rfind("path,sample,p1,p2\n1,-12,", 0) == 0);
  CHECK(std::count(csv.begin(), csv.end(), '\n') == 1 + 2 * 25);
}

TEST_CASE("outputs: animation frames share one camera and caption singular points", "[scenes][outputs]") {
  const scenes::Scene scene = example("double_watt", {"motion.steps=30", "render.frame_step=4", "render.fps=4"});
  const pipeline::Motion m = pipeline::track(scene, scene.motion.steps);
  const present::Animation anim(scene, m.path, 200, 160);
  CHECK(anim.frameCount() == 9);  // samples 0, 4, ..., 28, 30
  render::Image first, last;
  anim.frame(0, renderer(), first);
  anim.frame(anim.frameCount() - 1, renderer(), last);
  CHECK(first.width == 200);
  CHECK(first.height == 160);
  CHECK(first.rgba != last.rgba);
  // The start of the double Watt is its cusp: the first frames carry a red caption top left.
  auto redTopLeft = [](const render::Image& im) {
    int n = 0;
    for (int y = 0; y < 25; ++y)
      for (int x = 0; x < 120; ++x) n += im.pixel(x, y)[0] > 150 && im.pixel(x, y)[1] < 80;
    return n;
  };
  CHECK(redTopLeft(first) > 10);
  CHECK(redTopLeft(last) == 0);
  const scenes::Scene quiet = example("double_watt", {"motion.steps=30", "render.mark_events=false"});
  render::Image plain;
  present::Animation(quiet, m.path, 200, 160).frame(0, renderer(), plain);
  CHECK(redTopLeft(plain) == 0);
  // Side by side: the mechanism on the left, the projection with its cursor on the right.
  const scenes::Scene side = example("double_watt", {"motion.steps=30", "render.side_by_side=true"});
  const auto paths = pipeline::projectionPaths(side, m);
  const present::Projection pr = present::projectPaths(side, paths, 1);
  const present::Animation both(side, m.path, 400, 160, &pr);
  render::Image wide;
  both.frame(2, renderer(), wide);
  CHECK(wide.width == 400);
  int right_dark = 0;
  for (int y = 0; y < 160; ++y)
    for (int x = 200; x < 400; ++x) right_dark += wide.pixel(x, y)[0] < 100;
  CHECK(right_dark > 100);  // axes, labels, the curve
}

TEST_CASE("outputs: a frame with --flex draws the arrows of a polytope's vertices", "[scenes][outputs]") {
  // The flex of a polytope also moves its facet normals (auxiliary blocks); only the vertices
  // get arrows, and they must get them.
  const scenes::Scene s = example("truncated_icosahedron", {"render.width=300", "render.height=300"});
  const std::string file = "outputs_test_flex.png";
  present::writeFrame(s, nullptr, 0, true, file, renderer());
  std::ifstream f(file, std::ios::binary);
  const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  std::remove(file.c_str());
  const render::Image im = render::decodePng(bytes);
  int green = 0;  // green3 arrows
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      const auto* q = im.pixel(x, y);
      green += q[1] > 150 && q[0] < 80 && q[2] < 80;
    }
  CHECK(green > 100);
}

TEST_CASE("outputs: the equi-affine normalisation puts the fixed simplex in place and keeps every volume",
          "[scenes][outputs]") {
  std::mt19937 rng(11);
  for (int d : {2, 3}) {
    INFO("dimension " << d);
    std::vector<Matrix> frames;
    for (int f = 0; f < 5; ++f) frames.push_back(randomConfiguration(rng, d, 7));
    const std::vector<Matrix> raw = frames;
    std::vector<int> simplex = {4, 1, 6};
    if (d == 3) simplex.push_back(2);
    present::normalizeEquiAffine(frames, simplex, 0.7, 0.25);
    for (size_t f = 0; f < frames.size(); ++f) {
      const Matrix& p = frames[f];
      CHECK(p.col(simplex[0]).norm() < 1e-12);
      CHECK(p(0, simplex[1]) == Approx(0.7));
      CHECK(std::abs(p(1, simplex[1])) < 1e-12);
      CHECK(p(0, simplex[2]) == Approx(0.25));
      if (d == 3) {
        CHECK(p(1, simplex[2]) == Approx(0.7));
        CHECK(std::abs(p(2, simplex[1])) + std::abs(p(2, simplex[2])) < 1e-12);
        CHECK(p(0, simplex[3]) == Approx(0.25));
        CHECK(p(1, simplex[3]) == Approx(0.25));
      }
      // Signed volumes of every simplex on the first d + 1 points and of another one are kept.
      for (std::vector<int> s : {std::vector<int>{0, 1, 2, 3}, std::vector<int>{6, 5, 3, 0}}) {
        s.resize(static_cast<size_t>(d) + 1);
        Matrix a(d, d), b(d, d);
        for (int k = 0; k < d; ++k) {
          a.col(k) = raw[f].col(s[static_cast<size_t>(k) + 1]) - raw[f].col(s[0]);
          b.col(k) = p.col(s[static_cast<size_t>(k) + 1]) - p.col(s[0]);
        }
        CHECK(b.determinant() == Approx(a.determinant()).margin(1e-12));
      }
    }
  }
  // The octahedral demo: triangle 6, 4, 5 is pinned in the frames; keys are checked.
  const scenes::Scene s = example("octahedral_volumes");
  CHECK(present::fixedSimplex(s) == std::vector<int>{5, 3, 4});
  CHECK(present::fixedSimplex(example("octahedral_volumes", {"render.fixed_simplex=[]"})).empty());
  CHECK_THROWS_WITH(example("octahedral_volumes", {"render.fixed_simplex=[1,2,3]"}),
                    Catch::Contains("fixed_simplex must be one of the simplices"));
  CHECK_THROWS_WITH(example("square", {"render.fixed_simplex=[1,2,3]"}), Catch::Contains("for volume hypergraphs"));
  CHECK_THROWS_WITH(example("octahedral_volumes", {"render.target_stretch=0"}), Catch::Contains("must be positive"));
}
