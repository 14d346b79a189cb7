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

}  // namespace flexure::engine::verified
