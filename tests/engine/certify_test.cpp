// Interval certificates (engine/interval/): outward-rounded arithmetic encloses the exact
// results (checked in GMP rationals), the verified eigenvalue bound is below the true smallest
// eigenvalue (computed here by Eigen), and the start certificate proves infinitesimal rigidity
// with a bound below the rigidity matrix's true smallest singular value on the complement of the
// trivial flexes, proves flexibility at a regular point, and proves nothing at a special position.
#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <Eigen/SparseCore>
#include <unsupported/Eigen/MatrixFunctions>
#include <optional>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>

#include "engine/exact/rational.h"
#include "engine/interval/certify.h"
#include "engine/interval/interval.h"
#include "engine/interval/verified.h"
#include "engine/flex_space.h"
#include "engine/rigidity.h"
#include "engine/systems/framework.h"

using namespace flexure::engine;

namespace {

bool encloses(const Interval& x, const Rational& q) { return Rational(x.lo) <= q && q <= Rational(x.hi); }

Framework framework(const std::vector<std::vector<double>>& pts, const std::vector<Framework::Edge>& edges,
                    const std::vector<int>& pinned = {}) {
  Matrix p(static_cast<int>(pts[0].size()), static_cast<int>(pts.size()));
  for (size_t i = 0; i < pts.size(); ++i)
    for (size_t k = 0; k < pts[i].size(); ++k) p(static_cast<int>(k), static_cast<int>(i)) = pts[i][k];
  return Framework(p, edges, pinned);
}

// The smallest singular value of J on the orthogonal complement of the trivial flexes, in double
// (an SVD of J times an orthonormal basis of that complement).
double sigmaOnComplement(const Model& m) {
  const Vector x = m.startCoordinates();
  const Matrix J = Matrix(m.system().jacobian(x));
  const Matrix T = trivialFlexes(m, x, 1e-10);
  const Matrix P = Matrix::Identity(J.cols(), J.cols()) - T * T.transpose();
  Eigen::JacobiSVD<Matrix> svd(P, Eigen::ComputeFullU);
  const Matrix C = svd.matrixU().leftCols(J.cols() - T.cols());
  return Eigen::JacobiSVD<Matrix>(J * C).singularValues().minCoeff();
}

}  // namespace

TEST_CASE("interval arithmetic encloses the exact results of its operations") {
  const double a = 0.1, b = 0.2, c = 3.0;
  CHECK(encloses(Interval(a) + Interval(b), Rational(a) + Rational(b)));
  CHECK(encloses(Interval(a) - Interval(c), Rational(a) - Rational(c)));
  CHECK(encloses(Interval(a) * Interval(b), Rational(a) * Rational(b)));
  CHECK(encloses(Interval(a) / Interval(c), Rational(a) / Rational(c)));
  const Interval w(-1.0, 2.0), v(3.0, 4.0);
  const Interval p = w * v;
  CHECK(p.lo <= -4.0);
  CHECK(p.hi >= 8.0);
  CHECK_THROWS_AS(Interval(1.0) / w, std::domain_error);
  CHECK(sqrt(Interval(2.0)).contains(std::sqrt(2.0)));
}

TEST_CASE("interval rounding steps to the neighbouring double, as std::nextafter does") {
  const double inf = std::numeric_limits<double>::infinity(), big = std::numeric_limits<double>::max(),
               tiny = std::numeric_limits<double>::denorm_min(), least = std::numeric_limits<double>::min();
  std::vector<double> xs = {0.0, -0.0, tiny, -tiny, least, -least, 1.0, -1.0, big, -big, inf, -inf, 0.1, -3e200};
  std::mt19937_64 rng(44);  // fixed seed: the same 2,000 bit patterns every run
  std::uniform_int_distribution<std::uint64_t> any;
  for (int i = 0; i < 2000; ++i) {
    const std::uint64_t bits = any(rng);
    double x;
    std::memcpy(&x, &bits, sizeof x);
    if (!std::isnan(x)) xs.push_back(x);
  }
  for (const double x : xs) {
    INFO("x = " << x);
    const double up = std::nextafter(x, inf), down = std::nextafter(x, -inf);
    CHECK((Interval::up(x) == up && std::signbit(Interval::up(x)) == std::signbit(up)));
    CHECK((Interval::down(x) == down && std::signbit(Interval::down(x)) == std::signbit(down)));
  }
  CHECK(std::isnan(Interval::up(std::numeric_limits<double>::quiet_NaN())));
}

