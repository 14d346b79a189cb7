#include "engine/flex_space.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "engine/factorization.h"

namespace flexure::engine {

Matrix orthonormalColumnSpace(const Matrix& M, double rel) {
  if (M.cols() == 0 || M.rows() == 0) return Matrix(M.rows(), 0);
  Eigen::JacobiSVD<Matrix> svd(M, Eigen::ComputeThinU);
  const auto& s = svd.singularValues();
  int r = 0;
  while (r < s.size() && s[r] > rel * std::max(s[0], 1e-300)) ++r;
  if (s.size() == 0 || s[0] == 0.0) r = 0;
  return svd.matrixU().leftCols(r);
}

Matrix trivialFlexes(const Model& model, const Vector& x, double tolerance) {
  const ConstraintSystem& sys = model.system();
  const int d = sys.dimension();
  const Matrix G = model.symmetryGenerators(sys.positions(x));
  const int g = static_cast<int>(G.cols());
  const int N = sys.numVariables();
  Matrix free_rows(N, g);
  int pinned_rows = 0;  // the coordinates that are constants: pinned blocks, a scalar's unused ones
  for (int b = 0; b < sys.numBlocks(); ++b) pinned_rows += d - sys.freeCoordinatesOf(b);
  Matrix A(pinned_rows, g);
  int a = 0;
  for (int b = 0; b < sys.numBlocks(); ++b)
    for (int k = 0; k < d; ++k) {
      const int v = sys.variableIndex(b, k);
      if (v >= 0) free_rows.row(v) = G.row(b * d + k);
      else A.row(a++) = G.row(b * d + k);
    }
  Matrix stabiliser = Matrix::Identity(g, g);
  if (pinned_rows > 0 && g > 0) {
    Eigen::JacobiSVD<Matrix> svd(A, Eigen::ComputeFullV);
    const Vector& s = svd.singularValues();
    int r = 0;
    while (r < s.size() && s[r] > tolerance) ++r;  // G's columns have unit norm
    stabiliser = svd.matrixV().rightCols(g - r);
  }
  return orthonormalColumnSpace(free_rows * stabiliser, tolerance);
}

Matrix nontrivialPart(const Matrix& kernel, const Matrix& trivial) {
  const Matrix K = kernel - trivial * (trivial.transpose() * kernel);
  if (K.cols() == 0) return Matrix(K.rows(), 0);
  // Singular values are ~1 on the nontrivial part and ~0 on the trivial one.
  Vector s;
  Matrix U;
  denseSvd(K, s, &U, nullptr, false);
  int c = 0;
  while (c < s.size() && s[c] > 0.5) ++c;
  return U.leftCols(c);
}

Matrix nontrivialPartFast(const Matrix& kernel, const Matrix& trivial) {
  if (kernel.cols() == 0) return Matrix(kernel.rows(), 0);
  if (trivial.cols() == 0) {  // nothing to remove (all symmetries broken by the pins)
    return kernel;
  }
  // P = K - T C with C = T^T K has singular values ~1 on the nontrivial part and ~0 on the
  // trivial one, and its small Gram matrix P^T P = I - C^T C (K and T orthonormal) tells them
  // apart without decomposing the tall P: with its eigenvectors V1 of eigenvalues > 1/4,
  // P V1 / sqrt(lambda) is orthonormal.
  const Matrix C = trivial.transpose() * kernel;
  const Eigen::Index t = C.rows(), k = C.cols();
  // The trivial flexes inside span(K) (C's singular values all near 1: those of the Gram
  // matrix's split below): the nontrivial part is K W with W an orthonormal basis of ker C, the
  // last k - t columns of the Householder reflections that take C^T to triangular form, applied
  // to K from the right: N k t work instead of N k^2.
  if (t > 0 && t < k) {
    const Eigen::JacobiSVD<Matrix> svd(C);
    if (svd.singularValues().minCoeff() > std::sqrt(0.75) && svd.singularValues().maxCoeff() < 1.0 + 1e-6) {
      const Eigen::HouseholderQR<Matrix> qr(C.transpose());
      // H = I - V S' with V the k x t unit lower trapezoidal Householder vectors, so that
      // K H's last k - t columns are K_(t..) - (K V) S with S = (I - H)'s last columns in V's
      // coordinates: one product N x k x t and one pass over K.
      Matrix V = qr.matrixQR().triangularView<Eigen::UnitLower>();
      const Matrix H = qr.householderQ() * Matrix::Identity(k, k);
      Matrix D = -H.rightCols(k - t);
      D.bottomRows(k - t).diagonal().array() += 1.0;
      const Matrix S = V.householderQr().solve(D);
      Matrix B = kernel.rightCols(k - t);
      B.noalias() -= (kernel * V) * S;
      return B;
    }
  }
  Matrix G = -C.transpose() * C;
  G.diagonal().array() += 1.0;
  const Eigen::SelfAdjointEigenSolver<Matrix> eig(G);
  const Vector& lambda = eig.eigenvalues();  // ascending
  Eigen::Index first = 0;
  while (first < lambda.size() && !(lambda[first] > 0.25)) ++first;
  const Eigen::Index c = lambda.size() - first;
  if (c == 0) return Matrix(kernel.rows(), 0);
  const Matrix W = eig.eigenvectors().rightCols(c) * lambda.tail(c).cwiseSqrt().cwiseInverse().asDiagonal();
  Matrix U = kernel * W - trivial * (C * W);
  // One Cholesky-QR pass restores orthonormality to rounding (U^T U is within rounding of I):
  // U <- U L^-T with U^T U = L L^T, two matrix products instead of Gram-Schmidt's N k^2 / 2
  // scalar updates.
  const Eigen::LLT<Matrix> llt(Matrix(U.transpose() * U));
  if (llt.info() == Eigen::Success)
    llt.matrixL().transpose().solveInPlace<Eigen::OnTheRight>(U);
  return U;
}

Matrix canonicalBasis(const Matrix& B) {
  const int N = static_cast<int>(B.rows()), k = static_cast<int>(B.cols());
  Matrix A = B.transpose();  // k x N; reflections from the left act as B -> B H
  for (int i = 0; i < k; ++i) {
    auto rest = A.bottomRows(k - i);
    const Eigen::RowVectorXd norms = rest.colwise().squaredNorm();
    const double best = norms.maxCoeff();
    int j = 0;
    while (j < N && norms[j] < (1.0 - 2e-9) * best) ++j;
    // Householder reflection taking column j of the remaining rows to alpha * e_0.
    Vector v = rest.col(j);
    const double alpha = v[0] >= 0 ? -v.norm() : v.norm();
    v[0] -= alpha;
    const double vn = v.norm();
    if (vn > 0) {
      v /= vn;
      const Eigen::RowVectorXd w = v.transpose() * rest;
      rest.noalias() -= (2.0 * v) * w;
    }
    if (A(i, j) < 0) A.row(i) *= -1.0;
    // Exact zeros where the echelon structure says so.
    A.bottomRows(k - i - 1).col(j).setZero();
  }
  return A.transpose();
}

}  // namespace flexure::engine
