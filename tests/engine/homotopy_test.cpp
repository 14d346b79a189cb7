// The homotopy continuation solver: solution counts on systems where they are known, residuals,
// certification, no lost paths, solutions at infinity and singular ones told apart.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "engine/homotopy.h"

using namespace flexure::engine;

namespace {

Monomial mono(double c, std::vector<int> e) { return {Complex(c, 0), std::move(e)}; }

// Katsura-n: n + 1 unknowns u_0..u_n (u_{-k} = u_k, u_k = 0 for k > n), 2^n solutions.
PolynomialSystem katsura(int n) {
  const int N = n + 1;
  PolynomialSystem f(N);
  auto var = [&](int k) { return std::abs(k); };
  // sum_{l=-n}^{n} u_l = 1
  std::vector<Monomial> lin;
  for (int l = -n; l <= n; ++l) {
    std::vector<int> e(static_cast<size_t>(N), 0);
    e[static_cast<size_t>(var(l))] = 1;
    lin.push_back(mono(1, e));
  }
  lin.push_back(mono(-1, std::vector<int>(static_cast<size_t>(N), 0)));
  // Merge equal monomials.
  auto merge = [](std::vector<Monomial> p) {
    std::vector<Monomial> out;
    for (auto& m : p) {
      auto it = std::find_if(out.begin(), out.end(), [&](const Monomial& o) { return o.exponents == m.exponents; });
      if (it == out.end()) out.push_back(m);
      else it->coefficient += m.coefficient;
    }
    return out;
  };
  f.add(merge(lin));
  // sum_{l=-n}^{n} u_l u_{m-l} = u_m for m = 0..n-1
  for (int m = 0; m < n; ++m) {
    std::vector<Monomial> q;
    for (int l = -n; l <= n; ++l) {
      const int k = m - l;
      if (std::abs(k) > n) continue;
      std::vector<int> e(static_cast<size_t>(N), 0);
      e[static_cast<size_t>(var(l))] += 1;
      e[static_cast<size_t>(var(k))] += 1;
      q.push_back(mono(1, e));
    }
    std::vector<int> e(static_cast<size_t>(N), 0);
    e[static_cast<size_t>(m)] = 1;
    q.push_back(mono(-1, e));
    f.add(merge(q));
  }
  return f;
}

PolynomialSystem randomQuadrics(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0, 1);
  PolynomialSystem f(n);
  for (int i = 0; i < n; ++i) {
    std::vector<Monomial> p;
    for (int a = 0; a < n; ++a)
      for (int b = a; b < n; ++b) {
        std::vector<int> e(static_cast<size_t>(n), 0);
        e[static_cast<size_t>(a)] += 1;
        e[static_cast<size_t>(b)] += 1;
        p.push_back(mono(g(rng), e));
      }
    for (int a = 0; a < n; ++a) {
      std::vector<int> e(static_cast<size_t>(n), 0);
      e[static_cast<size_t>(a)] = 1;
      p.push_back(mono(g(rng), e));
    }
    p.push_back(mono(g(rng), std::vector<int>(static_cast<size_t>(n), 0)));
    f.add(p);
  }
  return f;
}

void requireAllGood(const HomotopyResult& r, const PolynomialSystem& f) {
  for (const Solution& s : r.solutions) {
    CVector F;
    f.evaluate(s.x, F);
    CHECK(F.cwiseAbs().maxCoeff() <= 1e-10 * std::max(1.0, std::pow(s.x.norm(), 2)));
    CHECK(s.certified);
    CHECK(s.multiplicity == 1);
  }
}

}  // namespace

TEST_CASE("homotopy: Jacobian and derivative bounds of polynomial systems", "[engine]") {
  PolynomialSystem f(2);
  f.add({mono(2, {2, 1}), mono(-1, {0, 3}), mono(5, {0, 0})});  // 2 x^2 y - y^3 + 5
  f.add({mono(1, {1, 0}), mono(1, {0, 1})});
  CHECK(f.degree(0) == 3);
  CHECK(f.degree(1) == 1);
  const CVector x = (CVector(2) << Complex(0.3, 0.2), Complex(-0.7, 0.1)).finished();
  CVector F, F2;
  CMatrix J;
  f.evaluate(x, F, &J);
  CHECK(std::abs(F[0] - (2.0 * x[0] * x[0] * x[1] - x[1] * x[1] * x[1] + 5.0)) < 1e-14);
  const double h = 1e-7;
  for (int j = 0; j < 2; ++j) {
    CVector xp = x;
    xp[j] += h;
    f.evaluate(xp, F2);
    for (int i = 0; i < 2; ++i) CHECK(std::abs((F2[i] - F[i]) / h - J(i, j)) < 1e-5);
  }
  // D^2 f / 2 of 2 x^2 y - y^3 at x: the bound dominates the true quadratic form on random unit v.
  std::mt19937 rng(1);
  std::normal_distribution<double> g(0, 1);
  const double bound = f.derivativeBound(x, 2);
  for (int t = 0; t < 20; ++t) {
    CVector v(2);
    v << Complex(g(rng), g(rng)), Complex(g(rng), g(rng));
    v.normalize();
    // f(x + s v) = f(x) + s Df v + s^2 Q(v) + ...: Q from a symmetric difference.
    const double s = 1e-4;
    CVector fp, fm;
    f.evaluate(x + s * v, fp);
    f.evaluate(x - s * v, fm);
    const CVector Q = (fp + fm - 2.0 * F) / (2 * s * s);
    CHECK(Q.norm() <= bound * (1 + 1e-4));
  }
  CHECK_THROWS(f.add({mono(1, {1})}));
  CHECK_THROWS(f.add({mono(0, {1, 1})}));
}

