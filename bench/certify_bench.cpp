// Certified tracks (engine/interval/krawczyk.h) against the tracking they certify: CPU time of
// certifyPath and of trackMotion on the same path, best of `repeats`. Issue 44's targets: the
// double Watt's 500 steps at most 3x the tracking, a 1,000-vertex mechanism at most 5x. Quadratic
// systems from 64 coordinates get one anchor per step; beyond 300 coordinates what the anchors
// leave goes to the sparse norm test (engine/interval/krawczyk_sparse.cpp).
#include <algorithm>
#include <array>
#include <vector>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <ctime>

#include "bench/grids.h"
#include "engine/interval/krawczyk.h"
#include "engine/motion_tracker.h"
#include "engine/rigidity.h"
#include "engine/systems/framework.h"

using namespace flexure;
using engine::Framework;
using engine::Matrix;

namespace {

double cpu() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

Framework framework(const std::vector<std::array<double, 2>>& points, const std::vector<std::array<int, 2>>& edges,
                    const std::vector<int>& pins) {
  Matrix p(2, static_cast<int>(points.size()));
  for (size_t i = 0; i < points.size(); ++i) p(0, static_cast<int>(i)) = points[i][0], p(1, static_cast<int>(i)) = points[i][1];
  std::vector<Framework::Edge> e;
  for (const auto& [a, b] : edges) e.push_back({a, b});
  return Framework(p, e, pins);
}

// A ladder of `cells` squares, each braced by a diagonal except the first, pinned at its foot:
// the first cell is a four-bar that tilts the braced rest (one degree of freedom).
Framework ladder(int cells) {
  std::vector<std::array<double, 2>> pts;
  std::vector<std::array<int, 2>> edges;
  for (int i = 0; i <= cells; ++i) {
    pts.push_back({0.0, static_cast<double>(i)});
    pts.push_back({1.0, static_cast<double>(i)});
  }
  for (int i = 0; i < cells; ++i) {
    edges.push_back({2 * i, 2 * i + 2});
    edges.push_back({2 * i + 1, 2 * i + 3});
    edges.push_back({2 * i + 2, 2 * i + 3});
    if (i > 0) edges.push_back({2 * i, 2 * i + 3});
  }
  return framework(pts, edges, {0, 1});
}

void run(const char* name, const Framework& f, int steps, double step_size, int repeats) {
  const engine::RigidityReport rep = engine::analyzeRigidity(f, f.startCoordinates());
  engine::TrackerOptions opt;
  opt.steps = steps;
  opt.step_size = step_size;
  double track_best = 1e300, certify_best = 1e300;
  engine::DeformationPath p;
  engine::PathCertificate c;
  for (int i = 0; i < repeats; ++i) {
    double t = cpu();
    p = engine::trackMotion(f, f.startCoordinates(), rep.flex_basis * rep.auto_flex, opt);
    track_best = std::min(track_best, cpu() - t);
    p.startOn(f);
    t = cpu();
    c = engine::certify::certifyPath(p);
    certify_best = std::min(certify_best, cpu() - t);
  }
  int samples = 0, certified_steps = 0;
  for (double r : c.radii) samples += r >= 0;
  for (char s : c.steps) certified_steps += s != 0;
  std::printf("%-44s %5d vars  %4zu steps  track %7.3f s CPU  certify %7.3f s CPU  ratio %6.1f  certified: %zu/%zu "
              "samples, %d/%zu steps\n",
              name, f.system().numVariables(), p.samples.size() - 1, track_best, certify_best,
              certify_best / std::max(track_best, 1e-9), static_cast<size_t>(samples), c.radii.size(), certified_steps,
              c.steps.size());
  if (!c.certified()) std::printf("    %s\n", c.reason.substr(0, 400).c_str());
}

}  // namespace

int main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  // The cuspidal double Watt (scenes/examples/double_watt.toml), pinned at 1, 6 and 11.
  const auto doubleWatt = [] {
    return framework({{0, 0}, {1, 0}, {2, 1}, {1, 2}, {3, 2}, {4, 2}, {5, 2}, {7, 2}, {6, 1}, {7, 0}, {8, 0}},
                     {{0, 1}, {1, 2}, {1, 3}, {2, 8}, {2, 3}, {2, 4}, {3, 4}, {4, 5}, {5, 6}, {6, 7}, {6, 8},
                      {7, 8}, {7, 9}, {8, 9}, {9, 10}},
                     {0, 5, 10});
  };
  if (argc > 1 && std::string(argv[1]) == "watt") {  // the double Watt alone (profiling)
    run("double Watt, 500 steps of 0.02", doubleWatt(),
        500, 0.02, 20);
    return 0;
  }
  if (argc > 1) {  // one case: bench_certify ladder|grid SIZE STEPS STEP
    const std::string kind = argv[1];
    const int size = std::atoi(argv[2]);
    run(kind.c_str(), kind == "ladder" ? ladder(size) : bench::shearingGrid(size, size), std::atoi(argv[3]), std::atof(argv[4]), 1);
    return 0;
  }
  run("double Watt, 500 steps of 0.02",
      doubleWatt(),
      500, 0.02, 3);
  run("four-bar, unpinned (gauge slices), 200 steps",
      framework({{0, 0}, {2, 0}, {2.2, 1.1}, {0.3, 1.2}}, {{0, 1}, {0, 3}, {1, 2}, {2, 3}}, {}), 200, 0.05, 3);
  run("ladder of 49 cells (100 vertices), 50 steps", ladder(49), 50, 0.01, 1);
  run("ladder of 199 cells (400 vertices), 20 steps", ladder(199), 20, 0.002, 1);
  run("sheared grid 31x31 cells (1,024 vertices), 5 steps", bench::shearingGrid(31, 31), 5, 0.01, 1);
  run("sheared grid 31x31 cells (1,024 vertices), 50 steps", bench::shearingGrid(31, 31), 50, 0.01, 1);
  run("ladder of 499 cells (1,000 vertices), 5 steps", ladder(499), 5, 0.001, 1);
  return 0;
}
