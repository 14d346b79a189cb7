// Spherical disk packings (paper appendix B): caps on the unit sphere whose contacts keep
// their inversive distances. A Model: its constraint terms, its symmetry group (the Moebius
// group) and what to draw.
// Constructors throw ModelError pointing at the offending item; messages number vertices
// from `index_base`.
#pragma once

#include <array>
#include <vector>

#include "engine/model.h"

namespace flexure::engine {

// Caps on the unit sphere (points a, |a| > 1) whose contacts keep their inversive distances
// (InversiveDistanceTerm). Symmetries: the 6-dimensional Moebius group.
class SphericalDiskPacking final : public Model {
 public:
  using Contact = std::array<int, 2>;
  SphericalDiskPacking(const Matrix& points, std::vector<Contact> contacts, const std::vector<int>& pinned,
                       int index_base = 1);
  std::string typeName() const override { return "spherical_disk_packing"; }
  std::optional<SymmetryGroup> symmetryGroup() const override;
  // The inversive distances of all pairs of caps, which Moebius maps keep.
  Vector congruenceInvariants(const Matrix& positions) const override;
  Geometry geometry() const override;
  const std::vector<double>& inversiveDistances() const { return inversive_; }

 private:
  std::vector<Contact> contacts_;
  std::vector<double> inversive_;
};

}  // namespace flexure::engine
