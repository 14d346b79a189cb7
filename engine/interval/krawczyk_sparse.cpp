// The certified tracks' test for large systems (engine/interval/krawczyk.h), sparse throughout:
// a Newton-Kantorovich test in the 2-norm instead of the dense Krawczyk test, whose
// preconditioner is a dense inverse (N^3 per sample and per piece of a step).
//
// The square system G(x) = [F(x); x_j - s] (the slice fixes coordinate j, the one the path
// moves most), A = G'(c) at a point c in double (sparse). If sigma <= sigma_min(A) (proved:
// engine/interval/verified.h), Delta >= ||M - A||_2 for every M in the interval Jacobian over the
// box B around the ball B2(c, rho), kappa = Delta / sigma < 1, and eta >= ||G(c)||_2, then the map
// x - A^-1 G(x) sends B2(c, rho) into itself when eta / sigma + kappa rho <= rho, and contracts
// it: exactly one zero of G in B2(c, rho), within eta / (sigma (1 - kappa)) of c.
// Delta is bounded by sqrt(||D||_1 ||D||_inf) for D = |[J(B)] - A| entrywise.
//
// Quadratic systems first get the anchored form of that test (below): one factorization per
// step, at its midpoint, with the tangent and the curvature there, for the whole step at once;
// the piecewise test above takes what it leaves.
#include <Eigen/SparseLU>
#include <algorithm>
#include <cmath>
#include <memory>

#include "engine/interval/krawczyk_common.h"
#include "engine/interval/verified.h"

namespace flexure::engine::certify::detail {

namespace {

// An upper bound of the square root of a sum of squares s (whose lower end may be below 0 by
// rounding); infinity when s is not finite (a NaN must not pass as 0).
double rootUp(const Interval& s) {
  if (!(s.hi <= std::numeric_limits<double>::max())) return std::numeric_limits<double>::infinity();
  return sqrt(Interval(0.0, std::max(0.0, s.hi))).hi;
}

// The larger of two upper bounds, NaN-safe: a NaN makes the result infinite.
double maxUp(double a, double b) {
  if (std::isnan(a) || std::isnan(b)) return std::numeric_limits<double>::infinity();
  return std::max(a, b);
}

// The largest coordinate of v in magnitude.
int largestCoordinate(const Vector& v) {
  int j = 0;
  for (int i = 1; i < v.size(); ++i)
    if (std::abs(v[i]) > std::abs(v[j])) j = i;
  return j;
}

// A = [J; e_j^T] from the Jacobian's enclosure at a point (its midpoints). Empty when an entry
// of J appears twice (the spread below compares entry by entry).
SparseMatrix squareMatrix(const Enclosure& at, int N, int m, int j) {
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(at.J.size() + 1);
  for (const auto& en : at.J) t.emplace_back(en.row, en.column, en.value.mid());
  t.emplace_back(m, j, 1.0);
  SparseMatrix A(N, N);
  A.setFromTriplets(t.begin(), t.end());
  if (A.nonZeros() != static_cast<long>(t.size())) return SparseMatrix();
  return A;
}

// Upper bounds of matrix 2-norms from entrywise magnitudes: sqrt(||D||_1 ||D||_inf).
class NormFromEntries {
 public:
  explicit NormFromEntries(int n) : rows_(static_cast<size_t>(n), Interval(0.0)), columns_(rows_) {}
  void add(int row, int column, double magnitude) {
    rows_[static_cast<size_t>(row)] += Interval(magnitude);
    columns_[static_cast<size_t>(column)] += Interval(magnitude);
  }
  double bound() const {
    double r = 0, c = 0;
    for (const Interval& x : rows_) r = maxUp(r, x.hi);
    for (const Interval& x : columns_) c = maxUp(c, x.hi);
    return rootUp(Interval(r) * Interval(c));
  }

