// Rank-revealing factorization of a Jacobian J (m x N): a dense SVD for small systems,
// SuiteSparseQR of J^T for large ones. One factorization answers the rank, the kernel (flexes),
// the cokernel (stresses) and minimum-norm least-squares solves (Gauss-Newton steps,
// accelerations), so the tracker factors J once per point.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "engine/constraint_system.h"

namespace flexure::engine {

// Singular value decomposition A = U diag(s) V^T of a dense matrix, s descending: LAPACK's
// dgesdd, checked (finite, sorted), then JacobiSVD if LAPACK fails. Eigen 3.4.0's BDCSVD is not
// used: it reads out of bounds on some rank-deficient Jacobians and returns NaNs, unsorted or
// wrong small singular values on others.
// full: U is m x m and V is N x N; otherwise thin. U or V may be null (not computed).
void denseSvd(const Matrix& A, Vector& s, Matrix* U, Matrix* V, bool full);

struct FactorizationOptions {
  // sigma counts as nonzero when sigma > rank_tolerance * sigma_max (dense), or a column of
  // J^T counts as independent when its remaining norm exceeds rank_tolerance * (largest row
  // norm of J) (sparse, Heath's rank detection).
  double rank_tolerance = 1e-9;
  // Dense SVD when max(equations, variables) <= dense_limit.
  int dense_limit = 500;
  // The rank the caller expects (e.g. the tracker: the last sample's), or -1. Sparse: a first
  // factorization whose rank is unclear by its |R_ii| but, confirmed, equals this one is kept
  // without the search for the largest gap (two more factorizations).
  int expected_rank = -1;
  // Sparse: the order in which the variables are factored (ConstraintSystem::factorizationOrder:
  // by geometry), or null for their own order. The equations are then sorted by the variables
  // they touch in that order, so that neither the input's numbering of the vertices nor the order
  // of its terms changes the factorization, its rank evidence or its time. Results come back
  // in the caller's order.
  std::shared_ptr<const std::vector<int>> variable_order;
  // Dense: the singular values alone (the counts of a sweep item): the kernel, cokernel and
  // solves are then not available.
  bool values_only = false;
};

// `o` with the variable order of `sys` (ConstraintSystem::factorizationOrder) unless it has one.
inline FactorizationOptions orderedFor(FactorizationOptions o, const ConstraintSystem& sys) {
  if (!o.variable_order) o.variable_order = sys.factorizationOrder();
  return o;
}

class JacobianFactorization {
 public:
  JacobianFactorization(const SparseMatrix& J, const FactorizationOptions& options);
  ~JacobianFactorization();
  JacobianFactorization(JacobianFactorization&&) noexcept;
  JacobianFactorization& operator=(JacobianFactorization&&) noexcept;

  bool dense() const;
  const char* method() const { return dense() ? "dense SVD" : "sparse QR"; }
  int rows() const { return rows_; }
  int cols() const { return cols_; }
  int rank() const { return rank_; }
  double threshold() const { return threshold_; }
  double sigmaMax() const { return sigma_max_; }             // |R_ii| estimate when sparse
  double sigmaSmallestKept() const { return sigma_min_kept_; }  // |R_ii| when sparse
  // Largest singular value counted as zero (dense); with sparse QR, the largest norm of J
  // applied to a kernel vector (computed by kernel()).
  double sigmaLargestDropped() const { return sigma_max_dropped_; }

  // How clearly the rank is decided: the ratio of the smallest value counted as nonzero to the
  // largest counted as zero (singular values, dense; the QR's |R_ii|, sparse, where a kept one
  // near the threshold sends the decision to the largest gap, and the kept equations' own
  // singular values where their confirmation set dependent ones aside; see the constructor).
  // Below kClearGap the count may change with the tolerance or the order of the equations.
  static constexpr double kClearGap = 1e3;
  double rankGap() const { return rank_gap_; }

  // Orthonormal basis of ker J, N x (N - rank).
  Matrix kernel() const;
  // Orthonormal basis of ker J^T, m x (m - rank). Sparse: a second factorization.
  Matrix cokernel() const;
  // The minimum-norm solution of J x = b in the least-squares sense over the independent
  // equations (dense: the truncated pseudo-inverse V S^+ U^T b).
  Vector solveMinNorm(const Vector& b) const;
  // The same solution from the seminormal equations, x = J1^T (R11^T R11)^-1 b1 with J1 the
  // independent equations (sparse; dense: solveMinNorm): no product with the QR's Q, whose
  // Householder vectors fill far more than R, at the price of a squared condition number in
  // the rounding. For iterations that correct their own steps, as the motion check's.
  Vector solveSeminormal(const Vector& b) const;
  // The orthogonal projection of v (N) onto ker J: v minus its part in the row space.
  Vector projectOntoKernel(const Vector& v) const;
  // A least-squares solution of J^T y = w (w: N values; y: m, zero on the equations that the
  // factorization found dependent when sparse, minimum-norm when dense): the equation weights
  // (a stress, when w is a load) that balance w's row-space part.
  Vector solveTransposed(const Vector& w) const;
  // The singular values (dense only; empty when sparse), descending.
  const Vector& singularValues() const { return s_; }

 private:
  struct Sparse;
  Vector seminormal(const Vector& b) const;
  int rows_ = 0, cols_ = 0, rank_ = 0;
  double threshold_ = 0, sigma_max_ = 0, sigma_min_kept_ = 0, rank_gap_ = 0;
  mutable double sigma_max_dropped_ = 0;
  Matrix U_, V_;
  bool values_only_ = false;
  const Matrix& denseVectors() const;  // V_, after checking that the vectors were computed
  Vector s_;
  SparseMatrix J_;
  std::unique_ptr<Sparse> sparse_;
};

}  // namespace flexure::engine
