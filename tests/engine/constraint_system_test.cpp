#include <catch2/catch.hpp>

#include "engine/systems/framework.h"
#include "engine/terms.h"
#include "../test_common.h"

using namespace flexure;
using engine::Framework;
using engine::Matrix;
using engine::Vector;

namespace {

// A random framework: n random points in R^d, each pair an edge with probability p.
Framework randomFramework(std::mt19937& rng, int d, int n, double p, std::vector<int> pinned) {
  Matrix pts(d, n);
  for (int i = 0; i < n; ++i) pts.col(i) = test::randomVector(rng, d, 2.0);
  std::bernoulli_distribution coin(p);
  std::vector<Framework::Edge> edges;
  for (int a = 0; a < n; ++a)
    for (int b = a + 1; b < n; ++b)
      if (coin(rng)) edges.push_back({a, b});
  return Framework(pts, edges, pinned);
}

}  // namespace

TEST_CASE("constraint system: framework Jacobians match finite differences", "[engine]") {
  std::mt19937 rng(12345);
  for (int d : {2, 3})
    for (const std::vector<int>& pins : {std::vector<int>{}, {0}, {1, 4}, {0, 2, 5}}) {
      const Framework f = randomFramework(rng, d, 8, 0.5, pins);
      const auto& sys = f.system();
      for (int trial = 0; trial < 3; ++trial) {
        const Vector x = test::randomVector(rng, sys.numVariables(), 1.5);
        INFO("d=" << d << " pins=" << pins.size() << " trial " << trial);
        test::requireJacobianMatchesFiniteDifferences(sys, x);
        test::requireSecondDerivativeMatchesFiniteDifferences(
            sys, x, test::randomVector(rng, sys.numVariables()), test::randomVector(rng, sys.numVariables()));
      }
    }
}

TEST_CASE("constraint system: residuals vanish at the realization and scale as squared lengths",
          "[engine]") {
  Matrix p(2, 3);
  p << 0, 3, 0,
       0, 0, 4;
  const Framework f(p, {{0, 1}, {1, 2}, {0, 2}}, {});
  const Vector x = f.startCoordinates();
  REQUIRE(f.system().residuals(x).cwiseAbs().maxCoeff() == 0.0);
  Vector y = x;
  y[2] += 1.0;  // vertex 2 moves from x=3 to x=4
  const Vector r = f.system().residuals(y);
  CHECK(r[0] == Approx(16.0 - 9.0));
  CHECK(r[1] == Approx(32.0 - 25.0));
  CHECK(r[2] == Approx(0.0));
}

TEST_CASE("constraint system: pinned vertices leave the variables and pinned-only edges are dropped",
          "[engine]") {
  Matrix p(2, 4);
  p << 0, 1, 1, 0,
       0, 0, 1, 1;
  const Framework f(p, {{0, 1}, {1, 2}, {2, 3}, {0, 3}}, {0, 1});
  const auto& sys = f.system();
  CHECK(sys.numVariables() == 4);
  CHECK(sys.numEquations() == 3);
  CHECK(sys.numPinned() == 2);
  CHECK(sys.variableIndex(0, 0) == -1);
  CHECK(sys.variableIndex(2, 0) == 0);
  CHECK(sys.variableIndex(3, 1) == 3);
  const Vector x = f.startCoordinates();
  CHECK(sys.positions(x).isApprox(p));
  CHECK(sys.equationLabels(1) == std::vector<std::string>{"edge 2-3", "edge 3-4", "edge 1-4"});
  // The Jacobian pattern has 2 entries for the edges touching one pinned vertex, 4 otherwise.
  CHECK(sys.jacobianPattern().nonZeros() == 2 + 4 + 2);
  // Residuals of every term, the dropped one included, at full positions.
  Matrix q = p;
  q(0, 1) = 2.0;  // stretch the pinned-only edge
  CHECK(sys.maxResidualAllTerms(q) == Approx(3.0));
}

TEST_CASE("constraint system: misuse throws", "[engine]") {
  engine::ConstraintSystem sys(2, 3, 3);
  CHECK_THROWS_AS(sys.pin(3), std::invalid_argument);
  CHECK_THROWS_AS(sys.addTerm(std::make_unique<engine::SquaredDistanceTerm>(0, 0, 1.0)),
                  std::invalid_argument);
  CHECK_THROWS_AS(sys.addTerm(std::make_unique<engine::SquaredDistanceTerm>(0, 5, 1.0)),
                  std::invalid_argument);
  CHECK_THROWS_AS(sys.finalize(Matrix::Zero(3, 3)), std::invalid_argument);
}

TEST_CASE("constraint system: blocks of any kind can be pinned and a scalar block is one variable", "[engine]") {
  // Two vertices in 3D, a direction block n (|n| = 2) and a scalar block s: the bar's squared
  // length equals s^2 (UnitNormTerm on s reads s^2 + 0 + 0, its unused coordinates constants).
  engine::ConstraintSystem sys(3, 2, 4);
  sys.setBlockKind(2, engine::BlockKind::Direction);
  sys.setBlockKind(3, engine::BlockKind::Scalar);
  CHECK(sys.blockKind(0) == engine::BlockKind::Point);
  CHECK(sys.blockKind(3) == engine::BlockKind::Scalar);
  CHECK_THROWS_AS(sys.setBlockKind(1, engine::BlockKind::Scalar), std::invalid_argument);
  CHECK_THROWS_AS(sys.setBlockKind(2, engine::BlockKind::Point), std::invalid_argument);
  sys.addTerm(std::make_unique<engine::SquaredDistanceTerm>(0, 1, 9.0));
  sys.addTerm(std::make_unique<engine::UnitNormTerm>(2, 0, 2.0));
  sys.addTerm(std::make_unique<engine::UnitNormTerm>(3, 1, 3.0));
  sys.pin(0);
  sys.pin(2);  // the direction block: pinning an auxiliary block is allowed
  CHECK_THROWS_AS(sys.pin(4), std::invalid_argument);
  Matrix p(3, 4);
  p << 0, 3, 2, 3,  //
      0, 0, 0, 0,   //
      0, 0, 0, 0;
  sys.finalize(p);
  CHECK(sys.numPinned() == 1);  // vertices only
  CHECK(sys.freeCoordinatesOf(0) == 0);
  CHECK(sys.freeCoordinatesOf(1) == 3);
  CHECK(sys.freeCoordinatesOf(2) == 0);
  CHECK(sys.freeCoordinatesOf(3) == 1);
  CHECK(sys.numVariables() == 3 + 1);
  CHECK(sys.variableIndex(3, 0) == 3);
  CHECK(sys.variableIndex(3, 1) == -1);
  // The direction's term has only pinned blocks: inactive. The scalar's reads s^2 - 3^2.
  CHECK(sys.numEquations() == 2);
  Vector x = sys.freeCoordinates(p);
  REQUIRE(x.size() == 4);
  CHECK(x[3] == 3.0);
  x[3] = 4.0;
  const Vector r = sys.residuals(x);
  CHECK(r[0] == 0.0);
  CHECK(r[1] == 16.0 - 9.0);
  const Matrix back = sys.positions(x);
  CHECK(back(0, 3) == 4.0);
  CHECK(back(1, 3) == 0.0);  // the scalar's unused coordinates stay constants
  test::requireJacobianMatchesFiniteDifferences(sys, x);
}
