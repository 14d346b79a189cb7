// The exact mode (engine/exact/): rationals read exactly, and the exact analysis of frameworks
// whose answers are checked by hand here (the counts from the rank of small rigidity matrices
// and the literature: Bolker and Roth for K_{3,3} on a conic; the collinear triangle's stress).
#include <catch2/catch.hpp>

#include <flint/flint.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <set>

#include "engine/exact/exact_linear_algebra.h"
#include "engine/exact/exact_rigidity.h"
#include "engine/exact/number_memory.h"
#include "engine/interrupt.h"
#include "engine/resources.h"
#include "engine/systems/framework.h"
#include "engine/systems/polytope.h"

using namespace flexure::engine;
using flexure::engine::exact::analyzeExact;
using flexure::engine::exact::ExactAnalysis;

namespace {

// Points given as rationals: the model is built from their doubles, the analysis from them.
struct RationalFramework {
  RationalMatrix points;
  std::unique_ptr<Framework> model;
};

RationalFramework framework(const std::vector<std::vector<Rational>>& pts, const std::vector<Framework::Edge>& edges,
                            const std::vector<int>& pinned = {}) {
  RationalFramework f;
  const int d = static_cast<int>(pts[0].size()), n = static_cast<int>(pts.size());
  f.points = RationalMatrix(d, n);
  Matrix p(d, n);
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < d; ++k) {
      f.points(k, i) = pts[static_cast<size_t>(i)][static_cast<size_t>(k)];
      p(k, i) = f.points(k, i).get_d();
    }
  f.model = std::make_unique<Framework>(p, edges, pinned);
  return f;
}

ExactAnalysis analyze(const RationalFramework& f) { return analyzeExact(*f.model, f.points, nullptr); }

Rational q(const char* s) { return Rational(s); }

}  // namespace

TEST_CASE("decimal numerals are read as exact decimal fractions") {
  Rational v;
  REQUIRE(parseDecimal("0.1", v));
  CHECK(v == Rational(1, 10));
  REQUIRE(parseDecimal("-2.5E+2", v));
  CHECK(v == -250);
  REQUIRE(parseDecimal("1_000.5e-3", v));
  CHECK(v == Rational(2001, 2000));
  REQUIRE(parseDecimal("7", v));
  CHECK(v == 7);
  for (const char* bad : {"", "abc", "1.", ".5", "1e", "1__0", "inf", "nan", "1.5x", "1e999999"}) {
    INFO(bad);
    CHECK_FALSE(parseDecimal(bad, v));
  }
  CHECK(shortestDecimal(0.1) == Rational(1, 10));
  CHECK(shortestDecimal(-1e-5) == Rational(-1, 100000));
  CHECK(shortestDecimal(1.0 / 3) == Rational(3333333333333333, mpz_class("10000000000000000")));
}

TEST_CASE("decimal numerals: any exponent spelling, sizes bounded (issue 62)") {
  Rational v;
  // Leading zeros of the exponent mean nothing (TOML allows them), nor underscores in it.
  for (const char* same : {"1e-22", "1e-022", "1e-000000022", "1E-0000000000000000000022", "1e-0_22", "0.1e-21",
                           "100e-24", "0.000_1e-18"}) {
    INFO(same);
    REQUIRE(readDecimal(same, v) == DecimalRead::ok);
    CHECK(v == Rational(1, mpz_class("10000000000000000000000")));
  }
  REQUIRE(readDecimal("1E+0000001", v) == DecimalRead::ok);
  CHECK(v == 10);
  REQUIRE(readDecimal("-5e-0", v) == DecimalRead::ok);
  CHECK(v == -5);
  // Zero is zero whatever its exponent.
  REQUIRE(readDecimal("0e999999999999999999999", v) == DecimalRead::ok);
  CHECK(v == 0);
  // 5^k / 10^k = 1/2^k: lowest terms without a gcd.
  REQUIRE(readDecimal("0.0625", v) == DecimalRead::ok);
  CHECK(v == Rational(1, 16));
  REQUIRE(readDecimal("12.5e-1", v) == DecimalRead::ok);
  CHECK(v == Rational(5, 4));
  // Within the limit: 1e-100000 (332,193 bits); beyond it: refused, never rounded to 0 or a double.
  REQUIRE(readDecimal("1e-100000", v) == DecimalRead::ok);
  CHECK(rationalBits(v) < kMaxRationalBits);
  for (const char* big : {"1e-200000", "1e200000", "1e-99999999999999999999", "7e+0000000000000000000000000000500000",
                          "-3.5e-130000"}) {
    INFO(big);
    Rational untouched(3);
    CHECK(readDecimal(big, untouched) == DecimalRead::too_large);
    CHECK(untouched == 3);
    CHECK_FALSE(parseDecimal(big, untouched));
  }
  CHECK(readDecimal("1e", v) == DecimalRead::not_numeral);
  CHECK(readDecimal("1e_1", v) == DecimalRead::not_numeral);
}

