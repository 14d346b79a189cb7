#include "engine/normal_equations.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>
#include <Eigen/SPQRSupport>

#include "engine/sparse_qr.h"

namespace flexure::engine {

void NormalEquations::use(const std::vector<int>& gauge, const std::vector<int>& lift, double damping) {
  if (gauge == gauge_ && lift == lift_ && damping == damping_) return;
  gauge_ = gauge;
  lift_ = lift;
  damping_ = damping;
  analysed_ = factored_ = false;
}

bool NormalEquations::factor(const SparseMatrix& J) {
  Jt_ = J.transpose();
  M_ = Jt_ * J;
  if (damping_ > 0) {
    SparseMatrix D(J.cols(), J.cols());
    D.setIdentity();
    M_ += mu(J) * D;
  }
  for (int i : gauge_) M_.coeffRef(i, i) += 1.0;
  for (int i : lift_) M_.coeffRef(i, i) += 1.0;
  factored_ = withLdlt([&](auto& ldlt) {
    if (!analysed_) ldlt.analyzePattern(M_);
    ldlt.factorize(M_);
    return ldlt.info() == Eigen::Success;
  });
  analysed_ = true;
  return factored_;
}

Vector NormalEquations::solveFactored(const Vector& b) {
  return withLdlt([&](auto& ldlt) -> Vector { return ldlt.solve(Jt_ * b); });
}

Vector NormalEquations::solve(const SparseMatrix& J, const Vector& b, const Matrix& rows, const Vector& c,
                              bool refactor, bool by_qr) {
  if (by_qr) return leastSquares(J, b, rows, c);
  if (refactor || !factored_) factor(J);
  // Damped: a chord step's right-hand side is J0^T b, J0 the factored iterate's Jacobian, so
  // that it lies in the row space of J0. With the current J's, its part on the factored
  // kernel (|J - J0| |b|) would come back multiplied by 1 / mu.
  const Vector rhs = (damping_ > 0 ? Vector(Jt_ * b) : Vector(J.transpose() * b)) + rows.transpose() * c;
  if (factored_) {
    Vector d;
    if (solveWoodbury(rows, rhs, d)) return d;
    factored_ = false;
  }
  return leastSquares(J, b, rows, c);
}

bool NormalEquations::solveWoodbury(const Matrix& rows, const Vector& rhs, Vector& d) {
  const std::vector<int>& lift = lift_;
  const Eigen::Index N = M_.cols();
  const Eigen::Index k = rows.rows(), f = static_cast<Eigen::Index>(lift.size());
  // W = [U, F], C = diag(I_k, -I_f).
  Matrix W = Matrix::Zero(N, k + f);
  W.leftCols(k) = rows.transpose();
  for (Eigen::Index i = 0; i < f; ++i) W(lift[static_cast<size_t>(i)], k + i) = 1.0;
  Vector C = Vector::Ones(k + f);
  C.tail(f).setConstant(-1.0);
  d = withLdlt([&](auto& ldlt) -> Vector { return ldlt.solve(rhs); });
  if (k + f > 0) {
    const Matrix AW = withLdlt([&](auto& ldlt) -> Matrix { return ldlt.solve(W); });
    Matrix S = W.transpose() * AW;
    S.diagonal() += C;  // C^-1 = C
    d -= AW * S.fullPivLu().solve(Vector(W.transpose() * d));
  }
  // Accept when the pivots were sound: the result solves the normal equations (of the
  // factored iterate) to a small backward error, |r| <= 1e-8 (|M| |d| + |rhs|). Not
  // relative to |rhs| alone: soft modes make |d| >> |rhs| / |M| with a sound factorization
  // (that test sent every step of a 224 x 224 grid with 2 flexes to the QR, 0.56 s each).
  // A step that is still poor fails its line search, and correct() takes it again by QR.
  const Vector r = M_ * d + W * C.asDiagonal() * (W.transpose() * d) - rhs;
  const double size = M_.diagonal().maxCoeff() + (k ? rows.colwise().squaredNorm().maxCoeff() : 0.0);
  return d.allFinite() && r.norm() <= 1e-8 * std::max(size * d.norm() + rhs.norm(), 1e-300);
}

Vector NormalEquations::leastSquares(const SparseMatrix& J, const Vector& b, const Matrix& rows,
                                     const Vector& c) const {
  if (rows.rows() == 0) return leastSquaresQR(J, b);
  Vector bc(b.size() + c.size());
  bc << b, c;
  return leastSquaresQR(appendRows(J, rows), bc);
}

Vector NormalEquations::leastSquaresQR(const SparseMatrix& J, const Vector& b) const {
  // Below J: the gauge's identity rows, or sqrt(mu) I for the damping (its least-squares
  // solution is the damped normal equations').
  const int below = damping_ > 0 ? static_cast<int>(J.cols()) : static_cast<int>(gauge_.size());
  SparseMatrix A(J.rows() + below, J.cols());
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(static_cast<size_t>(J.nonZeros()) + static_cast<size_t>(below));
  for (int c = 0; c < J.outerSize(); ++c)
    for (SparseMatrix::InnerIterator it(J, c); it; ++it) t.emplace_back(it.row(), it.col(), it.value());
  for (size_t i = 0; i < gauge_.size(); ++i)
    t.emplace_back(static_cast<int>(J.rows() + i), gauge_[i], 1.0);
  if (damping_ > 0) {
    const double root = std::sqrt(mu(J));
    for (int i = 0; i < J.cols(); ++i) t.emplace_back(static_cast<int>(J.rows()) + i, i, root);
  }
  A.setFromTriplets(t.begin(), t.end());
  A.makeCompressed();
  Eigen::SPQR<SparseMatrix> qr;
  factorSparseQR(qr, A);
  Vector rhs = Vector::Zero(A.rows());
  rhs.head(J.rows()) = b;
  return qr.solve(rhs);
}

double NormalEquations::mu(const SparseMatrix& J) const {
  double size = 0.0;
  for (int c = 0; c < J.outerSize(); ++c) size = std::max(size, J.col(c).squaredNorm());
  return damping_ * std::max(size, 1e-300);
}

}  // namespace flexure::engine
