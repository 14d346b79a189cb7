#include <Eigen/Dense>
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <random>

#include "bench/grids.h"
#include "engine/corrector.h"
#include "engine/factorization.h"
#include "engine/motion_tracker.h"
#include "engine/resources.h"
#include "engine/rigidity.h"
#include "engine/sparse_qr.h"
#include "../test_common.h"

using namespace flexure;
using engine::FactorizationOptions;
using engine::JacobianFactorization;
using engine::Matrix;
using engine::Vector;

namespace {

FactorizationOptions sparseOnly() {
  FactorizationOptions o;
  o.dense_limit = 0;
  return o;
}

// The braced grid of bench/grids.h with every unbraced strip of squares sheared by its own
// angle: an exact configuration, on which the kernel keeps its dimension (3 trivial + one
// shear per unbraced strip).
Vector shearedGrid(int n, double angle) {
  Vector x(2 * n * n);
  double dx = 0, dy = 0;
  for (int r = 0; r < n; ++r) {
    if (r > 0) {
      const bool braced = (r - 1) % 2 == 0;  // the strip between rows r-1 and r
      const double t = braced ? 0.0 : angle * (1.0 + 0.1 * r);
      dx += std::sin(t);
      dy += std::cos(t);
    }
    for (int c = 0; c < n; ++c) {
      x[2 * (r * n + c)] = c + dx;
      x[2 * (r * n + c) + 1] = dy;
    }
  }
  return x;
}

// One gauge coordinate per tangent direction, as the tracker chooses them: the first pivots of a
// column-pivoted QR of K^T.
std::vector<int> gaugeOf(const Matrix& K) {
  const Eigen::ColPivHouseholderQR<Matrix> qr(K.transpose());
  std::vector<int> gauge;
  for (Eigen::Index i = 0; i < K.cols(); ++i) gauge.push_back(qr.colsPermutation().indices()[i]);
  return gauge;
}

// The 30x30 braced grid sheared at 0.05, its factorization there, and the gauge reduction the
// tracker would use: the corrector tests' common start.
struct ShearedGridCase {
  static constexpr int n = 30;
  engine::Framework f = bench::grid(n, n, 2);
  Vector x = shearedGrid(n, 0.05);
  JacobianFactorization fac{f.system().jacobian(x), sparseOnly()};
  engine::EquationReduction red;
  ShearedGridCase() { red.gauge = gaugeOf(fac.kernel()); }
};

// 600 bidiagonal rows e_i + 0.5 e_(i+1) on 700 columns (independent, well conditioned), and
// one more: row 3 + row 7 + eps e_650, whose remaining norm after the others is exactly eps.
// Its rank threshold (rank_tolerance times the largest row norm) is 1e-9 sqrt(2.5).
engine::SparseMatrix bidiagonalWithDependentRow(double eps) {
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < 600; ++i) {
    t.emplace_back(i, i, 1.0);
    t.emplace_back(i, i + 1, 0.5);
  }
  for (int i : {3, 7}) {
    t.emplace_back(600, i, 1.0);
    t.emplace_back(600, i + 1, 0.5);
  }
  t.emplace_back(600, 650, eps);
  engine::SparseMatrix A(601, 700);
  A.setFromTriplets(t.begin(), t.end());
  return A;
}

}  // namespace

