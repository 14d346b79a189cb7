// Rigidity analysis of large frameworks: time of analyzeRigidity (Jacobian, rank decision,
// kernel, trivial flexes, canonical bases), best of `repeats` runs.
#include <chrono>
#include <cstdio>

#include "bench/grids.h"
#include "engine/rigidity.h"

using namespace flexure;

namespace {

void run(const char* name, const engine::Framework& f, int repeats) {
  double best = 1e300;
  engine::RigidityReport rep;
  for (int i = 0; i < repeats; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    rep = engine::analyzeRigidity(f, f.startCoordinates());
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    best = std::min(best, s);
  }
  std::printf("%-44s %6d vars %6d eqs  rank %6d  trivial %d  nontrivial %5d  stresses %5d  %-10s %8.3f s\n",
              name, rep.variables, rep.equations, rep.rank, rep.trivial, rep.nontrivial, rep.stresses,
              rep.method.c_str(), best);
}

}  // namespace

int main() {
  run("triangulated grid 20x20 (400 vertices)", bench::grid(20, 20, 1), 3);
  run("triangulated grid 100x100 (10,000 vertices)", bench::grid(100, 100, 1), 3);
  run("grid 60x60, every other row braced", bench::grid(60, 60, 2), 3);
  return 0;
}
