// The motion check inside the rigidity analysis (issue 20: it should cost a small fraction of
// the analysis): analyzeRigidity of braced grids (every other row braced: flexible, with many
// stresses) without the check and with its default 8 steps. CPU time, best of 3.
#include <algorithm>
#include <cstdio>
#include <ctime>

#include "bench/grids.h"
#include "engine/rigidity.h"

using namespace flexure;

int main() {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  for (int n : {60, 100}) {
    const engine::Framework f = bench::grid(n, n, 2);
    double cpu[2] = {1e300, 1e300};
    engine::RigidityReport rep;
    for (int with = 0; with < 2; ++with)
      for (int k = 0; k < 3; ++k) {
        engine::RigidityOptions o;
        o.motion_check_steps = with ? 8 : 0;
        const std::clock_t t0 = std::clock();
        rep = engine::analyzeRigidity(f, f.startCoordinates(), o);
        cpu[with] = std::min(cpu[with], static_cast<double>(std::clock() - t0) / CLOCKS_PER_SEC);
      }
    std::printf("grid %dx%d, every other row braced  %6d vars  %3d flexes  %5d stresses  analysis %6.3f s CPU  "
                "with the motion check %6.3f s CPU (check: %4.1fx the rest)\n",
                n, n, rep.variables, rep.nontrivial, rep.stresses, cpu[0], cpu[1], (cpu[1] - cpu[0]) / cpu[0]);
  }
  return 0;
}
