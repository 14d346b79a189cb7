// Certified tracks (engine/interval/krawczyk.h): the four-bar's path certified sample by sample
// and step by step, a sample moved by 1e-6 refused, the double Watt certified away from its
// cusp and not at it, a start with a stress (redundant constraints) refused with the reason.
#include <catch2/catch.hpp>

#include <cmath>

#include "bench/grids.h"
#include "engine/interval/krawczyk.h"
#include "engine/motion_tracker.h"
#include "engine/rigidity.h"
#include "engine/systems/angular_framework.h"
#include "engine/systems/framework.h"
#include "engine/systems/spherical_disk_packing.h"
#include "engine/systems/volume_hypergraph.h"
#include "../test_common.h"

using namespace flexure;
using engine::DeformationPath;
using engine::Framework;
using engine::Vector;
using test::makeFramework;

namespace {

DeformationPath trackAuto(const engine::Model& f, int steps, double step_size) {
  const engine::RigidityReport rep = engine::analyzeRigidity(f, f.startCoordinates());
  engine::TrackerOptions opt;
  opt.steps = steps;
  opt.step_size = step_size;
  DeformationPath p = engine::trackMotion(f, f.startCoordinates(), rep.flex_basis * rep.auto_flex, opt);
  p.startOn(f);
  return p;
}

}  // namespace

TEST_CASE("certified track: the four-bar's every sample and step") {
  // Ground 1-2 pinned, cranks 1-4 and 2-3, coupler 3-4 (vertex numbers from 1).
  const Framework f = makeFramework({{0, 0}, {2, 0}, {2.2, 1.1}, {0.3, 1.2}}, {{1, 4}, {2, 3}, {3, 4}}, {1, 2});
  DeformationPath p = trackAuto(f, 40, 0.05);
  REQUIRE(p.samples.size() == 41);
  engine::PathCertificate c = engine::certify::certifyPath(p);
  INFO(c.reason);
  CHECK(c.certified());
  for (double r : c.radii) {
    CHECK(r >= 0);
    CHECK(r <= 1e-8 * 2.2);
  }
  // The certified chain from the start proves the motion nontrivial.
  REQUIRE(c.flexible);
  CHECK(*c.flexible);
  CHECK(c.reason.find("flexible: proved") != std::string::npos);
  // A chain cut right after the start proves nothing.
  DeformationPath cut = p;
  cut.samples[1][0] += 1e-6;
  CHECK_FALSE(engine::certify::certifyPath(cut).flexible);
  // A sample moved by 1e-6 is not certified, nor are its steps.
  p.samples[20][0] += 1e-6;
  c = engine::certify::certifyPath(p);
  CHECK_FALSE(c.certified());
  CHECK(std::isnan(c.radii[20]));
  CHECK_FALSE(c.steps[19]);
  CHECK_FALSE(c.steps[20]);
  CHECK(c.radii[19] >= 0);
  CHECK(c.reason.find("sample 20") != std::string::npos);
}

TEST_CASE("certified track: reasons that say what is true (issue 62)") {
  // A one-sample path has no steps: its certificate says what was certified, not "each step".
  const Framework f = makeFramework({{0, 0}, {2, 0}, {2.2, 1.1}, {0.3, 1.2}}, {{1, 4}, {2, 3}, {3, 4}}, {1, 2});
  DeformationPath one = trackAuto(f, 0, 0.05);
  REQUIRE(one.samples.size() == 1);
  const engine::PathCertificate c1 = engine::certify::certifyPath(one);
  INFO(c1.reason);
  CHECK(c1.certified());
  CHECK(c1.reason.find("one sample certified") != std::string::npos);
  CHECK(c1.reason.find("each step") == std::string::npos);
  // The same four-bar at scale 1e16: regular, its Jacobian's rows 1e16 against the slice's 1;
  // not called a singular point.
  const Framework big = makeFramework({{0, 0}, {2e16, 0}, {2.2e16, 1.1e16}, {0.3e16, 1.2e16}}, {{1, 4}, {2, 3}, {3, 4}},
                                      {1, 2});
  DeformationPath pb = trackAuto(big, 3, 0.05e16);
  const engine::PathCertificate cb = engine::certify::certifyPath(pb);
  INFO(cb.reason);
  CHECK(cb.reason.find("a singular point:") == std::string::npos);
  CHECK((cb.certified() || cb.reason.find("ill-conditioned") != std::string::npos));
}

