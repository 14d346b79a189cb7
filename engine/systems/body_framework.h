// Body-hinge and body-bar frameworks (paper appendix B): rigid bodies sharing vertices, plus
// bars. A Model: its constraint terms, its symmetry group (the Euclidean motions) and what to
// draw. Origami (engine/systems/origami.h) derives from it.
// Constructors throw ModelError pointing at the offending item; messages number vertices
// from `index_base`.
#pragma once

#include <array>
#include <vector>

#include "engine/model.h"

namespace flexure::engine {

// Rigid bodies (vertex lists) sharing vertices (hinges), plus bars. type_name is "body_hinge"
// or "body_bar". Each body is rigid whatever its shape (flat, collinear, two vertices, one):
// a frame of up to d + 1 of its vertices spanning its affine hull is held by bars (a simplex,
// infinitesimally rigid in any dimension), and every other vertex is an affine combination of
// the frame (AffineCombinationTerm). Not the paper's complete graph K_n, which is not
// infinitesimally rigid on four coplanar points in 3D or three collinear ones in 2D and adds
// n(n-1)/2 - (dn - d(d+1)/2) dependent bars per body. Constraints an earlier body already
// imposes (the distance of a hinge's two vertices) are left out, so a hinge adds no stress.
// Bodies are drawn as polygons in the order given.
class BodyFramework : public Model {
 public:
  using Edge = std::array<int, 2>;
  BodyFramework(std::string type_name, const Matrix& points, std::vector<std::vector<int>> bodies,
                const std::vector<Edge>& bars, const std::vector<int>& pinned, int index_base = 1);
  std::string typeName() const override { return type_; }
  std::optional<SymmetryGroup> symmetryGroup() const override;
  Geometry geometry() const override;
  // The first body (rigid: a body, or a panel of a sheet) holding both vertices, or -1.
  int rigidPartHolding(int a, int b) const override;

 private:
  struct Built;
  BodyFramework(std::string type_name, Built&& b);
  std::string type_;
  std::vector<std::vector<int>> bodies_;
  std::vector<Edge> drawn_;  // body boundaries and bars
};

}  // namespace flexure::engine
