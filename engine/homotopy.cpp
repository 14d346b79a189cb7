#include "engine/homotopy.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "engine/random.h"

namespace flexure::engine {

namespace {

Complex ipow(Complex z, int e) {
  Complex r = 1;
  while (e > 0) {
    if (e & 1) r *= z;
    z *= z;
    e >>= 1;
  }
  return r;
}

}  // namespace

void PolynomialSystem::add(std::vector<Monomial> polynomial) {
  std::vector<Monomial> kept;
  for (Monomial& m : polynomial) {
    if (static_cast<int>(m.exponents.size()) != n_)
      throw std::invalid_argument("a monomial needs one exponent per variable");
    if (std::any_of(m.exponents.begin(), m.exponents.end(), [](int e) { return e < 0; }))
      throw std::invalid_argument("negative exponent");
    if (m.coefficient != Complex(0)) kept.push_back(std::move(m));
  }
  if (kept.empty()) throw std::invalid_argument("the zero polynomial");
  std::vector<Term> terms;
  for (const Monomial& m : kept) {
    Term t{m.coefficient, {}};
    for (int j = 0; j < n_; ++j)
      if (m.exponents[static_cast<size_t>(j)] > 0) t.powers.push_back({j, m.exponents[static_cast<size_t>(j)]});
    terms.push_back(std::move(t));
  }
  sparse_.push_back(std::move(terms));
  polys_.push_back(std::move(kept));
}

int PolynomialSystem::degree(int i) const {
  int d = 0;
  for (const Monomial& m : polys_[static_cast<size_t>(i)])
    d = std::max(d, std::accumulate(m.exponents.begin(), m.exponents.end(), 0));
  return d;
}

void PolynomialSystem::evaluate(const CVector& x, CVector& f, CMatrix* J) const {
  const int m = size();
  f.setZero(m);
  if (J) J->setZero(m, n_);
  std::vector<Complex> pw(static_cast<size_t>(n_));  // the powers of the current term's variables
  for (int i = 0; i < m; ++i)
    for (const Term& t : sparse_[static_cast<size_t>(i)]) {
      const size_t q = t.powers.size();
      Complex v = t.c;
      for (size_t k = 0; k < q; ++k) v *= (pw[k] = ipow(x[t.powers[k].first], t.powers[k].second));
      f[i] += v;
      if (!J) continue;
      for (size_t k = 0; k < q; ++k) {
        const auto [var, e] = t.powers[k];
        Complex d = t.c * static_cast<double>(e) * ipow(x[var], e - 1);
        for (size_t l = 0; l < q; ++l)
          if (l != k) d *= pw[l];
        (*J)(i, var) += d;
      }
    }
}

double PolynomialSystem::derivativeBound(const CVector& x, int k) const {
  // For c x^e, sum over |a| = k of |c binom(e, a) x^(e - a)| is |c| times the coefficient of s^k
  // in prod_j (|x_j| + s)^(e_j); the sum over the terms bounds sum_a |d^a f_i(x) / a!|, which
  // bounds the k-linear form on unit vectors.
  double total = 0;
  for (const auto& poly : polys_) {
    double si = 0;
    for (const Monomial& t : poly) {
      std::vector<double> c{1.0};  // coefficients in s
      for (int j = 0; j < n_; ++j)
        for (int r = 0; r < t.exponents[static_cast<size_t>(j)]; ++r) {
          std::vector<double> next(c.size() + 1, 0.0);
          for (size_t q = 0; q < c.size(); ++q) {
            next[q] += c[q] * std::abs(x[j]);
            next[q + 1] += c[q];
          }
          c.swap(next);
        }
      if (static_cast<size_t>(k) < c.size()) si += std::abs(t.coefficient) * c[static_cast<size_t>(k)];
    }
    total += si * si;
  }
  return std::sqrt(total);
}

std::vector<Solution> HomotopyResult::realSolutions() const {
  std::vector<Solution> out;
  for (const Solution& s : solutions)
    if (s.real) out.push_back(s);
  return out;
}

namespace {

// The homogenized target F, the start system G_i = x_i^d_i - x_0^d_i, both in X = (x_0, x),
// and the patch a . X = 1: H(X, t) = (gamma t G + (1 - t) F, a . X - 1).
class Homotopy {
 public:
  Homotopy(const PolynomialSystem& f, Complex gamma, CVector patch)
      : n_(f.variables()), F_(n_ + 1), G_(n_ + 1), gamma_(gamma), a_(std::move(patch)) {
    for (int i = 0; i < f.size(); ++i) {
      const int d = f.degree(i);
      std::vector<Monomial> h;
      for (const Monomial& m : f.polynomial(i)) {
        Monomial hm;
        hm.coefficient = m.coefficient;
        hm.exponents.push_back(d - std::accumulate(m.exponents.begin(), m.exponents.end(), 0));
        hm.exponents.insert(hm.exponents.end(), m.exponents.begin(), m.exponents.end());
        h.push_back(std::move(hm));
      }
      F_.add(std::move(h));
      Monomial xi{1.0, std::vector<int>(static_cast<size_t>(n_) + 1, 0)}, x0{-1.0, std::vector<int>(static_cast<size_t>(n_) + 1, 0)};
      xi.exponents[static_cast<size_t>(i) + 1] = d;
      x0.exponents[0] = d;
      G_.add({xi, x0});
      degrees_.push_back(d);
    }
  }
  int dim() const { return n_ + 1; }
  const std::vector<int>& degrees() const { return degrees_; }
  const CVector& patch() const { return a_; }