TEST_CASE("homotopy: products of univariate polynomials have all their roots", "[engine]") {
  // (x^3 - 1)(...) style: x^3 = 1, y^2 = 4, z^4 = 16: 24 solutions, 1 * 2 * 2 = 4 real.
  PolynomialSystem f(3);
  f.add({mono(1, {3, 0, 0}), mono(-1, {0, 0, 0})});
  f.add({mono(1, {0, 2, 0}), mono(-4, {0, 0, 0})});
  f.add({mono(1, {0, 0, 4}), mono(-16, {0, 0, 0})});
  const HomotopyResult r = solveTotalDegree(f);
  CHECK(r.paths == 24);
  CHECK(r.solutions.size() == 24);
  CHECK(r.failed == 0);
  CHECK(r.at_infinity == 0);
  requireAllGood(r, f);
  const auto real = r.realSolutions();
  REQUIRE(real.size() == 4);
  for (const Solution& s : real) {
    CHECK(s.certified_real);
    CHECK(std::abs(s.x[0].real() - 1) < 1e-12);
    CHECK(std::abs(std::abs(s.x[1].real()) - 2) < 1e-12);
    CHECK(std::abs(std::abs(s.x[2].real()) - 2) < 1e-12);
  }
}

TEST_CASE("homotopy: Katsura systems have 2^n solutions", "[engine]") {
  for (int n : {3, 4, 5}) {
    INFO("katsura " << n);
    const PolynomialSystem f = katsura(n);
    const HomotopyResult r = solveTotalDegree(f);
    CHECK(r.paths == (1 << n));
    CHECK(r.solutions.size() == static_cast<size_t>(1 << n));
    CHECK(r.failed == 0);
    CHECK(r.singular.empty());
    requireAllGood(r, f);
  }
}

TEST_CASE("homotopy: random quadrics have Bezout-many solutions, for every seed", "[engine]") {
  for (unsigned seed : {1u, 2u}) {
    const PolynomialSystem f = randomQuadrics(6, seed);
    for (std::uint64_t hseed : {1u, 7u}) {
      HomotopyOptions opt;
      opt.seed = hseed;
      const HomotopyResult r = solveTotalDegree(f, opt);
      INFO("system " << seed << ", homotopy seed " << hseed);
      CHECK(r.paths == 64);
      CHECK(r.solutions.size() == 64);
      CHECK(r.failed == 0);
      requireAllGood(r, f);
    }
  }
}

TEST_CASE("homotopy: solutions at infinity and singular solutions are told apart", "[engine]") {
  // x y = 1, x = 2: one finite solution, the other path goes to infinity.
  PolynomialSystem a(2);
  a.add({mono(1, {1, 1}), mono(-1, {0, 0})});
  a.add({mono(1, {1, 0}), mono(-2, {0, 0})});
  const HomotopyResult ra = solveTotalDegree(a);
  CHECK(ra.paths == 2);
  REQUIRE(ra.solutions.size() == 1);
  CHECK(std::abs(ra.solutions[0].x[1] - 0.5) < 1e-12);
  CHECK(ra.at_infinity == 1);
  // x^2 + y^2 = 2, x = y... as (x - y)^2 = 0 and x + y = 2: the double root (1, 1).
  PolynomialSystem b(2);
  b.add({mono(1, {2, 0}), mono(-2, {1, 1}), mono(1, {0, 2})});
  b.add({mono(1, {1, 0}), mono(1, {0, 1}), mono(-2, {0, 0})});
  const HomotopyResult rb = solveTotalDegree(b);
  CHECK(rb.paths == 2);
  CHECK(rb.solutions.empty());
  REQUIRE(rb.singular.size() == 1);
  CHECK((rb.singular[0].x - CVector::Constant(2, 1.0)).norm() < 1e-4);
  CHECK(rb.singular[0].multiplicity == 2);
  CHECK_FALSE(rb.singular[0].certified);
}
