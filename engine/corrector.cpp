#include "engine/corrector.h"

#include <stdexcept>
#include <string>

#include <Eigen/Dense>

#include "engine/normal_equations.h"

#include <cmath>
#include <limits>
#include <optional>

namespace flexure::engine {

const char* toString(CorrectorStatus s) {
  switch (s) {
    case CorrectorStatus::Converged: return "converged";
    case CorrectorStatus::MaxIterations: return "no convergence within the iteration limit";
    case CorrectorStatus::LineSearchFailed: return "the line search found no decrease";
  }
  return "unknown";
}

std::shared_ptr<NormalEquations> EquationReduction::keptNormalEquations() {
  return std::make_shared<NormalEquations>(/*nested_dissection=*/true);
}

namespace {

// The minimum-norm least-squares solution of J d = b over J's numerical range. Small systems:
// a complete orthogonal decomposition (column-pivoted QR, then an RZ step on the rank rows),
// a few microseconds on the double Watt's 15 x 16 Jacobian where a full SVD takes ~40; its
// rank decision is |R_ii| > rank_tolerance * |R_11|. Large: the sparse rank-revealing QR.
Vector minNormStep(const SparseMatrix& J, const Vector& b, const FactorizationOptions& opt) {
  if (std::max(J.rows(), J.cols()) > opt.dense_limit || J.rows() == 0 || J.cols() == 0)
    return JacobianFactorization(J, opt).solveMinNorm(b);
  Eigen::CompleteOrthogonalDecomposition<Matrix> cod;
  cod.setThreshold(opt.rank_tolerance);  // before compute: the RZ step uses the rank
  cod.compute(Matrix(J));
  return cod.solve(b);
}

// The arguments correct() cannot work with.
void checkArguments(const ConstraintSystem& sys, const Vector& start, const EquationReduction& red,
                    const Sphere* sphere, bool normal) {
  if (sphere && normal) throw std::invalid_argument("a sphere needs a dense or no equation reduction");
  if (red.lambda.size() > 0 && red.lambda.cols() != sys.numEquations())
    throw std::invalid_argument("the randomization matrix has " + std::to_string(red.lambda.cols()) +
                                " columns for " + std::to_string(sys.numEquations()) + " equations");
  if (start.size() != sys.numVariables())
    throw std::invalid_argument("the start has " + std::to_string(start.size()) + " coordinates for " +
                                std::to_string(sys.numVariables()) + " variables");
}

// The system the steps solve, beside F = rhs: Lambda F (or F), then the sphere's
// (|x - c|^2 - r^2) / (2r), whose gradient (x - c)^T / r has unit length on the sphere, times
// sphere_units, then the extra equations. The sphere's residual is a length; the system's are
// in its own units (residualScale()): it is taken in those units (relative to the size of the
// coordinates), in the steps and against the tolerance, so that the same configuration at
// another scale converges alike.
struct AugmentedSystem {
  const ConstraintSystem& sys;
  const EquationReduction& red;
  const Vector* rhs;
  const Sphere* sphere;
  const ExtraEquations* extra;
  double sphere_units;

  AugmentedSystem(const ConstraintSystem& s, const EquationReduction& r, const Vector* b, const Sphere* sp,
                  const ExtraEquations* e)
      : sys(s), red(r), rhs(b), sphere(sp), extra(e),
        sphere_units(sp ? s.residualScale() / std::max({sp->center.cwiseAbs().maxCoeff(), sp->radius, 1e-300})
                        : 0.0) {}

  // The steps' equations are not F itself (J~ is not J).
  bool reduced() const { return red.lambda.size() > 0 || sphere || extra; }

  // F(x) - rhs.
  Vector residuals(const Vector& x) const {
    Vector f = sys.residuals(x);
    if (rhs) f -= *rhs;
    return f;
  }

  // The extra rows' residuals at x (sphere, then the extra equations).
  Vector extraResiduals(const Vector& x) const {
    const Vector e = extra ? extra->values(x) : Vector();
    Vector r(static_cast<Eigen::Index>(sphere != nullptr) + e.size());
    if (sphere)
      r[0] = sphere_units * ((x - sphere->center).squaredNorm() - sphere->radius * sphere->radius) / (2 * sphere->radius);
    r.tail(e.size()) = e;
    return r;
  }

  // F~: the steps' residuals from f = residuals(x).
  Vector reduce(const Vector& f, const Vector& x) const {
    Vector r = red.lambda.size() > 0 ? Vector(red.lambda * f) : f;
    if (!sphere && !extra) return r;
    const Vector e = extraResiduals(x);
    r.conservativeResize(r.size() + e.size());
    r.tail(e.size()) = e;
    return r;
  }

  // What convergence is tested on: the largest residual of all of F and the extra rows.
  double worst(const Vector& f, const Vector& x) const {
    double w = f.size() ? f.cwiseAbs().maxCoeff() : 0.0;
    const Vector e = sphere || extra ? extraResiduals(x) : Vector();
    return e.size() ? std::max(w, e.cwiseAbs().maxCoeff()) : w;
  }

