// Volume hypergraphs (paper appendix B): signed volumes of simplices kept. A Model: its
// constraint terms, its symmetry group (the equi-affine maps) and what to draw.
// Constructors throw ModelError pointing at the offending item; messages number vertices
// from `index_base`.
#pragma once

#include <vector>

#include "engine/model.h"

namespace flexure::engine {

// Signed volumes of simplices (d + 1 vertices each, d = 2 or 3). Symmetries: equi-affine maps.
class VolumeHypergraph final : public Model {
 public:
  VolumeHypergraph(const Matrix& points, std::vector<std::vector<int>> simplices, const std::vector<int>& pinned,
                   int index_base = 1);
  std::string typeName() const override { return "volume_hypergraph"; }
  std::optional<SymmetryGroup> symmetryGroup() const override;
  // Signed volumes of the simplices on (d + 1)-subsets of the points (the first 20,000 in
  // lexicographic order), which equi-affine maps keep.
  Vector congruenceInvariants(const Matrix& positions) const override;
  Geometry geometry() const override;
  const std::vector<std::vector<int>>& simplices() const { return simplices_; }

 private:
  std::vector<std::vector<int>> simplices_;
};

}  // namespace flexure::engine