TEST_CASE("factorization: sparse QR and dense SVD agree on rank and kernel", "[engine]") {
  std::mt19937 rng(7);
  // A random 2D framework with fewer and more edges than a rigid one would need, plus one collinear
  // (rank-deficient) triple.
  const int n = 40;
  Matrix p = Matrix::Random(2, n);
  p.col(2) = 0.5 * (p.col(0) + p.col(1));
  std::vector<engine::Framework::Edge> edges{{0, 1}, {1, 2}, {0, 2}};
  for (int v = 3; v < n; ++v) {
    edges.push_back({v, v - 1});
    if (v % 4 != 0) edges.push_back({v, v - 2});  // every fourth vertex hangs by one bar
    if (v % 3 == 0) edges.push_back({v, v - 3});
  }
  const engine::Framework f(p, edges, {});
  const engine::SparseMatrix J = f.system().jacobian(f.startCoordinates());
  const JacobianFactorization dense(J, FactorizationOptions{});
  const JacobianFactorization sparse(J, sparseOnly());
  REQUIRE(dense.dense());
  REQUIRE_FALSE(sparse.dense());
  REQUIRE(sparse.rank() == dense.rank());
  const Matrix Kd = dense.kernel(), Ks = sparse.kernel();
  REQUIRE(Ks.cols() == Kd.cols());
  // Same subspace: the projection of one basis onto the other keeps its norm.
  REQUIRE((Ks - Kd * (Kd.transpose() * Ks)).norm() < 1e-8);
  // Minimum-norm solutions agree on a consistent right-hand side.
  const Vector b = J * test::randomVector(rng, f.system().numVariables());
  REQUIRE((dense.solveMinNorm(b) - sparse.solveMinNorm(b)).norm() < 1e-8);
  // The seminormal equations give the same minimum-norm solution without the QR's Q.
  REQUIRE((sparse.solveSeminormal(b) - sparse.solveMinNorm(b)).norm() < 1e-8);
  // And the same projection onto the kernel (sparse: by them, twice), which J annihilates.
  const Vector v = test::randomVector(rng, f.system().numVariables());
  const Vector pd = dense.projectOntoKernel(v), ps = sparse.projectOntoKernel(v);
  REQUIRE((pd - ps).norm() < 1e-10 * v.norm());
  REQUIRE((J * ps).norm() < 1e-13 * v.norm());
  REQUIRE((dense.solveSeminormal(b) - dense.solveMinNorm(b)).norm() == 0.0);
}

TEST_CASE("factorization: sparse rank is exact on a sheared braced grid", "[engine]") {
  // Regression: with SuiteSparseQR's default (COLAMD) order Heath's rank detection kept 10 of
  // the 22 kernel directions of this 40 x 40 grid as "independent".
  const int n = 40;
  const engine::Framework f = bench::grid(n, n, 2);
  const Vector x = shearedGrid(n, 0.1);
  REQUIRE(f.system().residuals(x).cwiseAbs().maxCoeff() < 1e-12);
  const JacobianFactorization fac(f.system().jacobian(x), sparseOnly());
  const int unbraced = (n - 1) / 2;
  REQUIRE(fac.cols() - fac.rank() == 3 + unbraced);
  const Matrix K = fac.kernel();
  REQUIRE(fac.sigmaLargestDropped() < 1e-10);
  REQUIRE((K.transpose() * K - Matrix::Identity(K.cols(), K.cols())).norm() < 1e-10);
}

using test::permuted;

TEST_CASE("factorization: the sparse rank is decided at the largest gap, in every order of rows and columns",
          "[engine]") {
  const auto matrix = bidiagonalWithDependentRow;
  const double threshold = 1e-9 * std::sqrt(2 * 1.25);  // rank_tolerance times the largest row norm
  std::mt19937 rng(5);
  // eps 1.5 x the threshold: kept by the threshold alone, but 1e8 below the other values
  // (about 1) and only 1.5e5 above the floor: dependent. 300 x: 1e6 below the others and 3e7
  // above the floor: independent.
  for (const auto& [eps, rank] : {std::pair<double, int>{1.5 * threshold, 600}, {300 * threshold, 601},
                                  {1e-3, 601}, {0.5 * threshold, 600}}) {
    INFO("eps " << eps);
    const engine::SparseMatrix A = matrix(eps);
    const JacobianFactorization F(A, sparseOnly());
    CHECK(F.rank() == rank);
    CHECK(F.rankGap() >= JacobianFactorization::kClearGap);
    for (int trial = 0; trial < 4; ++trial) CHECK(JacobianFactorization(permuted(A, rng), sparseOnly()).rank() == rank);
    // The factorization of the rank decided is the one kept: its kernel is J's.
    const Matrix K = F.kernel();
    CHECK(K.cols() == 700 - rank);
    CHECK((A * K).norm() <= 10 * eps);
  }
}

