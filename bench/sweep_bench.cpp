// flexure sweep: items per second over nauty's geng output (every connected graph on 8 vertices
// with 13 edges, 1,454 of them; on 9 vertices with 15 edges, 20,303), on 1 and 2 threads, CPU
// time and wall time (min of 3); and the overhead per item: a sweep of 20,000 single bars
// against the same analyses called directly in a loop.
// Usage: bench_sweep (geng: /usr/bin/nauty-geng, Debian's package nauty)
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "pipeline/pipeline.h"
#include "present/report.h"
#include "scenes/importers.h"
#include "sweep/sweep.h"

namespace {

namespace fs = std::filesystem;
using flexure::sweep::Options;

double cpuSeconds() {
  struct rusage ru {};
  ::getrusage(RUSAGE_SELF, &ru);
  return ru.ru_utime.tv_sec + ru.ru_stime.tv_sec + 1e-6 * (ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

struct Times {
  double cpu = 1e300, wall = 1e300;
};

template <class F>
Times minOf3(F f) {
  Times best;
  for (int i = 0; i < 3; ++i) {
    const double c0 = cpuSeconds();
    const auto t0 = std::chrono::steady_clock::now();
    f();
    best.cpu = std::min(best.cpu, cpuSeconds() - c0);
    best.wall = std::min(best.wall, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

long long sweepOnce(const std::string& input, int threads, const fs::path& out) {
  Options o;
  o.threads = threads;
  fs::remove(out);
  auto family = flexure::sweep::openFamily(input, o);
  return flexure::sweep::run(*family, input, o, out.string()).tally.items;
}

}  // namespace

int main() {
  const fs::path dir = fs::temp_directory_path() / ("bench_sweep_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path out = dir / "out.jsonl";
  for (const auto& [n, e] : {std::pair{8, 13}, std::pair{9, 15}}) {
    const fs::path g = dir / ("g" + std::to_string(n) + ".g6");
    const std::string cmd = "/usr/bin/nauty-geng -c -q " + std::to_string(n) + " " + std::to_string(e) + ":" +
                            std::to_string(e) + " > " + g.string();
    if (std::system(cmd.c_str()) != 0) {
      std::fprintf(stderr, "bench_sweep: nauty-geng failed (Debian's package nauty)\n");
      return 1;
    }
    Times t[2];
    long long items = 0;
    for (int threads : {1, 2}) t[threads - 1] = minOf3([&] { items = sweepOnce(g.string(), threads, out); });
    for (int threads : {1, 2})
      std::printf("sweep analyze n=%d m=%-2d %6lld graphs, %d thread%s  CPU %6.3f s  wall %6.3f s  %7.0f items/s (wall)"
                  "  %5.3f ms CPU per item\n",
                  n, e, items, threads, threads == 1 ? " " : "s", t[threads - 1].cpu, t[threads - 1].wall,
                  items / t[threads - 1].wall, 1e3 * t[threads - 1].cpu / static_cast<double>(items));
    std::printf("sweep analyze n=%d m=%-2d scaling 1 -> 2 threads: %.2fx (wall), CPU ratio %.2f\n", n, e,
                t[0].wall / t[1].wall, t[1].cpu / t[0].cpu);
  }
  // The overhead: 20,000 single bars (graph6 "A_"), swept on one thread, against the same scene
  // loaded and analysed 20,000 times in a loop with the report's JSON built (what each line needs).
  const int kBars = 20000;
  {
    std::ofstream f(dir / "bars.g6");
    for (int i = 0; i < kBars; ++i) f << "A_\n";
  }
  const Times swept = minOf3([&] { sweepOnce((dir / "bars.g6").string(), 1, out); });
  const flexure::scenes::ImportedGraph bar = flexure::scenes::readGraph6("A_\n", "bar")[0];
  const Times direct = minOf3([&] {
    for (int i = 0; i < kBars; ++i) {
      const flexure::scenes::Scene s = flexure::scenes::loadGraphScene(bar, 2, static_cast<std::uint64_t>(i), "bar", "bar");
      const auto rep = flexure::pipeline::analyze(s);
      volatile size_t keep = flexure::present::analysisJson(s, rep).size();
      (void)keep;
    }
  });
  std::printf("sweep of %d single bars, 1 thread: CPU %.3f s (%.1f us per item); the same analyses in a loop: "
              "%.1f us; the sweep's own cost: %.1f us per item\n",
              kBars, swept.cpu, 1e6 * swept.cpu / kBars, 1e6 * direct.cpu / kBars, 1e6 * (swept.cpu - direct.cpu) / kBars);
  fs::remove_all(dir);
  return 0;
}
