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

}  // namespace flexure::bench