TEST_CASE("factorization: braced grids, plain and sheared, get one rank in every order of edges and coordinates",
          "[engine]") {
  std::mt19937 rng(11);
  for (const int n : {40, 100}) {
    const engine::Framework f = bench::grid(n, n, 2);
    for (const bool sheared : {false, true}) {
      INFO(n << " x " << n << (sheared ? ", sheared" : ""));
      const engine::SparseMatrix J = f.system().jacobian(sheared ? shearedGrid(n, 0.1) : f.startCoordinates());
      const JacobianFactorization F(J, sparseOnly());
      CHECK(F.cols() - F.rank() == 3 + (n - 1) / 2);  // trivial motions and one shear per unbraced strip
      for (int trial = 0; trial < 3; ++trial) CHECK(JacobianFactorization(permuted(J, rng), sparseOnly()).rank() == F.rank());
    }
  }
}

TEST_CASE("factorization: the kept equations' singular values confirm the rank where the |R_ii| mislead",
          "[engine]") {
  // The 224 x 224 braced grid, every unbraced strip sheared by its own angle in [-0.02, 0.02]
  // and the whole turned: an exact configuration with 3 + 111 flexes. Heath's |R_ii| keep one
  // dependent set of equations here at a gap of 1.05e4 (the kernel came out 113); R11 then has
  // a singular value at rounding level, 1e7 below the next, and the confirmation finds it.
  const int n = 224;
  const engine::Framework f = bench::grid(n, n, 2);
  std::mt19937 rng(5);
  const auto uniform = [&](double a) { return a * (2.0 * rng() / 4294967296.0 - 1.0); };
  Vector x(2 * n * n);
  double dx = 0, dy = 0;
  for (int r = 0; r < n; ++r) {
    if (r > 0) {
      const double t = (r - 1) % 2 == 0 ? 0.0 : uniform(0.02);
      dx += std::sin(t);
      dy += std::cos(t);
    }
    for (int c = 0; c < n; ++c) x.segment<2>(2 * (r * n + c)) << c + dx, dy;
  }
  const double turn = uniform(0.06);
  for (int i = 0; i < n * n; ++i) {
    const Eigen::Vector2d p = x.segment<2>(2 * i);
    x.segment<2>(2 * i) << std::cos(turn) * p.x() - std::sin(turn) * p.y() + 0.3, std::sin(turn) * p.x() + std::cos(turn) * p.y() - 0.7;
  }
  REQUIRE(f.system().residuals(x).cwiseAbs().maxCoeff() < 1e-12);
  const engine::SparseMatrix J = f.system().jacobian(x);
  const JacobianFactorization fac(J, sparseOnly());
  REQUIRE(fac.cols() - fac.rank() == 3 + (n - 1) / 2);
  CHECK(fac.rankGap() >= JacobianFactorization::kClearGap);
  // The kernel, with the direction found: orthonormal flexes.
  const Matrix K = fac.kernel();
  CHECK((K.transpose() * K - Matrix::Identity(K.cols(), K.cols())).cwiseAbs().maxCoeff() < 1e-10);
  CHECK(fac.sigmaLargestDropped() < 1e-8);
  // The solves keep out of the dependent set: for b = J v, the minimum-norm solution is v's
  // row-space part (it reproduces b and has no kernel part), by both routes.
  const Vector v = test::randomVector(rng, static_cast<int>(x.size()));
  const Vector b = J * v;
  const Vector s = fac.solveMinNorm(b);
  CHECK((J * s - b).norm() <= 1e-8 * b.norm());
  CHECK((K.transpose() * s).norm() <= 1e-8 * s.norm());
  CHECK((fac.solveSeminormal(b) - s).norm() <= 1e-6 * s.norm());
  const Vector k = fac.projectOntoKernel(v);
  CHECK((k - K * (K.transpose() * v)).norm() <= 1e-8 * v.norm());
  // A load in the row space is balanced by equation weights: J^T y = w.
  const Vector w = J.transpose() * test::randomVector(rng, static_cast<int>(J.rows()));
  CHECK((J.transpose() * fac.solveTransposed(w) - w).norm() <= 1e-8 * w.norm());
  // And the count does not depend on the order of the equations and coordinates.
  for (int trial = 0; trial < 2; ++trial) CHECK(JacobianFactorization(permuted(J, rng), sparseOnly()).rank() == fac.rank());
  // Nor with the equations sorted along the configuration's geometric order (its vertices by
  // their turned positions), the analysis's way: the same rank, and a clear gap.
  FactorizationOptions geometric = sparseOnly();
  geometric.variable_order = std::make_shared<const std::vector<int>>(f.system().geometricOrder(f.system().positions(x)));
  const JacobianFactorization ordered(J, geometric);
  CHECK(ordered.rank() == fac.rank());
  CHECK(ordered.rankGap() >= JacobianFactorization::kClearGap);
  CHECK((ordered.kernel() - K * (K.transpose() * ordered.kernel())).cwiseAbs().maxCoeff() < 1e-8);  // the same kernel
}

