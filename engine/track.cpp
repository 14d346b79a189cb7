#include "engine/track.h"

#include <stdexcept>

#include "engine/active_set.h"
#include "engine/piecewise_tracking.h"

namespace flexure::engine {

DeformationPath track(const Model& model, const Vector& start, const MotionSpec& spec, const TrackerOptions& options,
                      const StepCallback& on_step) {
  const Inequalities* inequalities = model.inequalities();
  if (inequalities && inequalities->rule() == Inequalities::Rule::Release)
    throw std::logic_error("engine::track: the " + model.typeName() +
                           " model's inequalities have the Release rule, which no tracker implements yet");
  DeformationPath path;
  const bool moves = spec.direction.size() > 0 && spec.direction.norm() > 0;
  if (spec.drive) {
    path = driveQuantity(model, start, spec.drive->quantity, spec.drive->target, spec.drive->options, on_step);
  } else if (spec.contraction) {
    path = contractEdge(model, start, spec.contraction->row, spec.contraction->target_length,
                        spec.contraction->options, on_step);
  } else if (moves && inequalities && inequalities->rule() == Inequalities::Rule::Stick) {
    // Contacts that join stay (a sticky packing): one model per segment.
    path = trackPiecewise(model, spec.direction, options, on_step);
  } else {
    const Vector direction = spec.direction.size() > 0 ? spec.direction : Vector::Zero(start.size());
    path = trackMotion(model, start, direction, options, moves ? on_step : StepCallback{});
  }
  if (path.segments.empty()) path.startOn(model);
  path.flex = spec.coefficients;
  path.flex_choice = spec.note;
  return path;
}

}  // namespace flexure::engine
