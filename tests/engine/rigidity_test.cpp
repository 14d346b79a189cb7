#include <catch2/catch.hpp>
#include <Eigen/Dense>
#include <cmath>

#include "bench/grids.h"
#include "engine/rigidity.h"
#include "engine/systems/framework.h"
#include "../test_common.h"

using namespace flexure;
using engine::Framework;
using engine::Matrix;
using engine::RigidityReport;
using engine::Vector;
using engine::Verdict;

namespace {

using test::makeFramework;

RigidityReport analyze(const Framework& f, engine::RigidityOptions opt = {}) {
  return engine::analyzeRigidity(f, f.startCoordinates(), opt);
}

// Triangulated grid: cols x rows vertices, squares split by a diagonal; `braced_every` = 1
// braces every square, 2 every other row, 0 none.
using bench::grid;

const double s3 = std::sqrt(3.0);

}  // namespace

TEST_CASE("rigidity: the equilateral triangle is infinitesimally rigid", "[engine]") {
  const RigidityReport r = analyze(makeFramework({{0, 0}, {1, 0}, {0.5, s3 / 2}}, {{1, 2}, {2, 3}, {1, 3}}));
  CHECK(r.rank == 3);
  CHECK(r.trivial == 3);
  CHECK(r.nontrivial == 0);
  CHECK(r.stresses == 0);
  CHECK(r.inf_rigid);
  CHECK(r.rigid == Verdict::Rigid);
}

TEST_CASE("rigidity: the collinear triangle is prestress stable (paper example 2.5)", "[engine]") {
  const RigidityReport r = analyze(makeFramework({{0, 0}, {1, 0}, {2, 0}}, {{1, 2}, {2, 3}, {1, 3}}));
  CHECK(r.rank == 2);
  CHECK(r.trivial == 3);
  CHECK(r.nontrivial == 1);
  CHECK(r.stresses == 1);
  CHECK_FALSE(r.inf_rigid);
  CHECK(r.prestress_stable == true);
  CHECK(r.second_order_rigid == true);
  CHECK(r.rigid == Verdict::Rigid);
  // The flex moves the middle vertex perpendicular to the line; with squared-length
  // constraints the stress is (2, 2, -1)/3 up to sign on the edges 12, 23, 13.
  const Matrix f = r.flex_basis;
  CHECK(std::abs(f(3, 0)) > 0.5);
  Vector w = r.stress_basis.col(0);
  w *= w[0] > 0 ? 1 : -1;
  CHECK((w - Vector((Vector(3) << 2, 2, -1).finished()) / 3).cwiseAbs().maxCoeff() < 1e-12);
}

TEST_CASE("rigidity: 3-prism has 1+3 flexes and one stress not prestress stable (notes 5.1)",
          "[engine]") {
  const Framework f = makeFramework({{0, 0}, {0, 1}, {s3 / 2, 0.5}, {1.05, 0}, {1.05, 1}, {1.05 + s3 / 2, 0.5}},
                           {{1, 2}, {1, 3}, {2, 3}, {4, 5}, {5, 6}, {4, 6}, {1, 4}, {2, 5}, {3, 6}});
  const RigidityReport r = analyze(f);
  CHECK(r.inf_flexes == 1 + 3);
  CHECK(r.trivial == 3);
  CHECK(r.stresses == 1);
  CHECK(r.prestress_stable == false);
  CHECK(r.second_order_rigid == false);
  CHECK(r.rigid == Verdict::Flexible);  // the parallel bars move: the tracked path leaves it
}

TEST_CASE("rigidity: notes 5.1 prestress-stable cases", "[engine]") {
  SECTION("rigid_prestress_stable") {
    const RigidityReport r = analyze(makeFramework({{0, 0}, {1, 0}, {2, 0}, {1, 1}, {1, 2}},
                                          {{1, 2}, {2, 3}, {3, 4}, {1, 4}, {1, 5}, {3, 5}, {4, 5}}, {1, 4}));
    CHECK_FALSE(r.inf_rigid);
    CHECK(r.prestress_stable == true);
    CHECK(r.second_order_rigid == true);
    CHECK(r.rigid == Verdict::Rigid);
  }
  SECTION("rigid_test") {
    const RigidityReport r =
        analyze(makeFramework({{0, 0}, {2, 0}, {1, 1}, {1. / 3, 2. / 3}, {2. / 3, 1. / 3}, {5. / 3, 2. / 3}, {4. / 3, 1. / 3}},
                     {{1, 2}, {1, 4}, {1, 5}, {4, 5}, {4, 3}, {5, 3}, {2, 6}, {2, 7}, {6, 7}, {3, 6}, {3, 7}}));
    CHECK(r.prestress_stable == true);
    CHECK(r.rigid == Verdict::Rigid);
  }
  SECTION("3Frustum") {
    const double c = std::cos(2 * M_PI / 3), s = std::sin(2 * M_PI / 3);
    const RigidityReport r =
        analyze(makeFramework({{c, s}, {c, -s}, {1, 0}, {2 * c, 2 * s}, {2 * c, -2 * s}, {2, 0}},
                     {{1, 2}, {2, 3}, {1, 3}, {4, 5}, {5, 6}, {4, 6}, {1, 4}, {2, 5}, {3, 6}}, {1, 2, 3}));
    CHECK(r.nontrivial == 1);
    CHECK(r.stresses == 1);
    CHECK(r.prestress_stable == true);
  }
  SECTION("completebipartite K_{2,4} is not prestress stable, and flexible") {
    const RigidityReport r = analyze(makeFramework({{0, 0}, {0, 1}, {1, -1}, {1, 0}, {1, 1}, {1, 2}},
                                          {{1, 3}, {1, 4}, {1, 5}, {1, 6}, {2, 3}, {2, 4}, {2, 5}, {2, 6}}));
    CHECK(r.nontrivial == 1);
    CHECK(r.stresses == 0);
    CHECK(r.prestress_stable == false);
    CHECK(r.rigid == Verdict::Flexible);
  }
}

