#include "engine/factorization.h"

#include "engine/fp_traps.h"

#include <Eigen/Dense>
#include <Eigen/SPQRSupport>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <vector>

extern "C" void dgesdd_(const char* jobz, const int* m, const int* n, double* a, const int* lda, double* s,
                        double* u, const int* ldu, double* vt, const int* ldvt, double* work, const int* lwork,
                        int* iwork, int* info);

namespace flexure::engine {

namespace {

bool sortedFinite(const Vector& s) {
  if (!s.allFinite()) return false;
  for (Eigen::Index i = 1; i < s.size(); ++i)
    if (s[i] > s[i - 1]) return false;
  return true;
}

}  // namespace

void denseSvd(const Matrix& A, Vector& s, Matrix* U, Matrix* V, bool full) {
  const bool vectors = U || V;
  const unsigned opts = !vectors ? 0u : full ? (Eigen::ComputeFullU | Eigen::ComputeFullV) : (Eigen::ComputeThinU | Eigen::ComputeThinV);
  // LAPACK's divide and conquer (dgesdd). Not Eigen 3.4.0's BDCSVD: it reads out of bounds in
  // perturbCol0 on some rank-deficient Jacobians (a SIGSEGV under AddressSanitizer on the small
  // rhombicuboctahedron and the rhombic triacontahedron; in a plain build it read whatever lay
  // there), and it returned NaNs, unsorted or wrong small singular values on others (the
  // body-bar cube, the truncated octahedron). dgesdd's output is checked (finite, sorted);
  // JacobiSVD is the fallback.
  const MaskedFloatingPointTraps masked;  // the result is checked below, not the arithmetic
  const int m = static_cast<int>(A.rows()), n = static_cast<int>(A.cols()), k = std::min(m, n);
  const char jobz = !vectors ? 'N' : full ? 'A' : 'S';
  Matrix a = A;
  s.resize(k);
  const int ucols = jobz == 'A' ? m : k, vrows = jobz == 'A' ? n : k;
  Matrix u(m, vectors ? ucols : 1), vt(vectors ? vrows : 1, n);
  const int lda = std::max(1, m), ldu = std::max(1, m), ldvt = std::max(1, vectors ? vrows : 1);
  std::vector<int> iwork(static_cast<size_t>(8 * std::max(1, k)));
  int info = 0, lwork = -1;
  double query = 0;
  if (k > 0) {
    dgesdd_(&jobz, &m, &n, a.data(), &lda, s.data(), u.data(), &ldu, vt.data(), &ldvt, &query, &lwork, iwork.data(), &info);
    lwork = std::max(1, static_cast<int>(query));
    std::vector<double> work(static_cast<size_t>(lwork));
    if (info == 0)
      dgesdd_(&jobz, &m, &n, a.data(), &lda, s.data(), u.data(), &ldu, vt.data(), &ldvt, work.data(), &lwork,
              iwork.data(), &info);
  }
  const bool ok = info == 0 && sortedFinite(s) && (!vectors || (u.allFinite() && vt.allFinite()));
  if (ok) {
    if (U) *U = vectors ? u : Matrix();
    if (V) *V = vt.transpose();
    return;
  }
  Eigen::JacobiSVD<Matrix> svd(A, opts);
  s = svd.singularValues();
  if (U) *U = svd.matrixU();
  if (V) *V = svd.matrixV();
}

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
      rank_gap_ = std::numeric_limits<double>::infinity();
      return;
    }
    denseSvd(Matrix(J), s_, &U_, &V_, true);
    sigma_max_ = s_[0];
    threshold_ = opt.rank_tolerance * s_[0];
    while (rank_ < s_.size() && s_[rank_] > threshold_) ++rank_;
    sigma_min_kept_ = rank_ > 0 ? s_[rank_ - 1] : 0.0;
    sigma_max_dropped_ = rank_ < s_.size() ? s_[rank_] : 0.0;
    rank_gap_ = rank_ == 0 ? std::numeric_limits<double>::infinity()
                           : sigma_min_kept_ / std::max(sigma_max_dropped_, threshold_ * 1e-5);
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
  const auto factor = [&](Eigen::SPQR<SparseMatrix>& qr, double tolerance) {
    qr.setSPQROrdering(SPQR_ORDERING_AMD);
    qr.setPivotThreshold(tolerance);
    qr.compute(Jt);
    return static_cast<int>(qr.rank());
  };
  // |R_ii| for the kept columns, read off R (column-major, upper triangular: R_jj is the last
  // entry of column j) without copying blocks of it: at 10^6 vertices every copy of R costs
  // about as much as a tenth of the factorization.
  const auto diagonalOf = [](const SparseMatrix& R, int rank) {
    Vector d = Vector::Zero(rank);
    for (int j = 0; j < rank; ++j)
      for (SparseMatrix::InnerIterator it(R, j); it; ++it)
        if (it.row() == j) d[j] = std::abs(it.value());
    return d;
  };
  const auto keptDiagonal = [&](const Eigen::SPQR<SparseMatrix>& qr, int rank) -> Vector {
    return diagonalOf(SparseMatrix(qr.matrixR()), rank);
  };
  rank_ = factor(sparse_->qr, threshold_);
  SparseMatrix R = sparse_->qr.matrixR();
  Vector d = diagonalOf(R, rank_);
  // The remaining norms |R_ii| of the elimination are not singular values, and rounding along
  // long chains of dependent columns lifts some of them towards the threshold (one at 4.01e-9
  // against 4e-9 made a 224x224 grid's count depend on the order of its edges). So when a kept
  // one lies within kClearGap of the threshold, the rank is decided where the values have their
  // largest relative gap, between threshold / 1e5 and threshold * 1e5: a second factorization
  // with the lower tolerance shows the values below the threshold, and a third, at the middle of
  // that gap, gives the factorization of that rank.
  rank_gap_ = rank_ > 0 ? d.minCoeff() / threshold_ : std::numeric_limits<double>::infinity();
  if (rank_ > 0 && rank_gap_ < kClearGap) {
    const double low = threshold_ * 1e-5, high = threshold_ * 1e5;
    Eigen::SPQR<SparseMatrix> below;
    const int r_low = factor(below, low);
    Vector all = keptDiagonal(below, r_low);
    std::sort(all.data(), all.data() + all.size(), std::greater<double>());
    // The values in the range, the largest one above it first, and the floor (what the
    // factorization dropped) last.
    std::vector<double> v;
    for (Eigen::Index i = 0; i < all.size(); ++i)
      if (all[i] <= high || i + 1 == all.size() || all[i + 1] <= high) v.push_back(all[i]);
    int above = static_cast<int>(all.size() - static_cast<Eigen::Index>(v.size()));  // values above the first of v
    v.push_back(low);
    size_t best = 0;
    for (size_t i = 0; i + 1 < v.size(); ++i)
      if (v[i] / v[i + 1] > v[best] / v[best + 1]) best = i;
    const int decided = above + static_cast<int>(best) + 1;
    rank_gap_ = v[best] / v[best + 1];
    if (decided != rank_) {
      threshold_ = std::sqrt(v[best] * v[best + 1]);
      rank_ = factor(sparse_->qr, threshold_);
      R = sparse_->qr.matrixR();
      d = diagonalOf(R, rank_);
    }
  }
  sparse_->R11t = SparseMatrix(R.topLeftCorner(rank_, rank_)).transpose();
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

