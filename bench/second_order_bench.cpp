// Second-order rigidity as the number of flexes r grows (r = 1..6): the time of each stage on
// random stress-energy forms (s = r stresses, and s = 2), and of the whole analysis on the
// catalog's second-order cases. Stages: prestress stability (the semidefinite program), the
// sum-of-squares certificate, and the critical-point homotopy (3^r paths, forced on).
#include <chrono>
#include <cstdio>
#include <random>

#include "engine/second_order.h"

using namespace flexure::engine;
using Clock = std::chrono::steady_clock;

namespace {

double seconds(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

const char* outcome(BlockedFlexResult::Outcome o) {
  switch (o) {
    case BlockedFlexResult::Outcome::AllBlocked: return "all blocked";
    case BlockedFlexResult::Outcome::Unblocked: return "unblocked flex";
    case BlockedFlexResult::Outcome::Undecided: return "undecided";
  }
  return "";
}

}  // namespace

int main() {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  for (int r = 1; r <= 6; ++r)
    for (int s : {r, r > 2 ? 2 : -1}) {
      if (s < 0) continue;  // r = 1, 2: s = r only
      std::mt19937 rng(static_cast<unsigned>(100 * r + s));
      std::normal_distribution<double> g(0, 1);
      std::vector<Matrix> forms;
      for (int i = 0; i < s; ++i) {
        Matrix a(r, r);
        for (int p = 0; p < r; ++p)
          for (int q = 0; q < r; ++q) a(p, q) = g(rng);
        forms.push_back(0.5 * (a + a.transpose()));
      }
      auto t0 = Clock::now();
      const PrestressResult ps = maximizeStressMargin(forms);
      const double t_ps = seconds(t0);
      t0 = Clock::now();
      const BlockedFlexResult full = findUnblockedFlex(forms, Vector::Ones(r));
      const double t_full = seconds(t0);
      BlockedFlexOptions homotopy_only;
      homotopy_only.max_sos_flexes = 0;
      t0 = Clock::now();
      const BlockedFlexResult h = findUnblockedFlex(forms, Vector::Ones(r), homotopy_only);
      const double t_h = seconds(t0);
      std::printf("r=%d s=%d  prestress %s %7.4f s | second-order: %-14s %7.3f s | homotopy alone: %-14s %4d paths "
                  "(%d failed) %7.3f s\n",
                  r, s, ps.stable ? "yes" : "no ", t_ps, outcome(full.outcome), t_full, outcome(h.outcome), h.paths,
                  h.failed_paths, t_h);
    }
}
