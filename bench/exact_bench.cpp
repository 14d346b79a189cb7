// The exact mode (engine/exact/) against the double analysis on the same frameworks: CPU time
// of analyzeExact (rational Jacobian, FLINT rank, trivial flexes; bases and the second-order
// step when there are flexes and stresses) and of analyzeRigidity, best of `repeats` runs.
// Issue 44's targets: the 20x20 triangulated grid (800 variables) under 1 s, 10^4 variables
// under 30 s. `bench_exact [NAME]`: only the cases whose name contains NAME.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <ctime>

#include "bench/grids.h"
#include "engine/exact/exact_rigidity.h"

using namespace flexure;

namespace {

double cpu() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

const char* only = nullptr;  // argv[1]: run the cases whose name contains it

void run(const char* name, const engine::Framework& f, int repeats) {
  if (only && !std::strstr(name, only)) return;
  double exact_best = 1e300, double_best = 1e300;
  engine::exact::ExactAnalysis ex;
  engine::RigidityReport rep;
  const engine::RationalMatrix points = engine::exact::pointsFromDoubles(f);
  for (int i = 0; i < repeats; ++i) {
    double t = cpu();
    rep = engine::analyzeRigidity(f, f.startCoordinates());
    double_best = std::min(double_best, cpu() - t);
    t = cpu();
    ex = engine::exact::analyzeExact(f, points, &rep);
    exact_best = std::min(exact_best, cpu() - t);
  }
  std::printf("%-46s %6d vars %6d eqs  exact: rank %6d  nontrivial %3d  stresses %5d  ps %-9s %8.3f s CPU   "
              "double: rank %6d %8.3f s CPU   ratio %5.1f\n",
              name, ex.variables, ex.equations, ex.rank, ex.nontrivial, ex.stresses,
              ex.prestress_stable ? (*ex.prestress_stable ? "proved" : "disproved") : "undecided", exact_best, rep.rank,
              double_best, exact_best / std::max(double_best, 1e-9));
}

}  // namespace

int main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  if (argc > 1) only = argv[1];
  run("triangulated grid 5x5 (25 vertices)", bench::grid(5, 5, 1), 3);
  run("triangulated grid 6x6 (36 vertices)", bench::grid(6, 6, 1), 3);
  run("triangulated grid 15x15 (225 vertices)", bench::grid(15, 15, 1), 3);
  run("triangulated grid 20x20 (400 vertices)", bench::grid(20, 20, 1), 3);
  run("triangulated grid 30x30 (900 vertices)", bench::grid(30, 30, 1), 3);
  run("triangulated grid 71x71 (10,082 variables)", bench::grid(71, 71, 1), 3);
  run("triangulated grid 100x100 (20,000 variables)", bench::grid(100, 100, 1), 1);
  run("grid 12x12, shears (2 flexes, 3 stresses)", bench::sparselyBraced(12, 3), 3);
  run("grid 20x20, every other row braced", bench::grid(20, 20, 2), 1);
  return 0;
}