TEST_CASE("rigidity: the double Watt has two flexes at its cusp and one stress", "[engine]") {
  const RigidityReport r =
      analyze(makeFramework({{0, 0}, {1, 0}, {2, 1}, {1, 2}, {3, 2}, {4, 2}, {5, 2}, {7, 2}, {6, 1}, {7, 0}, {8, 0}},
                   {{1, 2}, {2, 3}, {2, 4}, {3, 9}, {3, 4}, {3, 5}, {4, 5}, {5, 6}, {6, 7}, {7, 8}, {7, 9},
                    {8, 9}, {8, 10}, {9, 10}, {10, 11}},
                   {1, 6, 11}));
  CHECK(r.variables == 16);
  CHECK(r.equations == 15);
  CHECK(r.trivial == 0);
  CHECK(r.nontrivial == 2);
  CHECK(r.stresses == 1);
  CHECK(r.prestress_stable == false);
  CHECK(r.second_order_rigid == false);
  // A singular point: the chord path from J at the cusp cannot correct the stress's equation
  // to second order, and the motion tracker proves the motion.
  CHECK(r.rigid == Verdict::Flexible);
  CHECK_THAT(r.reason, Catch::Contains("a tracked path of 8 steps"));
}

TEST_CASE("rigidity: the motion check of a large braced grid with stresses corrects with the analysis's QR",
          "[engine]") {
  // Bolker and Crapo: the bipartite graph of square rows and columns joined by the braces has
  // three components (columns 1 and 2 alone), so the grid has two nontrivial flexes; each of
  // the 6 braces beyond a spanning tree adds one self-stress.
  const Framework f = bench::sparselyBraced(24, 6);
  const RigidityReport r = analyze(f);
  CHECK(r.method == "sparse QR");
  CHECK(r.nontrivial == 2);
  CHECK(r.stresses == 6);
  REQUIRE(r.rigid == Verdict::Flexible);
  // A regular point: the chord steps with J frozen at the start converge, the path stops once
  // it has moved far enough, and its largest residual is stated.
  CHECK_THAT(r.reason, Catch::Contains("a corrected path of 2 steps"));
  CHECK(r.motion_check_change >= 1e-3);
  // Without the check nothing decides it: the verdict is the check's.
  engine::RigidityOptions off;
  off.motion_check_steps = 0;
  CHECK(analyze(f, off).rigid == Verdict::Unknown);
}

TEST_CASE("rigidity: unit square flex basis matches the reference anchor (+ + + - - - - +)/sqrt(8)",
          "[engine]") {
  const RigidityReport r = analyze(makeFramework({{0, 0}, {1, 0}, {1, 1}, {0, 1}}, {{1, 2}, {2, 3}, {3, 4}, {1, 4}}));
  REQUIRE(r.nontrivial == 1);
  Vector expected(8);
  expected << 1, 1, 1, -1, -1, -1, -1, 1;
  expected /= std::sqrt(8.0);
  CHECK((r.flex_basis.col(0) - expected).cwiseAbs().maxCoeff() < 1e-12);
  CHECK(r.rigid == Verdict::Flexible);
}

