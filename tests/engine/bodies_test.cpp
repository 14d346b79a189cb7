// Rigid bodies of any shape (engine/systems/body_framework.h, BodyFramework): flat, collinear, two-vertex and
// one-vertex bodies, with the flex and stress counts of body-hinge and body-bar theory.
#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <cmath>

#include "engine/motion_tracker.h"
#include "engine/rigidity.h"
#include "engine/systems/body_framework.h"

using namespace flexure;
using engine::BodyFramework;
using engine::Matrix;
using engine::Vector;

namespace {

Matrix columns(std::initializer_list<std::initializer_list<double>> pts) {
  const int d = static_cast<int>(pts.begin()->size());
  Matrix p(d, static_cast<int>(pts.size()));
  int j = 0;
  for (const auto& q : pts) {
    int i = 0;
    for (double v : q) p(i++, j) = v;
    ++j;
  }
  return p;
}

struct Counts {
  int trivial, nontrivial, stresses;
};

Counts counts(const BodyFramework& f) {
  const engine::RigidityReport r = engine::analyzeRigidity(f, f.startCoordinates());
  return {r.trivial, r.nontrivial, r.stresses};
}

// Sarrus' linkage of flat plates: a bottom plate (pinned), a top plate, and two legs of two
// hinged plates each, the first leg's hinges along x, the second's along y (0-based vertices:
// 0-3 bottom, 4-7 top, 8-9 and 10-11 the legs' middle hinges).
BodyFramework sarrus() {
  const Matrix p = columns({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1},
                            {0, -0.4, 0.5}, {1, -0.4, 0.5}, {1.4, 0, 0.5}, {1.4, 1, 0.5}});
  return BodyFramework("body_hinge", p, {{0, 1, 2, 3}, {4, 5, 6, 7}, {0, 1, 9, 8}, {8, 9, 5, 4}, {1, 2, 11, 10}, {10, 11, 6, 5}},
                       {}, {0, 1, 2, 3});
}

}  // namespace

TEST_CASE("bodies: two flat panels on a hinge have one motion and no stress", "[engine]") {
  const BodyFramework f("body_hinge", columns({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {2, 0, 0.3}, {2, 1, 0.3}}),
                        {{0, 1, 2, 3}, {1, 4, 5, 2}}, {}, {});
  const Counts c = counts(f);
  CHECK(c.trivial == 6);
  CHECK(c.nontrivial == 1);  // 6 * 2 - 6 - 5
  CHECK(c.stresses == 0);
  // Coplanar panels too (the flat sheet): the hinge still turns, nothing else.
  const BodyFramework flat("body_hinge", columns({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {2, 0, 0}, {2, 1, 0}}),
                           {{0, 1, 2, 3}, {1, 4, 5, 2}}, {}, {});
  CHECK(counts(flat).nontrivial == 1);
  CHECK(counts(flat).stresses == 0);
}

TEST_CASE("bodies: Sarrus' linkage of flat plates has one motion, and its top plate translates", "[engine]") {
  const BodyFramework f = sarrus();
  const engine::RigidityReport r = engine::analyzeRigidity(f, f.startCoordinates());
  CHECK(r.trivial == 0);
  CHECK(r.nontrivial == 1);
  CHECK(r.stresses == 1);  // 6 * 5 - 6 * 5 hinge rows = 0, yet one motion: one dependency
  engine::TrackerOptions opt;
  opt.steps = 120;
  opt.step_size = 0.01;
  const engine::DeformationPath path = engine::trackMotion(f, f.startCoordinates(), r.flex_basis.col(0), opt);
  REQUIRE(path.summary.steps_done == 120);
  // The legs straighten (each a link of length sqrt(0.41) twice) at height 2 sqrt(0.41): a
  // singular point the path passes, turning down again; the only event.
  REQUIRE(path.events.size() == 1);
  CHECK(path.summary.max_residual < 1e-12);
  const Matrix top0 = f.system().positions(path.samples.front()).leftCols(8).rightCols(4);
  double worst = 0.0, highest = 0.0;
  for (const Vector& x : path.samples) {
    const Matrix top = f.system().positions(x).leftCols(8).rightCols(4);
    const Matrix moved = top - top0;
    for (int j = 1; j < 4; ++j) worst = std::max(worst, (moved.col(j) - moved.col(0)).cwiseAbs().maxCoeff());
    worst = std::max(worst, moved.col(0).head(2).cwiseAbs().maxCoeff());  // straight up or down
    highest = std::max(highest, top(2, 0));
  }
  CHECK(worst < 1e-10);
  CHECK(std::abs(highest - 2 * std::sqrt(0.41)) < 2e-3);
  const double at_event = f.system().positions(path.samples[static_cast<size_t>(path.events[0].sample)])(2, 4);
  CHECK(std::abs(at_event - 2 * std::sqrt(0.41)) < 2e-3);
}

