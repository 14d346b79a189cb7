// Frameworks on surfaces (paper appendix B): a bar-joint framework in R^3 with every vertex on
// a surface f = 0. A Model: its constraint terms, its symmetry group (the surface's isometries,
// found numerically once) and what to draw.
// Constructors throw ModelError pointing at the offending item; messages number vertices
// from `index_base`.
#pragma once

#include <array>
#include <Eigen/Core>
#include <memory>
#include <vector>

#include "engine/model.h"
#include "engine/terms.h"

namespace flexure::engine {

// A bar-joint framework in R^3 with every vertex on the surface f = 0. Symmetries: the
// Euclidean motions tangent to the surface (its isometries), found once by sampling the surface
// near the start. With project_start, a start off the surface is first corrected onto the
// constraint set (keeping the bar lengths of the given realization); without it, a vertex off
// the surface is an error.
class FrameworkOnSurface final : public Model {
 public:
  using Edge = std::array<int, 2>;
  FrameworkOnSurface(const Matrix& points, std::vector<Edge> edges, const std::vector<int>& pinned,
                     std::shared_ptr<const ScalarField> surface, bool project_start, int index_base = 1);
  std::string typeName() const override { return "framework_on_surface"; }
  Matrix symmetryGenerators(const Matrix& positions) const override;
  Geometry geometry() const override;
  // The isometries as (omega, t) columns: velocity omega x p + t, orthonormal.
  const Matrix& isometries() const { return killing_; }
  const ScalarField& surface() const { return *surface_; }

 private:
  struct Built;
  explicit FrameworkOnSurface(Built&& b);
  std::vector<Edge> edges_;
  std::shared_ptr<const ScalarField> surface_;
  Matrix killing_;  // 6 x k: (scale_ omega, t) about centre_
  Eigen::Vector3d centre_;
  double scale_;
};

}  // namespace flexure::engine
