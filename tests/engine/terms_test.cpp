// Every constraint term, from the one term list (engine/term_list.h): its double fast path's
// Jacobian and second derivative against finite differences, in every dimension the term is used
// in; the fast path against the term's formula (residual<T>) with derivatives from the jet; the
// formula in exact rational arithmetic, where its degree() is checked by exact finite
// differences; and a whole system evaluated in another arithmetic (engine/evaluate_in.h).
#include <catch2/catch.hpp>
#include <gmpxx.h>

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <fstream>
#include <functional>
#include <numeric>
#include <set>
#include <sstream>

#include "engine/evaluate_in.h"
#include "engine/terms.h"
#include "../test_common.h"

using namespace flexure;
using engine::ConstraintTerm;
using engine::Matrix;
using engine::Vector;

namespace {

// A quadric with exact derivatives: x^2 + 2 y^2 - z^2 + x y - 1.
class Quadric final : public engine::ScalarField {
 public:
  double value(const double* x) const override {
    return x[0] * x[0] + 2 * x[1] * x[1] - x[2] * x[2] + x[0] * x[1] - 1;
  }
  void evaluate(const double* x, double* f, double* g, double* h) const override {
    if (f) *f = value(x);
    if (g) g[0] = 2 * x[0] + x[1], g[1] = 4 * x[1] + x[0], g[2] = -2 * x[2];
    if (h) {
      const double H[9] = {2, 1, 0, 1, 4, 0, 0, 0, -2};
      std::copy(H, H + 9, h);
    }
  }
  std::string text() const override { return "x^2 + 2*y^2 - z^2 + x*y - 1"; }
};

struct TermCase {
  std::string name;          // the class in engine/terms.h
  std::vector<int> dimensions;
  int blocks;                // how many blocks the term takes (d + 1 for a simplex: -1)
  // The term at a start configuration (d x blocks), from which some terms take parameters.
  std::function<std::unique_ptr<ConstraintTerm>(int d, const Matrix& start)> make;
  // Moves the start where the term's builder would have it (a vertex in its frame's span).
  std::function<void(Matrix& start)> place = nullptr;
};

// Vertex 0 at affine weights 1/4, 9/8, -3/8 of vertices 1, 2, 3: in their span, on the grid.
void placeInFrame(Matrix& p) { p.col(0) = 0.25 * p.col(1) + 1.125 * p.col(2) - 0.375 * p.col(3); }

// v's coordinates in the frame {a, b(, c)} at the start, as the framework's builder solves for
// them (engine/systems/framework.cpp): the formula computes the same from the start.
std::unique_ptr<ConstraintTerm> framePointAtStart(int d, const Matrix& p, int frame) {
  const Vector e1 = p.col(2) - p.col(1), r = p.col(0) - p.col(1);
  std::array<double, 3> c{0, 0, 0};
  if (frame == 2) {
    c[0] = r.dot(e1) / e1.squaredNorm();
    if (d == 2) c[1] = (e1[0] * r[1] - e1[1] * r[0]) / e1.squaredNorm();
  } else {
    const Vector e2 = p.col(3) - p.col(1);
    Matrix B(d, d);
    if (d == 2) B << e1, e2;
    else B << e1, e2, Vector(e1.head<3>().cross(e2.head<3>()));
    const Vector s = B.colPivHouseholderQr().solve(r);
    for (int i = 0; i < d; ++i) c[static_cast<size_t>(i)] = s[i];
  }
  std::vector<int> blocks(static_cast<size_t>(frame) + 1);
  for (int i = 0; i <= frame; ++i) blocks[static_cast<size_t>(i)] = i;
  return std::make_unique<engine::FramePointTerm>(d, blocks, c, 1.3);
}

// The angle at j between the arms to i and k at `start`: cos, sin (2D signed, 3D positive) and
// |u0||w0|, as the angular framework's builder passes them.
std::unique_ptr<ConstraintTerm> angleAtStart(int d, const Matrix& p) {
  const Vector u = p.col(0) - p.col(1), w = p.col(2) - p.col(1);
  const double nn = u.norm() * w.norm();
  const double sin = d == 2 ? (u[0] * w[1] - u[1] * w[0]) / nn : u.head<3>().cross(w.head<3>()).norm() / nn;
  return std::make_unique<engine::AngleTerm>(0, 1, 2, u.dot(w) / nn, sin, nn);
}

const std::vector<TermCase>& termCases() {
  static const std::vector<TermCase> cases = {
      {"SquaredDistanceTerm", {2, 3}, 2,
       [](int, const Matrix&) { return std::make_unique<engine::SquaredDistanceTerm>(0, 1, 2.5); }},
      {"SquaredDistanceTerm", {2, 3}, 2,
       [](int, const Matrix& p) { return engine::SquaredDistanceTerm::atStart(0, 1, p); }},
      {"FacetPlaneTerm", {2, 3}, 3,
       [](int, const Matrix&) { return std::make_unique<engine::FacetPlaneTerm>(0, 1, 2, 0, 1.7); }},
      {"UnitNormTerm", {2, 3}, 1,
       [](int, const Matrix&) { return std::make_unique<engine::UnitNormTerm>(0, 0, 1.3); }},
      {"SimplexVolumeTerm", {2, 3}, -1,
       [](int d, const Matrix&) {
         std::vector<int> blocks(static_cast<size_t>(d) + 1);
         for (int i = 0; i <= d; ++i) blocks[static_cast<size_t>(i)] = i;
         return std::make_unique<engine::SimplexVolumeTerm>(blocks, 0.3, 1.2, 0.7);
       }},
      {"SimplexVolumeTerm", {2, 3}, -1,
       [](int d, const Matrix& p) {
         std::vector<int> blocks(static_cast<size_t>(d) + 1);
         Matrix E(d, d);
         for (int i = 0; i <= d; ++i) blocks[static_cast<size_t>(i)] = i;
         for (int i = 0; i < d; ++i) E.col(i) = p.col(i + 1) - p.col(0);
         return std::make_unique<engine::SimplexVolumeTerm>(blocks, E.determinant(), 1.2, 0.7, true);
       }},
      {"AffineCombinationTerm", {2, 3}, 4,
       [](int d, const Matrix&) {
         return std::make_unique<engine::AffineCombinationTerm>(d, std::vector<int>{0, 1, 2, 3},
                                                                std::vector<double>{0.25, 1.125, -0.375}, 1.7, "body 1");
       },
       placeInFrame},
      {"FramePointTerm", {2, 3}, 3, [](int d, const Matrix& p) { return framePointAtStart(d, p, 2); }},
      {"FramePointTerm", {2, 3}, 4, [](int d, const Matrix& p) { return framePointAtStart(d, p, 3); }},
      {"AngleTerm", {2, 3}, 3, angleAtStart},
      {"InversiveDistanceTerm", {3}, 2,
       [](int, const Matrix&) { return std::make_unique<engine::InversiveDistanceTerm>(0, 1, 0.4); }},
      {"SurfaceTerm", {3}, 1,
       [](int, const Matrix&) { return std::make_unique<engine::SurfaceTerm>(0, std::make_shared<Quadric>(), 1.3, 0.6); }},
  };
  return cases;
}

// Points spread around (1.5, 1.5, 1.5), away from the origin where caps and angles are
// singular, on a grid of 1/16 so that they are exact in every arithmetic.
Matrix startPoints(std::mt19937& rng, int d, int blocks) {
  Matrix p(d, blocks);
  for (int b = 0; b < blocks; ++b)
    for (int k = 0; k < d; ++k) p(k, b) = std::round(16 * (1.5 + std::uniform_real_distribution<double>(-1, 1)(rng))) / 16;
  return p;
}

}  // namespace

