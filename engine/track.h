// One entry point for every kind of motion: a flex followed by Algorithm ACM, a sticky
// packing's piecewise motion (chosen by the model's inequalities, engine/active_set.h), the
// contraction of an edge, or a driven quantity (a fold angle). The result is a DeformationPath
// whose segments name the model at every sample. Inequalities with the Release rule are refused
// (std::logic_error): no tracker implements them yet.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "engine/continuation.h"
#include "engine/contraction.h"
#include "engine/deformation_path.h"
#include "engine/motion_tracker.h"

namespace flexure::engine {

struct EdgeContraction {
  int row = -1;              // the edge's equation (distanceEquation)
  double target_length = 0;  // where its length goes
  ContractionOptions options;
};

// A scalar quantity driven to a target (a fold angle, a fold percentage: continuation.h).
struct QuantityDrive {
  DrivenQuantity quantity;
  double target = 0;
  DriveOptions options;
};

struct MotionSpec {
  // A nontrivial infinitesimal flex at the start (free coordinates). Zero or empty: nothing
  // moves, and the path is the start alone, stopped early.
  Vector direction;
  // Set: the edge is contracted instead, and `direction` is not used.
  std::optional<EdgeContraction> contraction;
  // Set: the quantity is driven instead.
  std::optional<QuantityDrive> drive;
  // Recorded with the path (DeformationPath::flex, flex_choice).
  std::vector<double> coefficients;
  std::string note;
};

// The motion of `model` from `start`. options.steps caps the samples after the start for a
// flex; the contraction's and the drive's own options set theirs.
DeformationPath track(const Model& model, const Vector& start, const MotionSpec& spec, const TrackerOptions& options,
                      const StepCallback& on_step = {});

}  // namespace flexure::engine
