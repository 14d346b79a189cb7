// Verified linear algebra in floating point: bounds that hold for the exact values, from
// computations in double whose rounding errors are bounded a priori (Higham's gamma_n) or
// enclosed by interval arithmetic (engine/interval/interval.h).
#pragma once

#include <optional>
#include <vector>

#include "engine/constraint_system.h"
#include "engine/interval/interval.h"

namespace flexure::engine::verified {

// A symmetric n x n interval matrix, row-major (both triangles held).
struct IntervalMatrix {
  int n = 0;
  std::vector<Interval> a;
  explicit IntervalMatrix(int size) : n(size), a(static_cast<size_t>(size) * static_cast<size_t>(size)) {}
  Interval& operator()(int i, int j) { return a[static_cast<size_t>(i) * static_cast<size_t>(n) + static_cast<size_t>(j)]; }
  const Interval& operator()(int i, int j) const {
    return a[static_cast<size_t>(i) * static_cast<size_t>(n) + static_cast<size_t>(j)];
  }
};

// A lower bound, proved, of the smallest eigenvalue of every symmetric matrix in A; none when it
// cannot be shown positive. Method: the Cholesky factor L of mid(A) - s I in double for a few
// shifts s below the estimated smallest eigenvalue, and an enclosure of E = A - s I - L L^T (the
// product's rounding bounded by gamma_n |L| |L|^T); then lambda_min(A) >= s - ||E||_inf, since
// L L^T is positive semidefinite and ||E||_2 <= ||E||_inf for symmetric E.
std::optional<double> smallestEigenvalueLowerBound(const IntervalMatrix& A);

// The same for a sparse symmetric matrix known entrywise as M +- E (M with both triangles; E >= 0
// on part of M's pattern), for large systems: the sparse Cholesky factor L of M - s I in a
// fill-reducing order (AMD) for a few shifts s below an estimate of the smallest eigenvalue
// (inverse iteration), and E + |M - s I - L L^T| enclosed over the union of the patterns.
// `estimate` (optional): an estimate of the smallest eigenvalue to take the shifts from (a
// neighbouring matrix's: no inverse iteration), and on success the estimate used.
std::optional<double> smallestEigenvalueLowerBound(const SparseMatrix& M, const SparseMatrix& E,
                                                   double* estimate = nullptr);

// A proved lower bound of the smallest singular value of the square sparse matrix A (its
// entries exact doubles): the square root of the bound above for A^T A (formed in double, its
// rounding in E by gamma_c |A|^T |A|, c the longest column). None when A is singular or too
// close to it. `estimate`: as above, of A^T A's smallest eigenvalue.
std::optional<double> smallestSingularValueLowerBound(const SparseMatrix& A, double* estimate = nullptr);

}  // namespace flexure::engine::verified
