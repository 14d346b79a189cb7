// The motion of a sticky packing, tracked piecewise: the tracker stops at the first sample with
// an overlap, the contact is located between the last sample and that one by bisection along
// the corrected chord, the packing is rebuilt with the new contact there (a new segment of the
// path), and the motion continues along the old direction projected onto the new flexes, until
// the packing is rigid.
#pragma once

#include "engine/deformation_path.h"
#include "engine/motion_tracker.h"
#include "engine/systems/sphere_packing.h"

namespace flexure::engine {

// The sticky motion of `packing` from its start along `direction` (a nontrivial flex there),
// options.steps samples at most (a located contact is one of them). Each new contact is an event
// of kind Contact with its pair in `vertices`. When the packing has become rigid the motion is
// over: Success, with the reason saying where and why (StoppedEarly is for failures).
DeformationPath trackStickyPacking(const SpherePacking& packing, const Vector& direction, const TrackerOptions& options,
                                   const StepCallback& on_step = {});

}  // namespace flexure::engine