TEST_CASE("the nearest double of a rational of any size") {
  CHECK(nearestDouble(Rational(1, 10)) == 0.1);
  CHECK(nearestDouble(Rational(-1, 3)) == -1.0 / 3);
  mpz_class p10;
  mpz_ui_pow_ui(p10.get_mpz_t(), 10, 1000);
  CHECK(nearestDouble(Rational(p10 + 1, p10)) == 1.0);
  CHECK(nearestDouble(Rational(p10, 7)) == HUGE_VAL);
  CHECK(nearestDouble(Rational(7, p10)) == 0.0);
  // Ties and the sticky bit: 1 + 2^-53 + 2^-200 rounds up, 1 + 2^-53 to even (1).
  mpz_class two200;
  mpz_ui_pow_ui(two200.get_mpz_t(), 2, 200);
  CHECK(nearestDouble(Rational(two200 + (two200 >> 53) + 1, two200)) == std::nextafter(1.0, 2.0));
  CHECK(nearestDouble(Rational(two200 + (two200 >> 53), two200)) == 1.0);
}

TEST_CASE("exact analysis: a triangle is infinitesimally rigid and a quadrilateral flexes") {
  const ExactAnalysis t = analyze(framework({{0, 0}, {1, 0}, {0, 1}}, {{0, 1}, {1, 2}, {0, 2}}));
  CHECK(t.rank == 3);
  CHECK(t.trivial == 3);
  CHECK(t.nontrivial == 0);
  CHECK(t.inf_rigid);
  CHECK(t.flexible == false);
  const ExactAnalysis s = analyze(framework({{0, 0}, {1, 0}, {1, 1}, {0, 1}}, {{0, 1}, {1, 2}, {2, 3}, {3, 0}}));
  CHECK(s.rank == 4);
  CHECK(s.nontrivial == 1);
  CHECK(s.stresses == 0);
  CHECK(s.flexible == true);  // a regular point with a nontrivial flex
  CHECK(s.prestress_stable == false);
}

TEST_CASE("exact analysis: pins remove the trivial flexes they fix") {
  // One pinned vertex of a triangle leaves the rotation about it; two leave nothing.
  const ExactAnalysis one = analyze(framework({{0, 0}, {1, 0}, {0, 1}}, {{0, 1}, {1, 2}, {0, 2}}, {0}));
  CHECK(one.variables == 4);
  CHECK(one.trivial == 1);
  CHECK(one.nontrivial == 0);
  const ExactAnalysis two = analyze(framework({{0, 0}, {1, 0}, {0, 1}}, {{0, 1}, {1, 2}, {0, 2}}, {0, 1}));
  CHECK(two.variables == 2);
  CHECK(two.trivial == 0);
  CHECK(two.rank == 2);
}

TEST_CASE("exact analysis: the collinear triangle is prestress stable") {
  // Points 0, 1, 3 on a line. Equilibrium at x = 1: w12 * 1 + w23 * (-2) = 0; at x = 0:
  // -w12 - 3 w13 = 0: the stress (w12, w23, w13) = (2, 1, -2/3). The flex moves the middle
  // point across the line; its energy w12 + w23 = 3 > 0.
  const ExactAnalysis a = analyze(framework({{0, 0}, {1, 0}, {3, 0}}, {{0, 1}, {1, 2}, {0, 2}}));
  CHECK(a.rank == 2);
  CHECK(a.trivial == 3);
  CHECK(a.nontrivial == 1);
  CHECK(a.stresses == 1);
  CHECK(a.prestress_stable == true);
  REQUIRE(a.blocking_stress.rows == 3);
  // The blocking stress is a positive multiple of (2, 1, -2/3).
  const Rational scale = a.blocking_stress(1, 0);
  CHECK(scale > 0);
  CHECK(a.blocking_stress(0, 0) == 2 * scale);
  CHECK(a.blocking_stress(2, 0) == Rational(-2, 3) * scale);
}