TEST_CASE("corrector: gauge-bordered steps converge on a large redundant system", "[engine]") {
  const ShearedGridCase c;
  const engine::Framework& f = c.f;
  const Vector& x = c.x;
  const engine::EquationReduction& red = c.red;
  std::mt19937 rng(3);
  const Vector start = x + 1e-3 * test::randomVector(rng, static_cast<int>(x.size()));
  engine::CorrectorOptions opt;
  opt.factorization.dense_limit = 0;
  const engine::CorrectorResult r = engine::correct(f.system(), start, opt, red);
  REQUIRE(r.status == engine::CorrectorStatus::Converged);
  REQUIRE(r.residual <= 1e-13 * f.system().residualScale());
  REQUIRE(r.iterations <= 6);
  // The gauge coordinates (nearly) keep their predicted values while the others move by ~1e-3:
  // the correction is transversal to the tangent space.
  for (int i : red.gauge) REQUIRE(std::abs(r.x[i] - start[i]) < 1e-5);
  REQUIRE((r.x - start).norm() > 1e-2);
}

TEST_CASE("corrector: kept normal equations serve the next correction as chord steps", "[engine]") {
  ShearedGridCase c;
  const engine::Framework& f = c.f;
  const Vector& x = c.x;
  engine::EquationReduction& red = c.red;
  red.normal_equations = engine::EquationReduction::keptNormalEquations();
  std::mt19937 rng(5);
  engine::CorrectorOptions opt;
  const double tol = opt.residual_tolerance * f.system().residualScale();
  Vector at = x;
  // Three corrections in a row from guesses 1e-4 off the last corrected point: each converges
  // on all equations and (nearly: to a tenth of the offset) keeps its gauge coordinates, whether
  // its steps used the factorization left by the previous one or a new one.
  for (int k = 0; k < 3; ++k) {
    const Vector start = at + 1e-4 * test::randomVector(rng, static_cast<int>(x.size()));
    const engine::CorrectorResult r = engine::correct(f.system(), start, opt, red);
    INFO("correction " << k);
    REQUIRE(r.status == engine::CorrectorStatus::Converged);
    REQUIRE(f.system().residuals(r.x).cwiseAbs().maxCoeff() <= tol);
    for (int i : red.gauge) REQUIRE(std::abs(r.x[i] - start[i]) < 1e-5);
    at = r.x;
  }
}