TEST_CASE("certified track: the double Watt away from its cusp, and not at it") {
  // The cuspidal double Watt (Connelly and Servatius), pinned at 1, 6 and 11; its start is the cusp.
  const Framework f =
      makeFramework({{0, 0}, {1, 0}, {2, 1}, {1, 2}, {3, 2}, {4, 2}, {5, 2}, {7, 2}, {6, 1}, {7, 0}, {8, 0}},
                    {{1, 2}, {2, 3}, {2, 4}, {3, 9}, {3, 4}, {3, 5}, {4, 5}, {5, 6}, {6, 7}, {7, 8}, {7, 9},
                     {8, 9}, {8, 10}, {9, 10}, {10, 11}},
                    {1, 6, 11});
  const DeformationPath p = trackAuto(f, 30, 0.02);
  const engine::PathCertificate c = engine::certify::certifyPath(p);
  INFO(c.reason);
  CHECK(std::isnan(c.radii[0]));  // the cusp: a singular point
  int certified = 0;
  for (size_t k = 1; k < c.radii.size(); ++k) certified += c.radii[k] >= 0;
  CHECK(certified >= static_cast<int>(c.radii.size()) - 3);
  // Steps next to the cusp (high curvature, small singular values) may fail; away from it, from
  // sample 10 on (0.2 along the path), every step is certified.
  for (size_t k = 10; k < c.steps.size(); ++k) {
    INFO("step " << k);
    CHECK(c.steps[k]);
  }
}

TEST_CASE("certified track: a start with a stress is refused with the reason") {
  // A quadrilateral with a degenerate (collinear) triangle attached: 1 stress along the path.
  const Framework f = makeFramework({{0, 0}, {1, 0}, {1.1, 1}, {0, 1}, {2, 0}, {3, 0}},
                                    {{1, 2}, {2, 3}, {3, 4}, {4, 1}, {2, 5}, {5, 6}, {2, 6}}, {1});
  const DeformationPath p = trackAuto(f, 3, 0.02);
  const engine::PathCertificate c = engine::certify::certifyPath(p);
  CHECK_FALSE(c.certified());
  CHECK(c.reason.find("redundant") != std::string::npos);
}

TEST_CASE("certified track: unpinned systems, in a gauge slice across their rigid motions") {
  // The four-bar with no pin (8 coordinates, 4 bars: 3 rigid motions and the motion) and two
  // tetrahedra hinged on a shared edge in space (18 coordinates, 11 bars: 6 rigid motions and the
  // rotation about the hinge). Each step: both samples moved by rigid motions onto their
  // midpoint, certified in the slice across the rigid motions there.
  const Framework planar = makeFramework({{0, 0}, {2, 0}, {2.2, 1.1}, {0.3, 1.2}}, {{1, 2}, {1, 4}, {2, 3}, {3, 4}});
  const Framework hinged = makeFramework(
      {{0, 0, 0}, {1, 0.1, 0}, {0.4, 0.9, 0.2}, {0.5, 0.3, 0.8}, {0.6, -0.8, 0.3}, {0.3, -0.2, -0.9}},
      {{1, 2}, {1, 3}, {1, 4}, {2, 3}, {2, 4}, {3, 4}, {1, 5}, {1, 6}, {2, 5}, {2, 6}, {5, 6}});
  for (const Framework* f : {&planar, &hinged}) {
    DeformationPath p = trackAuto(*f, 30, 0.05);
    REQUIRE(p.samples.size() == 31);
    engine::PathCertificate c = engine::certify::certifyPath(p);
    INFO(c.reason);
    CHECK(c.certified());
    // A sample moved by 1e-6 is not certified, nor are its steps; the others are.
    p.samples[12][1] += 1e-6;
    c = engine::certify::certifyPath(p);
    CHECK(std::isnan(c.radii[12]));
    CHECK_FALSE(c.steps[11]);
    CHECK_FALSE(c.steps[12]);
    CHECK(c.steps[10]);
    CHECK(c.steps[13]);
  }
}

