// Continuation in a scalar parameter c (paper B.2, notes 3.7): the solutions of G(x, c) = 0 from
// the start's c0 to a target, at c = c0, c0 +- h, ..., target. Each sample is predicted (the
// kind's first-order step at the first one, the secant through the last two after) and
// corrected with the tracker's Gauss-Newton. A step that fails or jumps is retried in halves
// internally (only the samples at the schedule's values are kept). Deterministic: no random
// restarts. Two kinds: an edge's length (edge contraction, contraction.h) and a driven scalar
// quantity such as a fold angle (driveQuantity below).
#pragma once

#include <functional>
#include <string>

#include "engine/corrector.h"
#include "engine/deformation_path.h"
#include "engine/motion_tracker.h"

namespace flexure::engine {

// What a kind of continuation supplies.
struct ParameterSteps {
  // The first-order change of x from the parameter c_from to c_to (the predictor where there is
  // no secant yet).
  std::function<Vector(const Vector& x, double c_from, double c_to)> tangent;
  // x corrected onto G(., c) = 0 from the guess, predicted from x_from (the point the step
  // starts at).
  std::function<CorrectorResult(const Vector& x_from, const Vector& guess, double c)> correct;
  // The largest |G(x, c)| (the path's max_residual).
  std::function<double(const Vector& x, double c)> residual;
  // Set: a sample outside ends the path before it (status LeftAdmissibleSet, the sample in
  // DeformationPath::outside).
  std::function<bool(const Vector&)> admissible;
  // The parameter as the messages name it ("edge length", "fold angle of crease [1, 2]"), and
  // its value as they print it.
  std::string parameter;
  std::function<std::string(double)> valueText;
  // Optional: the predicted point from x_from, changed by the kind (e.g. moved within the
  // first-order solutions to keep rates in proportion).
  std::function<Vector(const Vector& x_from, const Vector& predicted)> adjust;
};

struct ContinuationSchedule {
  double start = 0;     // c0, the start's value
  double target = 0;
  double step = 0;      // |change| per sample, > 0
  int max_steps = -1;   // at most this many samples after the start (-1: until the target)
  int max_halvings = 12;
};

DeformationPath continueParameter(const Vector& start, const ParameterSteps& kind, const ContinuationSchedule& schedule,
                                  const StepCallback& on_step = {});

// A scalar function of the configuration driven from its value at the start to a target, every
// constraint kept: a fold angle, or a fold percentage (origami). Where the constraints leave
// several degrees of freedom, the quantity says what else holds: other quantities held at their
// start values (`held`: exact, as equations), or rates the steps keep proportional to
// `proportions` as well as first order allows (`rates`: each step's predictor, least squares);
// without either, each step is the least displacement that moves the quantity.
struct DrivenQuantity {
  std::string name;                                // "fold angle of crease [1, 2]"
  std::function<double(const Vector&)> value;      // free coordinates -> the quantity
  std::function<Vector(const Vector&)> gradient;   // its gradient in free coordinates
  // The residual of "value = c" is units * (value - c), in the system's units (residualScale()),
  // and so are the held quantities' (units * (held - held at the start)).
  double units = 1;
  // Optional: the first predictor's direction (e.g. the fold the mountain/valley assignment
  // asks for, where the start is a flat sheet and the linearization has many more directions
  // than there are motions); scaled to the first parameter step.
  Vector first_direction;
  std::function<std::string(double)> valueText;   // how messages print a value
  // Optional: quantities held at their start values all along (e.g. the other creases' angles),
  // and their gradients (rows).
  std::function<Vector(const Vector&)> held;
  std::function<Matrix(const Vector&)> held_gradients;
  // Optional: rates (rows: gradients of quantities such as every crease's angle) and the
  // proportions their changes should keep: each step's predictor (secant, or first order) is
  // moved within the first-order steps that keep the constraints and the quantity's schedule
  // to the one whose rates are closest to a multiple of `proportions` (least squares).
  std::function<Matrix(const Vector&)> rates;
  Vector proportions;
};

struct DriveOptions {
  int steps = 100;                   // equal steps from the start's value to the target
  int max_halvings = 12;
  CorrectorOptions corrector = TrackerOptions::trackingCorrector();  // the tracker's factorization
  std::function<bool(const Vector&)> admissible;  // as ParameterSteps::admissible
};

// With 0 steps the path is the start alone. Throws std::invalid_argument when steps < 0 or the
// target is not finite.
DeformationPath driveQuantity(const Model& model, const Vector& start, const DrivenQuantity& quantity, double target,
                              const DriveOptions& options, const StepCallback& on_step = {});

}  // namespace flexure::engine