  // H(X, t), H_X and H_t, on the patch a^H X = 1 (a: the start patch, or one a path moved to).
  void evaluate(const CVector& X, double t, const CVector& a, CVector& H, CMatrix& HX, CVector& Ht) const {
    CVector f, g;
    CMatrix Jf, Jg;
    F_.evaluate(X, f, &Jf);
    G_.evaluate(X, g, &Jg);
    H.resize(n_ + 1);
    HX.resize(n_ + 1, n_ + 1);
    Ht.setZero(n_ + 1);
    H.head(n_) = gamma_ * t * g + (1 - t) * f;
    H[n_] = a.dot(X) - 1.0;  // a^H X - 1
    HX.topRows(n_) = gamma_ * t * Jg + (1 - t) * Jf;
    HX.row(n_) = a.adjoint();
    Ht.head(n_) = gamma_ * g - f;
  }

 private:
  int n_;
  PolynomialSystem F_, G_;
  Complex gamma_;
  CVector a_;
  std::vector<int> degrees_;
};

struct Tracked {
  CVector X;
  double t = 1;
  bool reached = false;  // t = 0 with a converged corrector
};

// Newton on H(., t) from X: at most `iterations` steps; true when the last step is below the
// tolerance (relative to |X|) and no step grew.
bool newton(const Homotopy& h, CVector& X, double t, const CVector& a, int iterations, double tol,
            double* first_step = nullptr) {
  CVector H, Ht;
  CMatrix HX;
  double prev = std::numeric_limits<double>::infinity();
  for (int it = 0; it < iterations; ++it) {
    h.evaluate(X, t, a, H, HX, Ht);
    const CVector dX = HX.partialPivLu().solve(H);
    if (!dX.allFinite()) return false;
    const double step = dX.norm();
    if (it == 0 && first_step) *first_step = step;
    X -= dX;
    if (step <= tol * std::max(1.0, X.norm())) return true;
    if (step > prev) return false;
    prev = step;
  }
  return false;
}

CVector velocity(const Homotopy& h, const CVector& X, double t, const CVector& a) {
  CVector H, Ht;
  CMatrix HX;
  h.evaluate(X, t, a, H, HX, Ht);
  return -HX.partialPivLu().solve(Ht);
}

Tracked track(const Homotopy& h, CVector X, const HomotopyOptions& opt, double max_step) {
  Tracked out;
  double t = 1, step = std::min(max_step, 0.01);
  int successes = 0;
  CVector a = h.patch();
  for (int it = 0; it < opt.max_steps && t > 0; ++it) {
    // Keep X of moderate size: when it drifts towards the patch's own infinity (a^H X = 0 for
    // the projective point), move the patch to X itself. The projective path is the same.
    const double size = X.norm();
    if (size > 10 || size < 0.1) a = X / (size * size);
    double hstep = std::min(step, t);
    if (t < opt.endgame_start) hstep = std::min(hstep, std::max(0.5 * t, opt.min_step));  // approach 0 geometrically
    if (t - hstep < 1e-14) hstep = t;  // the last step lands on 0
    // Runge-Kutta 4 in t (dt = -hstep).
    const double dt = -hstep;
    const CVector k1 = velocity(h, X, t, a);
    const CVector k2 = velocity(h, X + 0.5 * dt * k1, t + 0.5 * dt, a);
    const CVector k3 = velocity(h, X + 0.5 * dt * k2, t + 0.5 * dt, a);
    const CVector k4 = velocity(h, X + dt * k3, t + dt, a);
    CVector Y = X + dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    double first = 0;
    const bool ok = Y.allFinite() && newton(h, Y, t + dt, a, 3, opt.corrector_tolerance, &first) &&
                    first <= 0.1 * std::max(1.0, X.norm());
    if (ok) {
      X = Y;
      t += dt;
      if (++successes >= 3) step = std::min(2 * step, max_step), successes = 0;
    } else {
      successes = 0;
      step = 0.5 * hstep;
      if (step < opt.min_step) break;
    }
  }
  out.X = X;
  out.t = std::max(t, 0.0);
  out.reached = t <= 0;
  return out;
}

bool realCoefficients(const PolynomialSystem& f) {
  for (int i = 0; i < f.size(); ++i)
    for (const Monomial& m : f.polynomial(i))
      if (m.coefficient.imag() != 0) return false;
  return true;
}

// Newton on f, then Smale's constants. A Jacobian with condition number above
// `singular_condition` is singular to working precision: no certificate (gamma is infinite).
Solution refine(const PolynomialSystem& f, CVector x, bool real_coefficients, double singular_condition) {
  Solution s;
  CVector F;
  CMatrix J;
  for (int it = 0; it < 8; ++it) {
    f.evaluate(x, F, &J);
    const CVector dx = J.partialPivLu().solve(F);
    if (!dx.allFinite()) break;
    x -= dx;
    if (dx.norm() <= 1e-15 * std::max(1.0, x.norm())) break;
  }
  f.evaluate(x, F, &J);
  s.x = x;
  s.residual = F.size() ? F.cwiseAbs().maxCoeff() : 0.0;
  Eigen::JacobiSVD<CMatrix> svd(J, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd& sv = svd.singularValues();
  const double smin = sv.size() ? sv.minCoeff() : 0.0;
  s.condition = sv.size() == 0 ? 0.0 : smin > 0 ? sv[0] / smin : std::numeric_limits<double>::infinity();
  if (smin > 0) {
    s.beta = svd.solve(F).norm();
    int D = 0;
    for (int i = 0; i < f.size(); ++i) D = std::max(D, f.degree(i));
    for (int k = 2; k <= D; ++k) s.gamma = std::max(s.gamma, std::pow(f.derivativeBound(x, k) / smin, 1.0 / (k - 1)));
    s.alpha = s.beta * s.gamma;
    s.certified = s.alpha < (13 - 3 * std::sqrt(17.0)) / 4 && s.condition < singular_condition;
  }
  const double im = x.imag().norm();
  s.real = im <= 1e-8 * std::max(1.0, x.norm());
  s.certified_real = real_coefficients && s.certified && s.alpha < 0.03 && (s.gamma == 0 || im < 0.01 / s.gamma);
  return s;
}

}  // namespace

HomotopyResult solveTotalDegree(const PolynomialSystem& f, const HomotopyOptions& opt) {
  const int n = f.variables();
  if (f.size() != n) throw std::invalid_argument("solveTotalDegree needs a square system");
  Random rng(opt.seed);
  const double angle = 2 * M_PI * rng.uniform();
  const Complex gamma = std::polar(1.0, angle);
  CVector a(n + 1);
  for (int j = 0; j <= n; ++j) a[j] = Complex(rng.gaussian(), rng.gaussian());
  const Homotopy h(f, gamma, a);
  const std::vector<int>& deg = h.degrees();
  HomotopyResult out;
  long paths = 1;
  for (int d : deg) {
    if (d < 1) throw std::invalid_argument("a polynomial of degree 0 has no solutions");
    paths *= d;
    if (paths > 10'000'000) throw std::invalid_argument("more than 10^7 paths");
  }
  out.paths = static_cast<int>(paths);
  const bool real_coefficients = realCoefficients(f);
  std::vector<int> digit(static_cast<size_t>(n), 0);
  for (int p = 0; p < out.paths; ++p) {
    // Start point: x_j = exp(2 pi i k_j / d_j), X = (1, x) scaled onto the patch.
    CVector X(n + 1);
    X[0] = 1;
    for (int j = 0; j < n; ++j) X[j + 1] = std::polar(1.0, 2 * M_PI * digit[static_cast<size_t>(j)] / deg[static_cast<size_t>(j)]);
    X /= h.patch().dot(X);
    for (int j = 0; j < n && ++digit[static_cast<size_t>(j)] == deg[static_cast<size_t>(j)]; ++j) digit[static_cast<size_t>(j)] = 0;
    Tracked tr = track(h, X, opt, opt.max_step);
    // A path that could not be followed is tried again with shorter steps (twice).
    for (double f : {0.1, 0.01})
      if (!tr.reached && tr.t > 1e-6) tr = track(h, X, opt, f * opt.max_step);
    const double scale = tr.X.norm();
    if (!tr.X.allFinite() || (!tr.reached && tr.t > 1e-6)) {
      ++out.failed;
      continue;
    }
    // Near t = 0 a path to a singular or infinite endpoint converges slowly: it is classified
    // from where it got (t <= 1e-6).
    if (std::abs(tr.X[0]) <= (tr.reached ? opt.infinity_tolerance : 1e-4) * scale) {
      ++out.at_infinity;
      continue;
    }
    const CVector x = tr.X.tail(n) / tr.X[0];
    Solution s = refine(f, x, real_coefficients, opt.singular_condition);
    s.path = p;
    const bool singular = !tr.reached || !(s.condition < opt.singular_condition) || !s.x.allFinite();
    std::vector<Solution>& list = singular ? out.singular : out.solutions;
    const double tol = singular ? 1e-4 : opt.distinct_tolerance;
    bool merged = false;
    for (Solution& o : list)
      if ((o.x - s.x).norm() <= tol * std::max(1.0, s.x.norm())) {
        ++o.multiplicity;
        merged = true;
        break;
      }
    if (!merged) list.push_back(std::move(s));
  }
  return out;
}

}  // namespace flexure::engine