TEST_CASE("corrector: damped normal equations correct a large redundant system along the normal, without a gauge", "[engine]") {
  const ShearedGridCase c;
  const engine::Framework& f = c.f;
  std::mt19937 rng(13);
  const Vector start = c.x + 1e-3 * test::randomVector(rng, static_cast<int>(c.x.size()));
  engine::EquationReduction damped;
  damped.damping = 1e-11;
  engine::CorrectorOptions opt;
  // To convergence, on all equations (the stresses' too), with no kernel or gauge chosen.
  const engine::CorrectorResult r = engine::correct(f.system(), start, opt, damped);
  REQUIRE(r.status == engine::CorrectorStatus::Converged);
  REQUIRE(f.system().residuals(r.x).cwiseAbs().maxCoeff() <= opt.residual_tolerance * f.system().residualScale());
  REQUIRE(r.iterations <= 6);
  // From a predictor's guess (a tangent step of 1e-2 and noise of 1e-6), the damped steps are
  // the minimum-norm (normal-flow) ones: the correction is orthogonal to the tangent space, to
  // first order in the step (0.38 % of it along the tangent space without the noise, 0.48 % with
  // it). The damping also keeps out the small singular values that the noise creates off the
  // constraints: with 1e-12 that part is 4 %, with 1e-13 21 %. Plain minimum-norm Gauss-Newton
  // (a sparse QR per iteration) fails from here: its rank decisions keep those directions, and
  // its steps run away.
  const Vector tangent = c.fac.projectOntoKernel(test::randomVector(rng, static_cast<int>(c.x.size()))).normalized();
  const Vector guess = c.x + 1e-2 * tangent + 1e-6 * test::randomVector(rng, static_cast<int>(c.x.size()));
  const engine::CorrectorResult normal = engine::correct(f.system(), guess, opt, damped);
  REQUIRE(normal.status == engine::CorrectorStatus::Converged);
  CHECK(c.fac.projectOntoKernel(normal.x - guess).norm() <= 1e-2 * (normal.x - guess).norm());
  // Kept across corrections: chord steps from the last factorization while they converge fast
  // (their right-hand side formed with the factored Jacobian: with the current one, its part
  // on the old kernel came back 1 / damping larger). Three corrections in a row, from guesses a
  // tangent step of 1e-3 plus 1e-5 of noise away, each converge on all equations.
  damped.normal_equations = engine::EquationReduction::keptNormalEquations();
  Vector at = r.x;
  for (int k = 0; k < 3; ++k) {
    const Vector guess = at + 1e-3 * tangent + 1e-5 * test::randomVector(rng, static_cast<int>(at.size()));
    const engine::CorrectorResult rk = engine::correct(f.system(), guess, opt, damped);
    INFO("correction " << k);
    REQUIRE(rk.status == engine::CorrectorStatus::Converged);
    REQUIRE(f.system().residuals(rk.x).cwiseAbs().maxCoeff() <= opt.residual_tolerance * f.system().residualScale());
    at = rk.x;
  }
}

TEST_CASE("corrector: chord steps with a nearby point's QR converge and keep the tangent coordinates", "[engine]") {
  const int n = 30;
  const engine::Framework f = bench::grid(n, n, 2);
  const Vector x = shearedGrid(n, 0.05);
  const JacobianFactorization fac(f.system().jacobian(x), sparseOnly());
  std::mt19937 rng(11);
  const Vector start = x + 1e-3 * test::randomVector(rng, static_cast<int>(x.size()));
  const double scale = f.system().residualScale();
  const engine::CorrectorResult r = engine::correctChord(f.system(), start, fac, 1e-13 * scale, 1e-10 * scale, 40);
  REQUIRE(r.status == engine::CorrectorStatus::Converged);
  REQUIRE(f.system().residuals(r.x).cwiseAbs().maxCoeff() == r.residual);
  REQUIRE(r.residual <= 1e-10 * scale);
  // Every step lies in the row space of J at x: the start's kernel part is kept.
  REQUIRE((fac.projectOntoKernel(r.x - start)).norm() < 1e-9);
  REQUIRE((r.x - start).norm() > 1e-2);
}

TEST_CASE("tracker: a large sparse braced grid tracks with exact residuals and even spacing", "[engine]") {
  const int n = 24;
  const engine::Framework f = bench::grid(n, n, 2);
  const Vector x0 = f.startCoordinates();
  engine::RigidityOptions ro;
  ro.dense_limit = 0;
  const engine::RigidityReport rep = engine::analyzeRigidity(f, x0, ro);
  REQUIRE(rep.nontrivial == (n - 1) / 2);
  engine::TrackerOptions opt;
  opt.steps = 12;
  opt.step_size = 0.05;
  opt.factorization.dense_limit = 0;
  opt.corrector.factorization.dense_limit = 0;
  const engine::DeformationPath r = engine::trackMotion(f, x0, rep.flex_basis * rep.auto_flex, opt);
  REQUIRE(r.summary.status == engine::TrackStatus::Success);
  REQUIRE(r.samples.size() == 13);
  for (const Vector& s : r.samples) REQUIRE(f.system().residuals(s).cwiseAbs().maxCoeff() <= 1e-10 * 2);
  for (size_t i = 1; i < r.samples.size(); ++i)
    REQUIRE((r.samples[i] - r.samples[i - 1]).norm() == Approx(0.05).epsilon(0.05));
}

