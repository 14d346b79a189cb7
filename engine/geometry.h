// What a configuration is made of, for whoever draws it (present/figure.cpp): indices into the
// columns of the positions matrix (system().positions(x)), no rendering types. Each model type
// fills what it has.
#pragma once

#include <array>
#include <vector>

namespace flexure::engine {

class ScalarField;

struct Geometry {
  int dimension = 2;
  int points = 0;                              // vertices (columns of the positions)
  std::vector<std::array<int, 2>> bars;        // drawn as segments
  // Origami: per bar, its FOLD assignment (B boundary, M mountain, V valley, F flat, U
  // unassigned, J join); empty for every other model.
  std::vector<char> bar_kinds;
  std::vector<std::vector<int>> facets;        // planar polygons, cyclic vertex lists
  std::vector<int> pinned;
  std::vector<std::array<int, 3>> angles;      // (i, j, k): the angle at j, drawn as an arc
  std::vector<std::vector<int>> simplices;     // volume hypergraphs: d + 1 vertices each
  std::vector<double> radii;                   // sphere packings: one per point
  bool caps = false;                           // points are caps of the unit sphere (a.y = 1)
  const ScalarField* surface = nullptr;        // the surface the points live on
};

}  // namespace flexure::engine
