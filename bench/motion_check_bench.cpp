// The rigidity analysis of flexible frameworks with stresses, where the motion check (8 tracked
// steps) used to dominate (issue 20: the check should cost a small fraction of the analysis).
// analyzeRigidity without the check and with its default 8 steps; CPU time, best of 3 below
// 10^5 variables, one run above. Peak memory: the process's maximum resident set size after
// each case (it only grows, so the cases run from small to large).
#include <sys/resource.h>

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <string>

#include "bench/grids.h"
#include "engine/rigidity.h"

using namespace flexure;

namespace {

void run(const std::string& name, const engine::Framework& f, int repeats) {
  double cpu[2] = {1e300, 1e300};
  engine::RigidityReport rep;
  for (int with = 0; with < 2; ++with)
    for (int k = 0; k < repeats; ++k) {
      engine::RigidityOptions o;
      o.motion_check_steps = with ? 8 : 0;
      const std::clock_t t0 = std::clock();
      rep = engine::analyzeRigidity(f, f.startCoordinates(), o);
      cpu[with] = std::min(cpu[with], static_cast<double>(std::clock() - t0) / CLOCKS_PER_SEC);
    }
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  std::printf("%-44s %6d vars  %3d flexes  %5d stresses  %-8s  analysis %6.3f s CPU  with the motion check "
              "%6.3f s CPU (check: %5.2fx the rest)  peak %5.0f MB\n",
              name.c_str(), rep.variables, rep.nontrivial, rep.stresses, engine::toString(rep.rigid), cpu[0], cpu[1],
              (cpu[1] - cpu[0]) / cpu[0], static_cast<double>(u.ru_maxrss) / 1024.0);
}

}  // namespace

int main() {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  run("grid 60x60, every other row braced", bench::grid(60, 60, 2), 3);
  run("grid 100x100, every other row braced", bench::grid(100, 100, 2), 3);
  run("grid 224x224, 2 flexes, 20 redundant braces", bench::sparselyBraced(224, 20), 1);
  run("grid 224x224, every other row braced", bench::grid(224, 224, 2), 1);
  return 0;
}