TEST_CASE("tracker: the sparse path (projection transport, damped steps) follows the dense one", "[engine]") {
  // A 12 x 12 grid braced every other row: 5 nontrivial flexes, 288 coordinates. Tracked dense
  // (the paper's Procrustes transport, randomized steps) and sparse (the old tangent projected
  // onto the new flex space, the damped normal equations' steps): the transports
  // agree to second order in the step and both correctors land on the constraints, so the
  // paths stay close while their samples stay a step apart.
  const engine::Framework f = bench::grid(12, 12, 2);
  const Vector x0 = f.startCoordinates();
  const engine::RigidityReport rep = engine::analyzeRigidity(f, x0);
  REQUIRE(rep.nontrivial == 5);
  engine::TrackerOptions dense, sparse;
  dense.steps = sparse.steps = 20;
  dense.step_size = sparse.step_size = 0.05;
  dense.factorization.dense_limit = dense.corrector.factorization.dense_limit = 1000;
  sparse.factorization.dense_limit = sparse.corrector.factorization.dense_limit = 0;
  const Vector dir = rep.flex_basis * rep.auto_flex;
  const engine::DeformationPath a = engine::trackMotion(f, x0, dir, dense), b = engine::trackMotion(f, x0, dir, sparse);
  REQUIRE(a.summary.status == engine::TrackStatus::Success);
  REQUIRE(b.summary.status == engine::TrackStatus::Success);
  REQUIRE(a.samples.size() == b.samples.size());
  for (size_t i = 1; i < b.samples.size(); ++i) {
    INFO("sample " << i);
    CHECK(f.system().residuals(b.samples[i]).cwiseAbs().maxCoeff() <= 1e-12 * f.system().residualScale());
    CHECK((b.samples[i] - b.samples[i - 1]).norm() == Approx(0.05).epsilon(0.05));
    CHECK((a.samples[i] - b.samples[i]).norm() <= 1e-3 * i * 0.05);
  }
}

TEST_CASE("factorization: the nontrivial flexes from the Gram matrix span what the SVD's do", "[engine]") {
  // A braced grid's kernel (3 trivial motions and the unbraced strips' shears), its trivial
  // flexes, and both ways of taking the nontrivial part: the same space, orthonormal.
  const engine::Framework f = bench::grid(12, 12, 2);
  const engine::Vector x = f.startCoordinates();
  const JacobianFactorization fac(f.system().jacobian(x), FactorizationOptions{});
  const Matrix K = fac.kernel();
  const Matrix T = engine::trivialFlexes(f, x, 1e-9);
  const Matrix a = engine::nontrivialPart(K, T), b = engine::nontrivialPartFast(K, T);
  REQUIRE(a.cols() == 5);  // n / 2 - 1 shears, as the 60x60 grid has 29
  REQUIRE(b.cols() == a.cols());
  // With no trivial flexes (every symmetry pinned) the kernel is the nontrivial part.
  CHECK(engine::nontrivialPartFast(K, Matrix(K.rows(), 0)) == K);
  CHECK((b.transpose() * b - Matrix::Identity(b.cols(), b.cols())).cwiseAbs().maxCoeff() < 1e-12);
  CHECK((a * (a.transpose() * b) - b).cwiseAbs().maxCoeff() < 1e-10);  // span(b) inside span(a)
  CHECK((T.transpose() * b).cwiseAbs().maxCoeff() < 1e-10);              // and orthogonal to the trivial ones
  CHECK((f.system().jacobian(x) * b).cwiseAbs().maxCoeff() < 1e-9);     // flexes
  // A kernel with nothing nontrivial gives no columns.
  CHECK(engine::nontrivialPartFast(T, T).cols() == 0);
}

