// Tracking speed: steps per second, and time per step over the time of one factorization of
// the Jacobian at that size (the floor: every step needs at least one). CPU time (the machine
// is shared).
#include <cstdio>
#include <ctime>

#include "bench/grids.h"
#include "engine/factorization.h"
#include "engine/motion_tracker.h"
#include "engine/rigidity.h"

using namespace flexure;

namespace {

double seconds(std::clock_t t0) { return static_cast<double>(std::clock() - t0) / CLOCKS_PER_SEC; }

void run(const char* name, const engine::Framework& f, int steps, double step_size, int repeats) {
  const engine::Vector x0 = f.startCoordinates();
  const engine::RigidityReport rep = engine::analyzeRigidity(f, x0);
  engine::TrackerOptions opt;
  opt.steps = steps;
  opt.step_size = step_size;
  // The floor: one factorization of J at the start, best of 5 before the tracking and 5 after
  // it (the allocator's state moves its time: 0.12 against 0.17 s at 10^5 variables, when the
  // process's earlier large blocks were or were not handed back to the system).
  const engine::SparseMatrix J = f.system().jacobian(x0);
  double fact = 1e300;
  auto floor = [&] {
    for (int i = 0; i < 5; ++i) {
      const std::clock_t t0 = std::clock();
      const engine::JacobianFactorization fac(J, opt.factorization);
      fact = std::min(fact, seconds(t0));
    }
  };
  floor();
  double best = 1e300, later = 1e300;
  engine::DeformationPath r;
  for (int i = 0; i < repeats; ++i) {
    const std::clock_t t0 = std::clock();
    std::clock_t t1 = t0;
    r = engine::trackMotion(f, x0, rep.flex_basis * rep.auto_flex, opt, [&](int step, int) {
      if (step == 1) t1 = std::clock();
      return true;
    });
    best = std::min(best, seconds(t0));
    later = std::min(later, seconds(t1));
  }
  floor();
  // Per step over the whole run (the start's analysis and first step included), and over the
  // steps after the first (what a long path costs per step).
  const double per_step = best / std::max(1, r.summary.steps_done);
  const double per_later = later / std::max(1, r.summary.steps_done - 1);
  std::printf("%-46s %6d vars %3d flexes  %d/%d steps  %8.3f s  %8.0f steps/s  %7.3f ms/step  factorization %7.3f ms  ratio %5.1f  after the first step %7.3f ms/step, ratio %5.1f  (%s)\n",
              name, rep.variables, rep.nontrivial, r.summary.steps_done, steps, best, r.summary.steps_done / best,
              1e3 * per_step, 1e3 * fact, per_step / fact, 1e3 * per_later, per_later / fact, r.summary.briefReport().c_str());
}

}  // namespace

int main() {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  engine::Matrix p(2, 11);
  p << 0, 1, 2, 1, 3, 4, 5, 7, 6, 7, 8,
       0, 0, 1, 2, 2, 2, 2, 2, 1, 0, 0;
  std::vector<engine::Framework::Edge> e1 = {{1, 2}, {2, 3}, {2, 4}, {3, 9}, {3, 4}, {3, 5}, {4, 5}, {5, 6},
                                             {6, 7}, {7, 8}, {7, 9}, {8, 9}, {8, 10}, {9, 10}, {10, 11}};
  std::vector<engine::Framework::Edge> edges;
  for (auto e : e1) edges.push_back({e[0] - 1, e[1] - 1});
  run("double Watt, 500 steps of 0.05", engine::Framework(p, edges, {0, 5, 10}), 500, 0.05, 5);
  run("grid 60x60, every other row braced", bench::grid(60, 60, 2), 100, 0.05, 1);
  run("grid 60x60, 2 flexes, 20 redundant braces", bench::sparselyBraced(60, 20), 100, 0.05, 1);
  run("grid 224x224, 2 flexes, 20 redundant braces", bench::sparselyBraced(224, 20), 10, 0.05, 1);
  run("grid 224x224, every other row braced", bench::grid(224, 224, 2), 10, 0.05, 1);
  return 0;
}
