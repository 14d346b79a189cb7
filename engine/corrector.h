// The corrector of Algorithm ACM (paper section 4.1): damped Gauss-Newton with minimum-norm
// steps and an Armijo backtracking line search, randomized when the Jacobian has stresses.
// It stops by residual tolerance and iteration counts, never by time.
#pragma once

#include "engine/factorization.h"

namespace flexure::engine {

struct CorrectorOptions {
  // Converged when ||F(x)||_inf <= residual_tolerance * system.residualScale().
  double residual_tolerance = 1e-13;
  int max_iterations = 30;
  // Halvings of the step length alpha per iteration before giving up.
  int max_backtracks = 30;
  // Armijo condition on phi = ||F~||^2: phi(x + alpha d) <= phi(x) + 2 armijo alpha g, with g
  // the directional derivative F~^T J~ d (negative for a descent direction).
  double armijo = 1e-4;
  FactorizationOptions factorization;
};

enum class CorrectorStatus { Converged, MaxIterations, LineSearchFailed };
const char* toString(CorrectorStatus s);

struct CorrectorResult {
  Vector x;
  CorrectorStatus status = CorrectorStatus::MaxIterations;
  int iterations = 0;
  double residual = 0;  // ||F(x)||_inf at the returned point
};

// Corrects `start` onto F = 0. `randomization`, if non-empty, is a (m - s) x m matrix Lambda:
// the steps then solve Lambda F = 0 (paper Prop. 4.3), while convergence is tested on all of F.
CorrectorResult correct(const ConstraintSystem& system, const Vector& start,
                        const CorrectorOptions& options, const Matrix& randomization = Matrix());

}  // namespace flexure::engine
