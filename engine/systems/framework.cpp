// Bar-joint frameworks (engine/systems/framework.h).
#include "engine/systems/framework.h"

#include <Eigen/Dense>
#include <algorithm>
#include <stdexcept>

#include "engine/systems/common.h"
#include "engine/terms.h"

namespace flexure::engine {

namespace {

// A bad attachment, at its item of [system] attached.
[[noreturn]] void attachmentError(int index, const std::string& message) {
  throw ModelError("attached", index, "vertex attachment " + std::to_string(index + 1) + ": " + message);
}

// The coordinates of v in the frame of an attachment (FramePointTerm), from the start.
std::array<double, 3> frameCoordinates(const Matrix& points, const Attachment& at, int index) {
  const int d = static_cast<int>(points.rows());
  const Vector a = points.col(at.frame[0]), e1 = points.col(at.frame[1]) - a, r = points.col(at.vertex) - a;
  const double size = std::max({e1.norm(), r.norm(), 1e-300});
  auto fail = [&](const std::string& m) { attachmentError(index, m); };
  if (e1.norm() == 0) fail("its frame's first two vertices coincide");
  if (e1.norm() <= systems_detail::kDistinctTolerance * size)
    fail("its frame's first two vertices are " + shortNumber(e1.norm()) + " apart, less than " +
         shortNumber(systems_detail::kDistinctTolerance) + " of the attachment's size " + shortNumber(size) +
         " (the tolerance that tells vertices apart at that scale)");
  if (at.frame.size() == 2) {
    const double s = r.dot(e1) / e1.squaredNorm();
    if (d == 2) {
      const Eigen::Vector2d je1(-e1[1], e1[0]);
      return {s, r.dot(je1) / e1.squaredNorm(), 0.0};
    }
    const double off = (r - s * e1).norm();
    if (off > 1e-9 * size)
      fail("in 3D a point held by two vertices must lie on their line (it is " + shortNumber(off) +
           " away); give three frame vertices to hold it off the line");
    return {s, 0.0, 0.0};
  }
  const Vector e2 = points.col(at.frame[2]) - a;
  Matrix B(d, d);
  if (d == 2) {
    B << e1, e2;
  } else {
    const Eigen::Vector3d n = Eigen::Vector3d(e1).cross(Eigen::Vector3d(e2));
    B << e1, e2, n;
  }
  const double area = d == 2 ? std::abs(e1[0] * e2[1] - e1[1] * e2[0])
                             : Eigen::Vector3d(e1).cross(Eigen::Vector3d(e2)).norm();
  if (area <= 1e-9 * e1.norm() * std::max(e2.norm(), 1e-300))
    fail("its three frame vertices are collinear (they span no plane)");
  const Vector c = B.colPivHouseholderQr().solve(r);
  return {c[0], c[1], d == 3 ? c[2] : 0.0};
}

ConstraintSystem buildSystem(const Matrix& points, const std::vector<Framework::Edge>& edges,
                             const std::vector<int>& pinned, const std::vector<double>& lengths,
                             const std::vector<Attachment>& attached) {
  const int d = static_cast<int>(points.rows());
  const int n = static_cast<int>(points.cols());
  if (d != 2 && d != 3) throw std::invalid_argument("a framework lives in 2D or 3D");
  if (!lengths.empty() && lengths.size() != edges.size())
    throw std::invalid_argument("one length per edge");
  ConstraintSystem system(d, n, n);
  for (int v : pinned) system.pin(v);
  for (size_t e = 0; e < edges.size(); ++e) {
    const auto [a, b] = edges[e];
    if (lengths.empty())
      system.addTerm(SquaredDistanceTerm::atStart(a, b, points));
    else
      system.addTerm(std::make_unique<SquaredDistanceTerm>(a, b, lengths[e] * lengths[e]));
  }
  // Residuals in length^2, like the edges': the frame-point residual (a length) times the extent.
  const double extent = std::max((points.rowwise().maxCoeff() - points.rowwise().minCoeff()).norm(), 1e-300);
  std::vector<char> attached_already(static_cast<size_t>(n), 0);
  for (size_t i = 0; i < attached.size(); ++i) {
    const Attachment& at = attached[i];
    const int index = static_cast<int>(i);
    auto fail = [&](const std::string& m) { attachmentError(index, m); };
    if (at.frame.size() != 2 && at.frame.size() != 3) fail("a frame has 2 or 3 vertices");
    for (int f : at.frame)
      if (f == at.vertex) fail("the vertex is in its own frame");
    if (std::find(pinned.begin(), pinned.end(), at.vertex) != pinned.end())
      fail("a pinned vertex cannot be attached (pin its frame instead)");
    if (attached_already[static_cast<size_t>(at.vertex)]) fail("the vertex is attached twice");
    attached_already[static_cast<size_t>(at.vertex)] = 1;
    std::vector<int> blocks{at.vertex};
    blocks.insert(blocks.end(), at.frame.begin(), at.frame.end());
    system.addTerm(std::make_unique<FramePointTerm>(d, blocks, frameCoordinates(points, at, index), extent));
  }
  system.finalize(points);
  return system;
}

}  // namespace

Framework::Framework(const Matrix& points, std::vector<Edge> edges, const std::vector<int>& pinned,
                     const std::vector<double>& lengths, std::vector<Attachment> attached)
    : Model(buildSystem(points, edges, pinned, lengths, attached), points),
      edges_(std::move(edges)),
      attached_(std::move(attached)) {}

std::optional<SymmetryGroup> Framework::symmetryGroup() const {
  return SymmetryGroup{SymmetryGroup::Family::Euclidean, system().numVertices(), 0};
}

}  // namespace flexure::engine

namespace flexure::engine {

Geometry Framework::geometry() const {
  Geometry g = Model::geometry();
  g.bars.edges = edges_;
  // An attached point is drawn joined to its frame (the coupler triangle of a linkage).
  for (const Attachment& at : attached_)
    for (int f : at.frame) g.bars.edges.push_back({at.vertex, f});
  return g;
}

}  // namespace flexure::engine
