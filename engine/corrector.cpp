#include "engine/corrector.h"

#include <cmath>

namespace flexure::engine {

const char* toString(CorrectorStatus s) {
  switch (s) {
    case CorrectorStatus::Converged: return "converged";
    case CorrectorStatus::MaxIterations: return "no convergence within the iteration limit";
    case CorrectorStatus::LineSearchFailed: return "the line search found no decrease";
  }
  return "unknown";
}

CorrectorResult correct(const ConstraintSystem& sys, const Vector& start,
                        const CorrectorOptions& opt, const Matrix& lambda) {
  const double tol = opt.residual_tolerance * sys.residualScale();
  const bool randomized = lambda.size() > 0;
  CorrectorResult res;
  res.x = start;
  SparseMatrix J = sys.jacobianPattern();
  Vector F = sys.residuals(res.x);
  auto merit = [&](const Vector& f) { return randomized ? (lambda * f).squaredNorm() : f.squaredNorm(); };
  for (res.iterations = 0;; ++res.iterations) {
    res.residual = F.size() ? F.cwiseAbs().maxCoeff() : 0.0;
    if (!std::isfinite(res.residual)) {
      res.status = CorrectorStatus::LineSearchFailed;
      return res;
    }
    if (res.residual <= tol) {
      res.status = CorrectorStatus::Converged;
      return res;
    }
    if (res.iterations >= opt.max_iterations) {
      res.status = CorrectorStatus::MaxIterations;
      return res;
    }
    sys.jacobian(res.x, J);
    Vector Ft = F;
    Vector step;
    if (randomized) {
      Ft = lambda * F;
      const SparseMatrix Jt = (lambda * Matrix(J)).sparseView();
      const JacobianFactorization fac(Jt, opt.factorization);
      step = -fac.solveMinNorm(Ft);
    } else {
      const JacobianFactorization fac(J, opt.factorization);
      step = -fac.solveMinNorm(Ft);
    }
    const double g = randomized ? Ft.dot(lambda * (J * step)) : Ft.dot(J * step);
    const double phi = merit(F);
    if (!(g < 0)) {
      res.status = CorrectorStatus::LineSearchFailed;
      return res;
    }
    double alpha = 1.0;
    bool accepted = false;
    for (int b = 0; b <= opt.max_backtracks; ++b, alpha *= 0.5) {
      const Vector trial = res.x + alpha * step;
      const Vector Fn = sys.residuals(trial);
      if (merit(Fn) <= phi + 2.0 * opt.armijo * alpha * g) {
        res.x = trial;
        F = Fn;
        accepted = true;
        break;
      }
    }
    if (!accepted) {
      res.status = CorrectorStatus::LineSearchFailed;
      return res;
    }
  }
}

}  // namespace flexure::engine