TEST_CASE("certified track: the sparse norm test of large systems, on small ones and a 400-coordinate grid") {
  // The sparse test (engine/interval/krawczyk_sparse.cpp) forced on the four-bar: every sample
  // and step, and a sample moved by 1e-6 refused with its steps. Then a square grid of 10 x 10
  // cells braced along its first row and column but for the top-left cell (isostatic less one
  // brace: its top row shears), pinned at one bar: 238 coordinates, whole. Both ways: the step's
  // anchor (quadratic systems) and the piecewise norm test alone.
  engine::certify::PathCertifyOptions sparse;
  sparse.dense_variables = 0;
  sparse.anchored_variables = 0;
  sparse.quadratic_anchors = GENERATE(true, false);
  INFO("anchors: " << sparse.quadratic_anchors);
  const Framework f = makeFramework({{0, 0}, {2, 0}, {2.2, 1.1}, {0.3, 1.2}}, {{1, 4}, {2, 3}, {3, 4}}, {1, 2});
  DeformationPath p = trackAuto(f, 20, 0.05);
  engine::PathCertificate c = engine::certify::certifyPath(p, sparse);
  INFO(c.reason);
  CHECK(c.certified());
  CHECK(c.reason.find("sparse") != std::string::npos);
  for (double r : c.radii) CHECK(r <= 1e-8 * 2.2);
  CHECK((c.reason.find("anchored") != std::string::npos) == sparse.quadratic_anchors);
  p.samples[8][1] += 1e-6;
  c = engine::certify::certifyPath(p, sparse);
  CHECK(std::isnan(c.radii[8]));
  CHECK_FALSE(c.steps[7]);
  CHECK_FALSE(c.steps[8]);
  CHECK(c.steps[6]);
  CHECK(c.steps[9]);

  const Framework grid = bench::shearingGrid(10, 10);
  REQUIRE(grid.system().numVariables() - grid.system().numEquations() == 1);
  const DeformationPath q = trackAuto(grid, 4, 0.05);
  const engine::PathCertificate cg = engine::certify::certifyPath(q, sparse);
  INFO(cg.reason);
  CHECK(cg.certified());
}

TEST_CASE("certified track: an angular framework, in a gauge slice across its similarities") {
  // A quadrilateral with its angles kept at three corners (0-based (i, j, k): the angle at j):
  // 8 coordinates, 3 equations, the 4 similarities of the plane and one motion (the sides'
  // ratios change). Each step: both samples moved onto their midpoint by a similarity (rotation by
  // Kabsch, the scale that meets the slice's scaling row).
  engine::Matrix p(2, 4);
  p << 0, 2, 2.3, 0.2, 0, 0, 1.2, 1.0;
  const engine::AngularFramework f(p, {{3, 0, 1}, {0, 1, 2}, {1, 2, 3}}, {});
  const engine::RigidityReport rep = engine::analyzeRigidity(f, f.startCoordinates());
  REQUIRE(rep.nontrivial == 1);
  REQUIRE(rep.trivial == 4);
  DeformationPath path = trackAuto(f, 20, 0.03);
  engine::PathCertificate c = engine::certify::certifyPath(path);
  INFO(c.reason);
  CHECK(c.certified());
  path.samples[7][2] += 1e-6;
  c = engine::certify::certifyPath(path);
  CHECK(std::isnan(c.radii[7]));
  CHECK_FALSE(c.steps[6]);
  CHECK(c.steps[5]);
}