 private:
  std::vector<Interval> rows_, columns_;
};

// An upper bound of ||M - A||_2 over M in [J(box); e_j^T] (the slice row is exact).
double spread(const Enclosure& box, const SparseMatrix& A, int N) {
  NormFromEntries d(N);
  for (const auto& en : box.J) d.add(en.row, en.column, (en.value - Interval(A.coeff(en.row, en.column))).mag());
  return d.bound();
}

// An upper bound of the 2-norm of the magnitudes of v.
double norm2(const IVec& v) {
  Interval s(0.0);
  for (const Interval& x : v) s += Interval(x.mag()) * Interval(x.mag());
  return rootUp(s);
}

// A piece's centres x_s = xm + (s - sm) t (exact, as the test means them), enclosed.
struct Centres {
  Vector xm, t;
  double sm = 0;
  IVec at(double s) const {
    IVec c(static_cast<size_t>(xm.size()));
    const Interval ds = Interval(s) - Interval(sm);
    for (int k = 0; k < xm.size(); ++k) c[static_cast<size_t>(k)] = Interval(xm[k]) + ds * Interval(t[k]);
    return c;
  }
};

// An upper bound of ||x - y||_2 over the enclosures.
double distance(const IVec& x, const IVec& y) {
  Interval s(0.0);
  for (size_t i = 0; i < x.size(); ++i) {
    const Interval d = x[i] - y[i];
    s += Interval(d.mag()) * Interval(d.mag());
  }
  return rootUp(s);
}

double up(const Interval& x) { return x.hi; }

// The test above: true when it holds with contraction kappa <= 7/8; `existence` receives the
// radius eta / (sigma (1 - kappa)) within which the zero lies.
bool holds(double eta, double sigma, double delta, double rho, double& existence) {
  const Interval kappa = Interval(delta) / Interval(sigma);
  if (!(kappa.hi <= kContraction)) return false;
  const Interval e0 = Interval(eta) / Interval(sigma);
  if (!((e0 + kappa * Interval(rho)).hi <= rho)) return false;
  existence = (e0 / (Interval(1.0) - kappa)).hi;
  return true;
}

// Simplified Newton in double on [F(x); x_j - s] from x, with x_j = s held: `lu` factors the
// sliced Jacobian at the first point (false when singular), and stays for the tangent there.
bool refineInSlice(const ConstraintSystem& sys, Vector& x, int j, double s, Eigen::SparseLU<SparseMatrix>& lu) {
  const int N = sys.numVariables(), m = sys.numEquations();
  x[j] = s;
  SparseMatrix G = sys.jacobian(x);
  G.conservativeResize(N, N);
  G.insert(m, j) = 1.0;
  G.makeCompressed();
  lu.compute(G);
  if (lu.info() != Eigen::Success) return false;
  double last = std::numeric_limits<double>::infinity();
  for (int it = 0; it < 12; ++it) {
    Vector rhs = Vector::Zero(N);
    rhs.head(m) = sys.residuals(x);
    // Diverging (no point of the curve near: two branches, or a step too long): stop there, and
    // the test on that point says no.
    const double size = rhs.norm();
    if (!(size <= 2 * last)) return true;
    last = size;
    const Vector dx = lu.solve(rhs);
    if (!dx.allFinite()) return true;
    x -= dx;
    x[j] = s;
    if (!(dx.cwiseAbs().maxCoeff() > 1e-15 * (1 + x.cwiseAbs().maxCoeff()))) return true;
  }
  return true;
}

const char* const kSingular =
    "the sliced Jacobian is singular or too close to it to be proved regular (a singular point, or redundant "
    "constraints)";

}  // namespace

double certifySampleSparse(const Model& model, const Vector& x, const Vector& direction, std::string& why,
                           double* estimate) {
  const ConstraintSystem& sys = model.system();
  const int N = sys.numVariables(), m = sys.numEquations();
  if (m + 1 != N) {
    why = std::to_string(N - m) + " degrees of freedom: the sparse test certifies a curve with its trivial motions "
          "fixed by pins (and no redundant constraint)";
    return kNaN;
  }
  const int j = largestCoordinate(direction);
  // The test is centred on the curve's point in the slice, refined by Newton in double from the
  // sample (whose residual, the tracker's tolerance, divided by a small singular value would
  // leave no room for the test); the ball is then made to hold the max-norm ball around the
  // sample.
  Vector xr = x;
  Eigen::SparseLU<SparseMatrix> lu;
  refineInSlice(sys, xr, j, x[j], lu);
  const Enclosure at = enclose(model, pointBox(xr));
  for (const Interval& f : at.F)
    if (!f.finite()) {
      why = "the constraints are not finite there";
      return kNaN;
    }
  const SparseMatrix A = squareMatrix(at, N, m, j);
  const std::optional<double> sigma = A.size() ? verified::smallestSingularValueLowerBound(A, estimate) : std::nullopt;
  if (!sigma) {
    why = kSingular;
    return kNaN;
  }
  const double eta = norm2(at.F), scale = configurationScale(sys, x);
  const double e0 = up(Interval(eta) / Interval(*sigma));
  double shift_inf = 0;  // |xr - x| in max norm, and in the 2-norm
  for (int k = 0; k < N; ++k) shift_inf = std::max(shift_inf, (Interval(xr[k]) - Interval(x[k])).mag());
  const double shift_2 = distance(pointBox(xr), pointBox(x));
  if (up(Interval(shift_inf) + Interval(e0)) > kMaxRelativeRadius * scale) {
    why = "the norm test bounds the sample's distance from the curve only by " +
          shortNumber(up(Interval(shift_inf) + Interval(e0))) + ", more than the certified accuracy (" +
          shortNumber(kMaxRelativeRadius) +
          " of the configuration's size): an inaccurate sample, or a nearly singular point";
    return kNaN;
  }
  // Exactly one zero in B2(xr, rho), within `existence` of xr; B2(xr, rho) holds the max-norm
  // ball of radius r around x when rho >= sqrt(N) r + |xr - x|_2; the zero is within r of x when
  // |xr - x|_inf + existence <= r.
  const double sqrtN = sqrt(Interval(static_cast<double>(N))).hi;
  for (double r = up(Interval(shift_inf) + Interval(2.0) * Interval(e0)) + 1e-15 * scale; r <= kMaxRelativeRadius * scale;
       r *= 1.5) {
    const double rho = up(Interval(sqrtN) * Interval(r) + Interval(shift_2));
    double existence = 0;
    if (holds(eta, *sigma, spread(enclose(model, pointBox(xr, rho)), A, N), rho, existence) &&
        up(Interval(shift_inf) + Interval(existence)) <= r)
      return r;
  }
  // e0 is a bound (the residual over a lower bound of the smallest singular value), not a distance.
  why = "the norm test fails: it bounds the sample's distance from the curve by " +
        shortNumber(up(Interval(shift_inf) + Interval(e0))) + " (the residual over the sliced Jacobian's smallest "
        "singular value, proved at least " + shortNumber(*sigma) +
        "), too coarse to prove one zero nearby (an ill-conditioned system or a nearby singular point; a more accurate "
        "sample may pass)";
  return kNaN;
}

bool certifyStepSparse(const Model& model, const Vector& a, const Vector& b, double ra, double rb, std::string& why,
                       int& pieces, double* estimate, const std::function<bool()>* keep_going) {
  const ConstraintSystem& sys = model.system();
  const int N = sys.numVariables(), m = sys.numEquations();
  if (m + 1 != N) {
    why = std::to_string(N - m) + " degrees of freedom: the sparse test certifies a curve with its trivial motions "
          "fixed by pins (and no redundant constraint)";
    return false;
  }
  const int j = largestCoordinate(b - a);
  if (!(a[j] != b[j])) {
    why = "two equal samples";
    return false;
  }
  const double sqrtN = sqrt(Interval(static_cast<double>(N))).hi;
  const double r = std::max(ra, rb);
  // The parameter s = x_j over the samples' values and their uncertainty; the sample at the low
  // end is the first piece's, the other the last's.
  const bool rising = a[j] < b[j];
  const Vector& low = rising ? a : b;
  const Vector& high = rising ? b : a;
  const double r_low = rising ? ra : rb, r_high = rising ? rb : ra;
  const double s_lo = (Interval(low[j]) - Interval(r)).lo, s_hi = (Interval(high[j]) + Interval(r)).hi;
  for (int q = std::clamp(pieces / 2, 1, 64); q <= 64; q *= 2) {
    std::vector<double> ends(static_cast<size_t>(q) + 1);
    for (int i = 0; i <= q; ++i) ends[static_cast<size_t>(i)] = i == 0 ? s_lo : i == q ? s_hi : s_lo + (s_hi - s_lo) * i / q;
    bool ok = true;
    Centres prev;               // the previous piece's centres
    double prev_existence = 0;  // and how far from them its zeros may be
    for (int i = 0; i < q && ok; ++i) {
      if (keep_going && *keep_going && !(*keep_going)()) {
        why = "stopped on request";
        return false;
      }
      const Interval S(ends[static_cast<size_t>(i)], ends[static_cast<size_t>(i) + 1]);
      const double sm = S.mid();
      // The arc's point with x_j = sm: Newton in double from the chord (sparse LU).
      const double w = (sm - a[j]) / (b[j] - a[j]);
      Vector xm = a + w * (b - a);
      Eigen::SparseLU<SparseMatrix> lu;
      if (!refineInSlice(sys, xm, j, sm, lu)) {
        ok = false;
        why = kSingular;
        break;
      }
      const Enclosure at = enclose(model, pointBox(xm));
      const SparseMatrix A = squareMatrix(at, N, m, j);
      const std::optional<double> sigma = A.size() ? verified::smallestSingularValueLowerBound(A, estimate) : std::nullopt;
      if (!sigma) {
        ok = false;
        why = kSingular;
        break;
      }
      // The tangent with t_j = 1 (from the Newton's factor, near xm: the direction only places
      // the centres): x_s = xm + (s - sm) t has x_j = s exactly, so the slice row vanishes on them.
      Vector t = lu.solve(Vector::Unit(N, m));
      if (!t.allFinite()) {
        ok = false;
        why = kSingular;
        break;
      }
      t[j] = 1.0;
      // G over S at the centres: Taylor in s about sm with the second-order remainder enclosed.
      const Interval ds = S - Interval(sm), ds2(0.0, (Interval(ds.mag()) * Interval(ds.mag())).hi);
      IVec line(static_cast<size_t>(N));
      for (int k = 0; k < N; ++k) line[static_cast<size_t>(k)] = Interval(xm[k]) + ds * Interval(t[k]);
      const IVec second = secondDerivativeAlong(model, line, t);
      IVec g(static_cast<size_t>(m), Interval(0.0)), slope(static_cast<size_t>(m), Interval(0.0));
      for (const auto& en : at.J) slope[static_cast<size_t>(en.row)] += en.value * Interval(t[en.column]);
      for (int k = 0; k < m; ++k)
        g[static_cast<size_t>(k)] = at.F[static_cast<size_t>(k)] + ds * slope[static_cast<size_t>(k)] +
                                    Interval(0.5) * ds2 * second[static_cast<size_t>(k)];
      const double eta = norm2(g);
      // The ball must hold the sample's point (first and last piece) and the previous piece's
      // zero at the shared end.
      double need = up(Interval(2.0) * Interval(eta) / Interval(*sigma));
      const Centres centres{xm, t, sm};
      const double tnorm = norm2(pointBox(t));
      // The sample's point p (within rs of it in max norm: p_j within rs of sample_j, inside S)
      // is the zero at s = p_j: within sqrt(N) rs + |sample - x_{sample_j}| + rs |t| of x_s.
      auto holdsSample = [&](const Vector& sample, double rs) {
        return up(Interval(sqrtN) * Interval(rs) + Interval(distance(pointBox(sample), centres.at(sample[j]))) +
                  Interval(rs) * Interval(tnorm));
      };
      if ((i == 0 && !(S.hi >= up(Interval(low[j]) + Interval(r_low)))) ||
          (i == q - 1 && !(S.lo <= (Interval(high[j]) - Interval(r_high)).lo))) {
        ok = false;
        why = "a step shorter than its samples' radii";
        break;
      }
      if (i == 0) need = std::max(need, holdsSample(low, r_low));
      if (i == q - 1) need = std::max(need, holdsSample(high, r_high));
      // The previous piece's zero at the shared end, within prev_existence of its centre there.
      if (i > 0) need = std::max(need, up(Interval(prev_existence) + Interval(distance(prev.at(S.lo), centres.at(S.lo)))));
      bool passed = false;
      double existence = 0;
      for (double rho = need * 1.01; rho <= 4 * need + 0.25 * (S.hi - S.lo) * tnorm && !passed; rho *= 2) {
        IVec box(line);
        for (Interval& v : box) v += Interval(-rho, rho);
        passed = holds(eta, *sigma, spread(enclose(model, box), A, N), rho, existence);
      }
      if (!passed) {
        ok = false;
        why = "the norm test on the step's box fails (a long step or a nearby singular point)";
        break;
      }
      prev = centres;
      prev_existence = existence;
    }
    if (ok) {
      pieces = q;
      return true;
    }
  }
  return false;
}


// ---------------------------------------------------------------------------------------------
// Quadratic systems: one anchor per step (engine/interval/krawczyk_common.h).
//
// With every constraint of degree at most 2, F(x + u) = F(x) + J(x) u + B(u, u) / 2 and
// J(x + u) = J(x) + B(u, .) exactly, B constant. At the anchor xb (the step's midpoint on the
// curve, x_j = sb) with A ~ G'(xb) in double, the tangent t (A t = e_m: J t ~ 0, t_j = 1) and the
// curvature t2 (A t2 = -B(t, t), t2_j = 0), the centres c(d) = xb + d t + d^2 t2 / 2 follow the
// curve to third order, and for x = c(d) + w:
//   G(c(d)) = r0 + d r1 + d^2 r2 / 2 + d^3 B(t, t2) / 2 + d^4 B(t2, t2) / 8,
//   I - A^-1 G'(x) = A^-1 (A - J(xb)) - d A^-1 B(t, .) - d^2 A^-1 B(t2, .) / 2 - A^-1 B(w, .),
// (r0 = F(xb), r1 = J(xb) t, r2 = J(xb) t2 + B(t, t): residuals of the anchor's own solves). The
// Newton-Kantorovich test of krawczyk_sparse's norm test then runs for every d of the step at
// once with these bounds. The term that decides the step's length, ||A^-1 B(t, .)||, is bounded
// through solves with A (on the rows where B(t, .) is not negligible), not as ||B(t, .)|| /
// sigma_min(A): for a mechanism whose rigid part is soft (sigma_min 1e-3) the two differ by 10^3.
// ---------------------------------------------------------------------------------------------

namespace {

// Every value and Jacobian entry finite (the bounds below take a NaN for no bound at all).
bool finite(const Enclosure& e) {
  for (const Interval& f : e.F)
    if (!f.finite()) return false;
  for (const auto& en : e.J)
    if (!en.value.finite()) return false;
  return true;
}

// Enclosures of B(u, .) entry by entry: J(x + u) - J(x), both enclosed (J is affine); throws
// std::domain_error when they are not finite.
std::vector<JacobianEntry<Interval>> bilinearMatrix(const Model& model, const Vector& x, const Enclosure& at,
                                                    const Vector& u) {
  IVec moved(static_cast<size_t>(x.size()));
  for (int k = 0; k < x.size(); ++k) moved[static_cast<size_t>(k)] = Interval(x[k]) + Interval(u[k]);
  const Enclosure e = enclose(model, moved);
  if (!finite(e)) throw std::domain_error("the constraints are not finite there");
  if (e.J.size() != at.J.size()) throw std::domain_error("the Jacobian's pattern changed between two enclosures");
  std::vector<JacobianEntry<Interval>> out(e.J.size());
  for (size_t i = 0; i < e.J.size(); ++i) {
    if (e.J[i].row != at.J[i].row || e.J[i].column != at.J[i].column)
      throw std::domain_error("the Jacobian's pattern changed between two enclosures");
    out[i] = {e.J[i].row, e.J[i].column, e.J[i].value - at.J[i].value};
  }
  return out;
}

// M v for entries M (rows 0..m-1), enclosed; length m.
IVec times(const std::vector<JacobianEntry<Interval>>& M, int m, const Vector& v) {
  IVec out(static_cast<size_t>(m), Interval(0.0));
  for (const auto& en : M) out[static_cast<size_t>(en.row)] += en.value * Interval(v[en.column]);
  return out;
}

IVec plus(IVec a, const IVec& b) {
  for (size_t i = 0; i < a.size(); ++i) a[i] += b[i];
  return a;
}

}  // namespace

struct QuadraticAnchor {
  int j = 0;
  double sb = 0;
  Vector xb, t, t2;
  SparseMatrix A;
  // A's factors; shared with the next anchor of the same slice, which factors its matrix (of the
  // same pattern) into it after its Newton used it, without a new symbolic analysis.
  std::shared_ptr<Eigen::SparseLU<SparseMatrix>> lu;
  double sigma = 0;  // <= sigma_min(A)
  double e0 = 0;     // >= ||J(xb) - A||_2 (the Jacobian rows; the slice row is exact)
  double beta = 0;   // >= ||A^-1 B(t, .)||_2
  double h2 = 0;     // >= ||B(t2, .)||_2
  double lip = 0;    // >= ||B(w, .)||_2 / ||w||_inf for every w
  double n0 = 0, n1 = 0, n2 = 0;  // >= ||r0||, ||r1||, ||r2||
  double a3 = 0, a4 = 0;          // >= ||A^-1 B(t, t2)||, ||A^-1 B(t2, t2)||