TEST_CASE("exact analysis: K33 on a conic is infinitesimally flexible and one point off it is not") {
  // Bolker and Roth: K_{3,3} in the plane has a nontrivial infinitesimal flex exactly when its
  // six points lie on a conic. Rational points of the unit circle, the colour classes alternating.
  const std::vector<std::vector<Rational>> on = {{1, 0},          {q("3/5"), q("4/5")},   {0, 1},
                                                 {q("-5/13"), q("12/13")}, {-1, 0}, {q("8/17"), q("-15/17")}};
  const std::vector<Framework::Edge> k33 = {{0, 1}, {0, 3}, {0, 5}, {2, 1}, {2, 3}, {2, 5}, {4, 1}, {4, 3}, {4, 5}};
  const ExactAnalysis a = analyze(framework(on, k33));
  CHECK(a.rank == 8);
  CHECK(a.nontrivial == 1);
  CHECK(a.stresses == 1);
  CHECK_FALSE(a.inf_rigid);
  // Moved off the circle by 10^-12: exactly rigid, though the change is below floating point's
  // rank threshold.
  std::vector<std::vector<Rational>> off = on;
  off[5][1] += Rational(1, mpz_class("1000000000000"));
  const ExactAnalysis b = analyze(framework(off, k33));
  CHECK(b.rank == 9);
  CHECK(b.inf_rigid);
  CHECK(b.stresses == 0);
}

TEST_CASE("exact analysis: the start must be an exact solution and the unknowns the vertices") {
  RationalFramework f = framework({{0, 0}, {1, 0}, {0, 1}}, {{0, 1}, {1, 2}, {0, 2}});
  // Lengths that the points do not have.
  Matrix p(2, 3);
  p << 0, 1, 0, 0, 0, 1;
  const Framework wrong(p, {{0, 1}, {1, 2}, {0, 2}}, {}, {1.0, 1.5, 1.0});
  CHECK_THROWS_AS(analyzeExact(wrong, f.points, nullptr), exact::Refusal);
  // Rationals that are not the model's start.
  RationalMatrix moved = f.points;
  moved(0, 1) = Rational(2);
  CHECK_THROWS_AS(analyzeExact(*f.model, moved, nullptr), exact::Refusal);
  // A polytope's facet normals are unknowns besides the vertices.
  Matrix cube(3, 8);
  for (int i = 0; i < 8; ++i) cube.col(i) << (i & 1), (i >> 1 & 1), (i >> 2 & 1);
  const Polytope poly(cube, {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}}, {});
  RationalMatrix cq(3, 8);
  for (int i = 0; i < 8; ++i)
    for (int k = 0; k < 3; ++k) cq(k, i) = static_cast<long>(cube(k, i));
  CHECK_THROWS_AS(analyzeExact(poly, cq, nullptr), exact::Refusal);
}

TEST_CASE("exact linear algebra: rank, null space, definiteness") {
  RationalMatrix A(2, 3);
  A(0, 0) = Rational(1, 2), A(0, 1) = 1, A(0, 2) = Rational(3, 2);
  A(1, 0) = 1, A(1, 1) = 2, A(1, 2) = 3;  // twice row 0
  CHECK(exact::rank(A) == 1);
  const RationalMatrix K = exact::nullSpace(A);
  CHECK(K.cols == 2);
  const RationalMatrix AK = exact::multiply(A, K);
  for (const Rational& v : AK.data) CHECK(v == 0);
  RationalMatrix Q(2, 2);
  Q(0, 0) = 2, Q(0, 1) = Q(1, 0) = 1, Q(1, 1) = 1;
  CHECK(exact::positiveDefinite(Q));
  Q(1, 1) = Rational(1, 2);  // determinant 0
  CHECK_FALSE(exact::positiveDefinite(Q));
}