TEST_CASE("terms: every term's derivatives match finite differences in 2D and 3D", "[engine]") {
  std::mt19937 rng(2026);
  int checked = 0;
  for (const TermCase& c : termCases())
    for (int d : c.dimensions) {
      const int blocks = c.blocks < 0 ? d + 1 : c.blocks;
      engine::ConstraintSystem sys(d, blocks, blocks);
      Matrix p = startPoints(rng, d, blocks);
      if (c.place) c.place(p);
      sys.addTerm(c.make(d, p));
      sys.finalize(p);
      for (int trial = 0; trial < 5; ++trial) {
        Vector x = sys.freeCoordinates(p) + test::randomVector(rng, sys.numVariables(), 0.3);
        INFO(c.name << " in " << d << "D, trial " << trial);
        test::requireJacobianMatchesFiniteDifferences(sys, x);
        test::requireSecondDerivativeMatchesFiniteDifferences(
            sys, x, test::randomVector(rng, sys.numVariables()), test::randomVector(rng, sys.numVariables()));
        ++checked;
      }
    }
  CHECK(checked == 5 * 22);
}

TEST_CASE("terms: the cases name every term of the one term list", "[engine]") {
  std::set<std::string> declared, listed;
#define FLEXURE_TERM_NAME(Term) declared.insert(#Term);
  FLEXURE_TERMS(FLEXURE_TERM_NAME)
#undef FLEXURE_TERM_NAME
  for (const TermCase& c : termCases()) listed.insert(c.name);
  CHECK(declared.size() >= 9);
  CHECK(declared == listed);
}

