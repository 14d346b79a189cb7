// Where the frames of an animation come from: which samples are shown, and how each
// configuration is moved (rigidly, or equi-affinely for volumes) so that the picture stays put.
#pragma once

#include <vector>

#include "engine/constraint_system.h"
#include "scenes/scene.h"

namespace flexure::present {

using scenes::Scene;

// The samples an animation shows: 0, k, 2k, ... and always the last one.
std::vector<int> frameSamples(int sample_count, int step);

// [render] fixed_vertices, resolved: as given; else none when something is pinned (the pins fix
// the picture), else vertices 1, 2 (and 3 in 3D, when not collinear with them).
std::vector<int> fixedVertices(const Scene& scene);

// Moves every configuration (d x n) by a proper rigid motion so that fixed[0] is at the origin,
// fixed[1] on the ray along `direction` (empty: e_x) and, in 3D, fixed[2] in the half-plane
// spanned by `direction` and the axis of e_y (e_z if direction is along e_y) orthogonal to it.
// Degenerate frames (the vertices coincide or are collinear) keep the previous frame's motion.
// How a configuration was moved for display: shown = A p + b (each column p).
struct DisplayMap {
  engine::Matrix A;
  engine::Vector b;
  static DisplayMap identity(int d) { return {engine::Matrix::Identity(d, d), engine::Vector::Zero(d)}; }
  engine::Matrix apply(const engine::Matrix& p) const { return (A * p).colwise() + b; }
};

// `maps`, if given, receives the map of each frame.
void alignConfigurations(std::vector<engine::Matrix>& frames, const std::vector<int>& fixed,
                         const std::vector<double>& direction, std::vector<DisplayMap>* maps = nullptr);

// Moves every configuration (d x n) by the equi-affine map taking simplex (a, b, c[, d]) to the
// reference simplex of AnimationSettings::fixed_simplex (orientation and volume kept). Frames
// where the simplex is degenerate are left as they are.
void normalizeEquiAffine(std::vector<engine::Matrix>& frames, const std::vector<int>& simplex, double target_stretch,
                         double tip_value, std::vector<DisplayMap>* maps = nullptr);

// The simplex the animation of `scene` normalises on: as given, else the first simplex of an
// unpinned volume hypergraph, else none.
std::vector<int> fixedSimplex(const Scene& scene);

}  // namespace flexure::present