TEST_CASE("rigidity: trivial flexes are the stabiliser of the pins", "[engine]") {
  SECTION("2D: 0, 1, 2 pins") {
    CHECK(analyze(makeFramework({{0, 0}, {1, 0}, {0, 1}}, {{1, 2}})).trivial == 3);
    CHECK(analyze(makeFramework({{0, 0}, {1, 0}, {0, 1}}, {{1, 2}}, {1})).trivial == 1);
    CHECK(analyze(makeFramework({{0, 0}, {1, 0}, {0, 1}}, {{1, 2}}, {1, 2})).trivial == 0);
  }
  SECTION("3D: 0, 1, 2, 3 pins; 3 collinear pins leave the axis rotation") {
    CHECK(analyze(makeFramework({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {2, 0, 0}}, {{1, 2}})).trivial == 6);
    CHECK(analyze(makeFramework({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {2, 0, 0}}, {{1, 2}}, {1})).trivial == 3);
    CHECK(analyze(makeFramework({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {2, 0, 0}}, {{1, 2}}, {1, 2})).trivial == 1);
    CHECK(analyze(makeFramework({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {2, 0, 0}}, {{1, 2}}, {1, 2, 5})).trivial == 1);
    CHECK(analyze(makeFramework({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {2, 0, 0}}, {{1, 2}}, {1, 2, 3})).trivial == 0);
  }
  SECTION("3D: free points on the axis of the pins do not move") {
    // Pins 1, 2 on the x-axis; the only free vertex is on the axis too: no trivial motion left.
    CHECK(analyze(makeFramework({{0, 0, 0}, {1, 0, 0}, {3, 0, 0}}, {{2, 3}}, {1, 2})).trivial == 0);
  }
  SECTION("collinear points: 3 trivial flexes in 2D, 5 in 3D") {
    CHECK(analyze(makeFramework({{0, 0}, {1, 0}, {3, 0}}, {{1, 2}, {2, 3}})).trivial == 3);
    CHECK(analyze(makeFramework({{0, 0, 0}, {1, 1, 1}, {3, 3, 3}}, {{1, 2}, {2, 3}})).trivial == 5);
  }
  SECTION("trivial flexes lie in the kernel") {
    const Framework f = makeFramework({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
                             {{1, 2}, {1, 3}, {1, 4}, {2, 3}, {2, 4}, {3, 4}}, {});
    const RigidityReport r = analyze(f);
    CHECK(r.trivial == 6);
    CHECK(r.inf_rigid);
    const Matrix JT = Matrix(f.system().jacobian(f.startCoordinates())) * r.trivial_basis;
    CHECK(JT.cwiseAbs().maxCoeff() < 1e-12);
  }
}

TEST_CASE("rigidity: a degenerate realization with two coincident vertices", "[engine]") {
  // The reference's square F2: vertex 4 sits on vertex 2 (no edge between them).
  const RigidityReport r = analyze(makeFramework({{0, 0}, {1, 0}, {1, 1}, {1, 0}}, {{1, 2}, {2, 3}, {3, 4}, {1, 4}}, {1, 2}));
  CHECK(r.variables == 4);
  CHECK(r.equations == 3);
  CHECK(r.rank == 3);
  CHECK(r.trivial == 0);
  CHECK(r.nontrivial == 1);
  CHECK(r.stresses == 0);
  CHECK(r.rigid == Verdict::Flexible);
}

TEST_CASE("rigidity: the canonical basis does not depend on the basis it starts from", "[engine]") {
  std::mt19937 rng(7);
  for (int k : {1, 2, 5}) {
    const Matrix A = Eigen::HouseholderQR<Matrix>(Matrix::Random(30, k)).householderQ() * Matrix::Identity(30, k);
    const Matrix R = Eigen::HouseholderQR<Matrix>(Matrix::Random(k, k)).householderQ() * Matrix::Identity(k, k);
    const Matrix c1 = engine::canonicalBasis(A), c2 = engine::canonicalBasis(A * R);
    CHECK((c1 - c2).cwiseAbs().maxCoeff() < 1e-12);
    CHECK((c1.transpose() * c1 - Matrix::Identity(k, k)).cwiseAbs().maxCoeff() < 1e-12);
    // Same span as A.
    CHECK((c1 - A * (A.transpose() * c1)).cwiseAbs().maxCoeff() < 1e-12);
  }
}

TEST_CASE("rigidity: sparse QR and dense SVD agree", "[engine]") {
  for (int braced : {1, 2, 0}) {
    const Framework f = grid(9, 8, braced);
    engine::RigidityOptions dense, sparse;
    sparse.dense_limit = 0;
    const RigidityReport a = analyze(f, dense), b = analyze(f, sparse);
    INFO("braced every " << braced);
    CHECK(a.method == "dense SVD");
    CHECK(b.method == "sparse QR");
    CHECK(a.rank == b.rank);
    CHECK(a.trivial == b.trivial);
    CHECK(a.nontrivial == b.nontrivial);
    CHECK(a.stresses == b.stresses);
    REQUIRE(b.flex_basis_computed);
    REQUIRE(a.flex_basis.cols() == b.flex_basis.cols());
    if (a.flex_basis.cols() > 0) CHECK((a.flex_basis - b.flex_basis).cwiseAbs().maxCoeff() < 1e-8);
    REQUIRE(b.stress_basis_computed);
    REQUIRE(a.stress_basis.cols() == b.stress_basis.cols());
    if (a.stress_basis.cols() > 0)
      CHECK((a.stress_basis - b.stress_basis).cwiseAbs().maxCoeff() < 1e-8);
  }
  // Expected counts: a fully triangulated grid is infinitesimally rigid; bracing every other
  // row leaves one shear per unbraced row.
  CHECK(analyze(grid(9, 8, 1)).nontrivial == 0);
  CHECK(analyze(grid(9, 8, 2)).nontrivial == 3);
}

TEST_CASE("rigidity: the analysis is deterministic", "[engine]") {
  const Framework f = grid(6, 5, 2);
  const RigidityReport a = analyze(f), b = analyze(f);
  CHECK(a.flex_basis == b.flex_basis);
  CHECK(a.stress_basis == b.stress_basis);
}
