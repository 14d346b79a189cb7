#include <catch2/catch.hpp>

#include "engine/corrector.h"
#include "engine/random.h"
#include "engine/systems/framework.h"
#include "../test_common.h"

using namespace flexure;
using engine::Framework;
using engine::Matrix;
using engine::Vector;

TEST_CASE("factorization: dense SVD and sparse QR give the same minimum-norm solutions", "[engine]") {
  std::mt19937 rng(3);
  // A braced grid has stresses (dependent rows) and flexes (a kernel).
  Matrix p(2, 20);
  std::vector<Framework::Edge> edges;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 5; ++c) {
      const int i = r * 5 + c;
      p.col(i) << c + 0.1 * std::sin(i), r + 0.1 * std::cos(3 * i);
      if (c + 1 < 5) edges.push_back({i, i + 1});
      if (r + 1 < 4) edges.push_back({i, i + 5});
      if (c + 1 < 5 && r + 1 < 4) edges.push_back({i, i + 6});
      if (c > 0 && r + 1 < 4 && r % 2 == 0) edges.push_back({i, i + 4});
    }
  const Framework f(p, edges, {});
  const engine::SparseMatrix J = f.system().jacobian(f.startCoordinates());
  engine::FactorizationOptions dense_options, sparse_options;
  dense_options.dense_limit = 100000;
  sparse_options.dense_limit = 0;
  const engine::JacobianFactorization dense(J, dense_options), sparse(J, sparse_options);
  REQUIRE(dense.dense());
  REQUIRE_FALSE(sparse.dense());
  CHECK(dense.rank() == sparse.rank());
  CHECK(dense.rows() - dense.rank() > 0);  // stresses
  // A consistent right-hand side b = J z: both give the same minimum-norm solution.
  const Vector z = test::randomVector(rng, static_cast<int>(J.cols()));
  const Vector b = J * z;
  const Vector xd = dense.solveMinNorm(b), xs = sparse.solveMinNorm(b);
  CHECK((J * xd - b).norm() < 1e-10 * b.norm());
  CHECK((xd - xs).norm() < 1e-9 * xd.norm());
  // Minimum norm: orthogonal to the kernel.
  CHECK((dense.kernel().transpose() * xd).norm() < 1e-10 * xd.norm());
}

TEST_CASE("corrector: Gauss-Newton brings a perturbed framework back onto its constraints", "[engine]") {
  Matrix p(2, 4);
  p << 0, 1, 1, 0,
       0, 0, 1, 1;
  const Framework f(p, {{0, 1}, {1, 2}, {2, 3}, {0, 3}, {0, 2}}, {0});
  engine::Random rnd(5);
  Vector x = f.startCoordinates();
  for (int i = 0; i < x.size(); ++i) x[i] += 0.05 * rnd.gaussian();
  engine::CorrectorOptions opt;
  const engine::CorrectorResult r = engine::correct(f.system(), x, opt);
  REQUIRE(r.status == engine::CorrectorStatus::Converged);
  CHECK(r.residual <= 1e-13 * f.system().residualScale());
  CHECK(r.iterations <= 8);
  CHECK((r.x - x).norm() < 0.2);
}

TEST_CASE("corrector: randomization squares up a system with a stress", "[engine]") {
  // K4 in the plane with vertices 1 and 2 pinned: the edge between the pins drops out,
  // leaving 5 equations of rank 4 on the 4 free coordinates, so one stress.
  Matrix p(2, 4);
  p << 0, 2, 1, 1,
       0, 0, 2, 0.7;
  const Framework f(p, {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}}, {0, 1});
  REQUIRE(f.system().numEquations() == 5);
  engine::Random rnd(9);
  Matrix lambda(4, 5);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 5; ++j) lambda(i, j) = rnd.gaussian();
  Vector x = f.startCoordinates();
  x[0] += 0.03;
  x[3] -= 0.02;
  const engine::CorrectorResult r = engine::correct(f.system(), x, {}, engine::EquationReduction{lambda, {}, {}});
  REQUIRE(r.status == engine::CorrectorStatus::Converged);
  CHECK((r.x - f.startCoordinates()).norm() < 1e-9);  // the framework is rigid: back to the start
  // A randomization of the wrong width is refused, not read out of bounds.
  CHECK_THROWS_AS(engine::correct(f.system(), x, {}, engine::EquationReduction{Matrix::Ones(5, 6), {}, {}}),
                  std::invalid_argument);
}

