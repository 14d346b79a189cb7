// Bar-joint framework in R^2 or R^3 (paper appendix B.1): one squared edge-length constraint
// per edge, pinned vertices fixed in place. Symmetries: the Euclidean motions.
#pragma once

#include <array>
#include <optional>
#include <vector>

#include "engine/model.h"

namespace flexure::engine {

// A vertex attached to a frame of 2 or 3 other vertices (FramePointTerm): it keeps the
// coordinates it has at the start in that frame, and adds no degree of freedom (d variables,
// d equations). A coupler point of a bar in 2D, a point on a bar's line in 3D, a point of a
// ternary link or of a triangle in 3D (its frame's plane and normal).
struct Attachment {
  int vertex;
  std::vector<int> frame;
};

class Framework final : public Model {
 public:
  using Edge = std::array<int, 2>;
  // points: d x n (d = 2 or 3). edges: 0-based vertex pairs. lengths: one per edge, or empty to
  // take the lengths of the realization. attached: points held in the frame of others.
  // Throws ModelError (key "attached") on a bad attachment, std::invalid_argument on misuse.
  Framework(const Matrix& points, std::vector<Edge> edges, const std::vector<int>& pinned,
            const std::vector<double>& lengths = {}, std::vector<Attachment> attached = {});

  std::string typeName() const override { return "framework"; }
  std::optional<SymmetryGroup> symmetryGroup() const override;
  Geometry geometry() const override;
  const std::vector<Edge>& edges() const { return edges_; }
  const std::vector<Attachment>& attached() const { return attached_; }

 private:
  std::vector<Edge> edges_;
  std::vector<Attachment> attached_;
};

}  // namespace flexure::engine