TEST_CASE("factorization: an expected rank settles an unclear first factorization that agrees with it", "[engine]") {
  // The bidiagonal rows of the largest-gap test and one dependent row whose remaining norm is
  // 1.5 x the threshold: the first factorization keeps it (an unclear gap).
  const engine::SparseMatrix A = bidiagonalWithDependentRow(1.5e-9 * std::sqrt(2 * 1.25));
  const double threshold = 1e-9 * std::sqrt(2 * 1.25);  // rank_tolerance times the largest row norm
  FactorizationOptions o = sparseOnly();
  // Without an expected rank: the search, which refactors at the middle of the largest gap.
  const JacobianFactorization plain(A, o);
  CHECK(plain.rank() == 600);
  CHECK(plain.threshold() != Approx(threshold));
  // Expecting 600: the first factorization's confirmation (the kept equations' smallest singular
  // values) sets the dependent row aside, that gives 600, and the first factorization is kept
  // (its threshold is the default one) with its kernel.
  o.expected_rank = 600;
  const JacobianFactorization kept(A, o);
  CHECK(kept.rank() == 600);
  CHECK(kept.threshold() == Approx(threshold));
  const Matrix K = kept.kernel();
  CHECK(K.cols() == 100);
  CHECK((A * K).norm() <= 1e-8);
  CHECK((K.transpose() * K - Matrix::Identity(100, 100)).cwiseAbs().maxCoeff() < 1e-12);
  // Expecting what the first factorization does not confirm: the search decides, as without.
  for (const int wrong : {599, 601}) {
    o.expected_rank = wrong;
    const JacobianFactorization searched(A, o);
    CHECK(searched.rank() == 600);
    CHECK(searched.threshold() == Approx(plain.threshold()));
  }
}

TEST_CASE("factorization: a sparse QR that cannot fit is refused from the matrix's counts with the estimate") {
  // Issue 42: K_1000 in the plane (an 83 kB graph6 line) needed more than 9.5 GB in SuiteSparseQR
  // and crashed (SIGSEGV: its status was never checked; CHOLMOD printed on standard output).
  // The ordering's pattern alone has sum over variables of (equations at the variable)^2
  // entries: a column of A that every row touches is counted once per row pair.
  const int rows = 3, cols = 1000000;
  std::vector<Eigen::Triplet<double>> t;
  for (int c = 0; c < cols; ++c)
    for (int r = 0; r < rows; ++r) t.emplace_back(r, c, 1.0 + r + c);
  engine::SparseMatrix A(rows, cols);
  A.setFromTriplets(t.begin(), t.end());
  A.makeCompressed();
  Eigen::SPQR<engine::SparseMatrix> qr;
  // 3 rows of 10^6 entries: 3 * 10^12 * 16 bytes = 48 TB.
  CHECK_THROWS_WITH(engine::factorSparseQR(qr, A), Catch::Contains("needs about 48 TB of memory, more than the"));
  CHECK_THROWS_AS(engine::factorSparseQR(qr, A), engine::ResourceError);
  // A small one factors as before.
  engine::SparseMatrix B = A.leftCols(40);
  B.makeCompressed();
  CHECK_NOTHROW(engine::factorSparseQR(qr, B));
  CHECK(qr.rank() == 2);
}

TEST_CASE("resources: memory is told in units and refused above what the process can have") {
  CHECK(engine::bytesText(512) == "512 bytes");
  CHECK(engine::bytesText(9.5e9) == "9.5 GB");
  CHECK(engine::bytesText(3.2e10) == "32 GB");
  CHECK(engine::availableMemory() > 0);
  CHECK_NOTHROW(engine::requireMemory("a little", 1e3));
  CHECK_THROWS_WITH(engine::requireMemory("the work", 1e30), Catch::StartsWith("the work needs about"));
}

TEST_CASE("factorization: values_only gives the dense rank evidence of the full SVD, and no vectors") {
  std::mt19937_64 gen(45);
  std::normal_distribution<double> normal;
  // A 14 x 18 rigidity-like matrix of rank 11: a random product of ranks.
  Matrix A = Matrix::NullaryExpr(14, 11, [&] { return normal(gen); }) * Matrix::NullaryExpr(11, 18, [&] { return normal(gen); });
  const engine::SparseMatrix J = A.sparseView();
  FactorizationOptions values;
  values.values_only = true;
  const JacobianFactorization full(J, FactorizationOptions{}), only(J, values);
  CHECK(full.rank() == 11);
  CHECK(only.rank() == full.rank());
  CHECK(only.sigmaMax() == Approx(full.sigmaMax()).epsilon(1e-13));
  CHECK(only.sigmaSmallestKept() == Approx(full.sigmaSmallestKept()).epsilon(1e-12));
  CHECK(only.rankGap() > JacobianFactorization::kClearGap);
  CHECK_THROWS_AS(only.kernel(), std::logic_error);
  CHECK_THROWS_AS(only.cokernel(), std::logic_error);
  CHECK_THROWS_AS(only.solveMinNorm(Vector::Ones(14)), std::logic_error);
}