// Issue 62: the exact work estimated and bounded before it starts, interruptible, and GMP's and
// FLINT's allocation failures turned into std::bad_alloc.
namespace {

// n vertices at k/10^4 and 2n random bars: flexible with stresses, so that the exact rank needs
// FLINT's dense elimination.
RationalFramework randomFramework(int n, unsigned seed) {
  unsigned s = seed;
  auto next = [&s] { return s = s * 1103515245u + 12345u, (s >> 8) % 10000u; };
  std::vector<std::vector<Rational>> pts;
  for (int i = 0; i < n; ++i) {
    Rational x(static_cast<long>(next()), 10000), y(static_cast<long>(next()), 10000);
    x.canonicalize(), y.canonicalize();
    pts.push_back({x, y});
  }
  std::set<std::pair<int, int>> edges;
  while (static_cast<int>(edges.size()) < 2 * n) {
    const int a = static_cast<int>(next() % static_cast<unsigned>(n)), b = static_cast<int>(next() % static_cast<unsigned>(n));
    if (a != b) edges.insert({std::min(a, b), std::max(a, b)});
  }
  std::vector<Framework::Edge> e;
  for (const auto& [a, b] : edges) e.push_back({a, b});
  return framework(pts, e);
}

}  // namespace

TEST_CASE("exact analysis: work beyond the budget is refused with the estimate before it starts") {
  const RationalFramework f = randomFramework(120, 7);
  exact::ExactOptions o;
  o.budget_seconds = 1e-4;
  try {
    analyzeExact(*f.model, f.points, nullptr, o);
    FAIL("not refused");
  } catch (const ResourceError& e) {
    const std::string what = e.what();
    CHECK(what.find("240 variables") != std::string::npos);
    CHECK(what.find("of CPU") != std::string::npos);
    CHECK(what.find("exact_budget") != std::string::npos);
  }
  o.budget_seconds = 1000;
  const ExactAnalysis ex = analyzeExact(*f.model, f.points, nullptr, o);
  CHECK(ex.rank < ex.variables - ex.trivial);  // the dense step ran
  CHECK(ex.estimated_seconds > 0);
  CHECK(ex.estimated_seconds < 4 * ex.seconds + 0.05);  // (a sanitizer's build is slower: no bound the other way)
}

TEST_CASE("exact linear algebra: an interruption cancels FLINT's elimination at once, and FLINT works after") {
  const RationalFramework f = randomFramework(260, 11);
  const ConstraintSystem& sys = f.model->system();
  std::vector<exact::SparseEntry> J;
  int row = 0;
  for (const auto& [a, b] : f.model->edges()) {
    for (int k = 0; k < 2; ++k) {
      const Rational d = 2 * (f.points(k, a) - f.points(k, b));
      J.push_back({row, 2 * a + k, d});
      J.push_back({row, 2 * b + k, Rational(-d)});
    }
    ++row;
  }
  const int m = row, n = 2 * sys.numVertices();
  const auto t0 = std::chrono::steady_clock::now();
  auto seconds = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
  double stopped = 0;
  {
    InterruptCheck check([&] { return seconds() > 0.05; });
    RationalMatrix K;
    CHECK_THROWS_AS(exact::sparseRank(m, n, J, &K), Interrupted);
    stopped = seconds();
  }
  CHECK(stopped < 0.5);
  const int r = exact::sparseRank(m, n, J);
  CHECK(r < n - 3);
  CHECK(r == exact::modularRankLowerBound(m, n, J, [&] {
          std::vector<int> order(static_cast<size_t>(n));
          for (int i = 0; i < n; ++i) order[static_cast<size_t>(i)] = i;
          return order;
        }()));
}

#if !defined(__SANITIZE_ADDRESS__)
TEST_CASE("exact: an allocation FLINT or GMP cannot have is std::bad_alloc, not an abort") {
  exact::installNumberAllocators();
  CHECK_THROWS_AS(flint_malloc(std::numeric_limits<size_t>::max() / 4), std::bad_alloc);
  void* (*gmp_alloc)(size_t) = nullptr;
  mp_get_memory_functions(&gmp_alloc, nullptr, nullptr);
  REQUIRE(gmp_alloc);
  CHECK_THROWS_AS(gmp_alloc(std::numeric_limits<size_t>::max() / 4), std::bad_alloc);
}
#endif
