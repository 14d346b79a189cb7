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
#include <Eigen/SparseLU>
#include <algorithm>
#include <cmath>

#include "engine/interval/krawczyk_common.h"
#include "engine/interval/verified.h"

namespace flexure::engine::certify::detail {

namespace {

// An upper bound of the square root of a sum of squares s (whose lower end may be below 0 by
// rounding).
double rootUp(const Interval& s) { return sqrt(Interval(0.0, std::max(0.0, s.hi))).hi; }

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

// An upper bound of ||M - A||_2 over M in [J(box); e_j^T] (the slice row is exact).
double spread(const Enclosure& box, const SparseMatrix& A, int N) {
  std::vector<Interval> rows(static_cast<size_t>(N), Interval(0.0)), columns(static_cast<size_t>(N), Interval(0.0));
  for (const auto& en : box.J) {
    const Interval d(Interval(en.value - Interval(A.coeff(en.row, en.column))).mag());
    rows[static_cast<size_t>(en.row)] += d;
    columns[static_cast<size_t>(en.column)] += d;
  }
  double r = 0, c = 0;
  for (int i = 0; i < N; ++i) {
    r = std::max(r, rows[static_cast<size_t>(i)].hi);
    c = std::max(c, columns[static_cast<size_t>(i)].hi);
  }
  return rootUp(Interval(r) * Interval(c));
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
  for (int it = 0; it < 12; ++it) {
    Vector rhs = Vector::Zero(N);
    rhs.head(m) = sys.residuals(x);
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
    why = "the sample may be " + shortNumber(up(Interval(shift_inf) + Interval(e0))) +
          " from the curve, more than the certified accuracy (" + shortNumber(kMaxRelativeRadius) +
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
  why = "the norm test fails: the sample is about " + shortNumber(up(Interval(shift_inf) + Interval(e0))) +
        " from the curve where the sliced Jacobian's smallest singular value is only " + shortNumber(*sigma) +
        " (an ill-conditioned system or a nearby singular point; a more accurate sample may pass)";
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

}  // namespace flexure::engine::certify::detail
