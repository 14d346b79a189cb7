#include "engine/continuation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "engine/factorization.h"

namespace flexure::engine {

DeformationPath continueParameter(const Vector& start, const ParameterSteps& kind, const ContinuationSchedule& sch,
                                  const StepCallback& on_step) {
  if (!(sch.step > 0)) throw std::invalid_argument("the continuation step must be positive");
  DeformationPath out;
  out.samples.push_back(start);
  const double c0 = sch.start, span = sch.target - c0;
  const double needed_steps = std::ceil(std::abs(span) / sch.step - 1e-9);
  if (!(needed_steps <= std::numeric_limits<int>::max()) && sch.max_steps < 0)
    throw std::invalid_argument("the continuation needs more than 2^31 steps; give a larger step or a step limit");
  const int needed = static_cast<int>(std::min<double>(needed_steps, std::numeric_limits<int>::max()));
  const int steps = sch.max_steps >= 0 ? std::min(sch.max_steps, needed) : needed;
  out.summary.steps_requested = steps;
  out.summary.seed = 0;
  auto valueAt = [&](int k) { return k >= needed ? sch.target : c0 + (span > 0 ? 1 : -1) * sch.step * k; };
  const auto text = [&](double c) { return kind.valueText ? kind.valueText(c) : std::to_string(c); };
  double worst = kind.residual(start, c0);
  double last_distance = -1;  // between the last two samples
  double c_prev = c0;
  Vector x_prev = start, x_prev2;
  out.summary.status = TrackStatus::Success;
  for (int k = 1; k <= steps; ++k) {
    const double c_target = valueAt(k);
    // Reach c_target from c_prev, in sub-steps when a step fails or jumps.
    double c_from = c_prev;
    Vector x_from = x_prev;
    int halvings = 0;
    double frac = 1.0;
    bool failed = false;
    while (c_from != c_target) {
      const double c_to = frac >= 1.0 ? c_target : c_from + frac * (c_target - c_from);
      // The secant through the last two samples, scaled to this parameter step; the kind's
      // first-order step where there is none (or inside a halved step).
      const Vector predicted = x_prev2.size() && c_from == c_prev
                                   ? Vector(x_from + (x_prev - x_prev2) * ((c_to - c_from) / (c_prev - valueAt(k - 2))))
                                   : Vector(x_from + kind.tangent(x_from, c_from, c_to));
      const CorrectorResult r = kind.correct(predicted, c_to);
      const double moved = (r.x - x_from).norm();
      const double expected = last_distance > 0 ? last_distance * std::abs(c_to - c_from) / sch.step : -1;
      const bool jumped = expected > 0 && moved > 8.0 * expected + 1e-12;
      if (r.status == CorrectorStatus::Converged && !jumped) {
        x_from = r.x;
        c_from = c_to;
        frac = 1.0;
        continue;
      }
      ++out.summary.rejected_steps;
      if (++halvings > sch.max_halvings) {
        failed = true;
        out.summary.status = TrackStatus::StoppedEarly;
        out.summary.reason = "no converged step from " + kind.parameter + " " + text(c_from) + " toward " +
                             text(c_target) + " after " + std::to_string(sch.max_halvings) + " halvings (" +
                             (jumped ? "the corrector jumped" : toString(r.status)) + ")";
        break;
      }
      frac *= 0.5;
    }
    if (failed) break;
    if (kind.admissible && !kind.admissible(x_from)) {
      out.summary.status = TrackStatus::LeftAdmissibleSet;
      out.summary.reason = "the next sample left the admissible set";
      out.outside = x_from;
      break;
    }
    last_distance = (x_from - x_prev).norm();
    x_prev2 = x_prev;
    x_prev = x_from;
    c_prev = c_target;
    worst = std::max(worst, kind.residual(x_from, c_target));
    out.samples.push_back(x_from);
    if (on_step && !on_step(k, steps)) {
      out.summary.status = TrackStatus::StoppedByCallback;
      out.summary.reason = "stopped on request";
      break;
    }
  }
  out.summary.steps_done = static_cast<int>(out.samples.size()) - 1;
  out.summary.max_residual = worst;
  if (out.summary.status == TrackStatus::Success)
    out.summary.reason = steps < needed ? "" : "the " + kind.parameter + " reached its target, " + text(sch.target);
  return out;
}

DeformationPath driveQuantity(const Model& model, const Vector& start, const DrivenQuantity& q, double target,
                              const DriveOptions& opt, const StepCallback& on_step) {
  const ConstraintSystem& sys = model.system();
  if (opt.steps < 1) throw std::invalid_argument("a drive takes at least one step");
  if (!std::isfinite(target)) throw std::invalid_argument("the drive's target is not a finite number");
  const double c0 = q.value(start);
  ParameterSteps kind;
  kind.parameter = q.name;
  kind.valueText = q.valueText;
  kind.admissible = opt.admissible;
  kind.tangent = [&](const Vector& x, double from, double to) -> Vector {
    const Vector g = q.gradient(x);
    if (q.first_direction.size() == x.size() && from == c0 && x == start) {
      const double rate = g.dot(q.first_direction);
      if (std::abs(rate) > 1e-12 * g.norm() * q.first_direction.norm()) return q.first_direction * ((to - from) / rate);
    }
    // The least displacement with J dx = 0 and g . dx = to - from.
    const JacobianFactorization fac(appendRows(sys.jacobian(x), g.transpose()), opt.corrector.factorization);
    Vector b = Vector::Zero(sys.numEquations() + 1);
    b[sys.numEquations()] = to - from;
    return fac.solveMinNorm(b);
  };
  kind.correct = [&](const Vector& guess, double c) {
    ScalarEquation eq;
    eq.value = [&](const Vector& x) { return q.units * (q.value(x) - c); };
    eq.gradient = [&](const Vector& x) -> Vector { return q.units * q.gradient(x); };
    return correct(sys, guess, opt.corrector, {}, nullptr, nullptr, &eq);
  };
  kind.residual = [&](const Vector& x, double c) {
    const Vector f = sys.residuals(x);
    return std::max(f.size() ? f.cwiseAbs().maxCoeff() : 0.0, std::abs(q.units * (q.value(x) - c)));
  };
  ContinuationSchedule sch;
  sch.start = c0;
  sch.target = target;
  sch.step = std::abs(target - c0) / opt.steps;
  sch.max_halvings = opt.max_halvings;
  if (!(sch.step > 0)) {  // already there
    DeformationPath out;
    out.samples.push_back(start);
    out.summary.status = TrackStatus::Success;
    out.summary.reason = "the " + q.name + " is at its target already";
    out.summary.max_residual = kind.residual(start, c0);
    return out;
  }
  return continueParameter(start, kind, sch, on_step);
}

}  // namespace flexure::engine