namespace {

// Each case's term at a random start (exact on a grid of 1/16) and random local coordinates x
// near it, for every dimension: calls f(case, d, term, x0, x).
void forEachCase(const std::function<void(const TermCase&, int, const ConstraintTerm&, const std::vector<double>&,
                                          const std::vector<double>&)>& f) {
  std::mt19937 rng(2027);
  for (const TermCase& c : termCases())
    for (int d : c.dimensions) {
      const int blocks = c.blocks < 0 ? d + 1 : c.blocks;
      for (int trial = 0; trial < 3; ++trial) {
        Matrix p = startPoints(rng, d, blocks);
        if (c.place) c.place(p);
        const auto term = c.make(d, p);
        const std::vector<double> x0(p.data(), p.data() + p.size());
        std::vector<double> x = x0;
        for (double& v : x) v += std::uniform_real_distribution<double>(-0.3, 0.3)(rng);
        INFO(c.name << " in " << d << "D, trial " << trial);
        f(c, d, *term, x0, x);
      }
    }
}

void requireClose(const std::vector<double>& a, const std::vector<double>& b, double tolerance) {
  REQUIRE(a.size() == b.size());
  double scale = 1.0;
  for (double v : b) scale = std::max(scale, std::abs(v));
  for (size_t i = 0; i < a.size(); ++i) {
    INFO("entry " << i << ": " << a[i] << " against " << b[i]);
    REQUIRE(std::abs(a[i] - b[i]) <= tolerance * scale);
  }
}

}  // namespace

TEST_CASE("terms: the double fast path is the formula times the row weight with the jet's derivatives", "[engine]") {
  int checked = 0;
  forEachCase([&](const TermCase&, int d, const ConstraintTerm& t, const std::vector<double>& x0,
                  const std::vector<double>& x) {
    const int n = static_cast<int>(x.size()), rows = t.numResiduals();
    std::vector<double> fast_r(static_cast<size_t>(rows)), fast_J(static_cast<size_t>(rows * n));
    t.evaluate(x.data(), d, fast_r.data(), fast_J.data());
    std::vector<double> r(static_cast<size_t>(rows)), J(static_cast<size_t>(rows * n));
    engine::termResidual(t, x0.data(), x.data(), d, r.data());
    engine::termJacobian(t, x0.data(), x.data(), d, J.data());
    for (double& v : r) v *= t.rowWeight();
    for (double& v : J) v *= t.rowWeight();
    requireClose(fast_r, r, 1e-13);
    requireClose(fast_J, J, 1e-12);
    std::mt19937 rng(static_cast<unsigned>(checked));
    std::vector<double> u(static_cast<size_t>(n)), w(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) u[i] = std::normal_distribution<double>()(rng), w[i] = std::normal_distribution<double>()(rng);
    std::vector<double> fast_h(static_cast<size_t>(rows)), h(static_cast<size_t>(rows));
    t.secondDerivative(x.data(), u.data(), w.data(), d, fast_h.data());
    engine::termSecondDerivative(t, x0.data(), x.data(), u.data(), w.data(), d, h.data());
    for (double& v : h) v *= t.rowWeight();
    requireClose(fast_h, h, 1e-12);
    ++checked;
  });
  CHECK(checked == 3 * 22);
}

namespace {

// Exact rationals on GMP's integers. No sqrt: a term that takes a root is refused by the jet's
// root() (std::domain_error), as the exact back end refuses it by its degree.
struct Rational {
  mpz_class p = 0, q = 1;
  Rational() = default;
  Rational(int v) : p(v) {}  // NOLINT
  // A double is a dyadic rational: mpq's conversion is exact.
  explicit Rational(double v) {
    const mpq_class x(v);
    p = x.get_num(), q = x.get_den();
  }
  void normalize() {
    mpz_class g;
    mpz_gcd(g.get_mpz_t(), p.get_mpz_t(), q.get_mpz_t());
    if (g > 1) p /= g, q /= g;
    if (q < 0) p = -p, q = -q;
  }
  friend Rational operator+(const Rational& x, const Rational& y) {
    Rational r;
    r.p = x.p * y.q + y.p * x.q, r.q = x.q * y.q;
    r.normalize();
    return r;
  }
  friend Rational operator-(const Rational& x) {
    Rational r = x;
    r.p = -r.p;
    return r;
  }
  friend Rational operator-(const Rational& x, const Rational& y) { return x + (-y); }
  friend Rational operator*(const Rational& x, const Rational& y) {
    Rational r;
    r.p = x.p * y.p, r.q = x.q * y.q;
    r.normalize();
    return r;
  }
  friend Rational operator/(const Rational& x, const Rational& y) {
    REQUIRE(y.p != 0);
    Rational r;
    r.p = x.p * y.q, r.q = x.q * y.p;
    r.normalize();
    return r;
  }
  Rational& operator+=(const Rational& o) { return *this = *this + o; }
  Rational& operator-=(const Rational& o) { return *this = *this - o; }
  friend bool operator==(const Rational& x, const Rational& y) { return x.p == y.p && x.q == y.q; }
  double toDouble() const { return mpq_class(p, q).get_d(); }
};

}  // namespace