TEST_CASE("certified track: partial pins, in a gauge slice across the motions they leave") {
  // One pinned vertex leaves the rotations about it (2D: the four-bar pinned at vertex 1; with
  // the similarities also the scalings about it: an angular quadrilateral), two pinned vertices
  // in space the rotation about their line (the hinged tetrahedra pinned at the hinge).
  const Framework planar =
      makeFramework({{0, 0}, {2, 0}, {2.2, 1.1}, {0.3, 1.2}}, {{1, 2}, {1, 4}, {2, 3}, {3, 4}}, {1});
  const Framework hinged = makeFramework(
      {{0, 0, 0}, {1, 0.1, 0}, {0.4, 0.9, 0.2}, {0.5, 0.3, 0.8}, {0.6, -0.8, 0.3}, {0.3, -0.2, -0.9}},
      {{1, 2}, {1, 3}, {1, 4}, {2, 3}, {2, 4}, {3, 4}, {1, 5}, {1, 6}, {2, 5}, {2, 6}, {5, 6}}, {1, 2});
  for (const Framework* f : {&planar, &hinged}) {
    REQUIRE(f->system().numVariables() - f->system().numEquations() == 2);
    DeformationPath p = trackAuto(*f, 20, 0.05);
    engine::PathCertificate c = engine::certify::certifyPath(p);
    INFO(c.reason);
    CHECK(c.certified());
    p.samples[9][0] += 1e-6;
    c = engine::certify::certifyPath(p);
    CHECK(std::isnan(c.radii[9]));
    CHECK_FALSE(c.steps[8]);
    CHECK(c.steps[7]);
  }
  engine::Matrix q(2, 4);
  q << 0, 2, 2.3, 0.2, 0, 0, 1.2, 1.0;
  const engine::AngularFramework angular(q, {{3, 0, 1}, {0, 1, 2}, {1, 2, 3}}, {0});
  REQUIRE(engine::analyzeRigidity(angular, angular.startCoordinates()).nontrivial == 1);
  const DeformationPath path = trackAuto(angular, 15, 0.03);
  const engine::PathCertificate c = engine::certify::certifyPath(path);
  INFO(c.reason);
  CHECK(c.certified());
}

TEST_CASE("certified track: a step between two branches is refused, whichever test") {
  // The pinned four-bar's mirror image across the line of its pins is a realization too (the
  // other assembly mode). A path whose second sample is the mirror image of the tracked one has
  // two samples that certify (both on the curve) but a step that must not: no arc of the real
  // curve joins them. The dense test, the sparse norm test and the anchored test refuse it.
  const Framework f = makeFramework({{0, 0}, {2, 0}, {2.2, 1.1}, {0.3, 1.2}}, {{1, 4}, {2, 3}, {3, 4}}, {1, 2});
  DeformationPath p = trackAuto(f, 6, 0.02);
  REQUIRE(p.samples.size() == 7);
  // Free coordinates: vertices 3 and 4 (x, y each); the pins lie on y = 0.
  for (int k : {4, 5, 6}) p.samples[static_cast<size_t>(k)][1] *= -1, p.samples[static_cast<size_t>(k)][3] *= -1;
  for (int mode = 0; mode < 3; ++mode) {  // dense Krawczyk, anchored, sparse norm test
    engine::certify::PathCertifyOptions opt;
    opt.quadratic_anchors = mode == 1;
    opt.anchored_variables = 0;
    if (mode == 2) opt.dense_variables = 0;
    INFO("mode " << mode);
    const engine::PathCertificate c = engine::certify::certifyPath(p, opt);
    INFO(c.reason);
    for (double r : c.radii) CHECK_FALSE(std::isnan(r));
    CHECK(c.steps[0]);
    CHECK(c.steps[2]);
    CHECK_FALSE(c.steps[3]);
    CHECK(c.steps[4]);
  }
}