  // J~ (reduced() only) from J at x and the extra equations' gradients `more` there: the extra
  // rows below J (or Lambda J, dense), sparse when J is.
  SparseMatrix jacobian(const SparseMatrix& J, const Vector& x, const Matrix& more) const {
    Matrix rows(static_cast<Eigen::Index>(sphere != nullptr) + more.rows(), J.cols());
    if (sphere) rows.row(0) = sphere_units * (x - sphere->center).transpose() / sphere->radius;
    rows.bottomRows(more.rows()) = more;
    if (red.lambda.size() > 0) {
      Matrix D(red.lambda.rows() + rows.rows(), J.cols());
      D << red.lambda * Matrix(J), rows;
      return SparseMatrix(D.sparseView());
    }
    return appendRows(J, rows);
  }
};

// Gauge steps' normal equations (gauge or damping; none otherwise): the caller's, kept from
// earlier corrections, or this correction's own (on the stack, and only with a gauge: small
// systems correct thousands of times without one).
NormalEquations* normalEquations(const EquationReduction& red, std::optional<NormalEquations>& own) {
  if (red.gauge.empty() && !(red.damping > 0)) return nullptr;
  NormalEquations* bordered = red.normal_equations.get();
  if (!bordered) bordered = &own.emplace();
  bordered->use(red.gauge, red.lift, red.damping);
  return bordered;
}

// The best iterate so far: returned, as converged, when the iteration stalls at the rounding
// floor below stall_tolerance.
struct BestIterate {
  Vector x;
  double residual = std::numeric_limits<double>::infinity();

