// Random 2D projections of deformation paths (paper figures 8 and 9): the curves, their plot
// and their coordinates as CSV. The paths themselves are tracked by the pipeline.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "engine/constraint_system.h"
#include "render/plot.h"
#include "scenes/scene.h"

namespace flexure::present {

using scenes::Scene;

// A random n x k matrix with orthonormal columns (the Q factor of a seeded Gaussian matrix).
engine::Matrix randomProjection(int n, int k, std::uint64_t seed);

// One curve of a projection plot, in free coordinates, in order along the curve.
struct ProjectionPath {
  std::string label;
  std::vector<engine::Vector> samples;
  std::vector<int> sample_numbers;  // per sample: its index on the tracked path (negative: along -flex)
  int start = 0;                    // where the start configuration is in `samples`
  std::vector<int> singular;        // indices (into samples) of singular points passed
  engine::Vector flex;              // the initial direction, free coordinates, unit length
  std::string status;               // the tracker's brief report(s)
  bool complete = true;             // every tracked piece reached its steps
};

struct Projection {
  std::uint64_t seed = 1;
  engine::Matrix q;                               // n x 2, orthonormal columns
  std::vector<std::vector<render::Point2>> curves;  // per path
  std::vector<int> starts;                          // per path: the start's index in its curve
  render::Plot plot;
};
Projection projectPaths(const Scene& scene, const std::vector<ProjectionPath>& paths, std::uint64_t seed);
// path,sample,p1,p2 (sample: the index on the tracked path; negative along -flex).
std::string projectionCsv(const std::vector<ProjectionPath>& paths, const Projection& projection);
render::PlotStyle projectionStyle(const Scene& scene, int width, int height);

}  // namespace flexure::present
