// Large test frameworks for the benchmarks.
#pragma once

#include "engine/framework.h"

namespace flexure::bench {

// cols x rows unit grid; a square is braced by a diagonal when its row index r satisfies
// braced_every > 0 and r % braced_every == 0 (1: fully triangulated, 2: every other row);
// pin_bottom pins the vertices of row 0.
inline engine::Framework grid(int cols, int rows, int braced_every, bool pin_bottom = false) {
  engine::Matrix p(2, cols * rows);
  std::vector<engine::Framework::Edge> edges;
  auto id = [&](int c, int r) { return r * cols + c; };
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      p.col(id(c, r)) << c, r;
      if (c + 1 < cols) edges.push_back({id(c, r), id(c + 1, r)});
      if (r + 1 < rows) edges.push_back({id(c, r), id(c, r + 1)});
      if (c + 1 < cols && r + 1 < rows && braced_every > 0 && r % braced_every == 0)
        edges.push_back({id(c, r), id(c + 1, r + 1)});
    }
  std::vector<int> pinned;
  for (int c = 0; pin_bottom && c < cols; ++c) pinned.push_back(id(c, 0));
  return engine::Framework(p, edges, pinned);
}

// An n x n grid of vertices whose squares are braced so that the bipartite graph of square rows
// and square columns (a brace joins its row and column) has three components: two nontrivial
// flexes, the free shears of square columns 1 and 2 (Bolker and Crapo). Squares (r, 0) and
// (0, c >= 3) make a spanning tree of the rest; `redundant` more braces in row 1 close cycles,
// one self-stress each.
inline engine::Framework sparselyBraced(int n, int redundant) {
  engine::Matrix p(2, n * n);
  std::vector<engine::Framework::Edge> edges;
  auto id = [&](int c, int r) { return r * n + c; };
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      p.col(id(c, r)) << c, r;
      if (c + 1 < n) edges.push_back({id(c, r), id(c + 1, r)});
      if (r + 1 < n) edges.push_back({id(c, r), id(c, r + 1)});
    }
  auto brace = [&](int c, int r) { edges.push_back({id(c, r), id(c + 1, r + 1)}); };
  for (int r = 0; r + 1 < n; ++r) brace(0, r);
  for (int c = 3; c + 1 < n; ++c) brace(c, 0);
  for (int c = 3; c < 3 + redundant && c + 1 < n; ++c) brace(c, 1);
  return engine::Framework(p, edges, {});
}

}  // namespace flexure::bench
