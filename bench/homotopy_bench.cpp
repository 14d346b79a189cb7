// Homotopy continuation: all solutions of dense random quadratic systems (Bezout number 2^n,
// all of them finite and nonsingular for random coefficients), so the count is a check too.
#include <chrono>
#include <cstdio>
#include <random>

#include "engine/homotopy.h"

using namespace flexure::engine;
using Clock = std::chrono::steady_clock;

int main() {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  for (int n = 6; n <= 11; ++n) {
    std::mt19937 rng(static_cast<unsigned>(n));
    std::normal_distribution<double> g(0, 1);
    PolynomialSystem f(n);
    for (int i = 0; i < n; ++i) {
      std::vector<Monomial> p;
      for (int a = 0; a < n; ++a)
        for (int b = a; b < n; ++b) {
          std::vector<int> e(static_cast<size_t>(n), 0);
          ++e[static_cast<size_t>(a)], ++e[static_cast<size_t>(b)];
          p.push_back({g(rng), e});
        }
      for (int a = 0; a < n; ++a) {
        std::vector<int> e(static_cast<size_t>(n), 0);
        e[static_cast<size_t>(a)] = 1;
        p.push_back({g(rng), e});
      }
      p.push_back({g(rng), std::vector<int>(static_cast<size_t>(n), 0)});
      f.add(p);
    }
    const auto t0 = Clock::now();
    const HomotopyResult r = solveTotalDegree(f);
    const double s = std::chrono::duration<double>(Clock::now() - t0).count();
    int certified = 0;
    for (const Solution& x : r.solutions) certified += x.certified;
    std::printf("random quadrics n=%-2d  %5d paths  %5zu solutions (%d certified, %zu real)  %zu singular  %d at infinity  "
                "%d failed  %6.2f s  (%.2f ms/path)\n",
                n, r.paths, r.solutions.size(), certified, r.realSolutions().size(), r.singular.size(), r.at_infinity,
                r.failed, s, 1e3 * s / r.paths);
  }
  return 0;
}
