#include "engine/interval/krawczyk.h"

#include <Eigen/LU>
#include <Eigen/SVD>
#include <Eigen/QR>
#include <unsupported/Eigen/MatrixFunctions>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "engine/evaluate_in.h"
#include "engine/factorization.h"
#include "engine/flex_space.h"
#include "engine/interval/interval.h"
#include "engine/interval/krawczyk_common.h"

namespace flexure::engine::certify {

namespace detail {

namespace {

// The system's blocks at the free coordinates `free` (pinned blocks at their points), and the
// start's, as evaluateSystemIn takes them.
template <class T, class Free>
void blockPositions(const Model& model, const Free& free, std::vector<T>& pos, std::vector<T>& start_pos) {
  const ConstraintSystem& sys = model.system();
  const int d = sys.dimension();
  const Matrix pinned = sys.positions(Vector::Zero(sys.numVariables()));
  const Matrix& start = model.startPositions();
  pos.assign(static_cast<size_t>(sys.numBlocks() * d), T(0.0));
  start_pos.assign(pos.size(), T(0.0));
  for (int b = 0; b < sys.numBlocks(); ++b)
    for (int k = 0; k < d; ++k) {
      const int v = sys.variableIndex(b, k);
      pos[static_cast<size_t>(b * d + k)] = v >= 0 ? T(free[v]) : T(pinned(k, b));
      start_pos[static_cast<size_t>(b * d + k)] = T(start(k, b));
    }
}

}  // namespace

Enclosure enclose(const Model& model, const IVec& free) {
  IVec pos, start_pos;
  blockPositions(model, free, pos, start_pos);
  Enclosure e;
  e.F = evaluateSystemIn(model.system(), start_pos, pos, &e.J);
  return e;
}

IVec encloseResiduals(const Model& model, const IVec& free) {
  IVec pos, start_pos;
  blockPositions(model, free, pos, start_pos);
  return evaluateSystemIn(model.system(), start_pos, pos);
}

Matrix jacobianAt(const Model& model, const Vector& x) {
  std::vector<double> pos, start_pos;
  blockPositions(model, x, pos, start_pos);
  std::vector<JacobianEntry<double>> entries;
  evaluateSystemIn(model.system(), start_pos, pos, &entries);
  Matrix J = Matrix::Zero(model.system().numEquations(), model.system().numVariables());
  for (const auto& en : entries) J(en.row, en.column) += en.value;
  return J;
}

IVec encloseAlong(const Model& model, const IVec& free, const Vector& direction, IVec& slope) {
  const ConstraintSystem& sys = model.system();
  const int d = sys.dimension();
  IVec pos, start_pos;
  blockPositions(model, free, pos, start_pos);
  IVec F(static_cast<size_t>(sys.numEquations()), Interval(0.0));
  slope.assign(F.size(), Interval(0.0));
  std::vector<Dual<Interval>> local0, local, res;
  for (size_t i = 0; i < sys.activeTerms().size(); ++i) {
    const ConstraintTerm& t = *sys.terms()[static_cast<size_t>(sys.activeTerms()[i])];
    const size_t n = t.blocks().size() * static_cast<size_t>(d);
    local0.resize(n), local.resize(n), res.resize(static_cast<size_t>(t.numResiduals()));
    size_t c = 0;
    for (int b : t.blocks())
      for (int k = 0; k < d; ++k, ++c) {
        const int v = sys.variableIndex(b, k);
        const size_t at = static_cast<size_t>(b * d + k);
        local0[c] = Dual<Interval>(start_pos[at]);
        local[c] = Dual<Interval>(pos[at], Interval(v >= 0 ? direction[v] : 0.0));
      }
    termResidual(t, local0.data(), local.data(), d, res.data());
    for (int r = 0; r < t.numResiduals(); ++r) {
      const size_t row = static_cast<size_t>(sys.rowOffset(static_cast<int>(i)) + r);
      F[row] = res[static_cast<size_t>(r)].v;
      slope[row] = res[static_cast<size_t>(r)].a;
    }
  }
  return F;
}

IVec pointBox(const Vector& x, double r) {
  IVec out(static_cast<size_t>(x.size()));
  for (int i = 0; i < x.size(); ++i)
    out[static_cast<size_t>(i)] = r == 0 ? Interval(x[i]) : Interval(x[i]) + Interval(-r, r);
  return out;
}

double configurationScale(const ConstraintSystem& sys, const Vector& x) {
  const Matrix p = sys.vertexPositions(x);
  return std::max(1e-300, (p.rowwise().maxCoeff() - p.rowwise().minCoeff()).maxCoeff());
}

// Enclosures of d^T H_i d over a box for every equation i (H_i its Hessian): the second-order
// term of F along a line, through the terms' jets.
IVec secondDerivativeAlong(const Model& model, const IVec& free, const Vector& direction) {
  const ConstraintSystem& sys = model.system();
  const int d = sys.dimension();
  const Matrix pinned = sys.positions(Vector::Zero(sys.numVariables()));
  const Matrix& start = model.startPositions();
  IVec out(static_cast<size_t>(sys.numEquations()), Interval(0.0));
  IVec local0, local, u, res;
  for (size_t i = 0; i < sys.activeTerms().size(); ++i) {
    const ConstraintTerm& t = *sys.terms()[static_cast<size_t>(sys.activeTerms()[i])];
    const size_t n = t.blocks().size() * static_cast<size_t>(d);
    local0.resize(n), local.resize(n), u.resize(n), res.resize(static_cast<size_t>(t.numResiduals()));
    size_t c = 0;
    for (int b : t.blocks())
      for (int k = 0; k < d; ++k, ++c) {
        const int v = sys.variableIndex(b, k);
        local0[c] = Interval(start(k, b));
        local[c] = v >= 0 ? free[static_cast<size_t>(v)] : Interval(pinned(k, b));
        u[c] = Interval(v >= 0 ? direction[v] : 0.0);
      }
    termSecondDerivative(t, local0.data(), local.data(), u.data(), u.data(), d, res.data());
    for (int r = 0; r < t.numResiduals(); ++r) out[static_cast<size_t>(sys.rowOffset(static_cast<int>(i)) + r)] = res[static_cast<size_t>(r)];
  }
  return out;
}

}  // namespace detail

namespace {

using namespace detail;

// The Krawczyk test for the square system whose Jacobian over the box is [J(box); R] (J from
// `e`, R dense rows of constants) with preconditioner A and value enclosure g at the box's
// centre (over the whole parameter range): true when every |K_i| < 7/8 for the box of radius r.
// `bound` (if given) receives the bounds |K_i|: the zero lies within r bound_i of the centre.
// In midpoint-radius form, in double (an interval per product was most of a certified track's
// time): with G = [J; R] = Gm +- Gr entrywise, |I - A G| <= |I - fl(A Gm)| + |A| Gr plus the
// products' rounding, gamma_{k+1} (I + |A| |Gm|) for k terms per entry (Higham 3.5); sums of
// nonnegative terms computed in double are then inflated by (1 + 2 (n + 2) u) for n roundings.
bool contracts(const Matrix& A, const Enclosure& e, const Matrix& R, const IVec& g, double r,
               std::vector<double>* bound = nullptr) {
  const int N = static_cast<int>(A.rows()), m = N - static_cast<int>(R.rows());
  const double u = std::ldexp(1.0, -53), tiny = 4 * std::numeric_limits<double>::min();
  const auto inflation = [&](long n) { return (Interval(1.0) + Interval(2.0 * static_cast<double>(n + 2)) * Interval(u)).hi; };
  const auto gamma = [&](long n) {
    const Interval nu = Interval(static_cast<double>(n)) * Interval(u);
    return (nu / (Interval(1.0) - nu)).hi;
  };
  // C = A Gm, D = |A| |Gm|, E = |A| Gr, column by column from G's entries.
  Matrix C = Matrix::Zero(N, N), D = Matrix::Zero(N, N), E = Matrix::Zero(N, N);
  std::vector<int> terms(static_cast<size_t>(N), 0);  // per column of G
  for (const auto& en : e.J) {
    const double gm = en.value.mid(), gr = en.value.rad();
    ++terms[static_cast<size_t>(en.column)];
    for (int i = 0; i < N; ++i) {
      const double a = A(i, en.row);
      C(i, en.column) += a * gm;
      D(i, en.column) += std::abs(a * gm);
      E(i, en.column) += std::abs(a) * gr;
    }
  }
  for (int l = 0; l < R.rows(); ++l)
    for (int j = 0; j < N; ++j)
      if (R(l, j) != 0) {
        ++terms[static_cast<size_t>(j)];
        for (int i = 0; i < N; ++i) {
          C(i, j) += A(i, m + l) * R(l, j);
          D(i, j) += std::abs(A(i, m + l) * R(l, j));
        }
      }
  const long k = *std::max_element(terms.begin(), terms.end());
  const double g_k = gamma(k + 1), f_k = inflation(k + 1), f_row = inflation(N + 4);
  // |A g| <= |A mid(g)| + |A| rad(g) + gamma_N |A| |mid(g)|.
  const double g_n = gamma(N + 1), f_n = inflation(N + 1);
  if (bound) bound->assign(static_cast<size_t>(N), 0.0);
  for (int i = 0; i < N; ++i) {
    double am = 0, ar = 0;
    for (int j = 0; j < N; ++j) {
      const Interval& gj = g[static_cast<size_t>(j)];
      if (gj.lo == 0 && gj.hi == 0) continue;
      const double a = A(i, j), gm = gj.mid();
      am += a * gm;
      ar += std::abs(a) * gj.rad() + g_n * std::abs(a * gm);
    }
    const double ag = (std::abs(am) + ar * f_n + static_cast<double>(N + 2) * tiny) * f_n;
    // Row i of |I - A G|.
    double row = 0;
    for (int j = 0; j < N; ++j) {
      const double c = (i == j ? 1.0 : 0.0) - C(i, j);
      row += std::abs(c) + g_k * ((i == j ? 1.0 : 0.0) + D(i, j) * f_k + tiny) + E(i, j) * f_k + tiny;
    }
    row *= f_row;
    const Interval b = Interval(ag) / Interval(r) + Interval(row);
    if (!(b.hi < kContraction)) return false;
    if (bound) (*bound)[static_cast<size_t>(i)] = b.hi;
  }
  return true;
}

// [J; R] inverted (empty when singular or too close to it).
Matrix invertedSquare(const Matrix& G) {
  Eigen::PartialPivLU<Matrix> lu(G);
  // Singular, or too close to it for the test to pass: the reciprocal condition number (the
  // determinant would overflow or underflow for large systems).
  const Vector pivots = lu.matrixLU().diagonal().cwiseAbs();
  if (!pivots.allFinite() || !(pivots.minCoeff() > 1e-14 * pivots.maxCoeff())) return {};
  if (!(lu.rcond() > 1e-14)) return {};
  Matrix A = lu.inverse();
  if (!A.allFinite()) return {};
  return A;
}

// [J; R] inverted, J the Jacobian in double at a point (jacobianAt: the enclosures' formulas,
// without row weights) (empty when singular).
Matrix preconditioner(const Matrix& J, const Matrix& R) {
  Matrix G(J.rows() + R.rows(), J.cols());
  G << J, R;
  return invertedSquare(G);
}

// The same from the Jacobian in double at a point (approximations only: Newton's iterate).
Matrix preconditioner(const ConstraintSystem& sys, const Vector& x, const Matrix& R) {
  Matrix G = Matrix::Zero(sys.numVariables(), sys.numVariables());
  G.topRows(sys.numEquations()) = Matrix(sys.jacobian(x));
  G.bottomRows(R.rows()) = R;
  return invertedSquare(G);
}

// Why [J; R] (`what`: "the sliced Jacobian") could not be inverted: a singular matrix (a
// singular point), or one that is regular once each row is scaled to 1 but whose rows differ so
// much in size (the constraints' at the configuration's scale against the slice's unit rows)
// that double precision cannot invert it: then the conditioning is said, not a singular point.
std::string notInverted(const Matrix& J, const Matrix& R, const std::string& what) {
  Matrix G(J.rows() + R.rows(), J.cols());
  G << J, R;
  const Vector rows = G.rowwise().lpNorm<Eigen::Infinity>();
  if (G.allFinite() && rows.size() > 0 && rows.minCoeff() > 0) {
    const Matrix scaled = rows.cwiseInverse().asDiagonal() * G;
    if (invertedSquare(scaled).size() > 0)
      // By its order of magnitude, so that the samples of one path give one reason.
      return what + " is too ill-conditioned to invert in double precision: its rows differ in size by a factor of "
             "about 1e" + std::to_string(static_cast<int>(std::lround(std::log10(rows.maxCoeff()) - std::log10(rows.minCoeff())))) +
             " (the constraints at the configuration's scale against the slice's unit rows), though it is regular "
             "with each row scaled to 1: not a singular point (rescale the scene's coordinates)";
  }
  return "a singular point: " + what + " is singular (or too close to it for double precision)";
}

double certifyInSlice(const Model& model, const Vector& x, const IVec& F, const Matrix& J, const Matrix& R,
                      const IVec& rows_at_x, std::string& why);

// A sample's radius (NaN: not certified, with `why`).
double certifySample(const Model& model, const Vector& x, std::string& why) {
  const ConstraintSystem& sys = model.system();
  const int N = sys.numVariables(), m = sys.numEquations();
  const IVec F = encloseResiduals(model, pointBox(x));
  for (const Interval& f : F)
    if (!f.finite()) {
      why = "the constraints are not finite there";
      return kNaN;
    }
  // The rank and an orthonormal basis of the kernel from a rank-revealing QR of J^T, J in double
  // (the numbers only choose the slices; the test proves what it proves whatever they are).
  const Matrix J = jacobianAt(model, x);
  if (!J.allFinite()) {
    why = "the constraints are not finite there";
    return kNaN;
  }
  const Eigen::ColPivHouseholderQR<Matrix> qr(J.transpose());
  const auto& diagonal = qr.matrixQR().diagonal();
  int rank = 0;
  while (rank < diagonal.size() && std::abs(diagonal[rank]) > 1e-10 * std::max(std::abs(diagonal.size() ? diagonal[0] : 0.0), 1e-300))
    ++rank;
  if (rank < m) {
    why = std::to_string(m - rank) + " redundant constraint(s) (stresses): the square system drops them, and their "
          "dependence is not proved";
    return kNaN;
  }
  const Matrix Q = qr.householderQ();
  const Matrix R = Q.rightCols(N - rank).transpose();  // slices across the kernel
  return certifyInSlice(model, x, F, J, R, IVec(static_cast<size_t>(R.rows()), Interval(0.0)), why);
}

// The Krawczyk test at x for the square system [F; R x - R p]: F's enclosure at x given (`at`),
// `rows_at_x` the enclosures of R (x - p). A radius, or NaN with `why`.
double certifyInSlice(const Model& model, const Vector& x, const IVec& F, const Matrix& J, const Matrix& R,
                      const IVec& rows_at_x, std::string& why) {
  const ConstraintSystem& sys = model.system();
  const int N = sys.numVariables(), m = sys.numEquations();
  const Matrix A = preconditioner(J, R);
  if (A.size() == 0) {
    why = notInverted(J, R, "the sliced Jacobian");
    return kNaN;
  }
  IVec g(static_cast<size_t>(N), Interval(0.0));
  std::copy(F.begin(), F.end(), g.begin());
  std::copy(rows_at_x.begin(), rows_at_x.end(), g.begin() + m);
  double delta = 0;
  for (int i = 0; i < N; ++i) {
    double ag = 0;
    for (int j = 0; j < N; ++j) ag += A(i, j) * g[static_cast<size_t>(j)].mid();
    delta = std::max(delta, std::abs(ag));
  }
  const double scale = configurationScale(sys, x);
  // A certified sample is accurate: its radius at most 1e-8 of the configuration's size (the
  // tracker's samples are at rounding level; one moved by 1e-6 is not certified).
  if (delta > kMaxRelativeRadius * scale) {
    why = "the Newton correction is " + shortNumber(delta) + ", more than the certified accuracy (" +
          shortNumber(kMaxRelativeRadius) + " of the configuration's size): an inaccurate sample, or a nearly singular "
          "point";
    return kNaN;
  }
  for (double r = std::max(4 * delta, 1e-14 * scale); r <= kMaxRelativeRadius * scale; r *= 8) {
    const Enclosure box = enclose(model, pointBox(x, r));
    if (contracts(A, box, R, g, r)) return r;
  }
  why = "the Krawczyk test fails within the certified accuracy (" + shortNumber(kMaxRelativeRadius) +
        " of the configuration's size): a nearby singular point, or constraints too ill-conditioned there";
  return kNaN;
}


// A step between certified samples a and b (radii ra, rb) of a curve with no trivial motion and
// no redundant constraint (N - m = 1). Coordinates x = c + s t + y with c the midpoint, t the
// unit chord and t^T y = 0. The s-range, the chord and the samples' uncertainty along it, is cut
// into pieces (a piece that fails is halved, down to 1/64 of the range): piece j is the box
// s in S_j, y in y_j + rho_j [-1, 1] around the arc's point y_j (Newton in double), tested with
// g = F(x_j) + (S_j - s_j) F'(x_j) t + (S_j - s_j)^2 / 2 t^T F''(line) t (Taylor with an enclosed
// remainder: evaluating F on the line would lose the cancellation along it). Each piece holds
// one arc over its S_j; the zero of piece j at the shared end lies within piece j + 1 (its
// Krawczyk enclosure), so the arcs join; the samples' points lie in the first and last pieces.
// With a gauge (T, p: N x g orthonormal, and a point): the curve is the solution set in the slice
// T^T (x - p) = 0 across the trivial motions, and the square system has those g rows too.
// `pieces`: the number of pieces to begin with, and then the number that passed (a path's
// neighbouring steps need about as many).
bool certifyStep(const Model& model, const Vector& a, const Vector& b, double ra, double rb, std::string& why,
                 int& pieces, const Matrix& T = Matrix(), const Vector& p = Vector()) {
  const ConstraintSystem& sys = model.system();
  const int N = sys.numVariables(), m = sys.numEquations(), gauge = static_cast<int>(T.cols());
  const Vector delta = b - a;
  const double L = delta.norm();
  if (!(L > 0)) {
    why = "two equal samples";
    return false;
  }
  const Vector t = delta / L, c = 0.5 * (a + b);
  Matrix R(1 + gauge, N);
  R.row(0) = t.transpose();
  if (gauge > 0) R.bottomRows(gauge) = T.transpose();
  // T^T (c - p), enclosed: the gauge rows at the chord's midpoint (0 up to rounding).
  IVec gauge_at_c(static_cast<size_t>(gauge), Interval(0.0));
  for (int l = 0; l < gauge; ++l)
    for (int k = 0; k < N; ++k)
      gauge_at_c[static_cast<size_t>(l)] += Interval(T(k, l)) * (Interval(c[k]) - Interval(p[k]));
  // The samples in these coordinates, enclosed (c and t are rounded: a = c + s_a t + y_a with
  // t^T y_a = 0 only up to that), and how far their certified points (within r in max norm) can
  // be: |s_p - s_a| <= sqrt(N) r / |t| along the chord, |y_p - y_a| <= r + that |t|_inf across.
  const double r = std::max(ra, rb);
  const Interval sqrtN = sqrt(Interval(static_cast<double>(N)));
  Interval tt(0.0);
  double t_inf = 0;
  for (int k = 0; k < N; ++k) tt += Interval(t[k]) * Interval(t[k]), t_inf = std::max(t_inf, std::abs(t[k]));
  const auto along = [&](const Vector& x) {
    Interval dot(0.0);
    for (int k = 0; k < N; ++k) dot += Interval(t[k]) * (Interval(x[k]) - Interval(c[k]));
    return dot / tt;
  };
  const Interval s_a = along(a), s_b = along(b);
  const double margin_s = (sqrtN * Interval(r) / sqrt(tt)).hi;                        // along the chord
  const double margin_y = (Interval(r) + Interval(margin_s) * Interval(t_inf)).hi;  // across it
  const double s_end = (Interval(std::max(s_a.mag(), s_b.mag())) + Interval(margin_s)).hi;
  // How far a sample's certified point can be across the chord from y (a piece's centre).
  const auto across = [&](const Vector& x, const Interval& sx, const Vector& y) {
    double most = 0;
    for (int k = 0; k < N; ++k)
      most = std::max(most, (Interval(x[k]) - Interval(c[k]) - sx * Interval(t[k]) - Interval(y[k])).mag());
    return (Interval(most) + Interval(margin_y)).hi;
  };
  // The pieces, left to right; a piece that fails is halved (down to 1/64 of the step) and its
  // halves tried in its place, the ones that passed kept: a step next to a singular point costs a
  // few halvings where it fails, not 64 pieces everywhere.
  Vector prev_y;
  std::vector<double> prev_bound;
  double prev_rho = 0;
  const auto piece = [&](const Interval& S, bool first, bool last) -> bool {
    const double sm = S.mid();
    // The arc's point at sm: simplified Newton on F(c + sm t + y) = 0, t^T y = 0, from the
    // chord, with the inverse at the chord point (one dense inversion, not one per iteration).
    // In double: only the box's centre, which the test then proves or not.
    Vector y = Vector::Zero(N);
    Matrix A = preconditioner(sys, c + sm * t, R);
    bool diverged = false;
    for (int it = 0; it < 12 && A.size() > 0; ++it) {
      Vector G(N);
      G.head(m) = sys.residuals(c + sm * t + y);
      G[m] = t.dot(y);
      for (int l = 0; l < gauge; ++l) G[m + 1 + l] = T.col(l).dot(c - p + sm * t + y);
      // Far from the chord (two branches, or a step too long for its curve): no arc to find.
      if (!G.allFinite() || !(y.norm() <= L)) {
        diverged = true;
        break;
      }
      const Vector dy = A * G;
      y -= dy;
      if (!(dy.cwiseAbs().maxCoeff() > 1e-15 * (1 + y.cwiseAbs().maxCoeff()))) break;
    }
    if (A.size() == 0 || diverged) {
      why = diverged ? "no arc of the curve along the chord (Newton from it goes away: two branches, or a step too "
                       "long for its curve)"
                     : notInverted(Matrix(sys.jacobian(c + sm * t)), R, "the Jacobian across the chord");
      return false;
    }
    const Vector xm = c + sm * t + y;
    // F and F' t at the arc's point, enclosed in one pass (a directional jet), and the
    // preconditioner from the Jacobian there in double.
    IVec slope;
    const IVec F = encloseAlong(model, pointBox(xm), t, slope);
    const Matrix Jm = jacobianAt(model, xm);
    A = preconditioner(Jm, R);
    if (A.size() == 0) {
      why = notInverted(Jm, R, "the Jacobian across the chord");
      return false;
    }
    // g over S at the centre y: Taylor in s about sm with the second-order remainder enclosed.
    const Interval ds = S - Interval(sm), ds2(0.0, (Interval(ds.mag()) * Interval(ds.mag())).hi);
    IVec line(static_cast<size_t>(N));
    for (int k = 0; k < N; ++k) line[static_cast<size_t>(k)] = Interval(c[k]) + S * Interval(t[k]) + Interval(y[k]);
    const IVec second = secondDerivativeAlong(model, line, t);
    IVec g(static_cast<size_t>(N), Interval(0.0));
    for (int i = 0; i < m; ++i)
      g[static_cast<size_t>(i)] = F[static_cast<size_t>(i)] + ds * slope[static_cast<size_t>(i)] +
                                  Interval(0.5) * ds2 * second[static_cast<size_t>(i)];
    Interval ty(0.0);
    for (int k = 0; k < N; ++k) ty += Interval(t[k]) * Interval(y[k]);
    g[static_cast<size_t>(m)] = ty;
    for (int l = 0; l < gauge; ++l) {
      Interval v = gauge_at_c[static_cast<size_t>(l)];
      for (int k = 0; k < N; ++k) v += Interval(T(k, l)) * (S * Interval(t[k]) + Interval(y[k]));
      g[static_cast<size_t>(m + 1 + l)] = v;
    }
    double dev = 0;
    for (int i = 0; i < N; ++i) {
      Interval ag(0.0);
      for (int k = 0; k < N; ++k) ag += Interval(A(i, k)) * g[static_cast<size_t>(k)];
      dev = std::max(dev, ag.mag());
    }
    // The first and last pieces hold the samples' points along the chord, or the step fails
    // there (halving an end piece cannot make it hold them).
    // (a is at s_a ~ -L/2, b at s_b ~ L/2.)
    if ((first && !(S.hi >= (Interval(s_a.hi) + Interval(margin_s)).hi)) ||
        (last && !(S.lo <= (Interval(s_b.lo) - Interval(margin_s)).lo))) {
      why = "a step shorter than its samples' radii";
      return false;
    }
    // The smallest radius that holds the samples' points (first and last piece) and the
    // previous piece's zero at the shared end, then larger ones.
    double need = 2 * dev;
    if (first) need = std::max(need, across(a, s_a, y));
    if (last) need = std::max(need, across(b, s_b, y));
    if (!first)
      for (int k = 0; k < N; ++k)
        need = std::max(need, (Interval(std::abs(prev_y[k] - y[k])) + Interval(prev_rho) * Interval(prev_bound[static_cast<size_t>(k)])).hi);
    bool passed = false;
    std::vector<double> bound;
    for (double rho = need * 1.01; rho <= 4 * need + 0.25 * (S.hi - S.lo) && !passed; rho *= 2) {
      IVec box(static_cast<size_t>(N));
      for (int k = 0; k < N; ++k) box[static_cast<size_t>(k)] = line[static_cast<size_t>(k)] + Interval(-rho, rho);
      if (contracts(A, enclose(model, box), R, g, rho, &bound)) {
        passed = true;
        prev_rho = rho;
      }
    }
    if (!passed) {
      why = "the Krawczyk test on the step's box fails (a long step or a nearby singular point)";
      return false;
    }
    prev_y = y;
    prev_bound = bound;
    return true;
  };
  const int start_pieces = std::clamp(pieces / 2, 1, 64);
  const double min_width = 2 * s_end / 64 * (1 - 1e-9);
  std::vector<Interval> pending;  // the pieces to do, the next one last
  for (int j = start_pieces; j-- > 0;)
    pending.emplace_back(j == 0 ? -s_end : -s_end + 2 * s_end * j / start_pieces,
                         j == start_pieces - 1 ? s_end : -s_end + 2 * s_end * (j + 1) / start_pieces);
  int done = 0;
  while (!pending.empty()) {
    const Interval S = pending.back();
    if (piece(S, S.lo == -s_end, S.hi == s_end)) {
      pending.pop_back();
      ++done;
      continue;
    }
    if (!(S.hi - S.lo > min_width)) return false;
    const double middle = S.mid();
    pending.back() = Interval(middle, S.hi);
    pending.emplace_back(S.lo, middle);
  }
  pieces = done;
  return true;
}

// Steps of a system whose trivial motions the pins do not all fix (issue 44: gauge slices): a
// model with the Euclidean group or the similarities, every block free or pinned whole, the
// pinned ones points at one place (what is left: rotations about it, and scalings) or, in 3D,
// on one line (rotations about it).
struct Gauge {
  enum class Kind { Free, Point, Axis } kind = Kind::Free;
  Vector centre, axis;  // Point and Axis: a pinned point; Axis: the unit direction of the line
};

std::optional<Gauge> gaugeSlice(const Model& model) {
  const std::optional<SymmetryGroup> group = model.symmetryGroup();
  const ConstraintSystem& sys = model.system();
  const int d = sys.dimension();
  if (!group || group->num_points < 1 || group->num_points + group->num_directions != sys.numBlocks())
    return std::nullopt;
  // The equi-affine and Moebius groups: unpinned systems only (aligned by Newton in the group).
  if (group->family == SymmetryGroup::Family::EquiAffine || group->family == SymmetryGroup::Family::Moebius) {
    for (int b = 0; b < sys.numBlocks(); ++b)
      if (sys.freeCoordinatesOf(b) != d) return std::nullopt;
    if (lieAlgebra(*group, d).empty()) return std::nullopt;
    return Gauge{};
  }
  const Matrix positions = sys.positions(Vector::Zero(sys.numVariables()));
  std::vector<Vector> pins;
  for (int b = 0; b < sys.numBlocks(); ++b) {
    const int free = sys.freeCoordinatesOf(b);
    if (free == d) continue;
    if (free != 0 || b >= group->num_points) return std::nullopt;
    pins.push_back(positions.col(b));
  }
  Gauge g;
  if (pins.empty()) return g;
  g.centre = pins.front();
  double scale = 1e-300;
  for (const Vector& q : pins) scale = std::max(scale, (q - g.centre).norm());
  const Vector* far = nullptr;
  for (const Vector& q : pins)
    if ((q - g.centre).norm() > 1e-12 * (1 + g.centre.norm())) far = &q;
  if (!far) {
    g.kind = Gauge::Kind::Point;
    return g;
  }
  if (d != 3 || group->family != SymmetryGroup::Family::Euclidean) return std::nullopt;
  g.kind = Gauge::Kind::Axis;
  g.axis = (*far - g.centre).normalized();
  for (const Vector& q : pins) {
    const Vector r = q - g.centre;
    if ((r - r.dot(g.axis) * g.axis).norm() > 1e-12 * (1 + scale)) return std::nullopt;  // not on one line
  }
  return g;
}

// x moved by the rigid motion (no reflection) that fits it best to `target` in least squares over
// the points and the directions (Kabsch), within what the pins leave. Its optimality is the
// linear slice T(target)^T (x' - target) = 0 across the trivial motions at the target: the
// translations centre the points, and R H symmetric (H the cross-covariance) is the rotations'
// part; about one pinned point the same with that point as the centre; about a pinned line the
// angle theta with tr(K R(theta) H) = 0 (K the axis's cross-product matrix): theta =
// atan2(tr(K H), -tr(K^2 H)). For the similarities, the scale s about the centre that meets the
// scaling's row of the slice, sum q_i . (s R p_i - q_i) = 0 over the centred points:
// s = sum |q_i|^2 / sum q_i . R p_i.
// x moved by an element of a group with no closed-form fit (equi-affine maps, Moebius maps on
// caps) onto the slice T(target)^T (x' - target) = 0 (T the trivial flexes at the target): Gauss-
// Newton in the group, x' = G x with G <- exp(sum c_k X_k) G and (T^T V) c = -T^T (x' - target), V
// the velocities of the Lie algebra's X_k at x' (engine/model.h). In double: the certificate
// proves what it proves about the moved sample, wherever the slice lands.
Vector alignedByGroup(const Model& model, const Vector& x, const Vector& target) {
  const ConstraintSystem& sys = model.system();
  const SymmetryGroup group = *model.symmetryGroup();
  const int d = sys.dimension();
  const std::vector<Matrix> algebra = lieAlgebra(group, d);
  const Matrix T = trivialFlexes(model, target, 1e-9);
  const Matrix P = sys.positions(x);
  const int h = static_cast<int>(algebra.front().rows());
  Matrix G = Matrix::Identity(h, h);
  Vector y = x;
  for (int it = 0; it < 40; ++it) {
    const Vector r = T.transpose() * (y - target);
    if (!(r.norm() > 1e-14 * (1 + target.norm()))) break;
    const Matrix Q = sys.positions(y);
    Matrix V(y.size(), static_cast<Eigen::Index>(algebra.size()));
    for (size_t k = 0; k < algebra.size(); ++k)
      V.col(static_cast<Eigen::Index>(k)) = sys.freeCoordinates(groupVelocities(group, algebra[k], Q));
    const Vector c = (T.transpose() * V).colPivHouseholderQr().solve(-r);
    if (!c.allFinite()) break;
    Matrix X = Matrix::Zero(h, h);
    for (size_t k = 0; k < algebra.size(); ++k) X += c[static_cast<Eigen::Index>(k)] * algebra[k];
    G = Matrix(X.exp()) * G;
    y = sys.freeCoordinates(applyGroupElement(group, G, P));
  }
  return y;
}

Vector alignedTo(const Model& model, const Gauge& gauge, const Vector& x, const Vector& target) {
  const SymmetryGroup::Family family = model.symmetryGroup()->family;
  if (family == SymmetryGroup::Family::EquiAffine || family == SymmetryGroup::Family::Moebius)
    return alignedByGroup(model, x, target);
  const ConstraintSystem& sys = model.system();
  const int d = sys.dimension(), np = model.symmetryGroup()->num_points;
  const bool similarity = model.symmetryGroup()->family == SymmetryGroup::Family::Similarity;
  const Matrix P = sys.positions(x), Q = sys.positions(target);
  const Vector pc = gauge.kind == Gauge::Kind::Free ? Vector(P.leftCols(np).rowwise().mean()) : gauge.centre;
  const Vector qc = gauge.kind == Gauge::Kind::Free ? Vector(Q.leftCols(np).rowwise().mean()) : gauge.centre;
  Matrix H = Matrix::Zero(d, d);
  for (int i = 0; i < np; ++i) H += (P.col(i) - pc) * (Q.col(i) - qc).transpose();
  for (int i = np; i < P.cols(); ++i) H += P.col(i) * Q.col(i).transpose();
  Matrix rotation;
  if (gauge.kind == Gauge::Kind::Axis) {
    Matrix K = Matrix::Zero(3, 3);
    K << 0, -gauge.axis[2], gauge.axis[1], gauge.axis[2], 0, -gauge.axis[0], -gauge.axis[1], gauge.axis[0], 0;
    const double theta = std::atan2((K * H).trace(), -(K * K * H).trace());
    rotation = Matrix::Identity(3, 3) + std::sin(theta) * K + (1 - std::cos(theta)) * K * K;
  } else {
    Eigen::JacobiSVD<Matrix> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Matrix D = Matrix::Identity(d, d);
    if ((svd.matrixV() * svd.matrixU().transpose()).determinant() < 0) D(d - 1, d - 1) = -1;
    rotation = svd.matrixV() * D * svd.matrixU().transpose();
  }
  if (similarity) {
    double qq = 0, qrp = 0;
    for (int i = 0; i < np; ++i) {
      qq += (Q.col(i) - qc).squaredNorm();
      qrp += (Q.col(i) - qc).dot(rotation * (P.col(i) - pc));
    }
    if (qrp > 0) rotation *= qq / qrp;
  }
  Matrix out(d, P.cols());
  for (int i = 0; i < np; ++i) out.col(i) = rotation * (P.col(i) - pc) + qc;
  for (int i = np; i < P.cols(); ++i) out.col(i) = rotation * P.col(i);
  return sys.freeCoordinates(out);
}

// A step of an unpinned system with `dof` = 1 + the trivial motions: b moved onto a,
// both onto their midpoint p; the curve is the solution set in the slice T(p)^T (x - p) = 0
// (T the trivial motions at p), where the moved samples are certified again (slice across the
// chord) and the step between them. The step then says: the samples, moved by rigid motions
// into one gauge, lie on one smooth arc of the motion modulo rigid motions (or similarities).
bool certifyGaugeStep(const Model& model, const Gauge& gauge, const Vector& a, const Vector& b, int dof, std::string& why,
                      int& pieces) {
  const int N = model.system().numVariables();
  const Vector b1 = alignedTo(model, gauge, b, a), p = 0.5 * (a + b1);
  const Matrix T = trivialFlexes(model, p, 1e-9);
  if (static_cast<int>(T.cols()) + 1 != dof) {
    why = std::to_string(dof) + " degrees of freedom with " + std::to_string(T.cols()) +
          " trivial motions: several nontrivial flexes (the step test certifies a curve)";
    return false;
  }
  const Vector a2 = alignedTo(model, gauge, a, p), b2 = alignedTo(model, gauge, b1, p);
  if (!((b2 - a2).norm() > 0)) {
    why = "two congruent samples";
    return false;
  }
  const Vector t = (b2 - a2).normalized();
  Matrix R(1 + T.cols(), N);
  R.row(0) = t.transpose();
  R.bottomRows(T.cols()) = T.transpose();
  double radius[2];
  const Vector* ends[2] = {&a2, &b2};
  for (int e = 0; e < 2; ++e) {
    const Vector& x = *ends[e];
    IVec rows(static_cast<size_t>(R.rows()), Interval(0.0));
    for (int l = 0; l < T.cols(); ++l)
      for (int k = 0; k < N; ++k)
        rows[static_cast<size_t>(1 + l)] += Interval(T(k, l)) * (Interval(x[k]) - Interval(p[k]));
    const IVec F = encloseResiduals(model, pointBox(x));
    radius[e] = certifyInSlice(model, x, F, jacobianAt(model, x), R, rows, why);
    if (std::isnan(radius[e])) {
      why = "the sample moved into the step's gauge is not certified: " + why;
      return false;
    }
  }
  return certifyStep(model, a2, b2, radius[0], radius[1], why, pieces, T, p);
}

}  // namespace

namespace {

// Failures grouped by reason, each with where it first happened and how often:
// "; sample 0: WHY; step 3-4 (and 2 more): WHY".
class Failures {
 public:
  void add(const std::string& where, const std::string& why) {
    for (Group& g : groups_)
      if (g.reason == why) {
        ++g.count;
        return;
      }
    groups_.push_back({why, where, 1});
  }
  // The first `most` groups (all by default); the others counted.
  std::string text(size_t most = static_cast<size_t>(-1)) const {
    std::string out;
    long rest = 0;
    for (size_t i = 0; i < groups_.size(); ++i) {
      const Group& g = groups_[i];
      if (i >= most) {
        rest += g.count;
        continue;
      }
      out += "; " + g.first + (g.count > 1 ? " (and " + std::to_string(g.count - 1) + " more)" : "") + ": " + g.reason;
    }
    if (rest > 0)
      out += "; " + std::to_string(rest) + " more for " + std::to_string(groups_.size() - most) +
             " other reasons (all in the path JSON's certificate)";
    return out;
  }