TEST_CASE("terms: the formula in exact rational arithmetic has the degree the term declares", "[engine]") {
  // Along a line x + t u through dyadic points, a polynomial of degree k in the coordinates is a
  // polynomial of degree at most k in t: its (k+1)-th finite difference over t = 0..k+1 is exactly
  // zero, and (for these generic lines) its k-th is not. Terms that are not polynomial (degree -1)
  // need a root, which exact arithmetic does not have.
  int polynomial = 0, refused = 0;
  forEachCase([&](const TermCase&, int d, const ConstraintTerm& t, const std::vector<double>& x0,
                  const std::vector<double>& x) {
    const int n = static_cast<int>(x.size()), rows = t.numResiduals(), k = t.degree(d);
    std::vector<Rational> x0q(static_cast<size_t>(n)), xq(static_cast<size_t>(n)), uq(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) {
      x0q[i] = Rational(x0[i]);
      xq[i] = Rational(std::round(x[i] * 16) / 16);
      uq[i] = Rational(std::round((x[i] - 1.5) * 8 + 3 * (i % 3) - 4) / 8);
    }
    std::vector<Rational> r(static_cast<size_t>(rows));
    if (k < 0) {
      REQUIRE_THROWS_AS(engine::termResidual(t, x0q.data(), xq.data(), d, r.data()), std::domain_error);
      ++refused;
      return;
    }
    // The order-th forward difference over t = 0..order of the residuals at x + t u.
    auto difference = [&](int order) {
      std::vector<std::vector<Rational>> values;
      for (int j = 0; j <= order; ++j) {
        std::vector<Rational> y(static_cast<size_t>(n));
        for (int i = 0; i < n; ++i) y[i] = xq[i] + Rational(j) * uq[i];
        engine::termResidual(t, x0q.data(), y.data(), d, r.data());
        values.push_back(r);
      }
      for (int o = 1; o <= order; ++o)
        for (int j = 0; j + o <= order; ++j)
          for (int row = 0; row < rows; ++row) values[j][row] = values[j + 1][row] - values[j][row];
      return values[0];
    };
    // A residual that the double path finds zero at the start comes from the start (a bar's
    // length, an angle, a volume taken there): exactly zero there in exact arithmetic.
    std::vector<double> at_start(static_cast<size_t>(rows));
    t.evaluate(x0.data(), d, at_start.data(), nullptr);
    engine::termResidual(t, x0q.data(), x0q.data(), d, r.data());
    for (int row = 0; row < rows; ++row)
      if (std::abs(at_start[row]) < 1e-12) CHECK(r[row] == Rational(0));
    bool top_nonzero = false;
    for (const Rational& v : difference(k + 1)) CHECK(v == Rational(0));
    for (const Rational& v : difference(k)) top_nonzero |= !(v == Rational(0));
    CHECK(top_nonzero);  // the degree is not overstated
    // The exact Jacobian and second derivative agree with the double fast path.
    std::vector<Rational> Jq(static_cast<size_t>(rows * n)), uw(static_cast<size_t>(rows));
    engine::termJacobian(t, x0q.data(), xq.data(), d, Jq.data());
    engine::termSecondDerivative(t, x0q.data(), xq.data(), uq.data(), uq.data(), d, uw.data());
    std::vector<double> xd(static_cast<size_t>(n)), ud(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) xd[i] = xq[i].toDouble(), ud[i] = uq[i].toDouble();
    std::vector<double> fr(static_cast<size_t>(rows)), fJ(static_cast<size_t>(rows * n)), fh(static_cast<size_t>(rows));
    t.evaluate(xd.data(), d, fr.data(), fJ.data());
    t.secondDerivative(xd.data(), ud.data(), ud.data(), d, fh.data());
    std::vector<double> J(static_cast<size_t>(rows * n)), h(static_cast<size_t>(rows));
    for (size_t i = 0; i < J.size(); ++i) J[i] = t.rowWeight() * Jq[i].toDouble();
    for (size_t i = 0; i < h.size(); ++i) h[i] = t.rowWeight() * uw[i].toDouble();
    requireClose(fJ, J, 1e-12);
    requireClose(fh, h, 1e-12);
    ++polynomial;
  });
  CHECK(polynomial == 3 * 19);  // all but the 3D angle, the inversive distance and the surface
  CHECK(refused == 3 * 3);
}

