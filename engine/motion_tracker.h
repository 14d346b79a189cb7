// Algorithm ACM (paper section 4): a deformation path from a start configuration along a
// nontrivial flex. Predictor along the transported tangent (quadratic, with the acceleration
// from the constraints' true second derivatives), damped Gauss-Newton corrector, unit-speed
// step control, vector transport (Procrustes; large systems: projection onto the new flex
// space), jump rejection, and strategies that carry the path through singular points (nodes,
// cusps). Deterministic for a given seed.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "engine/corrector.h"
#include "engine/deformation_path.h"
#include "engine/model.h"

namespace flexure::engine {

struct TrackerOptions {
  int steps = 100;              // samples to produce after the start
  // Distance between consecutive samples: the 2-norm of the vertices' free coordinates (the
  // configuration; auxiliary variables such as facet normals do not count).
  double step_size = 0.01;
  std::uint64_t seed = 1;       // the randomization matrices derive from it
  // A corrected step whose secant makes an angle larger than acos(max_turn_cos) with the
  // predicted direction jumped (possibly to another branch): it is rejected and retried shorter.
  double max_turn_cos = 0.8;
  // Give up on a regular step after this many halvings of the predictor length.
  int max_halvings = 10;
  // The predictor length is rescaled (unit speed, paper 4.2) until the sample distance is
  // within spacing_tolerance * step_size of step_size, at most max_rescales times.
  double spacing_tolerance = 0.05;
  int max_rescales = 4;
  // Tracking factors the Jacobian at every corrector iteration: a dense SVD (full U and V)
  // costs ~50 ms at 400 x 400 where the sparse QR takes ~2 ms, so the dense path stops at 200
  // (the rank decisions of the analysis keep the SVD up to RigidityOptions::dense_limit).
  static constexpr int kDenseLimit = 200;
  static FactorizationOptions trackingFactorization() {
    FactorizationOptions f;
    f.dense_limit = kDenseLimit;
    return f;
  }
  static CorrectorOptions trackingCorrector() {
    CorrectorOptions c;
    c.factorization = trackingFactorization();
    return c;
  }
  CorrectorOptions corrector = trackingCorrector();
  FactorizationOptions factorization = trackingFactorization();
  // Optional: a corrected sample for which this returns false is not accepted; the path ends
  // before it with status LeftAdmissibleSet and the sample in DeformationPath::outside (sticky
  // packings stop at the first overlap and locate the contact between the two).
  std::function<bool(const Vector&)> admissible;
  // Sample numbers in messages count from this (a path tracked piece by piece).
  int sample_offset = 0;
  // Optional: the first sample, a point on the constraints about a step from the start that
  // the caller found (origami's mountain/valley fold from its flat state); the path goes on
  // from it along its tangent, away from the start.
  std::optional<Vector> first_point;
};

// `direction`: a nontrivial infinitesimal flex at `start` (free coordinates, any length > 0).
// The path's segments are left empty (engine::track sets them).
DeformationPath trackMotion(const Model& model, const Vector& start, const Vector& direction,
                        const TrackerOptions& options, const StepCallback& on_step = {});

}  // namespace flexure::engine
