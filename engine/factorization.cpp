#include "engine/factorization.h"

#include "engine/fp_traps.h"
#include "engine/interrupt.h"

#include <Eigen/Dense>
#include <Eigen/SPQRSupport>
#include <numeric>

#include "engine/sparse_qr.h"
#include <algorithm>
#include <stdexcept>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
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

// The right singular vectors z of the upper triangular R11 (given as R11t = R11^T) whose
// singular values |R11 z| are at most `bound` and a clear gap below the others (left: the left
// ones, |R11^T z|), by inverse iteration on R11^T R11 (R11 R11^T), one step of two triangular
// solves on a block of 2 vectors, doubled (up to 64) while all its values are clearly null, and
// the smallest singular value above them (an upper bound). Seeded: the same matrix gives the
// same answer.
struct SmallSingular {
  Matrix null_vectors;  // r x c, orthonormal
  double largest_null = 0.0;
  double smallest_kept = std::numeric_limits<double>::infinity();
};

SmallSingular smallestSingular(const SparseMatrix& R11t, double bound, bool left) {
  SmallSingular out;
  const Eigen::Index r = R11t.rows();
  out.null_vectors = Matrix(r, 0);
  std::mt19937_64 rng(20261126);
  std::normal_distribution<double> gauss;
  const auto orthonormal = [](Matrix& Z) {
    for (Eigen::Index j = 0; j < Z.cols(); ++j) {
      const double n = Z.col(j).norm();
      if (!(n > 0) || !std::isfinite(n)) return false;
      Z.col(j) /= n;  // scaled first: the solves can grow a column by 1/sigma_min
    }
    const Eigen::HouseholderQR<Matrix> qr(Z);
    Z = qr.householderQ() * Matrix::Identity(Z.rows(), Z.cols());
    return Z.allFinite();
  };
  for (Eigen::Index p = std::min<Eigen::Index>(r, 2);; p = std::min(r, 2 * p)) {
    Matrix Z(r, p);
    for (Eigen::Index j = 0; j < p; ++j)
      for (Eigen::Index i = 0; i < r; ++i) Z(i, j) = gauss(rng);
    bool ok = orthonormal(Z);
    // Right vectors: (R11^T R11)^-1 = R11^-1 R11^-T; left ones: (R11 R11^T)^-1 = R11^-T R11^-1.
    const auto lowerSolve = [&] { R11t.triangularView<Eigen::Lower>().solveInPlace(Z); };               // R11^-T
    const auto upperSolve = [&] { R11t.transpose().triangularView<Eigen::Upper>().solveInPlace(Z); };  // R11^-1
    if (ok) {
      left ? upperSolve() : lowerSolve();
      ok = orthonormal(Z);
    }
    if (ok) {
      left ? lowerSolve() : upperSolve();
      ok = orthonormal(Z);
    }
    if (!ok) return out;  // an exactly singular R11 cannot come from Heath's rank detection
    // Rayleigh-Ritz: the singular values of R11 Z (right) or R11^T Z (left), ascending.
    const Matrix A = left ? Matrix(R11t * Z) : Matrix(R11t.transpose() * Z);
    const Eigen::JacobiSVD<Matrix> svd(A, Eigen::ComputeThinV);
    const Vector s = svd.singularValues().reverse();
    const Matrix V = svd.matrixV().rowwise().reverse();
    // Null: the values below the bound's clearest gap, if that gap is clear (a continuum of
    // small singular values, as a 10^6-vertex grid's kept equations have below 1e-9, is a
    // conditioning, not rounding's dependencies). All of them clearly null: there may be more.
    const double clear = JacobianFactorization::kClearGap;
    if (s[p - 1] <= bound / clear && p < std::min<Eigen::Index>(r, 64)) continue;
    Eigen::Index c = 0;
    for (Eigen::Index i = 1; i < p && s[i - 1] <= bound; ++i)
      if (s[i] >= clear * std::max(s[i - 1], 1e-300) && (c == 0 || s[i] / s[i - 1] > s[c] / s[c - 1])) c = i;
    out.null_vectors = Z * V.leftCols(c);
    out.largest_null = c > 0 ? s[c - 1] : 0.0;
    out.smallest_kept = s[c];
    return out;
  }
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
  // J_ is the caller's J with its columns and rows put in a canonical order: column i is the
  // caller's variable col_of[i], row i its equation row_of[i]. Everything below is in that order.
  std::vector<int> col_of, row_of;
  Eigen::SPQR<SparseMatrix> qr;  // of J^T
  int kept = 0;                  // the columns of J^T P the QR kept (rank plus those set aside)
  SparseMatrix R11t;             // the leading kept x kept block of R, transposed
  // kept x c, orthonormal: the null vectors of R11 that the confirmation set aside, left
  // (R11^T Y ~ 0: kernel directions Q [Y; 0]) and right (R11 Z ~ 0: dependent equations).
  Matrix left_null, right_null;
  // b minus its part along the orthonormal columns of V.
  static void deflate(Eigen::Ref<Vector> b, const Matrix& V) {
    if (V.cols() > 0) b -= V * (V.transpose() * b);
  }
  // v in the canonical order from the caller's (gather), and back (scatter), by `of`.
  static Vector gather(const std::vector<int>& of, const Vector& v) {
    Vector out(v.size());
    for (size_t i = 0; i < of.size(); ++i) out[static_cast<Eigen::Index>(i)] = v[of[i]];
    return out;
  }
  static Vector scatter(const std::vector<int>& of, const Vector& v) {
    Vector out(v.size());
    for (size_t i = 0; i < of.size(); ++i) out[of[i]] = v[static_cast<Eigen::Index>(i)];
    return out;
  }
  static Matrix scatterRows(const std::vector<int>& of, const Matrix& M) {
    Matrix out(M.rows(), M.cols());
    for (size_t i = 0; i < of.size(); ++i) out.row(of[i]) = M.row(static_cast<Eigen::Index>(i));
    return out;
  }
};