TEST_CASE("bodies: two flat plates on four bars: Tay's count, and the parallel case", "[engine]") {
  // Generic bars: 6 * 2 - 6 - 4 = 2 motions; the top plate is flat (in a tilted plane).
  const Matrix p = columns({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                            {0.2, 0.1, 1.0}, {1.3, -0.1, 1.22}, {0.9, 1.2, 1.21}, {-0.2, 0.8, 0.97}});
  // (make the top plate exactly planar: z = 1 + 0.2 x + 0.1 y - 0.05)
  Matrix q = p;
  for (int j = 4; j < 8; ++j) q(2, j) = 0.95 + 0.2 * q(0, j) + 0.1 * q(1, j);
  const BodyFramework generic("body_bar", q, {{0, 1, 2, 3}, {4, 5, 6, 7}}, {{0, 5}, {1, 6}, {2, 4}, {3, 7}}, {});
  const Counts g = counts(generic);
  CHECK(g.nontrivial == 2);
  CHECK(g.stresses == 0);
  // Four parallel bars (a cube): their lines span 3 screws: 3 motions, 1 stress.
  const BodyFramework cube("body_bar",
                           columns({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}),
                           {{0, 1, 2, 3}, {4, 5, 6, 7}}, {{0, 4}, {1, 5}, {2, 6}, {3, 7}}, {});
  const Counts c = counts(cube);
  CHECK(c.nontrivial == 3);
  CHECK(c.stresses == 1);
}

TEST_CASE("bodies: collinear, two-vertex and one-vertex bodies in 2D", "[engine]") {
  // Three collinear points as one body are rigid (the paper's triangle on them flexes).
  const BodyFramework rod("body_hinge", columns({{0, 0}, {1, 0}, {3, 0}}), {{0, 1, 2}}, {}, {});
  CHECK(counts(rod).trivial == 3);
  CHECK(counts(rod).nontrivial == 0);
  CHECK(counts(rod).stresses == 0);
  // A four-bar: the collinear body and a two-vertex body (the ground, pinned) joined by two
  // bars, and a one-vertex body held by two bars to the ground: 3 + 2 - 4 bars = 1 motion.
  const BodyFramework fourbar("body_bar", columns({{0, 0}, {1, 0}, {3, 0}, {0, -1}, {3, -1.5}, {5, -1}}),
                              {{0, 1, 2}, {3, 5}, {4}}, {{0, 3}, {2, 5}, {4, 3}, {4, 5}}, {3, 5});
  const Counts c = counts(fourbar);
  CHECK(c.trivial == 0);
  CHECK(c.nontrivial == 1);
  CHECK(c.stresses == 0);
}

TEST_CASE("bodies: a degree-4 vertex of flat panels", "[engine]") {
  // Creases at 0, 80, 180 and 260 degrees (flat-foldable: 80 + 100 = 180), each panel the centre,
  // two crease ends and a corner between them.
  const double deg = M_PI / 180;
  const double a[4] = {0, 80, 180, 260};
  Matrix p(3, 9);
  p.col(0).setZero();
  for (int i = 0; i < 4; ++i) {
    p.col(1 + i) << std::cos(a[i] * deg), std::sin(a[i] * deg), 0;
    const double b = i < 3 ? a[i + 1] : 360, m = (a[i] + b) / 2 * deg, r = 1 / std::cos((b - a[i]) / 2 * deg);
    p.col(5 + i) << r * std::cos(m), r * std::sin(m), 0;
  }
  const BodyFramework f("body_hinge", p, {{0, 1, 5, 2}, {0, 2, 6, 3}, {0, 3, 7, 4}, {0, 4, 8, 1}}, {}, {});
  // Flat: every crease turns to first order, the loop closing only in the plane: 4 - 2 = 2
  // flexes, and 1 stress.
  const engine::RigidityReport r = engine::analyzeRigidity(f, f.startCoordinates());
  CHECK(r.nontrivial == 2);
  CHECK(r.stresses == 1);
  // Folded: one motion (a spherical four-bar), no stress.
  engine::TrackerOptions opt;
  opt.steps = 30;
  opt.step_size = 0.02;
  const engine::DeformationPath path = engine::trackMotion(f, f.startCoordinates(), r.flex_basis.col(0), opt);
  REQUIRE(path.summary.steps_done == 30);
  CHECK(path.summary.max_residual < 1e-12);
  const engine::RigidityReport folded = engine::analyzeRigidity(f, path.samples.back());
  CHECK(folded.nontrivial == 1);
  CHECK(folded.stresses == 0);
  // The panels stayed flat: each corner in its panel's plane.
  for (const Vector& x : {path.samples.back()}) {
    const Matrix q = f.system().positions(x);
    for (int i = 0; i < 4; ++i) {
      const Eigen::Vector3d c = q.col(0), e1 = q.col(1 + i), e2 = q.col(1 + (i + 1) % 4), k = q.col(5 + i);
      CHECK(std::abs((e1 - c).cross(e2 - c).normalized().dot(k - c)) < 1e-12);
    }
  }
}

TEST_CASE("bodies: a body 1e10 across gets its frame, as at unit size", "[engine]") {
  // Regression (found by the scene fuzzer): the first frame vertex's distance from the empty
  // span was a unit stand-in, below the flatness tolerance 1e-9 * diameter of a body over 1e9
  // across; the frame stayed empty and its affine weights read an empty matrix.
  for (const double scale : {1.0, 1e10}) {
    INFO("scale " << scale);
    const BodyFramework f("body_hinge", scale * columns({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {2, 0, 0.3}, {2, 1, 0.3}}),
                          {{0, 1, 2, 3}, {1, 4, 5, 2}}, {}, {});
    const Counts c = counts(f);
    CHECK(c.trivial == 6);
    CHECK(c.nontrivial == 1);
    CHECK(c.stresses == 0);
  }
}