TEST_CASE("terms: a system evaluated in another arithmetic matches the double evaluation", "[engine]") {
  // A braced square with a pinned vertex, an angle and a point on a bar, at integer coordinates:
  // exact residuals (all zero at the start) and an exact Jacobian whose entries are known in
  // closed form for the bars: 2 (x_a - x_b) and its negative.
  const std::vector<std::array<int, 2>> p = {{0, 0}, {4, 0}, {4, 3}, {0, 3}, {2, 0}};
  Matrix positions(2, 5);
  for (int v = 0; v < 5; ++v) positions.col(v) << p[v][0], p[v][1];
  engine::ConstraintSystem sys(2, 5, 5);
  const std::vector<std::array<int, 2>> bars = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {0, 2}};
  for (auto [a, b] : bars)
    sys.addTerm(std::make_unique<engine::SquaredDistanceTerm>(a, b, (positions.col(a) - positions.col(b)).squaredNorm()));
  sys.addTerm(std::make_unique<engine::AngleTerm>(1, 0, 3, 0.0, 1.0, 12.0));
  sys.addTerm(std::make_unique<engine::FramePointTerm>(2, std::vector<int>{4, 0, 1}, std::array<double, 3>{0.5, 0.0, 0.0}, 5.0));
  sys.pin(0);
  sys.finalize(positions);
  std::vector<Rational> at;
  for (int v = 0; v < 5; ++v) at.push_back(Rational(p[v][0])), at.push_back(Rational(p[v][1]));
  std::vector<engine::JacobianEntry<Rational>> J;
  const std::vector<Rational> r = engine::evaluateSystemIn(sys, at, at, &J);
  REQUIRE(static_cast<int>(r.size()) == sys.numEquations());
  for (const Rational& v : r) CHECK(v == Rational(0));
  // Bars: row k, the columns of its free endpoints hold +-2 (x_a - x_b) exactly.
  int bar_entries = 0;
  for (const auto& e : J)
    if (e.row < 5) {
      const auto [a, b] = bars[static_cast<size_t>(e.row)];
      for (int v : {a, b})
        for (int k = 0; k < 2; ++k)
          if (sys.variableIndex(v, k) == e.column) {
            const int expected = (v == a ? 2 : -2) * (p[a][k] - p[b][k]);
            CHECK(e.value == Rational(expected));
            ++bar_entries;
          }
    }
  CHECK(bar_entries == 2 * 2 * 5 - 2 * 3);  // vertex 0 is pinned: bars 0-1, 3-0 and 0-2 lose a side
  // At a moved point, the double evaluation of the same system times the row weights.
  const Vector x = sys.freeCoordinates(positions) + Vector::LinSpaced(sys.numVariables(), 0.25, -0.5);
  const Matrix moved = sys.positions(x);
  std::vector<double> pos(moved.data(), moved.data() + moved.size());
  std::vector<engine::JacobianEntry<double>> Jd;
  const std::vector<double> start(positions.data(), positions.data() + positions.size());
  const std::vector<double> rd = engine::evaluateSystemIn(sys, start, pos, &Jd);
  const Vector fast = sys.residuals(x);
  const Matrix fast_J(sys.jacobian(x));
  std::vector<double> weights;
  for (int t : sys.activeTerms())
    for (int i = 0; i < sys.terms()[static_cast<size_t>(t)]->numResiduals(); ++i)
      weights.push_back(sys.terms()[static_cast<size_t>(t)]->rowWeight());
  Matrix dense = Matrix::Zero(sys.numEquations(), sys.numVariables());
  for (const auto& e : Jd) dense(e.row, e.column) += weights[static_cast<size_t>(e.row)] * e.value;
  for (int i = 0; i < sys.numEquations(); ++i) CHECK(fast[i] == Approx(weights[static_cast<size_t>(i)] * rd[i]).margin(1e-12));
  CHECK((dense - fast_J).cwiseAbs().maxCoeff() < 1e-12);
}
