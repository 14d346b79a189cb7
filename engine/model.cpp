#include "engine/model.h"

#include <Eigen/Core>
#include <cstdio>
#include <vector>

#include "engine/continuation.h"

namespace flexure::engine {

std::optional<DrivenQuantity> Model::drivenQuantity(int item, double target, const Vector& x, const Matrix& flexes,
                                                    double step) const {
  (void)item, (void)target, (void)x, (void)flexes, (void)step;
  return std::nullopt;
}

Matrix Model::symmetryGenerators(const Matrix& positions) const {
  const std::optional<SymmetryGroup> g = symmetryGroup();
  if (!g) throw std::logic_error(typeName() + ": a model without a symmetry group must give its generators");
  switch (g->family) {
    case SymmetryGroup::Family::Euclidean: return euclideanGenerators(positions, g->num_points, g->num_directions);
    case SymmetryGroup::Family::Similarity: return similarityGenerators(positions, g->num_points);
    case SymmetryGroup::Family::EquiAffine: return equiAffineGenerators(positions, g->num_points);
    case SymmetryGroup::Family::Moebius: return moebiusGenerators(positions, g->num_points);
  }
  throw std::logic_error("unknown symmetry group");
}

bool Model::quadraticConstraints() const {
  const int degree = system_.polynomialDegree();
  return degree >= 0 && degree <= 2;
}

namespace {

void normaliseColumns(Matrix& g) {
  for (int j = 0; j < g.cols(); ++j) {
    const double n = g.col(j).norm();
    if (n > 0) g.col(j) /= n;
  }
}

// Translations and the linear maps L of `linear` (velocity L (p - centre) on points, L n on
// directions when `move_directions`), unnormalised.
Matrix affineGenerators(const Matrix& positions, int num_points, int num_directions,
                        const std::vector<Matrix>& linear, bool translations = true) {
  const int d = static_cast<int>(positions.rows());
  const int blocks = static_cast<int>(positions.cols());
  const int t = translations ? d : 0;
  Matrix g = Matrix::Zero(static_cast<Eigen::Index>(blocks) * d, t + static_cast<int>(linear.size()));
  if (num_points == 0) return g;
  const Vector centre = positions.leftCols(num_points).rowwise().mean();
  for (int i = 0; i < num_points + num_directions; ++i) {
    const bool point = i < num_points;
    const Vector p = point ? Vector(positions.col(i) - centre) : Vector(positions.col(i));
    if (point)
      for (int k = 0; k < t; ++k) g(i * d + k, k) = 1.0;
    for (size_t j = 0; j < linear.size(); ++j) g.block(i * d, t + static_cast<int>(j), d, 1) = linear[j] * p;
  }
  return g;
}

std::vector<Matrix> rotationAlgebra(int d) {
  std::vector<Matrix> out;
  for (int a = 0; a < d; ++a)
    for (int b = a + 1; b < d; ++b) {
      // rotation in the (a, b) plane: velocity p_a e_b - p_b e_a
      Matrix w = Matrix::Zero(d, d);
      w(b, a) = 1.0;
      w(a, b) = -1.0;
      out.push_back(w);
    }
  return out;
}

}  // namespace

Matrix euclideanGenerators(const Matrix& positions, int num_points, int num_directions) {
  Matrix g = affineGenerators(positions, num_points, num_directions, rotationAlgebra(static_cast<int>(positions.rows())));
  normaliseColumns(g);
  return g;
}

Matrix similarityGenerators(const Matrix& positions, int num_points) {
  const int d = static_cast<int>(positions.rows());
  std::vector<Matrix> lin = rotationAlgebra(d);
  lin.push_back(Matrix::Identity(d, d));
  Matrix g = affineGenerators(positions, num_points, 0, lin);
  normaliseColumns(g);
  return g;
}

Matrix equiAffineGenerators(const Matrix& positions, int num_points) {
  const int d = static_cast<int>(positions.rows());
  std::vector<Matrix> lin;
  for (int a = 0; a < d; ++a)
    for (int b = 0; b < d; ++b)
      if (a != b) {
        Matrix e = Matrix::Zero(d, d);
        e(a, b) = 1.0;
        lin.push_back(e);
      }
  for (int a = 0; a + 1 < d; ++a) {
    Matrix e = Matrix::Zero(d, d);
    e(a, a) = 1.0;
    e(a + 1, a + 1) = -1.0;
    lin.push_back(e);
  }
  Matrix g = affineGenerators(positions, num_points, 0, lin);
  normaliseColumns(g);
  return g;
}

Matrix moebiusGenerators(const Matrix& positions, int num_points) {
  const int d = static_cast<int>(positions.rows());
  const int blocks = static_cast<int>(positions.cols());
  Matrix g = Matrix::Zero(static_cast<Eigen::Index>(blocks) * d, 6);
  if (d != 3) return g;
  const std::vector<Matrix> rot = rotationAlgebra(3);
  for (int i = 0; i < num_points; ++i) {
    const Eigen::Vector3d a = positions.col(i);
    for (int j = 0; j < 3; ++j) g.block(i * 3, j, 3, 1) = rot[static_cast<size_t>(j)] * a;
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d v = -a[k] * a;
      v[k] += 1.0;
      g.block(i * 3, 3 + k, 3, 1) = v;
    }
  }
  normaliseColumns(g);
  return g;
}

}  // namespace flexure::engine

