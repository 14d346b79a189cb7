// The same large frameworks in several input orders (issue 45): the vertices and bars of
// bench/grids.h's generator order, with the braces listed last (as a simple generator writes
// them), reversed, shuffled (seeded), and numbered along the grid's diagonals (sheared). The
// analysis (rank decision, bases, motion check) should take about the same time and give the
// same decision in every order: the worst order's CPU time against the best is printed.
#include <algorithm>
#include <cstdio>
#include <ctime>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "bench/grids.h"
#include "engine/rigidity.h"

using namespace flexure;
using engine::Framework;

namespace {

// `f` with vertex v renamed vertex_name[v] and its edges listed in the order `edge_order`.
Framework reordered(const Framework& f, const std::vector<int>& vertex_name, const std::vector<int>& edge_order,
                    const std::vector<int>& pinned) {
  const engine::Matrix p0 = f.system().positions(f.startCoordinates());
  engine::Matrix p(p0.rows(), p0.cols());
  for (int v = 0; v < static_cast<int>(vertex_name.size()); ++v) p.col(vertex_name[v]) = p0.col(v);
  std::vector<Framework::Edge> edges;
  for (int e : edge_order) edges.push_back({vertex_name[f.edges()[e][0]], vertex_name[f.edges()[e][1]]});
  std::vector<int> pins;
  for (int v : pinned) pins.push_back(vertex_name[v]);
  return Framework(p, edges, pins);
}

void runOrders(const std::string& name, int cols, int rows, const Framework& f, const std::vector<int>& pinned) {
  const int n = cols * rows, m = static_cast<int>(f.edges().size());
  std::vector<int> identity(n), edges(m);
  std::iota(identity.begin(), identity.end(), 0);
  std::iota(edges.begin(), edges.end(), 0);
  struct Order {
    std::string name;
    std::vector<int> vertices, edges;
  };
  std::vector<Order> orders;
  orders.push_back({"generator", identity, edges});
  {  // bars first, then the diagonals
    std::vector<int> e = edges;
    std::stable_partition(e.begin(), e.end(), [&](int k) {
      const auto& b = f.edges()[k];
      return std::abs(b[0] - b[1]) == 1 || std::abs(b[0] - b[1]) == cols;
    });
    orders.push_back({"braces last", identity, e});
  }
  {
    std::vector<int> v(n), e(edges.rbegin(), edges.rend());
    for (int i = 0; i < n; ++i) v[i] = n - 1 - i;
    orders.push_back({"reversed", v, e});
  }
  {
    std::mt19937_64 rng(45);
    std::vector<int> v = identity, e = edges;
    std::shuffle(v.begin(), v.end(), rng);
    std::shuffle(e.begin(), e.end(), rng);
    orders.push_back({"shuffled (seed 45)", v, e});
  }
  {  // numbered along the diagonals c + r = const; edges sorted by their new endpoints
    std::vector<int> byDiagonal(identity);
    std::stable_sort(byDiagonal.begin(), byDiagonal.end(),
                     [&](int a, int b) { return a % cols + a / cols < b % cols + b / cols; });
    std::vector<int> v(n);
    for (int i = 0; i < n; ++i) v[byDiagonal[i]] = i;
    std::vector<int> e = edges;
    std::stable_sort(e.begin(), e.end(), [&](int a, int b) {
      const auto ka = std::minmax(v[f.edges()[a][0]], v[f.edges()[a][1]]);
      const auto kb = std::minmax(v[f.edges()[b][0]], v[f.edges()[b][1]]);
      return ka < kb;
    });
    orders.push_back({"sheared (diagonals)", v, e});
  }
  double best = 1e300, worst = 0.0;
  std::string decisions;
  bool same = true;
  for (const Order& o : orders) {
    const Framework g = reordered(f, o.vertices, o.edges, pinned);
    const std::clock_t t0 = std::clock();
    const engine::RigidityReport rep = engine::analyzeRigidity(g, g.startCoordinates());
    const double cpu = static_cast<double>(std::clock() - t0) / CLOCKS_PER_SEC;
    best = std::min(best, cpu);
    worst = std::max(worst, cpu);
    const std::string decision = std::to_string(rep.rank) + " " + std::to_string(rep.nontrivial) + " " +
                                 std::to_string(rep.stresses) + " " + engine::toString(rep.rigid);
    if (decisions.empty()) decisions = decision;
    same = same && decision == decisions;
    std::printf("%-42s %-20s rank %6d  flexes %4d  stresses %6d  %-9s kept %9.3g  dropped %9.3g  %8.3f s CPU\n", name.c_str(),
                o.name.c_str(), rep.rank, rep.nontrivial, rep.stresses, engine::toString(rep.rigid), rep.sigma_smallest_kept,
                rep.sigma_largest_dropped, cpu);
  }
  std::printf("%-42s worst order %.3f s CPU, best %.3f s: %.2fx; decisions %s\n", name.c_str(), worst, best,
              worst / best, same ? "the same in every order" : "DIFFER between orders");
}

}  // namespace

int main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  const int n = argc > 1 ? std::atoi(argv[1]) : 224;
  runOrders("grid " + std::to_string(n) + "^2, every other row braced", n, n, bench::grid(n, n, 2), {});
  runOrders("grid " + std::to_string(n) + "^2, every third row braced", n, n, bench::grid(n, n, 3), {});
  runOrders("sheared grid " + std::to_string(n) + "^2", n, n, bench::shearingGrid(n - 1, n - 1), {0, 1});
  return 0;
}
