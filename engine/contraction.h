// Edge contraction (paper B.2, notes 3.7): a continuation in the length c of one edge, from its
// current length to a target, every other constraint kept. Samples at c = c0, c0 +- h, ...,
// target; each one predicted (minimum-norm tangent at the first step, secant after) and
// corrected with the tracker's Gauss-Newton. A step that fails or jumps is retried in halves
// internally (only the samples at the schedule's lengths are kept). Deterministic: no random
// restarts. The result is a deformation path, with max_residual measured
// against the moving edge length.
#pragma once

#include "engine/corrector.h"
#include "engine/deformation_path.h"

namespace flexure::engine {

struct ContractionOptions {
  double step = 0.002;   // change of the edge length per sample
  int max_steps = -1;    // at most this many samples after the start (-1: until the target)
  int max_halvings = 12; // a parameter step is halved at most this often before giving up
  CorrectorOptions corrector;
};

// The equation row of the squared-distance constraint between vertices a and b, or -1.
int distanceEquation(const ConstraintSystem& system, int a, int b);

// `row`: the edge's equation (distanceEquation). Throws std::invalid_argument when target <= 0.
DeformationPath contractEdge(const Model& model, const Vector& start, int row, double target_length,
                         const ContractionOptions& options, const StepCallback& on_step = {});

}  // namespace flexure::engine
