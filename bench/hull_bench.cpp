// facets = "hull": convexHullFacets (Qhull, merged into planar polygons) on random points on
// the unit sphere, and on a polytope with big planar facets; CPU time, best of 3. The O(n^4)
// search it replaced took 51 s for 800 points and hours for 3,000.
#include <ctime>
#include <cstdio>
#include <random>

#include "engine/systems/polytope.h"

using namespace flexure;

namespace {

double cpuSeconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

void run(const char* name, const engine::Matrix& p) {
  double best = 1e300;
  size_t facets = 0;
  for (int r = 0; r < 3; ++r) {
    const double t0 = cpuSeconds();
    facets = engine::convexHullFacets(p).size();
    best = std::min(best, cpuSeconds() - t0);
  }
  std::printf("%-40s %7d points %7zu facets  %9.4f s CPU\n", name, static_cast<int>(p.cols()), facets, best);
}

engine::Matrix sphere(int n) {
  std::mt19937_64 rng(1);
  std::normal_distribution<double> g;
  engine::Matrix p(3, n);
  for (int i = 0; i < n; ++i) p.col(i) = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
  return p;
}

}  // namespace

int main() {
  for (int n : {800, 3000, 30000, 100000}) run(("random points on a sphere, n = " + std::to_string(n)).c_str(), sphere(n));
  // A prism over a regular 5,000-gon: two 5,000-gons and 5,000 squares.
  const int m = 5000;
  engine::Matrix prism(3, 2 * m);
  for (int i = 0; i < m; ++i) {
    const double a = 2 * M_PI * i / m;
    prism.col(i) << std::cos(a), std::sin(a), 0;
    prism.col(m + i) << std::cos(a), std::sin(a), 1;
  }
  run("prism over a 5,000-gon", prism);
  return 0;
}
