// Polytopes with edge-length constraints (paper B.2): 3D vertices, facets given as cyclic vertex
// lists, edges derived from the facets (consecutive vertices), one normal per facet as an
// auxiliary block, of length L (the extent of the start: every variable is then a length, and
// verdicts do not depend on the unit). Constraints: edge lengths, facet planarity
// n_f . (x_v - x_a(f)) = 0 for every facet vertex v other than the facet's first vertex a(f),
// and |n_f|^2 = L^2: 3E equations, as
// many as the reference's polar form, but regular when a facet plane passes through the origin.
// Symmetries: the Euclidean motions, the normals rotating along.
#pragma once

#include <array>
#include <vector>

#include "engine/model.h"

namespace flexure::engine {

class Polytope final : public Model {
 public:
  using Edge = std::array<int, 2>;
  // Throws ModelError (key "facets" or "vertices") when a facet has fewer than 3 vertices or
  // repeats one, is not planar (relative tolerance `planarity_tolerance` of the polytope's
  // size) or degenerate, when an edge does not lie in exactly two facets, when a vertex is in
  // no facet, or when V - E + F != 2. Messages number vertices from `index_base`.
  Polytope(const Matrix& points, std::vector<std::vector<int>> facets, const std::vector<int>& pinned,
           double planarity_tolerance = 1e-8, int index_base = 1);

  std::string typeName() const override { return "polytope"; }
  std::optional<SymmetryGroup> symmetryGroup() const override;
  Geometry geometry() const override;
  const std::vector<Edge>& edges() const { return edges_; }
  const std::vector<std::vector<int>>& facets() const { return facets_; }

 private:
  struct Built;
  explicit Polytope(Built&& b);
  std::vector<std::vector<int>> facets_;
  std::vector<Edge> edges_;
};

// The facets of the convex hull of `points` (3 x n), each a cyclic vertex list, counter-
// clockwise seen from outside, sorted by their smallest vertex. Throws ModelError (key
// "vertices") when the points are coplanar or when a point is not a corner of the hull (inside
// it, or on a facet or edge without being a vertex of it). Points within `tolerance` (relative
// to their extent) of a supporting plane count as on it.
std::vector<std::vector<int>> convexHullFacets(const Matrix& points, double tolerance = 1e-9, int index_base = 1);

}  // namespace flexure::engine
