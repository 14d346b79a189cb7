#include "engine/contraction.h"

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
  DeformationPath out;
  out.samples.push_back(start);
  // The edge's current length at the start (the realization satisfies l0).
  const double c0 = std::sqrt(std::max(0.0, l0sq + sys.residuals(start)[row]));
  const double span = target - c0;
  const double needed_steps = std::ceil(std::abs(span) / opt.step - 1e-9);
  if (!(needed_steps <= std::numeric_limits<int>::max()) && opt.max_steps < 0)
    throw std::invalid_argument("the contraction needs more than 2^31 steps; give a larger step or a step limit");
  const int needed = static_cast<int>(std::min<double>(needed_steps, std::numeric_limits<int>::max()));
  const int steps = opt.max_steps >= 0 ? std::min(opt.max_steps, needed) : needed;
  out.summary.steps_requested = steps;
  out.summary.seed = 0;
  auto lengthAt = [&](int k) { return k >= needed ? target : c0 + (span > 0 ? 1 : -1) * opt.step * k; };
  Vector rhs = Vector::Zero(sys.numEquations());
  auto residualAt = [&](const Vector& x, double c) {
    rhs[row] = c * c - l0sq;
    const Vector f = sys.residuals(x) - rhs;
    return f.size() ? f.cwiseAbs().maxCoeff() : 0.0;
  };
  double worst = residualAt(start, c0);
  double last_distance = -1;  // between the last two samples
  double c_prev = c0;
  Vector x_prev = start, x_prev2;
  out.summary.status = TrackStatus::Success;
  for (int k = 1; k <= steps; ++k) {
    const double c_target = lengthAt(k);
    // Reach c_target from c_prev, in sub-steps when a step fails or jumps.
    double c_from = c_prev;
    Vector x_from = x_prev;
    int halvings = 0;
    double frac = 1.0;
    bool failed = false;
    while (c_from != c_target) {
      const double c_to = frac >= 1.0 ? c_target : c_from + frac * (c_target - c_from);
      Vector predicted;
      if (x_prev2.size() && c_from == c_prev) {
        // Secant through the last two samples, scaled to this parameter step.
        predicted = x_from + (x_prev - x_prev2) * ((c_to - c_from) / (c_prev - lengthAt(k - 2)));
      } else {
        // Minimum-norm tangent: J dx = d(c^2) e_row.
        const JacobianFactorization fac(sys.jacobian(x_from), opt.corrector.factorization);
        Vector b = Vector::Zero(sys.numEquations());
        b[row] = c_to * c_to - c_from * c_from;
        predicted = x_from + fac.solveMinNorm(b);
      }
      rhs[row] = c_to * c_to - l0sq;
      const CorrectorResult r = correct(sys, predicted, opt.corrector, {}, &rhs);
      const double moved = (r.x - x_from).norm();
      const double expected = last_distance > 0 ? last_distance * std::abs(c_to - c_from) / opt.step : -1;
      const bool jumped = expected > 0 && moved > 8.0 * expected + 1e-12;
      if (r.status == CorrectorStatus::Converged && !jumped) {
        x_from = r.x;
        c_from = c_to;
        frac = 1.0;
        continue;
      }
      ++out.summary.rejected_steps;
      if (++halvings > opt.max_halvings) {
        failed = true;
        out.summary.status = TrackStatus::StoppedEarly;
        out.summary.reason = "no converged step from edge length " + std::to_string(c_from) + " toward " +
                             std::to_string(c_target) + " after " + std::to_string(opt.max_halvings) +
                             " halvings (" + (jumped ? "the corrector jumped" : toString(r.status)) + ")";
        break;
      }
      frac *= 0.5;
    }
    if (failed) break;
    last_distance = (x_from - x_prev).norm();
    x_prev2 = x_prev;
    x_prev = x_from;
    c_prev = c_target;
    worst = std::max(worst, residualAt(x_from, c_target));
    out.samples.push_back(x_from);
    if (on_step && !on_step(k, steps)) {
      out.summary.status = TrackStatus::StoppedByCallback;
      out.summary.reason = "stopped on request";
      break;
    }
  }
  out.summary.steps_done = static_cast<int>(out.samples.size()) - 1;
  out.summary.max_residual = worst;
  if (out.summary.status == TrackStatus::Success && steps < needed) out.summary.reason.clear();
  return out;
}

}  // namespace flexure::engine
