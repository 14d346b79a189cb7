// Dragging a vertex (engine::dragVertex, as the viewer calls it): CPU time per pointer move, and
// per move over the time of one factorization of the Jacobian (the floor of a move that walks
// on the constraint set). Cases: the double Watt's vertex 4 up and down its curve, and the
// viewer latency benchmark's 1,000-vertex grid (40 x 25, every other row braced, the bottom row
// pinned) pulled sideways by its top middle vertex, pointer moves of 3 pixels at 800x800.
#include <algorithm>
#include <cstdio>
#include <ctime>
#include <vector>

#include "bench/grids.h"
#include "engine/drag.h"
#include "engine/factorization.h"
#include "engine/motion_tracker.h"
#include "engine/rigidity.h"

using namespace flexure;

namespace {

double cpu() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

// pixel: world units per pixel of an 800x800 frame; step: pointer move in pixels.
// max_moves: corrector moves per pointer move (the viewer's: 12 up to 500 variables, else 3; the
// page asks again when the limit stopped a drag). Prints the farthest the vertex stayed from
// the pointer, in pixels (a stop "held by the constraints" leaves it at the foot).
void run(const char* name, const engine::Framework& f, const engine::Vector& x0, int vertex, engine::Vector direction,
         double pixel, int moves, int max_moves) {
  engine::DragOptions o;
  o.tolerance = 0.25 * pixel;
  o.max_moves = max_moves;
  o.regular_flexes = -1;
  double best = 1e300;
  int total_moves = 0, reached = 0;
  double remaining = 0;
  double worst_residual = 0;
  for (int repeat = 0; repeat < 3; ++repeat) {
    engine::Vector x = x0;
    engine::Vector at = f.system().vertexPositions(x).col(vertex);
    total_moves = reached = 0;
    remaining = 0;
    const double t0 = cpu();
    for (int i = 0; i < moves; ++i) {
      at += (i < moves / 2 ? 1.0 : -1.0) * 3 * pixel * direction;
      const engine::DragResult r = engine::dragVertex(f, x, vertex, at, o);
      x = r.x;
      total_moves += r.moves;
      reached += r.reached;
      remaining = std::max(remaining, r.remaining / pixel);
      worst_residual = std::max(worst_residual, r.residual / f.system().residualScale());
    }
    best = std::min(best, cpu() - t0);
  }
  double fact = 1e300;
  const engine::SparseMatrix J = f.system().jacobian(x0);
  for (int i = 0; i < 5; ++i) {
    const double t0 = cpu();
    const engine::JacobianFactorization F(J, o.factorization);
    fact = std::min(fact, cpu() - t0);
  }
  const double per = best / moves;
  std::printf("%-36s %5d vars  %3d pointer moves  %7.3f ms CPU/move  factorization %7.3f ms  ratio %4.1f  "
              "%.2f corrector moves each  reached %d/%d  farthest %.1f px  residual %.1e\n",
              name, f.system().numVariables(), moves, 1e3 * per, 1e3 * fact, per / fact,
              double(total_moves) / moves, reached, moves, remaining, worst_residual);
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
  // 800 pixels over the figure's extent and its margin.
  // The double Watt from sample 100 of its path (as the viewer benchmark).
  const engine::Framework watt(p, edges, {0, 5, 10});
  const engine::RigidityReport rep = engine::analyzeRigidity(watt, watt.startCoordinates());
  engine::TrackerOptions opt;
  opt.steps = 100;
  opt.step_size = 0.05;
  const engine::DeformationPath path = engine::trackMotion(watt, watt.startCoordinates(), rep.flex_basis * rep.auto_flex, opt);
  run("drag, double Watt vertex 4", watt, path.samples.back(), 3, engine::Vector::Unit(2, 1), 8.8 / 800, 100, 12);
  const engine::Framework g = bench::grid(40, 25, 2, true);
  run("drag, grid 40x25 (1,000 vertices)", g, g.startCoordinates(), 980, -engine::Vector::Unit(2, 0), 44.0 / 800, 60, 3);
  run("drag, grid 40x25 (at most 12 moves)", g, g.startCoordinates(), 980, -engine::Vector::Unit(2, 0), 44.0 / 800, 60, 12);
  return 0;
}