  // An upper bound of ||A^-1 v|| (v: m enclosed Jacobian rows; the slice row 0): the solve in
  // double and its residual over sigma.
  double solveBound(const IVec& v) const {
    const int N = static_cast<int>(A.rows());
    Vector mid = Vector::Zero(N);
    for (size_t i = 0; i < v.size(); ++i) mid[static_cast<Eigen::Index>(i)] = v[i].mid();
    const Vector z = lu->solve(mid);
    if (!z.allFinite()) throw std::domain_error("a solve with the anchor's matrix failed");
    IVec res(static_cast<size_t>(N), Interval(0.0));
    for (size_t i = 0; i < v.size(); ++i) res[i] = v[i];
    for (int c = 0; c < N; ++c)
      for (SparseMatrix::InnerIterator it(A, c); it; ++it) res[static_cast<size_t>(it.row())] -= Interval(it.value()) * Interval(z[c]);
    return up(Interval(norm2(pointBox(z))) + Interval(norm2(res)) / Interval(sigma));
  }
};

namespace {

// An upper bound of ||A^-1 H||_2 for H = B(t, .) (entries, rows 0..m-1 of N columns): the rows
// with the most weight through solves (A Z = the unit vectors of those rows, Z's residual over
// sigma), the others as ||rest|| / sigma. Infinity when that needs more than `max_rows` solves.
double inverseTimesBound(const QuadraticAnchor& q, const std::vector<JacobianEntry<Interval>>& H, int N, int max_rows) {
  // Each row's squared magnitude, and the rows by weight.
  std::vector<double> weight(static_cast<size_t>(N), 0.0);
  for (const auto& en : H) weight[static_cast<size_t>(en.row)] = (Interval(weight[static_cast<size_t>(en.row)]) + Interval(en.value.mag()) * Interval(en.value.mag())).hi;
  std::vector<int> order(static_cast<size_t>(N));
  for (int i = 0; i < N; ++i) order[static_cast<size_t>(i)] = i;
  std::sort(order.begin(), order.end(), [&](int a, int b) { return weight[static_cast<size_t>(a)] > weight[static_cast<size_t>(b)]; });
  // The rest's Frobenius norm from the light end up: keep rows until it is below 1 % of sigma.
  Interval rest(0.0);
  int kept = N;
  for (int k = N - 1; k >= 0; --k) {
    const Interval next = rest + Interval(weight[static_cast<size_t>(order[static_cast<size_t>(k)])]);
    if (rootUp(next) > 0.01 * q.sigma) break;
    rest = next;
    kept = k;
  }
  if (kept > max_rows) return std::numeric_limits<double>::infinity();
  std::vector<int> slot(static_cast<size_t>(N), -1);
  for (int k = 0; k < kept; ++k) slot[static_cast<size_t>(order[static_cast<size_t>(k)])] = k;
  double bound = up(Interval(rootUp(rest)) / Interval(q.sigma));
  if (kept == 0) return bound;
  Matrix unit = Matrix::Zero(N, kept);
  for (int k = 0; k < kept; ++k) unit(order[static_cast<size_t>(k)], k) = 1.0;
  const Matrix Z = q.lu->solve(unit);
  if (!Z.allFinite()) throw std::domain_error("a solve with the anchor's matrix failed");
  // In double with the rounding bounded a priori (an interval per product was most of the
  // anchor's time): a sum of n products in double is within gamma_n of the sum of the
  // magnitudes of the products (Higham 3.1), and a sum of n nonnegative terms computed in
  // double is at least the true sum times (1 - u)^n.
  const double u = std::ldexp(1.0, -53), tiny = 4 * std::numeric_limits<double>::min();
  // For x >= 0 computed in double through `depth` roundings of nonnegative terms: x times
  // factor(depth) (rounded, whose own rounding the + 2 covers), plus depth tiny for underflow,
  // is at least the exact value.
  const auto factor = [&](long depth) {
    return (Interval(1.0) + Interval(2.0 * static_cast<double>(depth + 2)) * Interval(u)).hi;
  };
  const auto upper = [&](double x, long depth) {
    return (Interval(x) * Interval(factor(depth)) + Interval(static_cast<double>(depth + 1)) * Interval(tiny)).hi;
  };
  const auto gamma = [&](long n) {  // gamma_n = n u / (1 - n u), enclosed
    const Interval nu = Interval(static_cast<double>(n)) * Interval(u);
    return nu / (Interval(1.0) - nu);
  };
  // ||Res||_F, Res = the unit vectors - A Z: |Res - fl(Res)| <= gamma_{c+1} (|P| + |A| |Z|), c the
  // longest row of A.
  std::vector<int> row_length(static_cast<size_t>(N), 0);
  for (int c = 0; c < N; ++c)
    for (SparseMatrix::InnerIterator it(q.A, c); it; ++it) ++row_length[static_cast<size_t>(it.row())];
  const long c_len = *std::max_element(row_length.begin(), row_length.end());
  const double g_res = gamma(c_len + 1).hi, f_res = factor(c_len + 1), f_v = factor(3),
               tiny_res = static_cast<double>(c_len + 4) * tiny;
  double res2 = 0;
  Vector y(N), yabs(N);
  for (int k = 0; k < kept; ++k) {
    y.setZero(), yabs.setZero();
    for (int c = 0; c < N; ++c) {
      const double z = Z(c, k);
      if (z == 0) continue;
      for (SparseMatrix::InnerIterator it(q.A, c); it; ++it) {
        y[it.row()] += it.value() * z;
        yabs[it.row()] += std::abs(it.value() * z);
      }
    }
    const int unit_row = order[static_cast<size_t>(k)];
    for (int i = 0; i < N; ++i) {
      const double r = (i == unit_row ? 1.0 : 0.0) - y[i];
      const double v = (std::abs(r) + g_res * ((yabs[i] + (i == unit_row ? 1.0 : 0.0)) * f_res + tiny_res)) * f_v;
      res2 += v * v;
    }
  }
  const double res_norm = rootUp(Interval(upper(res2, static_cast<long>(N) * kept + 4)));
  // M = Z H_kept, a column at a time (the columns H_kept touches): |M| <= |fl(Z mid H)| +
  // |Z| (rad H + gamma_p |mid H|), p the column's terms; its Frobenius norm and its row and
  // column sums; and ||H_kept||_2.
  std::vector<std::vector<std::pair<int, Interval>>> by_column(static_cast<size_t>(N));
  NormFromEntries hk(N);
  for (const auto& en : H)
    if (const int k = slot[static_cast<size_t>(en.row)]; k >= 0) {
      by_column[static_cast<size_t>(en.column)].emplace_back(k, en.value);
      hk.add(en.row, en.column, en.value.mag());
    }
  double frobenius = 0;
  long columns = 0;
  std::vector<double> row_sums(static_cast<size_t>(N), 0.0);
  double column_max = 0;
  Vector mid(N), spread(N);
  for (int c = 0; c < N; ++c) {
    const auto& entries = by_column[static_cast<size_t>(c)];
    if (entries.empty()) continue;
    ++columns;
    const long p = static_cast<long>(entries.size());
    const double g = gamma(p).hi, f_spread = factor(2 * p), f_b = factor(3),
                 tiny_b = static_cast<double>(2 * p + 4) * tiny;
    mid.setZero(), spread.setZero();
    for (const auto& [k, value] : entries) {
      const double hm = value.mid(), hr = (Interval(value.rad()) + Interval(g) * Interval(std::abs(hm))).hi;
      const double* z = Z.col(k).data();
      for (int i = 0; i < N; ++i) {
        mid[i] += z[i] * hm;
        spread[i] += std::abs(z[i]) * hr;
      }
    }
    double column_sum = 0;
    for (int i = 0; i < N; ++i) {
      const double b = (std::abs(mid[i]) + spread[i] * f_spread + tiny_b) * f_b;
      frobenius += b * b;
      column_sum += b;
      row_sums[static_cast<size_t>(i)] += b;
    }
    column_max = maxUp(column_max, upper(column_sum, N));
  }
  double row_max = 0;
  for (double r : row_sums) row_max = maxUp(row_max, r);
  row_max = upper(row_max, columns);
  const double m_norm = std::min(rootUp(Interval(upper(frobenius, static_cast<long>(N) * columns))),
                                 rootUp(Interval(row_max) * Interval(column_max)));
  bound = up(Interval(bound) + Interval(m_norm) + Interval(res_norm) * Interval(hk.bound()) / Interval(q.sigma));
  return bound;
}

}  // namespace

std::shared_ptr<QuadraticAnchor> quadraticAnchor(const Model& model, const Vector& start, int j, double sb,
                                                 const QuadraticAnchor* previous, double* estimate, std::string& why) {
  const ConstraintSystem& sys = model.system();
  const int N = sys.numVariables(), m = sys.numEquations();
  auto q = std::make_shared<QuadraticAnchor>();
  q->j = j;
  q->sb = sb;
  q->xb = start;
  // The curve's point with x_j = sb: simplified Newton with the previous anchor's factor when it
  // slices the same coordinate (one step away: it converges in a few solves), else a fresh one.
  bool refined = false;
  if (previous && previous->j == j) {
    Vector& x = q->xb;
    x[j] = sb;
    double last = std::numeric_limits<double>::infinity();
    for (int it = 0; it < 30; ++it) {
      Vector rhs = Vector::Zero(N);
      rhs.head(m) = sys.residuals(x);
      const double size = rhs.norm();
      if (!(size <= 2 * last)) break;
      last = size;
      const Vector dx = previous->lu->solve(rhs);
      if (!dx.allFinite()) break;
      x -= dx;
      x[j] = sb;
      if (!(dx.cwiseAbs().maxCoeff() > 1e-15 * (1 + x.cwiseAbs().maxCoeff()))) {
        refined = true;
        break;
      }
    }
    if (!refined) q->xb = start;
  }
  if (!refined) {
    Eigen::SparseLU<SparseMatrix> lu;
    if (!refineInSlice(sys, q->xb, j, sb, lu)) {
      why = kSingular;
      return nullptr;
    }
  }
  const Enclosure at = enclose(model, pointBox(q->xb));
  if (!finite(at)) {
    why = "the constraints are not finite there";
    return nullptr;
  }
  q->A = squareMatrix(at, N, m, j);
  if (!q->A.size()) {
    why = kSingular;
    return nullptr;
  }
  if (refined && previous->lu->rows() == N) {
    q->lu = previous->lu;
    q->lu->factorize(q->A);
  } else {
    q->lu = std::make_shared<Eigen::SparseLU<SparseMatrix>>();
    q->lu->compute(q->A);
  }
  const std::optional<double> sigma =
      q->lu->info() == Eigen::Success ? verified::smallestSingularValueLowerBound(q->A, estimate) : std::nullopt;
  if (!sigma) {
    why = kSingular;
    return nullptr;
  }
  q->sigma = *sigma;
  NormFromEntries e0(N);
  for (const auto& en : at.J) e0.add(en.row, en.column, (en.value - Interval(q->A.coeff(en.row, en.column))).mag());
  q->e0 = e0.bound();
  q->t = q->lu->solve(Vector::Unit(N, m));
  if (!q->t.allFinite()) {
    why = kSingular;
    return nullptr;
  }
  q->t[j] = 1.0;
  // B(t, .) and B(t2, .) as matrices (J is affine): B(t, t) = B(t, .) t and so on, without a
  // second-derivative pass per pair.
  const std::vector<JacobianEntry<Interval>> H = bilinearMatrix(model, q->xb, at, q->t);
  const IVec btt = times(H, m, q->t);
  Vector rhs = Vector::Zero(N);
  for (int k = 0; k < m; ++k) rhs[k] = -btt[static_cast<size_t>(k)].mid();
  q->t2 = q->lu->solve(rhs);
  if (!q->t2.allFinite()) {
    why = kSingular;
    return nullptr;
  }
  q->t2[j] = 0.0;
  const std::vector<JacobianEntry<Interval>> H2 = bilinearMatrix(model, q->xb, at, q->t2);
  q->n0 = norm2(at.F);
  q->n1 = norm2(times(at.J, m, q->t));
  q->n2 = norm2(plus(times(at.J, m, q->t2), btt));
  q->a3 = q->solveBound(times(H, m, q->t2));
  q->a4 = q->solveBound(times(H2, m, q->t2));
  NormFromEntries h2(N);
  for (const auto& en : H2) h2.add(en.row, en.column, en.value.mag());
  q->h2 = h2.bound();
  // B(w, .) over the unit max-norm box: J over xb + [-1, 1]^N minus J(xb). B is the same at
  // every point: the previous anchor's bound (of the same model) holds here.
  if (previous) {
    q->lip = previous->lip;
  } else {
    NormFromEntries lip(N);
    const Enclosure unit = enclose(model, pointBox(q->xb, 1.0));
    if (!finite(unit)) throw std::domain_error("the constraints are not finite there");
    if (unit.J.size() != at.J.size()) throw std::domain_error("the Jacobian's pattern changed between two enclosures");
    for (size_t i = 0; i < unit.J.size(); ++i) {
      if (unit.J[i].row != at.J[i].row || unit.J[i].column != at.J[i].column)
        throw std::domain_error("the Jacobian's pattern changed between two enclosures");
      lip.add(unit.J[i].row, unit.J[i].column, (unit.J[i].value - at.J[i].value).mag());
    }
    q->lip = lip.bound();
  }
  // At most 4,000 solves, and Z (N x rows, dense) within 2 * 10^7 numbers.
  q->beta = inverseTimesBound(*q, H, N, std::min({std::max(64, N / 8), 4000, 20000000 / std::max(N, 1)}));
  return q;
}

namespace {

// The anchor's centre c(d), enclosed (d may be an interval).
IVec anchorCentre(const QuadraticAnchor& q, const Interval& d) {
  IVec c(static_cast<size_t>(q.xb.size()));
  const Interval half_d2 = Interval(0.5) * d * d;
  for (int k = 0; k < q.xb.size(); ++k)
    c[static_cast<size_t>(k)] = Interval(q.xb[k]) + d * Interval(q.t[k]) + half_d2 * Interval(q.t2[k]);
  return c;
}

// The test of the block comment for |d| <= dmax, with the centres `offset` (2-norm) from where
// the ball is centred: true with the smallest radius rho >= need that passes and the distance
// of the zero from the centre (`existence`).
bool anchoredTest(const QuadraticAnchor& q, double eta, double dmax, double offset, double need, double& rho_out,
                  double& existence) {
  const Interval D(dmax), sigma(q.sigma);
  const Interval kappa0 = Interval(q.e0) / sigma + D * Interval(q.beta) + Interval(0.5) * D * D * Interval(q.h2) / sigma +
                          Interval(q.lip) * Interval(offset) / sigma;
  if (!(kappa0.hi < kContraction)) return false;
  // The smallest rho with eta + (kappa0 + lip rho / sigma) rho <= rho, then checked in intervals.
  const double a = (Interval(q.lip) / sigma).hi, b = 1 - kappa0.hi;
  const double disc = b * b - 4 * a * eta;
  if (!(disc >= 0)) return false;
  double rho = std::max(need, a > 0 ? (b - std::sqrt(disc)) / (2 * a) : eta / b);
  for (int attempt = 0; attempt < 8; ++attempt, rho = std::max(rho * 1.25, need)) {
    const Interval kappa = kappa0 + Interval(q.lip) * Interval(rho) / sigma;
    if (!(kappa.hi <= kContraction)) return false;
    if ((Interval(eta) + kappa * Interval(rho)).hi <= rho) {
      rho_out = rho;
      existence = (Interval(eta) / (Interval(1.0) - kappa)).hi;
      return true;
    }
  }
  return false;
}

}  // namespace

double anchoredSampleRadius(const Model& model, const QuadraticAnchor& q, const Vector& x, std::string& why) {
  const ConstraintSystem& sys = model.system();
  const int N = sys.numVariables();
  const IVec g = encloseResiduals(model, pointBox(x));
  for (const Interval& f : g)
    if (!f.finite()) {
      why = "the constraints are not finite there";
      return kNaN;
    }
  const double eta = q.solveBound(g);  // the slice row x_j - x_j = 0
  const Interval d = Interval(x[q.j]) - Interval(q.sb);
  const double offset = distance(pointBox(x), anchorCentre(q, d));
  const double scale = configurationScale(sys, x), sqrtN = sqrt(Interval(static_cast<double>(N))).hi;
  // Existence within r, and uniqueness in the 2-ball of radius sqrt(N) r, which holds the
  // max-norm ball of radius r.
  double rho = 0, existence = 0;
  if (!anchoredTest(q, eta, d.mag(), offset, 0, rho, existence)) {
    why = "the anchored test fails at the sample";
    return kNaN;
  }
  const double r = std::max(1.01 * existence, 1e-300);
  if (!anchoredTest(q, eta, d.mag(), offset, up(Interval(sqrtN) * Interval(r)), rho, existence) || existence > r) {
    why = "the anchored test fails at the sample";
    return kNaN;
  }
  if (r > kMaxRelativeRadius * scale) {
    why = "the anchored test bounds the sample's distance from the curve only by " + shortNumber(r) +
          ", more than the certified accuracy (" +
          shortNumber(kMaxRelativeRadius) + " of the configuration's size)";
    return kNaN;
  }
  return r;
}

bool anchoredStep(const Model& model, const QuadraticAnchor& q, const Vector& a, const Vector& b, double ra, double rb,
                  std::string& why) {
  const int N = model.system().numVariables();
  const int j = q.j;
  const double sqrtN = sqrt(Interval(static_cast<double>(N))).hi;
  // Every d of the step: the samples' parameters and their points' uncertainty.
  const Interval da = Interval(a[j]) - Interval(q.sb) + Interval(-ra, ra);
  const Interval db = Interval(b[j]) - Interval(q.sb) + Interval(-rb, rb);
  const double dmax = std::max(da.mag(), db.mag());
  const Interval D(dmax), D2 = D * D, sigma(q.sigma);
  const double eta =
      up((Interval(q.n0) + D * Interval(q.n1) + Interval(0.5) * D2 * Interval(q.n2)) / sigma +
         Interval(0.5) * D2 * D * Interval(q.a3) + Interval(0.125) * D2 * D2 * Interval(q.a4));
  // A sample's point p (within r of it in max norm, p_j within r of its x_j) is the zero at
  // d = p_j - sb: within sqrt(N) r + |sample - c(d)| of the centre there.
  const auto need = [&](const Vector& x, const Interval& d, double r) {
    return up(Interval(sqrtN) * Interval(r) + Interval(distance(pointBox(x), anchorCentre(q, d))));
  };
  double rho = 0, existence = 0;
  if (!anchoredTest(q, eta, dmax, 0, std::max(need(a, da, ra), need(b, db, rb)), rho, existence)) {
    why = "the anchored test fails on the step's box";
    return false;
  }
  return true;
}

void certifyQuadraticPath(const DeformationPath& path, int min_variables, int max_variables,
                          std::vector<double>& radii, std::vector<char>& steps, double* estimate,
                          const std::function<bool()>& stop) {
  std::shared_ptr<QuadraticAnchor> previous;
  const Model* previous_model = nullptr;
  for (size_t k = 0; k + 1 < path.samples.size(); ++k) {
    if (stop()) return;
    const Model& model = path.modelAt(static_cast<int>(k) + 1);
    const ConstraintSystem& sys = model.system();
    const int N = sys.numVariables();
    if (&path.modelAt(static_cast<int>(k)) != &model || N < min_variables || N > max_variables ||
        sys.numEquations() + 1 != N || !model.quadraticConstraints())
      continue;
    const Vector& a = path.samples[k];
    const Vector& b = path.samples[k + 1];
    // The slice's coordinate: the one the step moves most, or the previous anchor's when it moves
    // at least half as much (its factorization then starts this anchor's Newton).
    int j = largestCoordinate(b - a);
    if (previous && previous_model == &model && std::abs(b[previous->j] - a[previous->j]) >= 0.5 * std::abs(b[j] - a[j]))
      j = previous->j;
    if (!(a[j] != b[j])) continue;
    try {
      std::string why;
      const Vector start = 0.5 * (a + b);
      const std::shared_ptr<QuadraticAnchor> q = quadraticAnchor(
          model, start, j, start[j], previous_model == &model ? previous.get() : nullptr, estimate, why);
      if (!q) continue;
      previous = q;
      previous_model = &model;
      for (size_t s : {k, k + 1})
        if (std::isnan(radii[s])) radii[s] = anchoredSampleRadius(model, *q, path.samples[s], why);
      if (!std::isnan(radii[k]) && !std::isnan(radii[k + 1]))
        steps[k] = anchoredStep(model, *q, a, b, radii[k], radii[k + 1], why);
    } catch (const std::domain_error&) {
      // Left to the general tests, which give the reason.
    }
  }
}

}  // namespace flexure::engine::certify::detail
