// The exact mode's cost model (engine/exact/exact_cost.h, issue 62) against the work it
// estimates: for random frameworks (n vertices at coordinates k/10^4, 2n random bars: flexible,
// with stresses, so FLINT's dense elimination runs) and triangulated grids (the modular rank
// proves them), the estimate made before the work beside the measured CPU time and peak memory
// of analyzeExact, each case in its own child process (its own peak). The estimate must be
// within 4x of the measured time on every case (docs/benchmarks.md).
// `bench_exact_budget [NAME]`: only the cases whose name contains NAME.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <random>
#include <set>
#include <string>

#include "bench/grids.h"
#include "engine/exact/exact_rigidity.h"

using namespace flexure;

namespace {

const char* only = nullptr;

// n vertices at coordinates k/10^4 (exact decimals: pointsFromDoubles reads them back exactly)
// and 2n distinct random bars.
engine::Framework randomFramework(int n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> coord(0, 9999), vertex(0, n - 1);
  engine::Matrix p(2, n);
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < 2; ++k) p(k, i) = coord(rng) / 1e4;
  std::set<std::pair<int, int>> edges;
  while (static_cast<int>(edges.size()) < 2 * n) {
    const int a = vertex(rng), b = vertex(rng);
    if (a != b) edges.insert({std::min(a, b), std::max(a, b)});
  }
  std::vector<engine::Framework::Edge> e;
  for (const auto& [a, b] : edges) e.push_back({a, b});
  return engine::Framework(p, e, {});
}

// Runs the case in a child; prints one line.
template <class Make>
void run(const std::string& name, Make make) {
  if (only && name.find(only) == std::string::npos) return;
  std::fflush(stdout);
  const pid_t pid = ::fork();
  if (pid == 0) {
    const engine::Framework f = make();
    const engine::RationalMatrix points = engine::exact::pointsFromDoubles(f);
    const engine::RigidityReport rep = engine::analyzeRigidity(f, f.startCoordinates());
    engine::exact::ExactOptions o;
    o.budget_seconds = 1e9;
    const engine::exact::ExactAnalysis ex = engine::exact::analyzeExact(f, points, &rep, o);
    rusage u{};
    ::getrusage(RUSAGE_SELF, &u);
    const double ratio = ex.estimated_seconds / std::max(ex.seconds, 1e-9);
    std::printf("%-34s %5d vars %5d eqs  rank %5d  nontrivial %4d  stresses %4d   estimate %8.3f s %9.1f MB   "
                "measured %8.3f s CPU  peak RSS %8.1f MB   estimate/measured %5.2f%s\n",
                name.c_str(), ex.variables, ex.equations, ex.rank, ex.nontrivial, ex.stresses, ex.estimated_seconds,
                ex.estimated_bytes / 1e6, ex.seconds, u.ru_maxrss / 1e3, ratio,
                ratio > 4 || ratio < 0.25 ? "  OUTSIDE 4x" : "");
    std::fflush(stdout);
    ::_exit(0);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) std::printf("%-34s failed (status %d)\n", name.c_str(), status);
}

}  // namespace

int main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  if (argc > 1) only = argv[1];
  for (int n : {100, 200, 300, 400, 500, 600, 700})
    run("random " + std::to_string(n) + " vertices, 2n bars", [n] { return randomFramework(n, 62u + n); });
  for (int c : {10, 14, 17, 20, 22, 24, 26})
    run("triangulated grid " + std::to_string(c) + "x" + std::to_string(c), [c] { return bench::grid(c, c, 1); });
  for (int c : {10, 14, 17, 20})
    run("grid " + std::to_string(c) + "x" + std::to_string(c) + ", every other row braced",
        [c] { return bench::grid(c, c, 2); });
  return 0;
}
