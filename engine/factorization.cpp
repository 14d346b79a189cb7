#include "engine/factorization.h"

#include <Eigen/Dense>
#include <Eigen/SPQRSupport>
#include <algorithm>
#include <cmath>

namespace flexure::engine {

struct JacobianFactorization::Sparse {
  Eigen::SPQR<SparseMatrix> qr;  // of J^T
  SparseMatrix R11t;             // the leading rank x rank block of R, transposed
};

JacobianFactorization::~JacobianFactorization() = default;
JacobianFactorization::JacobianFactorization(JacobianFactorization&&) noexcept = default;
JacobianFactorization& JacobianFactorization::operator=(JacobianFactorization&&) noexcept = default;

bool JacobianFactorization::dense() const { return !sparse_; }

JacobianFactorization::JacobianFactorization(const SparseMatrix& J, const FactorizationOptions& opt)
    : rows_(static_cast<int>(J.rows())), cols_(static_cast<int>(J.cols())), J_(J) {
  const int m = rows_, N = cols_;
  if (std::max(m, N) <= opt.dense_limit || m == 0 || N == 0) {
    if (m == 0 || N == 0) {
      U_ = Matrix::Identity(m, m);
      V_ = Matrix::Identity(N, N);
      s_ = Vector(0);
      return;
    }
    Eigen::BDCSVD<Matrix> svd(Matrix(J), Eigen::ComputeFullU | Eigen::ComputeFullV);
    s_ = svd.singularValues();
    U_ = svd.matrixU();
    V_ = svd.matrixV();
    sigma_max_ = s_[0];
    threshold_ = opt.rank_tolerance * s_[0];
    while (rank_ < s_.size() && s_[rank_] > threshold_) ++rank_;
    sigma_min_kept_ = rank_ > 0 ? s_[rank_ - 1] : 0.0;
    sigma_max_dropped_ = rank_ < s_.size() ? s_[rank_] : 0.0;
    return;
  }
  sparse_ = std::make_unique<Sparse>();
  SparseMatrix Jt = J.transpose();
  Jt.makeCompressed();
  double max_col = 0.0;
  for (int c = 0; c < Jt.outerSize(); ++c) {
    double s = 0.0;
    for (SparseMatrix::InnerIterator it(Jt, c); it; ++it) s += it.value() * it.value();
    max_col = std::max(max_col, std::sqrt(s));
  }
  threshold_ = opt.rank_tolerance * max_col;
  // SuiteSparseQR decides the rank by Heath's method (a column is dead when its remaining norm
  // is below the threshold), which depends on the elimination order: with the default
  // (COLAMD) order, rounding grows along long chains of dependent columns and the rank of
  // e.g. a sheared braced grid comes out too high; the AMD order of J J^T keeps it exact on
  // every case we have (tests/engine/factorization_test.cpp) and is also the fastest.
  sparse_->qr.setSPQROrdering(SPQR_ORDERING_AMD);
  sparse_->qr.setPivotThreshold(threshold_);
  sparse_->qr.compute(Jt);
  rank_ = static_cast<int>(sparse_->qr.rank());
  const SparseMatrix R = sparse_->qr.matrixR();
  const SparseMatrix R11 = R.topLeftCorner(rank_, rank_);
  sparse_->R11t = R11.transpose();
  const Vector d = R11.diagonal().cwiseAbs();
  sigma_max_ = rank_ > 0 ? d.maxCoeff() : 0.0;
  sigma_min_kept_ = rank_ > 0 ? d.minCoeff() : 0.0;
}

Matrix JacobianFactorization::kernel() const {
  const int N = cols_, r = rank_;
  if (!sparse_) return V_.rightCols(N - r);
  Matrix E = Matrix::Zero(N, N - r);
  for (int i = 0; i < N - r; ++i) E(r + i, i) = 1.0;
  Matrix K = sparse_->qr.matrixQ() * E;
  sigma_max_dropped_ = N - r > 0 ? (J_ * K).colwise().norm().maxCoeff() : 0.0;
  return K;
}

Matrix JacobianFactorization::cokernel() const {
  const int m = rows_, r = rank_;
  if (!sparse_) return U_.rightCols(m - r);
  if (m - r == 0) return Matrix(m, 0);
  Eigen::SPQR<SparseMatrix> qr2;
  qr2.setSPQROrdering(SPQR_ORDERING_AMD);
  qr2.setPivotThreshold(threshold_);
  SparseMatrix Jc = J_;
  Jc.makeCompressed();
  qr2.compute(Jc);
  if (qr2.rank() != r) return Matrix(m, 0);  // the caller treats a wrong size as "not formed"
  Matrix E = Matrix::Zero(m, m - r);
  for (int i = 0; i < m - r; ++i) E(r + i, i) = 1.0;
  return qr2.matrixQ() * E;
}

Vector JacobianFactorization::solveMinNorm(const Vector& b) const {
  const int r = rank_;
  if (!sparse_) {
    Vector c = U_.leftCols(r).transpose() * b;
    for (int i = 0; i < r; ++i) c[i] /= s_[i];
    return V_.leftCols(r) * c;
  }
  // J^T P = Q R  =>  J = P R^T Q^T. With y = Q^T x: R11^T y1 = (P^T b)_{1..r}, y2 = 0.
  const Vector pb = sparse_->qr.colsPermutation().transpose() * b;
  Vector y = Vector::Zero(cols_);
  y.head(r) = sparse_->R11t.triangularView<Eigen::Lower>().solve(pb.head(r));
  return sparse_->qr.matrixQ() * y;
}

}  // namespace flexure::engine