Vector JacobianFactorization::solveSeminormal(const Vector& b) const {
  if (!sparse_) return solveMinNorm(b);
  const int r = rank_;
  // J^T P = Q R: the first r columns of J^T P are J1^T = Q1 R11, so J1^T R11^-1 R11^-T b1 =
  // Q1 R11^-T b1, solveMinNorm's answer.
  const Vector pb = sparse_->qr.colsPermutation().transpose() * b;
  Vector w = sparse_->R11t.triangularView<Eigen::Lower>().solve(pb.head(r));
  sparse_->R11t.transpose().triangularView<Eigen::Upper>().solveInPlace(w);
  Vector z = Vector::Zero(rows_);
  z.head(r) = w;
  return J_.transpose() * (sparse_->qr.colsPermutation() * z);
}

Vector JacobianFactorization::projectOntoKernel(const Vector& v) const {
  const int r = rank_;
  if (!sparse_) return v - V_.leftCols(r) * (V_.leftCols(r).transpose() * v);
  // J^T P = Q R: the row space of J is the span of Q's first r columns.
  Vector y = sparse_->qr.matrixQ().transpose() * v;
  y.head(r).setZero();
  return sparse_->qr.matrixQ() * y;
}

Vector JacobianFactorization::solveTransposed(const Vector& w) const {
  const int r = rank_;
  if (!sparse_) {
    Vector c = V_.leftCols(r).transpose() * w;
    for (int i = 0; i < r; ++i) c[i] /= s_[i];
    return U_.leftCols(r) * c;
  }
  // J^T = Q R P^T: R11 z = (Q^T w)_{1..r}, y = P [z; 0].
  const Vector qw = sparse_->qr.matrixQ().transpose() * w;
  Vector z = Vector::Zero(rows_);
  const SparseMatrix R11 = sparse_->R11t.transpose();
  z.head(r) = R11.triangularView<Eigen::Upper>().solve(qw.head(r));
  return sparse_->qr.colsPermutation() * z;
}

}  // namespace flexure::engine
