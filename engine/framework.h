// Bar-joint framework in R^2 or R^3 (paper appendix B.1): one squared edge-length constraint
// per edge, pinned vertices fixed in place. Symmetries: the Euclidean motions.
#pragma once

#include <array>
#include <optional>
#include <vector>

#include "engine/model.h"

namespace flexure::engine {

class Framework final : public Model {
 public:
  using Edge = std::array<int, 2>;
  // points: d x n (d = 2 or 3). edges: 0-based vertex pairs. lengths: one per edge, or empty to
  // take the lengths of the realization. Throws std::invalid_argument on misuse.
  Framework(const Matrix& points, std::vector<Edge> edges, const std::vector<int>& pinned,
            const std::vector<double>& lengths = {});

  std::string typeName() const override { return "framework"; }
  Matrix symmetryGenerators(const Matrix& positions) const override;
  Geometry geometry() const override;
  const std::vector<Edge>& edges() const { return edges_; }

 private:
  std::vector<Edge> edges_;
};

}  // namespace flexure::engine