namespace {

// J with its columns in the order `order` and its rows sorted by the columns they touch in that
// order (lexicographically; ties keep their order): the canonical form the sparse factorization
// works on, so that the input's numbering changes neither the fill nor the rounding. Without an
// order (null), J as it is. col_of / row_of receive the caller's column / row of each.
// The equations of J sorted by the columns they touch in the order new_col gives them.
std::vector<int> sortedRows(const SparseMatrix& J, const std::vector<int>& new_col) {
  const int m = static_cast<int>(J.rows()), N = static_cast<int>(J.cols());
  std::vector<int> row_of(static_cast<size_t>(m));
  std::iota(row_of.begin(), row_of.end(), 0);
  // Each row's columns in the new order, sorted: a counting pass into row-major slots.
  std::vector<long> start(static_cast<size_t>(m) + 1, 0);
  for (int c = 0; c < N; ++c)
    for (SparseMatrix::InnerIterator it(J, c); it; ++it) ++start[static_cast<size_t>(it.row()) + 1];
  for (int r = 0; r < m; ++r) start[static_cast<size_t>(r) + 1] += start[static_cast<size_t>(r)];
  std::vector<int> cols(static_cast<size_t>(start.back()));
  std::vector<long> fill(start.begin(), start.end() - 1);
  for (int c = 0; c < N; ++c)
    for (SparseMatrix::InnerIterator it(J, c); it; ++it)
      cols[static_cast<size_t>(fill[static_cast<size_t>(it.row())]++)] = new_col[static_cast<size_t>(c)];
  const auto from = [&](int r) { return cols.begin() + start[static_cast<size_t>(r)]; };
  for (int r = 0; r < m; ++r) std::sort(from(r), from(r + 1));
  std::stable_sort(row_of.begin(), row_of.end(),
                   [&](int a, int b) { return std::lexicographical_compare(from(a), from(a + 1), from(b), from(b + 1)); });
  return row_of;
}

// J with its columns in the order `order` and its rows sorted by the columns they touch in that
// order (lexicographically; ties keep their order): the canonical form the sparse factorization
// works on, so that the input's numbering changes neither the fill nor the rounding. Without an
// order (null), J as it is. col_of / row_of receive the caller's column / row of each.
SparseMatrix canonicalForm(const SparseMatrix& J, const std::shared_ptr<const std::vector<int>>& order,
                           std::vector<int>& col_of, std::vector<int>& row_of) {
  const int m = static_cast<int>(J.rows()), N = static_cast<int>(J.cols());
  col_of.resize(static_cast<size_t>(N));
  const bool ordered = order != nullptr && static_cast<int>(order->size()) == N;
  if (ordered) col_of = *order;
  else std::iota(col_of.begin(), col_of.end(), 0);
  std::vector<int> new_col(static_cast<size_t>(N));
  for (int i = 0; i < N; ++i) new_col[static_cast<size_t>(col_of[static_cast<size_t>(i)])] = i;
  if (ordered) {
    // A system's Jacobians share one pattern (the tracker factors one per sample): the rows'
    // order is sorted once per thread for the last order asked. The cache holds the order, so
    // no other system's order can take its address; the pattern's size tells appended rows.
    struct RowOrder {
      std::shared_ptr<const std::vector<int>> order;
      int rows = -1;
      long nonzeros = -1;
      std::vector<int> row_of;
    };
    thread_local RowOrder last;
    if (last.order != order || last.rows != m || last.nonzeros != static_cast<long>(J.nonZeros()))
      last = RowOrder{order, m, static_cast<long>(J.nonZeros()), sortedRows(J, new_col)};
    row_of = last.row_of;
  } else {
    // Without an order the rows keep theirs: sorted by arbitrary column numbers (coordinates in
    // a random order) they make AMD's ties a bad elimination order, where the rows' own order
    // does not (tests/engine/factorization_test.cpp).
    row_of.resize(static_cast<size_t>(m));
    std::iota(row_of.begin(), row_of.end(), 0);
  }
  std::vector<int> new_row(static_cast<size_t>(m));
  for (int i = 0; i < m; ++i) new_row[static_cast<size_t>(row_of[static_cast<size_t>(i)])] = i;
  // The permuted matrix, column by column, each column's entries sorted by their new row.
  SparseMatrix P(m, N);
  P.resizeNonZeros(J.nonZeros());
  int* outer = P.outerIndexPtr();
  int* inner = P.innerIndexPtr();
  double* value = P.valuePtr();
  std::vector<std::pair<int, double>> column;
  long k = 0;
  for (int i = 0; i < N; ++i) {
    outer[i] = static_cast<int>(k);
    column.clear();
    for (SparseMatrix::InnerIterator it(J, col_of[static_cast<size_t>(i)]); it; ++it)
      column.emplace_back(new_row[static_cast<size_t>(it.row())], it.value());
    std::sort(column.begin(), column.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    for (const auto& [r, v] : column) {
      inner[k] = r;
      value[k++] = v;
    }
  }
  outer[N] = static_cast<int>(k);
  return P;
}

}  // namespace

JacobianFactorization::~JacobianFactorization() = default;
JacobianFactorization::JacobianFactorization(JacobianFactorization&&) noexcept = default;
JacobianFactorization& JacobianFactorization::operator=(JacobianFactorization&&) noexcept = default;

bool JacobianFactorization::dense() const { return !sparse_; }

JacobianFactorization::JacobianFactorization(const SparseMatrix& J, const FactorizationOptions& opt)
    : rows_(static_cast<int>(J.rows())), cols_(static_cast<int>(J.cols())) {
  const int m = rows_, N = cols_;
  if (std::max(m, N) <= opt.dense_limit || m == 0 || N == 0) {
    if (m == 0 || N == 0) {
      U_ = Matrix::Identity(m, m);
      V_ = Matrix::Identity(N, N);
      s_ = Vector(0);
      rank_gap_ = std::numeric_limits<double>::infinity();
      return;
    }
    values_only_ = opt.values_only;
    if (values_only_) denseSvd(Matrix(J), s_, nullptr, nullptr, true);
    else denseSvd(Matrix(J), s_, &U_, &V_, true);
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
  J_ = canonicalForm(J, opt.variable_order, sparse_->col_of, sparse_->row_of);
  SparseMatrix Jt = J_.transpose();
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
  // (An analysis stopped from outside stops between the factorizations and solves here: the
  // sparse factorization of a 10^5-variable system can take seconds.)
  const auto factor = [&](Eigen::SPQR<SparseMatrix>& qr, double tolerance) {
    interruptionPoint();
    factorSparseQR(qr, Jt, tolerance);
    interruptionPoint();
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
  // The confirmation: the smallest singular values of the kept equations' own R11 (by inverse
  // iteration, a few triangular solves) show whether rounding kept dependent equations: Heath's
  // |R_ii| bound the singular values from above only, and along long chains of dependent
  // equations a kept set can be singular to rounding with every |R_ii| far above the threshold
  // (sheared 224 x 224 braced grids: one such set at rank gaps of 3.4e3 and 1e4 by the |R_ii|,
  // 52 in a random order of the equations; tests/engine/factorization_test.cpp). The
  // null vectors found are set aside: the left ones Y (R11^T Y ~ 0) give the kernel's missing
  // directions Q [Y; 0], the right ones Z (R11 Z ~ 0) the dependent combinations of the kept
  // equations, and the solves below project both out. The rank is the QR's minus their number.
  const auto confirm = [&] {
    sparse_->R11t = SparseMatrix(R.topLeftCorner(rank_, rank_)).transpose();
    sparse_->kept = rank_;
    sparse_->left_null = sparse_->right_null = Matrix(rank_, 0);
    if (rank_ > 0) {
      const SmallSingular right = smallestSingular(sparse_->R11t, threshold_, false);
      interruptionPoint();
      const Eigen::Index c = right.null_vectors.cols();
      const SmallSingular left = c > 0 ? smallestSingular(sparse_->R11t, threshold_, true) : SmallSingular{};
      // Confirmed when both sides agree (singular values at rounding level, clearly below the
      // others, cannot be a conditioning) and, against gross error, the directions Q [Y; 0]
      // violate no equation by more than kClearGap times the tolerance: |J Q [Y; 0]| = |R1^T Y|,
      // R1 the kept rows of R, whose columns for the dependent equations carry the rounding of
      // Heath's elimination, up to the threshold each (measured on the 224 x 224 grid in random
      // orders: 1e-11 to 1.3e-7 per equation, as the QR's own kernel columns).
      bool confirmed = c > 0 && left.null_vectors.cols() == c;
      if (confirmed) {
        const Matrix RY = SparseMatrix(R.topRows(rank_)).transpose() * left.null_vectors;
        confirmed = RY.rowwise().norm().maxCoeff() <= kClearGap * std::max(threshold_, opt.rank_tolerance * max_col);
      }
      if (confirmed) {
        sparse_->left_null = left.null_vectors;
        sparse_->right_null = right.null_vectors;
        rank_ -= static_cast<int>(c);
        rank_gap_ = left.smallest_kept / std::max(std::max(left.largest_null, right.largest_null), threshold_ * 1e-5);
      }
    }
  };
  // A rank the caller expects (the tracker: the last sample's, decided in full) settles an
  // unclear first factorization when its confirmation gives exactly that rank: the search of
  // the largest gap below costs two more factorizations. Otherwise the search decides.
  rank_gap_ = rank_ > 0 ? d.minCoeff() / threshold_ : std::numeric_limits<double>::infinity();
  if (opt.expected_rank >= 0 && rank_ > 0 && rank_gap_ < kClearGap) {
    confirm();
    if (rank_ == opt.expected_rank) {
      sigma_max_ = rank_ > 0 ? d.maxCoeff() : 0.0;
      sigma_min_kept_ = rank_ > 0 ? d.minCoeff() : 0.0;
      return;
    }
    rank_ = sparse_->kept;
    rank_gap_ = d.minCoeff() / threshold_;
  }
  // The remaining norms |R_ii| of the elimination are not singular values, and rounding along
  // long chains of dependent columns lifts some of them towards the threshold (one at 4.01e-9
  // against 4e-9 made a 224x224 grid's count depend on the order of its edges). So when a kept
  // one lies within kClearGap of the threshold, the rank is decided where the values have their
  // largest relative gap, between threshold / 1e5 and threshold * 1e5: a second factorization
  // with the lower tolerance shows the values below the threshold, and a third, at the middle of
  // that gap, gives the factorization of that rank.
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
  confirm();
  sigma_max_ = rank_ > 0 ? d.maxCoeff() : 0.0;
  sigma_min_kept_ = rank_ > 0 ? d.minCoeff() : 0.0;
}

const Matrix& JacobianFactorization::denseVectors() const {
  if (values_only_) throw std::logic_error("JacobianFactorization: singular vectors asked of a values_only factorization");
  return V_;
}

Matrix JacobianFactorization::kernel() const {
  const int N = cols_, r = rank_;
  if (!sparse_) return denseVectors().rightCols(N - r);
  // Q's columns past the kept ones, and Q [Y; 0] for the null vectors set aside.
  const int kept = sparse_->kept, extra = static_cast<int>(sparse_->left_null.cols());
  Matrix E = Matrix::Zero(N, N - r);
  for (int i = 0; i < N - kept; ++i) E(kept + i, i) = 1.0;
  E.block(0, N - kept, kept, extra) = sparse_->left_null;
  Matrix K = sparse_->qr.matrixQ() * E;
  sigma_max_dropped_ = N - r > 0 ? (J_ * K).colwise().norm().maxCoeff() : 0.0;
  return Sparse::scatterRows(sparse_->col_of, K);
}

Matrix JacobianFactorization::cokernel() const {
  const int m = rows_, r = rank_;
  if (!sparse_) return (denseVectors(), U_.rightCols(m - r));
  if (m - r == 0) return Matrix(m, 0);
  Eigen::SPQR<SparseMatrix> qr2;
  SparseMatrix Jc = J_;
  Jc.makeCompressed();
  factorSparseQR(qr2, Jc, threshold_);
  if (qr2.rank() != r) return Matrix(m, 0);  // the caller treats a wrong size as "not formed"
  Matrix E = Matrix::Zero(m, m - r);
  for (int i = 0; i < m - r; ++i) E(r + i, i) = 1.0;
  return Sparse::scatterRows(sparse_->row_of, qr2.matrixQ() * E);
}

Vector JacobianFactorization::solveMinNorm(const Vector& b) const {
  const int r = rank_;
  if (!sparse_) {
    denseVectors();
    Vector c = U_.leftCols(r).transpose() * b;
    for (int i = 0; i < r; ++i) c[i] /= s_[i];
    return V_.leftCols(r) * c;
  }
  // J^T P = Q R  =>  J = P R^T Q^T. With y = Q^T x: R11^T y1 = (P^T b)_{1..kept}, y2 = 0; the
  // dependent combinations of the kept equations (Z) leave b1, the kernel directions (Y) y1.
  const int kept = sparse_->kept;
  Vector b1 = (sparse_->qr.colsPermutation().transpose() * Sparse::gather(sparse_->row_of, b)).head(kept);
  Sparse::deflate(b1, sparse_->right_null);
  Vector y = Vector::Zero(cols_);
  y.head(kept) = sparse_->R11t.triangularView<Eigen::Lower>().solve(b1);
  Sparse::deflate(y.head(kept), sparse_->left_null);
  return Sparse::scatter(sparse_->col_of, sparse_->qr.matrixQ() * y);
}

Vector JacobianFactorization::solveSeminormal(const Vector& b) const {
  if (!sparse_) return solveMinNorm(b);
  return Sparse::scatter(sparse_->col_of, seminormal(Sparse::gather(sparse_->row_of, b)));
}

// solveSeminormal in the canonical order.
Vector JacobianFactorization::seminormal(const Vector& b) const {
  const int kept = sparse_->kept;
  // J^T P = Q R: the first kept columns of J^T P are J1^T = Q1 R11, so J1^T R11^-1 R11^-T b1 =
  // Q1 R11^-T b1, solveMinNorm's answer (with the same deflations in between).
  Vector w = (sparse_->qr.colsPermutation().transpose() * b).head(kept);
  Sparse::deflate(w, sparse_->right_null);
  sparse_->R11t.triangularView<Eigen::Lower>().solveInPlace(w);
  Sparse::deflate(w, sparse_->left_null);
  sparse_->R11t.transpose().triangularView<Eigen::Upper>().solveInPlace(w);
  Sparse::deflate(w, sparse_->right_null);
  Vector z = Vector::Zero(rows_);
  z.head(kept) = w;
  return J_.transpose() * (sparse_->qr.colsPermutation() * z);
}

Vector JacobianFactorization::projectOntoKernel(const Vector& v) const {
  const int r = rank_;
  if (!sparse_) return v - denseVectors().leftCols(r) * (V_.leftCols(r).transpose() * v);
  // v less its row-space part J^+ J v from the seminormal equations, twice: the second pass
  // takes out what the first left (its error grows with the squared condition number). J w is
  // then at rounding level: 1e-16 |w| on the 224 x 224 grids, where the QR's Q gave 2.6e-12
  // in five times the time (0.02-0.04 s against 0.004-0.009 s: its Householder vectors fill
  // far more than R).
  const Vector u = Sparse::gather(sparse_->col_of, v);
  Vector w = u - seminormal(J_ * u);
  w -= seminormal(J_ * w);
  return Sparse::scatter(sparse_->col_of, w);
}

Vector JacobianFactorization::solveTransposed(const Vector& w) const {
  const int r = rank_;
  if (!sparse_) {
    denseVectors();
    Vector c = V_.leftCols(r).transpose() * w;
    for (int i = 0; i < r; ++i) c[i] /= s_[i];
    return U_.leftCols(r) * c;
  }
  // J^T = Q R P^T: R11 z = (Q^T w)_{1..kept}, y = P [z; 0], deflated as in solveMinNorm.
  const int kept = sparse_->kept;
  Vector qw = (sparse_->qr.matrixQ().transpose() * Sparse::gather(sparse_->col_of, w)).head(kept);
  Sparse::deflate(qw, sparse_->left_null);
  Vector z = Vector::Zero(rows_);
  const SparseMatrix R11 = sparse_->R11t.transpose();
  z.head(kept) = R11.triangularView<Eigen::Upper>().solve(qw);
  Sparse::deflate(z.head(kept), sparse_->right_null);
  return Sparse::scatter(sparse_->row_of, sparse_->qr.colsPermutation() * z);
}

}  // namespace flexure::engine