TEST_CASE("certified track: a 1,024-vertex mechanism whole, each step by its anchor") {
  // The sheared grid of 31 x 31 cells (2,044 coordinates; the certify benchmark's case): every
  // sample and step, by the anchored test; a sample moved by 1e-6 refused, with its two steps.
  const Framework grid = bench::shearingGrid(31, 31);
  REQUIRE(grid.system().numVariables() == 2044);
  DeformationPath p = trackAuto(grid, 4, 0.01);
  engine::PathCertificate c = engine::certify::certifyPath(p);
  INFO(c.reason);
  CHECK(c.certified());
  CHECK(c.reason.find("anchored") != std::string::npos);
  for (double r : c.radii) CHECK(r <= 1e-8 * 31);
  p.samples[2][100] += 1e-6;
  c = engine::certify::certifyPath(p);
  CHECK(std::isnan(c.radii[2]));
  CHECK_FALSE(c.steps[1]);
  CHECK_FALSE(c.steps[2]);
  CHECK(c.steps[0]);
  CHECK(c.steps[3]);
}

TEST_CASE("certified track: gauge slices across the equi-affine and the Moebius groups") {
  // Unpinned: a sample is moved onto the slice across the group's motions at the step's midpoint
  // by Gauss-Newton in the group (exp of its Lie algebra), then certified again there.
  SECTION("a volume hypergraph: five points in the plane, four triangles of fixed area") {
    // 10 coordinates - 5 equi-affine motions - 4 areas: one flex.
    engine::Matrix p(2, 5);
    p << 0, 3, 0.4, 2.2, 1.1,  //
        0, 0.2, 2.5, 2.1, 3.3;
    const engine::VolumeHypergraph v(p, {{0, 1, 2}, {1, 3, 2}, {2, 3, 4}, {0, 1, 3}}, {}, 0);
    REQUIRE(v.system().numVariables() - v.system().numEquations() == 6);
    DeformationPath path = trackAuto(v, 20, 0.02);
    engine::PathCertificate c = engine::certify::certifyPath(path);
    INFO(c.reason);
    CHECK(c.certified());
    // The samples from 10 on moved by an equi-affine shear (det 1): the same motion modulo the
    // group, still certified step by step; by a map of det 1.1, no longer a realization.
    engine::Matrix G(3, 3);
    G << 1, 0.3, 0.5, 0, 1, -0.2, 0, 0, 1;
    const engine::SymmetryGroup group = *v.symmetryGroup();
    for (size_t k = 10; k < path.samples.size(); ++k)
      path.samples[k] = v.system().freeCoordinates(engine::applyGroupElement(group, G, v.system().positions(path.samples[k])));
    c = engine::certify::certifyPath(path);
    INFO(c.reason);
    CHECK(c.certified());
    G(0, 0) = 1.1;
    path.samples[15] = v.system().freeCoordinates(engine::applyGroupElement(group, G, v.system().positions(path.samples[15])));
    c = engine::certify::certifyPath(path);
    CHECK(std::isnan(c.radii[15]));
    CHECK_FALSE(c.steps[14]);
    CHECK(c.steps[13]);
  }
  SECTION("a spherical disk packing: four caps, five contacts") {
    // 12 coordinates - 6 Moebius motions - 5 inversive distances: one flex.
    engine::Matrix p(3, 4);
    p << 1.3, 0.1, -0.2, 0.4,  //
        0.2, 1.4, 0.3, -0.9,   //
        0.1, 0.2, 1.5, 0.9;
    const engine::SphericalDiskPacking s(p, {{0, 1}, {0, 2}, {1, 2}, {1, 3}, {2, 3}}, {}, 0);
    REQUIRE(s.system().numVariables() - s.system().numEquations() == 7);
    const DeformationPath path = trackAuto(s, 20, 0.02);
    engine::PathCertificate c = engine::certify::certifyPath(path);
    INFO(c.reason);
    CHECK(c.certified());
    // A sample moved by 1e-6: refused, with its steps; the others still certified.
    DeformationPath moved = path;
    moved.samples[10][0] += 1e-6;
    c = engine::certify::certifyPath(moved);
    CHECK(std::isnan(c.radii[10]));
    CHECK_FALSE(c.steps[9]);
    CHECK_FALSE(c.steps[10]);
    CHECK(c.steps[8]);
    CHECK(c.steps[11]);
  }
}
