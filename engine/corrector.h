// The corrector of Algorithm ACM (paper section 4.1): damped Gauss-Newton with minimum-norm
// steps and an Armijo backtracking line search, randomized when the Jacobian has stresses.
// It stops by residual tolerance and iteration counts, never by time.
#pragma once

#include <functional>
#include <memory>

#include "engine/factorization.h"

namespace flexure::engine {

struct CorrectorOptions {
  // Converged when ||F(x)||_inf <= residual_tolerance * system.residualScale().
  double residual_tolerance = 1e-13;
  // When the iteration stalls (no decrease, or the iteration limit) at a residual below
  // stall_tolerance * system.residualScale(), its best iterate counts as converged: large
  // redundant systems reach a rounding floor above residual_tolerance.
  double stall_tolerance = 1e-12;
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

class NormalEquations;  // a kept factorization of the steps' normal equations (normal_equations.h)

// How the steps treat a system with s stresses (paper Prop. 4.3). Either a dense (m - s) x m
// matrix Lambda: the steps solve Lambda F = 0. Or, keeping large systems sparse, a set of
// gauge coordinates, one per tangent direction at the last sample (chosen so that they
// parametrize the tangent space well): the steps are the least-squares solutions of
// [J; E^T] d = [-F; 0] with E the columns of the identity for these coordinates, a sparse
// full-column-rank system in which the redundant equations do no harm, and the corrected
// point (nearly) keeps the predictor's gauge coordinates. Empty: minimum-norm steps on all of F.
struct EquationReduction {
  Matrix lambda;
  std::vector<int> gauge;
  // With gauge coordinates and extra equations: coordinates that, with the gauge, parametrize
  // ker J (the directions only the extra equations fix). The sparse normal equations hold them
  // too, so that they can be factored, and Woodbury's identity takes them out again.
  std::vector<int> lift;
  // With gauge coordinates or a damping: the factorization of the normal equations kept across
  // corrections (the tracker's, from one sample to the next). Steps reuse it while the residual
  // falls by 4 or more per iteration (chord steps), and factor again at the current iterate
  // when not or when the gauge or damping changed. Null: each correction factors at its first
  // iterate.
  std::shared_ptr<NormalEquations> normal_equations;
  static std::shared_ptr<NormalEquations> keptNormalEquations();
  // Without a gauge: a damping mu > 0 (relative to the largest diagonal entry of J^T J) makes
  // the steps those of the normal equations (J^T J + mu I) d = -J^T F, kept as above, instead
  // of minimum-norm steps by a QR per iteration (Levenberg-Marquardt with a small fixed mu).
  // They are the minimum-norm step up to a relative mu / sigma^2 on each singular direction,
  // and zero on ker J (J^T F has no part there), without knowing ker J: no gauge to choose.
  double damping = 0.0;
  bool empty() const { return lambda.size() == 0 && gauge.empty() && damping == 0.0; }
};

// An extra equation |x - center| = radius: the corrected point keeps its distance from the
// center (pseudo-arclength continuation's sphere). Where two branches pass close to each other,
// as at a cusp, the corrector then lands on the branch the guess points at instead of the
// nearest one.
struct Sphere {
  Vector center;
  double radius = 1.0;
};

// More equations g(x) = 0 beside F, such as a driven fold angle at its scheduled value and the
// fold angles held at theirs. `values` are in the system's units (those of residualScale()),
// `gradients` their gradients in free coordinates, one row per equation.
struct ExtraEquations {
  std::function<Vector(const Vector&)> values;
  std::function<Matrix(const Vector&)> gradients;
};

// Corrects `start` onto F = rhs (rhs null: F = 0; a parameter continuation such as edge
// contraction moves rhs), and onto the sphere (not with gauge coordinates) and the extra
// equations if given; the steps use the reduced system, convergence is tested on all of F (and the
// sphere, and the extra equations).
CorrectorResult correct(const ConstraintSystem& system, const Vector& start,
                        const CorrectorOptions& options, const EquationReduction& reduction = {},
                        const Vector* rhs = nullptr, const Sphere* sphere = nullptr,
                        const ExtraEquations* extra = nullptr);

// Corrects `start` onto F = 0 by chord steps: the minimum-norm Gauss-Newton step with J frozen
// at the point `fac` factored (the last sample), from the seminormal equations (no product with
// the QR's Q), so that a correction costs no factorization. The steps keep the start's
// projection onto that point's kernel (the tangent coordinates). The chord converges linearly,
// more slowly the farther from that point; Anderson's acceleration (depth 5) over its last steps
// makes up for that, restarted when it stagnates. Safeguarded: an accelerated point that does
// not lower the residual gives way to the plain step, and the iteration ends when neither does
// (first on the seminormal equations, then with the QR's orthogonal factor, more accurate and
// more costly, unless the residual is already below `floor`). Converged when ||F||_inf <= tol,
// or when it stops at or below `floor`.
CorrectorResult correctChord(const ConstraintSystem& system, const Vector& start, const JacobianFactorization& fac,
                             double tol, double floor, int max_iterations);

}  // namespace flexure::engine