namespace flexure::engine {

Geometry Model::geometry() const {
  Geometry g;
  g.dimension = system_.dimension();
  g.points = system_.numVertices();
  for (int b = 0; b < g.points; ++b)
    if (system_.isPinned(b)) g.pinned.push_back(b);
  return g;
}

Vector Model::congruenceInvariants(const Matrix& positions) const {
  return pairwiseDistances(positions.leftCols(system_.numVertices()));
}

Vector pairwiseDistances(const Matrix& points) {
  const int n = static_cast<int>(points.cols());
  // Any subset of the invariants shows non-congruence: beyond 400 points, each point with the
  // next 64 (cyclically).
  const int reach = n <= 400 ? n - 1 : 64;
  std::vector<double> d;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j <= i + reach && (n <= 400 ? j < n : true); ++j)
      d.push_back((points.col(i) - points.col(j % n)).norm());
  return Eigen::Map<const Vector>(d.data(), static_cast<Eigen::Index>(d.size()));
}

double extentOf(const Matrix& points) {
  return points.cols() ? (points.rowwise().maxCoeff() - points.rowwise().minCoeff()).norm() : 0.0;
}

std::string shortNumber(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

std::vector<Matrix> lieAlgebra(const SymmetryGroup& group, int d) {
  using Family = SymmetryGroup::Family;
  std::vector<Matrix> linear;  // top-left blocks
  switch (group.family) {
    case Family::Euclidean: linear = rotationAlgebra(d); break;
    case Family::Similarity:
      linear = rotationAlgebra(d);
      linear.push_back(Matrix::Identity(d, d));
      break;
    case Family::EquiAffine:
      for (int a = 0; a < d; ++a)
        for (int b = 0; b < d; ++b)
          if (a != b || a + 1 < d) {
            Matrix e = Matrix::Zero(d, d);
            e(a, b) = 1.0;
            if (a == b) e(a + 1, a + 1) = -1.0;
            linear.push_back(e);
          }
      break;
    case Family::Moebius: {
      std::vector<Matrix> out;
      if (d != 3) return out;
      for (const Matrix& w : rotationAlgebra(3)) {
        Matrix x = Matrix::Zero(4, 4);
        x.topLeftCorner(3, 3) = w;
        out.push_back(x);
      }
      for (int k = 0; k < 3; ++k) {  // boosts
        Matrix x = Matrix::Zero(4, 4);
        x(k, 3) = x(3, k) = 1.0;
        out.push_back(x);
      }
      return out;
    }
  }
  std::vector<Matrix> out;
  for (int k = 0; k < d; ++k) {  // translations
    Matrix x = Matrix::Zero(d + 1, d + 1);
    x(k, d) = 1.0;
    out.push_back(x);
  }
  for (const Matrix& l : linear) {
    Matrix x = Matrix::Zero(d + 1, d + 1);
    x.topLeftCorner(d, d) = l;
    out.push_back(x);
  }
  return out;
}

Matrix applyGroupElement(const SymmetryGroup& group, const Matrix& G, const Matrix& positions) {
  const int d = static_cast<int>(positions.rows());
  Matrix out = positions;
  for (int i = 0; i < group.num_points + group.num_directions && i < positions.cols(); ++i) {
    if (i < group.num_points) {
      const Vector h = G.leftCols(d) * positions.col(i) + G.col(d);
      out.col(i) = h.head(d) / h[d];
    } else {
      out.col(i) = G.topLeftCorner(d, d) * positions.col(i);
    }
  }
  return out;
}

Matrix groupVelocities(const SymmetryGroup& group, const Matrix& X, const Matrix& positions) {
  const int d = static_cast<int>(positions.rows());
  Matrix v = Matrix::Zero(d, positions.cols());
  for (int i = 0; i < group.num_points + group.num_directions && i < positions.cols(); ++i) {
    if (i < group.num_points) {
      const Vector h = X.leftCols(d) * positions.col(i) + X.col(d);
      v.col(i) = h.head(d) - h[d] * positions.col(i);
    } else {
      v.col(i) = X.topLeftCorner(d, d) * positions.col(i);
    }
  }
  return v;
}

}  // namespace flexure::engine
