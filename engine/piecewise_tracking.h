// The motion of a model whose inequalities stick (engine/active_set.h, Rule::Stick: a sticky
// packing's contacts), tracked piecewise: the tracker stops at the first sample that breaks an
// inequality, the point where it becomes tight is located between the last sample and that one
// by bisection along the corrected chord, the model is rebuilt with it active there (a new
// segment of the path), and the motion continues along the old direction projected onto the new
// flexes, until the model is rigid.
#pragma once

#include "engine/deformation_path.h"
#include "engine/motion_tracker.h"

namespace flexure::engine {

// The motion of `model` (its inequalities() have the Stick rule) from its start along
// `direction` (a nontrivial flex there), options.steps samples at most (a located contact is one
// of them). Each inequality that becomes active is an event of kind Contact with its vertices in
// `vertices`. When the model has become rigid the motion is over: Success, with the reason
// saying where and why (StoppedEarly is for failures).
DeformationPath trackPiecewise(const Model& model, const Vector& direction, const TrackerOptions& options,
                               const StepCallback& on_step = {});

}  // namespace flexure::engine
