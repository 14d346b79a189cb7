#include "engine/model.h"

namespace flexure::engine {

Matrix euclideanGenerators(const Matrix& positions, int num_points) {
  const int d = static_cast<int>(positions.rows());
  const int blocks = static_cast<int>(positions.cols());
  const int rotations = d * (d - 1) / 2;
  Matrix g = Matrix::Zero(static_cast<Eigen::Index>(blocks) * d, d + rotations);
  if (num_points == 0) return g;
  const Vector centre = positions.leftCols(num_points).rowwise().mean();
  for (int i = 0; i < num_points; ++i) {
    const Vector p = positions.col(i) - centre;
    for (int k = 0; k < d; ++k) g(i * d + k, k) = 1.0;
    int col = d;
    for (int a = 0; a < d; ++a)
      for (int b = a + 1; b < d; ++b, ++col) {
        // rotation in the (a, b) plane: velocity p_a e_b - p_b e_a
        g(i * d + b, col) = p[a];
        g(i * d + a, col) = -p[b];
      }
  }
  for (int j = 0; j < g.cols(); ++j) {
    const double n = g.col(j).norm();
    if (n > 0) g.col(j) /= n;
  }
  return g;
}

}  // namespace flexure::engine

namespace flexure::engine {

Geometry Model::geometry() const {
  Geometry g;
  g.dimension = system_.dimension();
  g.points = system_.numBlocks();
  for (int b = 0; b < g.points; ++b)
    if (system_.isPinned(b)) g.pinned.push_back(b);
  return g;
}

}  // namespace flexure::engine
