#include "engine/contraction.h"

#include "engine/continuation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "engine/factorization.h"
#include "engine/terms.h"

namespace flexure::engine {

int distanceEquation(const ConstraintSystem& sys, int a, int b) {
  int row = 0;
  for (int t : sys.activeTerms()) {
    const ConstraintTerm& term = *sys.terms()[static_cast<size_t>(t)];
    if (dynamic_cast<const SquaredDistanceTerm*>(&term)) {
      const auto& bl = term.blocks();
      if ((bl[0] == a && bl[1] == b) || (bl[0] == b && bl[1] == a)) return row;
    }
    row += term.numResiduals();
  }
  return -1;
}

namespace {

// The squared length the edge's equation compares with at the start (its residual is
// |x_a - x_b|^2 - l0^2, so F = (c^2 - l0^2) e_row asks for length c).
double squaredLengthOfRow(const ConstraintSystem& sys, int row) {
  int r = 0;
  for (int t : sys.activeTerms()) {
    const ConstraintTerm& term = *sys.terms()[static_cast<size_t>(t)];
    if (r == row) {
      if (auto d = dynamic_cast<const SquaredDistanceTerm*>(&term)) return d->squaredLength();
      break;
    }
    r += term.numResiduals();
  }
  throw std::invalid_argument("the contracted equation is not an edge length");
}

}  // namespace

DeformationPath contractEdge(const Model& model, const Vector& start, int row, double target, const ContractionOptions& opt,
                         const StepCallback& on_step) {
  const ConstraintSystem& sys = model.system();
  if (!(target > 0)) throw std::invalid_argument("the target length must be positive");
  if (!(opt.step > 0)) throw std::invalid_argument("the contraction step must be positive");
  if (row < 0 || row >= sys.numEquations()) throw std::invalid_argument("no such equation");
  const double l0sq = squaredLengthOfRow(sys, row);
  // The edge's current length at the start (the realization satisfies l0).
  const double c0 = std::sqrt(std::max(0.0, l0sq + sys.residuals(start)[row]));
  const int n = sys.numEquations();
  ParameterSteps kind;
  kind.parameter = "edge length";
  kind.tangent = [&](const Vector& x, double from, double to) -> Vector {
    // Minimum-norm tangent: J dx = d(c^2) e_row.
    const JacobianFactorization fac(sys.jacobian(x), orderedFor(opt.corrector.factorization, sys));
    Vector b = Vector::Zero(n);
    b[row] = to * to - from * from;
    return fac.solveMinNorm(b);
  };
  // F = (c^2 - l0^2) e_row asks for length c.
  const auto rhsAt = [&](double c) {
    Vector rhs = Vector::Zero(n);
    rhs[row] = c * c - l0sq;
    return rhs;
  };
  kind.correct = [&](const Vector&, const Vector& guess, double c) {
    const Vector rhs = rhsAt(c);
    return correct(sys, guess, opt.corrector, {}, &rhs);
  };
  kind.residual = [&](const Vector& x, double c) {
    const Vector f = sys.residuals(x) - rhsAt(c);
    return f.size() ? f.cwiseAbs().maxCoeff() : 0.0;
  };
  ContinuationSchedule sch;
  sch.start = c0;
  sch.target = target;
  sch.step = opt.step;
  sch.max_steps = opt.max_steps;
  sch.max_halvings = opt.max_halvings;
  return continueParameter(start, kind, sch, on_step);
}

}  // namespace flexure::engine
