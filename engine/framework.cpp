#include "engine/framework.h"

#include <stdexcept>

#include "engine/terms.h"

namespace flexure::engine {

namespace {

ConstraintSystem buildSystem(const Matrix& points, const std::vector<Framework::Edge>& edges,
                             const std::vector<int>& pinned, const std::vector<double>& lengths) {
  const int d = static_cast<int>(points.rows());
  const int n = static_cast<int>(points.cols());
  if (d != 2 && d != 3) throw std::invalid_argument("a framework lives in 2D or 3D");
  if (!lengths.empty() && lengths.size() != edges.size())
    throw std::invalid_argument("one length per edge");
  ConstraintSystem system(d, n, n);
  for (int v : pinned) system.pin(v);
  for (size_t e = 0; e < edges.size(); ++e) {
    const auto [a, b] = edges[e];
    const double l2 = lengths.empty() ? (points.col(a) - points.col(b)).squaredNorm()
                                      : lengths[e] * lengths[e];
    system.addTerm(std::make_unique<SquaredDistanceTerm>(a, b, l2));
  }
  system.finalize(points);
  return system;
}

}  // namespace

Framework::Framework(const Matrix& points, std::vector<Edge> edges, const std::vector<int>& pinned,
                     const std::vector<double>& lengths)
    : Model(buildSystem(points, edges, pinned, lengths), points), edges_(std::move(edges)) {}

Matrix Framework::symmetryGenerators(const Matrix& positions) const {
  return euclideanGenerators(positions, system().numVertices());
}

}  // namespace flexure::engine

namespace flexure::engine {

Geometry Framework::geometry() const {
  Geometry g = Model::geometry();
  g.bars = edges_;
  return g;
}

}  // namespace flexure::engine