TEST_CASE("interval products by the signs enclose every product of their points") {
  // Every sign case (both bounds of one sign, or straddling 0, on either side), against the
  // products of the bounds in rationals: the result holds the four, and its bounds are within
  // one rounding of the true extremes.
  std::mt19937_64 rng(7);  // fixed seed
  std::uniform_real_distribution<double> u(-3, 3);
  for (int i = 0; i < 3000; ++i) {
    double a0 = u(rng), a1 = u(rng), b0 = u(rng), b1 = u(rng);
    if (i % 5 == 0) a0 = std::abs(a0), a1 = std::abs(a1);
    if (i % 7 == 0) b0 = -std::abs(b0), b1 = -std::abs(b1);
    if (i % 11 == 0) a1 = a0;
    const Interval a(std::min(a0, a1), std::max(a0, a1)), b(std::min(b0, b1), std::max(b0, b1));
    const Interval p = a * b;
    INFO("[" << a.lo << ", " << a.hi << "] * [" << b.lo << ", " << b.hi << "]");
    Rational lo, hi;
    bool first = true;
    for (const double x : {a.lo, a.hi})
      for (const double y : {b.lo, b.hi}) {
        const Rational q = Rational(x) * Rational(y);
        CHECK(encloses(p, q));
        if (first || q < lo) lo = q;
        if (first || q > hi) hi = q;
        first = false;
      }
    CHECK(Rational(p.lo) <= lo);
    CHECK(Rational(p.hi) >= hi);
    CHECK(Rational(p.lo) >= Rational(Interval::down(Interval::down(lo.get_d()))));
    CHECK(Rational(p.hi) <= Rational(Interval::up(Interval::up(hi.get_d()))));
  }
}

TEST_CASE("the verified eigenvalue bound is below the smallest eigenvalue and refuses singular matrices") {
  verified::IntervalMatrix A(3);
  const double M[3][3] = {{4, 1, 0}, {1, 3, 1}, {0, 1, 2}};
  Matrix D(3, 3);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) A(i, j) = Interval(M[i][j]), D(i, j) = M[i][j];
  const double lambda = Eigen::SelfAdjointEigenSolver<Matrix>(D).eigenvalues()(0);
  const auto bound = verified::smallestEigenvalueLowerBound(A);
  REQUIRE(bound);
  CHECK(*bound <= lambda);
  CHECK(*bound >= 0.4 * lambda);
  // Rank one: no positive bound.
  verified::IntervalMatrix S(2);
  S(0, 0) = S(0, 1) = S(1, 0) = S(1, 1) = Interval(1.0);
  CHECK_FALSE(verified::smallestEigenvalueLowerBound(S));
  // Radii count: [1 - 2, 1 + 2] on the diagonal holds indefinite matrices.
  verified::IntervalMatrix W(1);
  W(0, 0) = Interval(-1.0, 3.0);
  CHECK_FALSE(verified::smallestEigenvalueLowerBound(W));
}

TEST_CASE("the sparse verified singular value bound is below the true one, and refuses singular matrices") {
  // Random sparse square matrices (a banded pattern with random extra entries), the true smallest
  // singular value from a dense Jacobi SVD: the bound is at most it and not far below it.
  std::mt19937_64 rng(45);  // fixed seed
  std::normal_distribution<double> normal;
  std::uniform_int_distribution<int> pick(0, 59);
  for (int trial = 0; trial < 6; ++trial) {
    const int n = 60;
    std::vector<Eigen::Triplet<double>> t;
    for (int i = 0; i < n; ++i) {
      t.emplace_back(i, i, 2.0 + normal(rng));
      if (i + 1 < n) t.emplace_back(i, i + 1, normal(rng));
      t.emplace_back(pick(rng), pick(rng), 0.3 * normal(rng));
    }
    SparseMatrix A(n, n);
    A.setFromTriplets(t.begin(), t.end());
    const double truth = Eigen::JacobiSVD<Matrix>(Matrix(A)).singularValues().minCoeff();
    INFO("trial " << trial << ": sigma_min " << truth);
    const std::optional<double> bound = verified::smallestSingularValueLowerBound(A);
    if (truth > 1e-6) {
      REQUIRE(bound);
      CHECK(*bound <= truth);
      CHECK(*bound >= 0.2 * truth);
      // From a neighbour's estimate (no inverse iteration), the same guarantee.
      double estimate = 1.3 * truth * truth;
      const std::optional<double> hinted = verified::smallestSingularValueLowerBound(A, &estimate);
      REQUIRE(hinted);
      CHECK(*hinted <= truth);
    }
  }
  // Singular: a zero column.
  SparseMatrix S(3, 3);
  S.insert(0, 0) = 1;
  S.insert(1, 0) = 2;
  S.insert(2, 2) = 1;
  CHECK_FALSE(verified::smallestSingularValueLowerBound(S));
}

