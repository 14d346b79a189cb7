// Large test frameworks for the benchmarks.
#pragma once

#include "engine/systems/framework.h"

namespace flexure::bench {

// The vertices of a cols x rows unit grid (vertex (c, r) at index r * cols + c) and its
// horizontal and vertical bars; `brace(c, r)` says whether square (c, r) gets the diagonal
// from (c, r) to (c + 1, r + 1).
template <class Brace>
engine::Framework bracedGrid(int cols, int rows, Brace brace, const std::vector<int>& pinned = {}) {
  engine::Matrix p(2, cols * rows);
  std::vector<engine::Framework::Edge> edges;
  auto id = [&](int c, int r) { return r * cols + c; };
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      p.col(id(c, r)) << c, r;
      if (c + 1 < cols) edges.push_back({id(c, r), id(c + 1, r)});
      if (r + 1 < rows) edges.push_back({id(c, r), id(c, r + 1)});
      if (c + 1 < cols && r + 1 < rows && brace(c, r)) edges.push_back({id(c, r), id(c + 1, r + 1)});
    }
  return engine::Framework(p, edges, pinned);
}

// A grid of w x h unit squares braced along its first row and first column (a spanning tree of
// the rows-and-columns graph: isostatic) except the top-left square, pinned at the two ends of
// its bottom-left bar: the top row of squares shears, one degree of freedom.
inline engine::Framework shearingGrid(int w, int h) {
  return bracedGrid(w + 1, h + 1, [&](int c, int r) { return r == 0 || (c == 0 && r < h - 1); }, {0, 1});
}

// cols x rows unit grid; a square is braced by a diagonal when its row index r satisfies
// braced_every > 0 and r % braced_every == 0 (1: fully triangulated, 2: every other row);
// pin_bottom pins the vertices of row 0.
inline engine::Framework grid(int cols, int rows, int braced_every, bool pin_bottom = false) {
  std::vector<int> pinned;
  for (int c = 0; pin_bottom && c < cols; ++c) pinned.push_back(c);
  return bracedGrid(
      cols, rows, [&](int, int r) { return braced_every > 0 && r % braced_every == 0; }, pinned);
}

// An n x n grid of vertices whose squares are braced so that the bipartite graph of square rows
// and square columns (a brace joins its row and column) has three components: two nontrivial
// flexes, the free shears of square columns 1 and 2 (Bolker and Crapo). The squares of column 0
// and those of row 0 from column 3 on make a spanning tree of the rest; `redundant` more braces in row 1 close cycles,
// one self-stress each.
inline engine::Framework sparselyBraced(int n, int redundant) {
  return bracedGrid(n, n, [&](int c, int r) {
    return c == 0 || (r == 0 && c >= 3) || (r == 1 && c >= 3 && c < 3 + redundant);
  });
}

}  // namespace flexure::bench
