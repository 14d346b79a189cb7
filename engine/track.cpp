#include "engine/track.h"

#include "engine/sticky_tracking.h"
#include "engine/systems/sphere_packing.h"

namespace flexure::engine {

DeformationPath track(const Model& model, const Vector& start, const MotionSpec& spec, const TrackerOptions& options,
                      const StepCallback& on_step) {
  DeformationPath path;
  const bool moves = spec.direction.size() > 0 && spec.direction.norm() > 0;
  if (spec.drive) {
    path = driveQuantity(model, start, spec.drive->quantity, spec.drive->target, spec.drive->options, on_step);
  } else if (spec.contraction) {
    path = contractEdge(model, start, spec.contraction->row, spec.contraction->target_length,
                        spec.contraction->options, on_step);
  } else if (moves && model.tracking() == Model::Tracking::Sticky) {
    // The model said it is a packing: the one type whose tracking is Sticky.
    path = trackStickyPacking(static_cast<const SpherePacking&>(model), spec.direction, options, on_step);
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