TEST_CASE("certify: infinitesimal rigidity with a singular value bound below the true one") {
  const Framework tri = framework({{0, 0}, {1, 0}, {0.3, 0.9}}, {{0, 1}, {1, 2}, {0, 2}});
  const Framework braced = framework({{0, 0}, {1, 0}, {1.2, 1}, {0, 1.1}}, {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {0, 2}}, {0});
  const Framework prism = framework({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.1, 0.1, 1}, {1.2, 0, 1.1}, {0, 0.9, 1}},
                                    {{0, 1}, {1, 2}, {0, 2}, {3, 4}, {4, 5}, {3, 5}, {0, 3}, {1, 4}, {2, 5}, {0, 4}, {1, 5}, {2, 3}});
  for (const Framework* f : {&tri, &braced, &prism}) {
    const RigidityReport rep = analyzeRigidity(*f, f->startCoordinates());
    REQUIRE(rep.inf_rigid);
    const certify::StartCertificate c = certify::certifyStart(*f, f->startCoordinates(), rep);
    INFO(c.reason);
    CHECK(c.inf_rigid == true);
    CHECK(c.flexible == false);
    const double sigma = sigmaOnComplement(*f);
    CHECK(c.sigma_lower_bound <= sigma * (1 + 1e-12));
    CHECK(c.sigma_lower_bound >= 0.05 * sigma);
  }
}

TEST_CASE("certify: flexible at a regular point, nothing at a special position") {
  const Framework square = framework({{0, 0}, {1, 0}, {1, 1}, {0, 1}}, {{0, 1}, {1, 2}, {2, 3}, {3, 0}});
  const RigidityReport rs = analyzeRigidity(square, square.startCoordinates());
  const certify::StartCertificate s = certify::certifyStart(square, square.startCoordinates(), rs);
  CHECK(s.flexible == true);
  CHECK(s.inf_rigid == false);
  // K_{3,3} on the unit circle (Bolker and Roth: a flex, and a stress) given in floating point:
  // a rank deficiency is not provable there, and nothing is claimed.
  const double c3 = 0.6, s3 = 0.8;
  const Framework k33 = framework({{1, 0}, {c3, s3}, {0, 1}, {-s3, c3}, {-1, 0}, {c3, -s3}},
                                  {{0, 1}, {0, 3}, {0, 5}, {2, 1}, {2, 3}, {2, 5}, {4, 1}, {4, 3}, {4, 5}});
  const RigidityReport rk = analyzeRigidity(k33, k33.startCoordinates());
  const certify::StartCertificate k = certify::certifyStart(k33, k33.startCoordinates(), rk);
  CHECK_FALSE(k.inf_rigid.has_value());
  CHECK_FALSE(k.flexible.has_value());
  CHECK(k.reason.find("--exact") != std::string::npos);
}

TEST_CASE("symmetry groups: the finite maps of each family match its generators") {
  // For each family, at seeded random points: every Lie algebra element's velocities
  // (groupVelocities) lie in the span of the model-independent generators (engine/model.h), the
  // velocities together span all of them, and the map exp(e X) moves the points by e times the
  // velocity to first order (a finite difference, 1e-6).
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  struct Case {
    SymmetryGroup::Family family;
    int d;
  };
  for (const Case& k : {Case{SymmetryGroup::Family::Euclidean, 2}, Case{SymmetryGroup::Family::Euclidean, 3},
                        Case{SymmetryGroup::Family::Similarity, 2}, Case{SymmetryGroup::Family::EquiAffine, 2},
                        Case{SymmetryGroup::Family::EquiAffine, 3}, Case{SymmetryGroup::Family::Moebius, 3}}) {
    const int n = 6;
    Matrix P(k.d, n);
    for (int i = 0; i < n; ++i)
      for (int r = 0; r < k.d; ++r) P(r, i) = normal(rng) + (k.family == SymmetryGroup::Family::Moebius && r == 0 ? 2.0 : 0.0);
    SymmetryGroup g;
    g.family = k.family;
    g.num_points = n;
    const Matrix generators = k.family == SymmetryGroup::Family::Euclidean    ? euclideanGenerators(P, n)
                              : k.family == SymmetryGroup::Family::Similarity ? similarityGenerators(P, n)
                              : k.family == SymmetryGroup::Family::EquiAffine ? equiAffineGenerators(P, n)
                                                                                : moebiusGenerators(P, n);
    const std::vector<Matrix> algebra = lieAlgebra(g, k.d);
    REQUIRE(static_cast<long>(algebra.size()) == generators.cols());
    Matrix V(generators.rows(), static_cast<long>(algebra.size()));
    for (size_t a = 0; a < algebra.size(); ++a) {
      const Matrix v = groupVelocities(g, algebra[a], P);
      V.col(static_cast<long>(a)) = Eigen::Map<const Vector>(v.data(), v.size());
      // exp(e X) to first order.
      const double e = 1e-6;
      const Matrix moved = applyGroupElement(g, Matrix((e * algebra[a]).exp()), P);
      CHECK(((moved - P) / e - v).cwiseAbs().maxCoeff() < 1e-4);
    }
    Matrix both(V.rows(), V.cols() + generators.cols());
    both << V, generators;
    const auto rank = [](const Matrix& m) {
      return static_cast<long>(Eigen::ColPivHouseholderQR<Matrix>(m).setThreshold(1e-10).rank());
    };
    INFO("family " << static_cast<int>(k.family) << ", d = " << k.d);
    CHECK(rank(V) == generators.cols());
    CHECK(rank(both) == generators.cols());
  }
}
