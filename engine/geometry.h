// What a configuration is made of, for whoever draws it (scenes/figure.cpp): indices into the
// columns of the positions matrix (system().positions(x)), no rendering types. Each model type
// fills what it has.
#pragma once

#include <array>
#include <vector>

namespace flexure::engine {

struct Geometry {
  int dimension = 2;
  int points = 0;                              // vertices (columns of the positions)
  std::vector<std::array<int, 2>> bars;        // drawn as segments
  std::vector<std::vector<int>> facets;        // planar polygons, cyclic vertex lists
  std::vector<int> pinned;
};

}  // namespace flexure::engine