  void see(const Vector& y, double r) {
    if (r < residual) residual = r, x = y;
  }
  // The result when the iteration ends with `status` short of the tolerance.
  CorrectorResult giveUp(CorrectorResult res, CorrectorStatus status, double stall) const {
    if (residual <= stall) {
      res.x = x;
      res.residual = residual;
      res.status = CorrectorStatus::Converged;
    } else {
      res.status = status;
    }
    return res;
  }
};

// The step at the iterate: by the normal equations (`normal`, gauge or damped; a chord step
// reuses their factorization; by_qr: SuiteSparseQR instead), F the residuals and Ft the steps'
// (F~); otherwise the minimum-norm step of J~ (Jt).
Vector direction(const AugmentedSystem& a, NormalEquations* normal, const SparseMatrix& J, const SparseMatrix& Jt,
                 const Vector& F, const Vector& Ft, const Matrix& more, bool chord, bool by_qr,
                 const FactorizationOptions& fo) {
  if (!normal) return -minNormStep(Jt, Ft, fo);
  if (a.extra)  // no sphere with a gauge: Ft ends with the extra equations' residuals
    return -normal->solve(J, F, more, Ft.tail(more.rows()), !chord, by_qr);
  return -normal->solve(J, F, !chord, by_qr);
}

// Armijo on phi = ||F~||^2 along `step` from x, with its directional derivative 2 g,
// g = F~^T J~ step: the first alpha = 2^-b, b <= backtracks, with
// phi(x + alpha step) <= phi + 2 c alpha g. x and F (= residuals(x)) move there; nothing when
// no alpha does (or when step is no descent direction).
std::optional<double> armijo(const AugmentedSystem& a, const Vector& step, double g, double phi, int backtracks,
                             double c, Vector& x, Vector& F) {
  double alpha = 1.0;
  for (int b = 0; g < 0 && b <= backtracks; ++b, alpha *= 0.5) {
    const Vector trial = x + alpha * step;
    const Vector Fn = a.residuals(trial);
    if (a.reduce(Fn, trial).squaredNorm() <= phi + 2.0 * c * alpha * g) {
      x = trial;
      F = Fn;
      return alpha;
    }
  }
  return std::nullopt;
}

// One iteration's step from x, F: the direction, then Armijo; the step length alpha taken, or
// nothing. A chord step is taken whole or not at all: where a stale normal matrix gives a poor
// direction (soft modes of a flexible grid, whose curvature moved since it was factored), a new
// factorization is cheaper than the backtracking (8 halvings per correction were typical on a
// 60 x 60 grid). A gauge step from a new factorization of the normal equations that finds no
// decrease is taken again by QR (their squared condition number).
std::optional<double> takeStep(const AugmentedSystem& a, const CorrectorOptions& opt, NormalEquations* normal,
                               bool chord, const SparseMatrix& J, const SparseMatrix& Jt, const Matrix& more,
                               const Vector& Ft, double phi, Vector& x, Vector& F) {
  for (const bool by_qr : {false, true}) {
    if (by_qr && (!normal || chord)) break;
    const Vector step = direction(a, normal, J, Jt, F, Ft, more, chord, by_qr, opt.factorization);
    const double g = Ft.dot(Jt * step);
    if (const std::optional<double> alpha = armijo(a, step, g, phi, chord ? 0 : opt.max_backtracks, opt.armijo, x, F))
      return alpha;
  }
  return std::nullopt;
}

}  // namespace

CorrectorResult correctChord(const ConstraintSystem& sys, const Vector& start, const JacobianFactorization& fac,
                             double tol, double floor, int max_iterations) {
  CorrectorResult res;
  res.x = start;
  Vector& y = res.x;
  Vector F = sys.residuals(y);
  double r = F.size() ? F.cwiseAbs().maxCoeff() : 0.0;
  std::vector<Vector> dy, dg;
  Vector y_prev, g_prev;
  bool accurate = false;
  for (res.iterations = 0; res.iterations < max_iterations && r > tol; ++res.iterations) {
    const Vector g = accurate ? Vector(-fac.solveMinNorm(F)) : Vector(-fac.solveSeminormal(F));
    if (res.iterations > 0 && y_prev.size() > 0) {
      dy.push_back(y - y_prev), dg.push_back(g - g_prev);
      if (dy.size() > 5) dy.erase(dy.begin()), dg.erase(dg.begin());
    }
    y_prev = y, g_prev = g;
    Vector next = y + g;
    if (!dg.empty()) {
      Matrix G(g.size(), static_cast<Eigen::Index>(dg.size())), Y(G.rows(), G.cols());
      for (size_t j = 0; j < dg.size(); ++j) {
        G.col(static_cast<Eigen::Index>(j)) = dg[j];
        Y.col(static_cast<Eigen::Index>(j)) = dy[j];
      }
      const Vector gamma = G.colPivHouseholderQr().solve(g);
      if (gamma.allFinite()) next -= (Y + G) * gamma;
    }
    Vector Fn = sys.residuals(next);
    double rn = Fn.cwiseAbs().maxCoeff();
    if (!(rn < r) && !dg.empty()) {
      next = y + g;
      Fn = sys.residuals(next);
      rn = Fn.cwiseAbs().maxCoeff();
      dy.clear(), dg.clear();
    }
    if (!(rn < r)) {
      if (accurate || fac.dense() || r <= floor) break;
      // The seminormal equations' rounding floor (their condition number is squared): the
      // last iterations take the QR's Q.
      accurate = true;
      dy.clear(), dg.clear(), y_prev.resize(0);
      continue;
    }
    if (rn > 0.25 * r) dy.clear(), dg.clear();  // stagnating: restart the acceleration
    y = std::move(next), F = std::move(Fn), r = rn;
  }
  res.residual = r;
  res.status = r <= tol || r <= floor ? CorrectorStatus::Converged
               : res.iterations >= max_iterations ? CorrectorStatus::MaxIterations
                                                  : CorrectorStatus::LineSearchFailed;
  return res;
}

CorrectorResult correct(const ConstraintSystem& sys, const Vector& start, const CorrectorOptions& opt,
                        const EquationReduction& red, const Vector* rhs, const Sphere* sphere,
                        const ExtraEquations* extra) {
  const bool normal = !red.gauge.empty() || red.damping > 0;  // steps by the normal equations
  checkArguments(sys, start, red, sphere, normal);
  const double tol = opt.residual_tolerance * sys.residualScale();
  CorrectorResult res;
  res.x = start;
  SparseMatrix J = sys.jacobianPattern();
  std::optional<NormalEquations> own;
  NormalEquations* const bordered = normalEquations(red, own);
  bool refactor = !red.normal_equations;
  if (rhs && rhs->size() != sys.numEquations())
    throw std::invalid_argument("the right-hand side has the wrong size");
  const AugmentedSystem aug(sys, red, rhs, sphere, extra);
  Vector F = aug.residuals(res.x);
  BestIterate best{res.x};
  const double stall = opt.stall_tolerance * sys.residualScale();
  for (res.iterations = 0;; ++res.iterations) {
    res.residual = aug.worst(F, res.x);
    if (!std::isfinite(res.residual)) return best.giveUp(res, CorrectorStatus::LineSearchFailed, stall);
    best.see(res.x, res.residual);
    if (res.residual <= tol) {
      res.status = CorrectorStatus::Converged;
      return res;
    }
    if (res.iterations >= opt.max_iterations) return best.giveUp(res, CorrectorStatus::MaxIterations, stall);
    sys.jacobian(res.x, J);
    const Matrix more = extra ? extra->gradients(res.x) : Matrix(0, J.cols());
    const SparseMatrix Jr = aug.reduced() ? aug.jacobian(J, res.x, more) : SparseMatrix();
    const SparseMatrix& Jt = aug.reduced() ? Jr : J;
    const Vector Ft = aug.reduce(F, res.x);
    // Normal-equation steps (gauge or damped) with kept normal equations reuse their
    // factorization (chord steps).
    const bool chord = bordered && !refactor && bordered->factored();
    const double phi = Ft.squaredNorm();
    const std::optional<double> alpha = takeStep(aug, opt, bordered, chord, J, Jt, more, Ft, phi, res.x, F);
    if (!alpha) {
      if (chord) {
        refactor = true;
        continue;
      }
      return best.giveUp(res, CorrectorStatus::LineSearchFailed, stall);
    }
    // Kept normal equations serve while a full step lowers the residual by 4 or more; a
    // correction's own are factored at every iterate (Gauss-Newton).
    refactor = !red.normal_equations || *alpha < 1.0 || aug.reduce(F, res.x).squaredNorm() > phi / 16.0;
  }
}

}  // namespace flexure::engine