 private:
  struct Group {
    std::string reason, first;
    int count;
  };
  std::vector<Group> groups_;
};

}  // namespace

namespace {

// Flexibility from a certified chain (issue 44): samples 0..K and steps 0..K-1 certified, one
// model throughout, a group of Euclidean motions (distances kept). The start is exactly on the
// curve (its constraints' parameters are its own), so it is sample 0's certified point, and the
// arcs join it to the curve point y within r of sample K (max norm; pinned coordinates exact).
// A distance |p_a - p_b| differs between y and the start when it differs at sample K by more
// than 2 sqrt(d) r: y is then no trivial motion of the start, and the motion is not trivial.
// Sets c.flexible and says so in the reason.
void proveFlexible(const DeformationPath& path, PathCertificate& c) {
  int K = 0;
  while (K + 1 < static_cast<int>(c.radii.size()) && c.steps[static_cast<size_t>(K)] &&
         !std::isnan(c.radii[static_cast<size_t>(K) + 1]) && &path.modelAt(K + 1) == &path.modelAt(0))
    ++K;
  if (K == 0 || std::isnan(c.radii[0])) return;
  const Model& model = path.modelAt(0);
  const std::optional<SymmetryGroup> group = model.symmetryGroup();
  if (!group || group->family != SymmetryGroup::Family::Euclidean) return;
  const ConstraintSystem& sys = model.system();
  const int d = sys.dimension(), n = std::min(group->num_points, static_cast<int>(sys.numBlocks()));
  const Matrix p0 = sys.positions(path.samples[0]), pk = sys.positions(path.samples[static_cast<size_t>(K)]);
  const Interval slack = Interval(2.0) * sqrt(Interval(static_cast<double>(d))) * Interval(c.radii[static_cast<size_t>(K)]);
  const auto distance = [&](const Matrix& p, int a, int b) {
    Interval s(0.0);
    for (int i = 0; i < d; ++i) {
      const Interval e = Interval(p(i, a)) - Interval(p(i, b));
      s += e * e;
    }
    return sqrt(s);
  };
  // Every pair up to 2,000 points, else each point against 16 spread over the numbering.
  const int partners = n <= 2000 ? n : 16;
  for (int ib = 0; ib < partners; ++ib) {
    const int b = n <= 2000 ? ib : static_cast<int>(static_cast<long>(ib) * (n - 1) / 15);
    for (int a = 0; a < n; ++a) {
      if (a == b || (n <= 2000 && a < b)) continue;
      const Interval d0 = distance(p0, a, b), dk = distance(pk, a, b);
      if ((dk - slack).lo > d0.hi || (dk + slack).hi < d0.lo) {
        c.flexible = true;
        c.reason += "; flexible: proved (the certified chain from the start to sample " + std::to_string(K) +
                    " changes the distance of points " + std::to_string(a) + " and " + std::to_string(b) +
                    " (0-based) by " + shortNumber(std::abs(dk.mid() - d0.mid())) + ", more than its radius allows: " +
                    shortNumber(slack.hi) + ")";
        return;
      }
    }
  }
}

}  // namespace

PathCertificate certifyPath(const DeformationPath& path, const PathCertifyOptions& opt) {
  PathCertificate c;
  const int n = static_cast<int>(path.samples.size());
  c.radii.assign(static_cast<size_t>(n), kNaN);
  c.steps.assign(static_cast<size_t>(std::max(0, n - 1)), 0);
  Failures sample_failures, step_failures;
  int certified_samples = 0, certified_steps = 0;
  double estimate = 0;  // the sparse test's last smallest eigenvalue of A^T A (its shifts start there)
  bool stopped = false;  // on request (opt.keep_going)
  const auto stopHere = [&]() {
    if (!stopped && opt.keep_going && !opt.keep_going()) stopped = true;
    return stopped;
  };
  // Quadratic systems beyond the dense test's size: one anchor per step certifies the step and
  // its samples; the tests below take what it leaves, and say why.
  if (opt.quadratic_anchors)
    certifyQuadraticPath(path, opt.anchored_variables, opt.max_variables, c.radii, c.steps, &estimate, stopHere);
  const long anchored_steps = std::count(c.steps.begin(), c.steps.end(), 1);
  for (int k = 0; k < n; ++k) {
    const Model& model = path.modelAt(k);
    const int N = model.system().numVariables();
    std::string why;
    if (!std::isnan(c.radii[static_cast<size_t>(k)])) {
      // certified by its step's anchor
    } else if (stopHere()) {
      why = "stopped on request";
    } else if (N > opt.max_variables) {
      why = std::to_string(N) + " free coordinates: beyond the certificate's size (" + std::to_string(opt.max_variables) +
            ")";
    } else {
      try {
        const Vector& x = path.samples[static_cast<size_t>(k)];
        if (N <= opt.dense_variables) {
          c.radii[static_cast<size_t>(k)] = certifySample(model, x, why);
        } else {
          // The path's direction there, for the slice.
          const Vector& before = path.samples[static_cast<size_t>(std::max(0, k - 1))];
          const Vector& after = path.samples[static_cast<size_t>(std::min(n - 1, k + 1))];
          c.radii[static_cast<size_t>(k)] = certifySampleSparse(
              model, x, after.size() == x.size() && before.size() == x.size() ? Vector(after - before) : Vector(x), why,
              &estimate);
        }
      } catch (const std::domain_error& e) {
        why = e.what();
      }
    }
    if (!std::isnan(c.radii[static_cast<size_t>(k)])) ++certified_samples;
    else sample_failures.add("sample " + std::to_string(k), why);
  }
  int pieces = 1;  // the pieces the last certified step needed
  for (int k = 0; k + 1 < n; ++k) {
    const Model& model = path.modelAt(k + 1);
    const ConstraintSystem& sys = model.system();
    std::string why;
    if (c.steps[static_cast<size_t>(k)]) {
      // certified by its anchor
    } else if (stopHere()) {
      why = "stopped on request";
    } else if (&path.modelAt(k) != &model) {
      why = "the constraints change between the samples (a contact)";
    } else if (std::isnan(c.radii[static_cast<size_t>(k)]) || std::isnan(c.radii[static_cast<size_t>(k + 1)])) {
      why = "a sample of the step is not certified";
    } else if (sys.numVariables() > opt.dense_variables) {
      try {
        c.steps[static_cast<size_t>(k)] =
            certifyStepSparse(model, path.samples[static_cast<size_t>(k)], path.samples[static_cast<size_t>(k + 1)],
                              c.radii[static_cast<size_t>(k)], c.radii[static_cast<size_t>(k + 1)], why, pieces,
                              &estimate, &opt.keep_going);
      } catch (const std::domain_error& e) {
        why = e.what();
      }
    } else if (const int dof = sys.numVariables() - sys.numEquations(); dof != 1) {
      const std::optional<Gauge> gauge = dof > 1 ? gaugeSlice(model) : std::nullopt;
      if (gauge) {
        try {
          c.steps[static_cast<size_t>(k)] = certifyGaugeStep(model, *gauge, path.samples[static_cast<size_t>(k)],
                                                             path.samples[static_cast<size_t>(k + 1)], dof, why, pieces);
        } catch (const std::domain_error& e) {
          why = e.what();
        }
      } else {
        why = std::to_string(dof) +
              " degrees of freedom (trivial motions that neither pins nor a gauge slice fix, or several flexes): the "
              "step test certifies a curve";
      }
    } else {
      try {
        c.steps[static_cast<size_t>(k)] = certifyStep(model, path.samples[static_cast<size_t>(k)],
                                                      path.samples[static_cast<size_t>(k + 1)],
                                                      c.radii[static_cast<size_t>(k)], c.radii[static_cast<size_t>(k + 1)], why,
                                                      pieces);
      } catch (const std::domain_error& e) {
        why = e.what();
      }
    }
    if (c.steps[static_cast<size_t>(k)]) ++certified_steps;
    else step_failures.add("step " + std::to_string(k) + "-" + std::to_string(k + 1), why);
  }
  if (c.certified() && n == 1) {  // no steps: what was certified is the one sample
    const bool sparse = path.modelAt(0).system().numVariables() > opt.dense_variables;
    c.reason = std::string("the path's one sample certified (") + (sparse ? "a sparse norm test" : "Krawczyk") +
               ", interval arithmetic); it has no steps";
  } else if (c.certified()) {
    const bool sparse = path.modelAt(0).system().numVariables() > opt.dense_variables;
    c.reason = "every sample (" + std::to_string(n) + ") and step certified (" +
               (anchored_steps == n - 1 ? "a sparse norm test anchored at each step's midpoint"
                : sparse                 ? "a sparse norm test"
                                         : "Krawczyk") +
               ", interval arithmetic)";
  } else {
    const std::string counts = std::to_string(certified_samples) + " of " + std::to_string(n) + " samples and " +
                               std::to_string(certified_steps) + " of " + std::to_string(std::max(0, n - 1)) +
                               " steps certified";
    c.reason = counts + sample_failures.text() + step_failures.text();
    // For a person: the first few reasons of each kind, the others counted (a long path whose
    // every failure has its own numbers would otherwise make a line of megabytes).
    constexpr size_t kShown = 3;
    c.summary = counts + sample_failures.text(kShown) + step_failures.text(kShown);
    if (c.summary.size() > 2000) c.summary = counts + sample_failures.text(1) + step_failures.text(1);
    if (c.summary.size() > 2000) {
      // Cut at a character's first byte, never inside a UTF-8 sequence.
      size_t cut = 1997;
      while (cut > 0 && (static_cast<unsigned char>(c.summary[cut]) & 0xC0) == 0x80) --cut;
      c.summary = c.summary.substr(0, cut) + "...";
    }
    if (c.summary == c.reason) c.summary.clear();
  }
  proveFlexible(path, c);
  return c;
}

}  // namespace flexure::engine::certify