TEST_CASE("random: the seeded Gaussian stream is reproducible", "[engine]") {
  engine::Random a(42), b(42), c(43);
  double sa = 0, sc = 0, s2 = 0;
  for (int i = 0; i < 20000; ++i) {
    const double x = a.gaussian();
    CHECK(x == b.gaussian());
    sa += x;
    s2 += x * x;
    sc += c.gaussian();
  }
  CHECK(std::abs(sa / 20000) < 0.03);
  CHECK(s2 / 20000 == Approx(1.0).epsilon(0.05));
  CHECK(sa != sc);
}

TEST_CASE("corrector: small (complete orthogonal decomposition) and large (sparse QR) steps agree", "[engine]") {
  // Both are minimum-norm Gauss-Newton steps: from the same start, the same iterates, so the
  // same point of the solution curve (one flex: the chain 0-3-4-2 between pins).
  Matrix p(2, 5);
  p << 0, 1, 2, 0.3, 1.6,
       0, 0.1, 0, 1, 1.2;
  const Framework f(p, {{0, 1}, {1, 2}, {0, 3}, {3, 4}, {2, 4}}, {0, 2});
  engine::Random rnd(11);
  Vector x = f.startCoordinates();
  for (int i = 0; i < x.size(); ++i) x[i] += 0.02 * rnd.gaussian();
  engine::CorrectorOptions small, large;
  large.factorization.dense_limit = 0;
  const engine::CorrectorResult a = engine::correct(f.system(), x, small), b = engine::correct(f.system(), x, large);
  REQUIRE(a.status == engine::CorrectorStatus::Converged);
  REQUIRE(b.status == engine::CorrectorStatus::Converged);
  CHECK(std::abs(a.iterations - b.iterations) <= 1);  // the last one may straddle the tolerance
  CHECK((a.x - b.x).norm() < 1e-10);
  CHECK((a.x - x).norm() > 1e-3);
}

TEST_CASE("corrector: on a sphere, the point at that distance on the side the guess points to", "[engine]") {
  // A four-bar (two pinned vertices): its configurations form a curve; the sphere of radius r
  // around a point of it meets the curve twice nearby, once on each side.
  Matrix p(2, 4);
  p << 0, 3, 2.6, 0.4,
       0, 0, 1.5, 1.2;
  const Framework f(p, {{0, 1}, {1, 2}, {2, 3}, {3, 0}}, {0, 1});
  const Vector x0 = f.startCoordinates();
  const engine::JacobianFactorization fac(f.system().jacobian(x0), {});
  const Vector t = fac.kernel().col(0);
  const double r = 0.2;
  const engine::Sphere sphere{x0, r};
  Vector ends[2];
  for (int side = 0; side < 2; ++side) {
    // A guess off the curve and off the sphere: the corrector meets both.
    const Vector guess = x0 + (side ? -1.3 : 1.3) * r * t + 0.01 * Vector::Ones(x0.size());
    const engine::CorrectorResult c = engine::correct(f.system(), guess, {}, {}, nullptr, &sphere);
    REQUIRE(c.status == engine::CorrectorStatus::Converged);
    CHECK(std::abs((c.x - x0).norm() - r) < 1e-12);
    CHECK(f.system().residuals(c.x).cwiseAbs().maxCoeff() < 1e-12);
    CHECK((c.x - x0).dot(side ? -t : t) > 0.9 * r);
    ends[side] = c.x;
  }
  CHECK((ends[0] - ends[1]).norm() > 1.9 * r);
  // The sphere's equation (|x - c|^2 - r^2) / (2r) and its gradient (x - c) / r, by differences.
  const Vector y = ends[0] + 0.05 * Vector::Ones(x0.size());
  const auto g = [&](const Vector& z) { return ((z - x0).squaredNorm() - r * r) / (2 * r); };
  for (int i = 0; i < y.size(); ++i) {
    Vector e = Vector::Zero(y.size());
    e[i] = 1e-6;
    CHECK(std::abs((g(y + e) - g(y - e)) / 2e-6 - (y - x0)[i] / r) < 1e-8);
  }
  // With gauge coordinates (the sparse reduction) a sphere is refused, not ignored.
  engine::EquationReduction gauge;
  gauge.gauge = {0};
  CHECK_THROWS_AS(engine::correct(f.system(), x0, {}, gauge, nullptr, &sphere), std::invalid_argument);
}
