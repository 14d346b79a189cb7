#include "engine/interval/verified.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <limits>

namespace flexure::engine::verified {

std::optional<double> smallestEigenvalueLowerBound(const IntervalMatrix& A) {
  const int n = A.n;
  if (n == 0) return std::numeric_limits<double>::infinity();
  Matrix M(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      if (!A(i, j).finite()) return std::nullopt;
      M(i, j) = A(i, j).mid();
    }
  M = 0.5 * (M + M.transpose());
  const double lambda = Eigen::SelfAdjointEigenSolver<Matrix>(M, Eigen::EigenvaluesOnly).eigenvalues()(0);
  if (!(lambda > 0)) return std::nullopt;
  // gamma_n = n u / (1 - n u), computed upward; an absolute term for products that underflow.
  const double u = std::ldexp(1.0, -53);
  const Interval nu = Interval(static_cast<double>(n + 2)) * Interval(u);
  const Interval gamma = nu / (Interval(1.0) - nu);
  const Interval g = gamma / (Interval(1.0) - gamma);
  const double tiny = static_cast<double>(n + 2) * std::numeric_limits<double>::min();
  for (double fraction : {0.5, 0.125, 1.0 / 64}) {
    const double s = lambda * fraction;
    Matrix C = M;
    C.diagonal().array() -= s;
    Eigen::LLT<Matrix> llt(C);
    if (llt.info() != Eigen::Success) continue;
    const Matrix L = llt.matrixL();
    const Matrix P = L * L.transpose();                   // fl(L L^T)
    const Matrix Labs = L.cwiseAbs();
    const Matrix Q = Labs * Labs.transpose();             // fl(|L| |L|^T) >= (1 - gamma) |L| |L|^T
    double norm = 0;
    for (int i = 0; i < n; ++i) {
      Interval row(0.0);
      for (int j = 0; j < n; ++j) {
        // E_ij in A_ij - s [i = j] - P_ij +- (g Q_ij + tiny)
        Interval e = A(i, j) - Interval(P(i, j));
        if (i == j) e -= Interval(s);
        const Interval slack = g * Interval(Q(i, j)) + Interval(tiny);
        row += Interval(e.mag()) + slack;
      }
      norm = std::isnan(row.hi) ? std::numeric_limits<double>::infinity() : std::max(norm, row.hi);
    }
    const Interval bound = Interval(s) - Interval(norm);
    if (bound.lo > 0) return bound.lo;
  }
  return std::nullopt;
}

namespace {

// gamma_k = k u / (1 - k u) (u = 2^-53), an upper bound.
Interval gammaOf(long k) {
  const Interval ku = Interval(static_cast<double>(k)) * Interval(std::ldexp(1.0, -53));
  return ku / (Interval(1.0) - ku);
}

// The longest column of a sparse matrix.
long longestColumn(const SparseMatrix& A) {
  long k = 0;
  for (int j = 0; j < A.outerSize(); ++j) {
    long c = 0;
    for (SparseMatrix::InnerIterator it(A, j); it; ++it) ++c;
    k = std::max(k, c);
  }
  return k;
}

}  // namespace

std::optional<double> smallestEigenvalueLowerBound(const SparseMatrix& M, const SparseMatrix& E, double* estimate) {
  using Cholesky = Eigen::SimplicialLLT<SparseMatrix, Eigen::Lower, Eigen::AMDOrdering<int>>;
  const int n = static_cast<int>(M.rows());
  if (n == 0) return std::numeric_limits<double>::infinity();
  for (int j = 0; j < M.outerSize(); ++j)
    for (SparseMatrix::InnerIterator it(M, j); it; ++it)
      if (!std::isfinite(it.value())) return std::nullopt;
  // The smallest eigenvalue, estimated (only the shifts depend on it): the caller's estimate,
  // else inverse iteration from a fixed vector and its Rayleigh quotient.
  const auto estimated = [&]() -> double {
    Cholesky factor(M);
    if (factor.info() != Eigen::Success) return 0;
    Vector v(n);
    for (int i = 0; i < n; ++i) v[i] = 1.0 + 0.1 * (i % 7);
    v.normalize();
    for (int it = 0; it < 12; ++it) {
      const Vector w = factor.solve(v);
      const double norm = w.norm();
      if (!(norm > 0) || !std::isfinite(norm)) return 0;
      v = w / norm;
    }
    return v.dot(M * v);
  };
  const double tiny = static_cast<double>(n + 2) * std::numeric_limits<double>::min();
  SparseMatrix identity(n, n);
  identity.setIdentity();
  const bool hinted = estimate && *estimate > 0 && std::isfinite(*estimate);
  double lambda = hinted ? *estimate : estimated();
  if (!(lambda > 0)) return std::nullopt;
  std::vector<double> fractions = {0.5, 0.125, 1.0 / 64};
  if (hinted) fractions = {0.5, -1, 0.5, 0.125, 1.0 / 64};  // -1: the estimate, computed afresh
  // ||E||_2 <= its largest row sum (E >= 0 symmetric), and M's largest diagonal entry.
  std::vector<Interval> e_rows(static_cast<size_t>(n), Interval(0.0));
  for (int j = 0; j < E.outerSize(); ++j)
    for (SparseMatrix::InnerIterator it(E, j); it; ++it) e_rows[static_cast<size_t>(it.row())] += Interval(std::abs(it.value()));
  double e_norm = 0, diagonal = 0;
  for (const Interval& r : e_rows) e_norm = std::max(e_norm, r.hi);
  for (int j = 0; j < n; ++j) diagonal = std::max(diagonal, std::abs(M.coeff(j, j)));
  for (double fraction : fractions) {
    if (fraction < 0) {
      lambda = estimated();
      if (!(lambda > 0)) return std::nullopt;
      continue;
    }
    const double s = lambda * fraction;
    Cholesky f(SparseMatrix(M - s * identity));
    if (f.info() != Eigen::Success) continue;
    {
      // A priori, without forming L L^T (Demmel; Rump's test of positive definiteness): a
      // Cholesky factorization in floating point that runs to completion gives
      // L L^T = fl(M - s I) + D with |D| <= gamma_{k+1} |L| |L|^T plus underflow (k: L's longest
      // row, the longest inner product), so ||D||_2 <= gamma_{k+1} ||L||_F^2 + n tiny; fl(M - s I)
      // is M - s I but for a rounding of each diagonal entry (at most an ulp of max |M_ii| + s).
      // L L^T >= 0 then gives lambda_min(M) >= s - ||D|| - that rounding - ||E||.
      const auto& L = f.matrixL().nestedExpression();  // L, lower triangular, column by column
      std::vector<int> row_length(static_cast<size_t>(n), 0);
      Interval frobenius(0.0);
      for (int k = 0; k < L.outerSize(); ++k)
        for (SparseMatrix::InnerIterator it(L, k); it; ++it) {
          ++row_length[static_cast<size_t>(it.row())];
          frobenius += Interval(it.value()) * Interval(it.value());
        }
      const int longest = *std::max_element(row_length.begin(), row_length.end());
      const Interval g = gammaOf(longest + 1);
      const Interval rounding = Interval(2.0 * std::ldexp(1.0, -53)) * (Interval(diagonal) + Interval(s));
      // A subnormal quotient l_ki = y / l_ii errs by up to 2^-1075, times l_ii <= sqrt(M_ii + s)
      // in L L^T: n of those per row at most.
      const Interval subnormal = Interval(static_cast<double>(n)) * sqrt(Interval(diagonal) + Interval(s)) *
                                 Interval(std::ldexp(1.0, -1074));
      const Interval bound = Interval(s) - g * frobenius - Interval(static_cast<double>(n)) * Interval(tiny) - rounding -
                             subnormal - Interval(e_norm);
      if (bound.lo > 0) {
        if (estimate) *estimate = lambda;
        return bound.lo;
      }
    }
    // P (M - s I) P^T = L L^T + error: everything in the factor's order.
    const SparseMatrix L = f.matrixL();
    const SparseMatrix Mp = f.permutationP() * M * f.permutationP().transpose();
    const SparseMatrix Ep = f.permutationP() * E * f.permutationP().transpose();
    const SparseMatrix P = L * SparseMatrix(L.transpose());  // fl(L L^T)
    // Each entry of L L^T sums at most k products (k: L's longest row = L^T's longest column),
    // so |fl(L L^T) - L L^T| <= gamma_k |L| |L|^T, whose column sums are |L| c for c the column
    // sums of |L| (computed upward: no product of the factors).
    const Interval g = gammaOf(longestColumn(SparseMatrix(L.transpose())) + 2);
    std::vector<Interval> c(static_cast<size_t>(n), Interval(0.0)), lc(static_cast<size_t>(n), Interval(0.0));
    for (int k = 0; k < L.outerSize(); ++k)
      for (SparseMatrix::InnerIterator it(L, k); it; ++it) c[static_cast<size_t>(k)] += Interval(std::abs(it.value()));
    for (int k = 0; k < L.outerSize(); ++k)
      for (SparseMatrix::InnerIterator it(L, k); it; ++it)
        lc[static_cast<size_t>(it.row())] += Interval(std::abs(it.value())) * c[static_cast<size_t>(k)];
    double rounding = 0;
    for (const Interval& x : lc)
      rounding = std::isnan((g * x).hi) ? std::numeric_limits<double>::infinity() : std::max(rounding, (g * x).hi);
    // The largest column sum of |E| over the union of the patterns (E symmetric: the 1-norm is
    // the infinity norm, a bound of the 2-norm).
    double norm = 0;
    for (int j = 0; j < n; ++j) {
      Interval column(0.0);
      SparseMatrix::InnerIterator im(Mp, j), ip(P, j), ie(Ep, j);
      for (;;) {
        int row = n;
        if (im) row = std::min<int>(row, static_cast<int>(im.row()));
        if (ip) row = std::min<int>(row, static_cast<int>(ip.row()));
        if (ie) row = std::min<int>(row, static_cast<int>(ie.row()));
        if (row == n) break;
        Interval e(0.0);
        if (im && im.row() == row) e += Interval(im.value()), ++im;
        if (row == j) e -= Interval(s);
        if (ip && ip.row() == row) e -= Interval(ip.value()), ++ip;
        Interval entry = Interval(e.mag()) + Interval(tiny);
        if (ie && ie.row() == row) entry += Interval(ie.value()), ++ie;
        column += entry;
      }
      norm = std::isnan(column.hi) ? std::numeric_limits<double>::infinity() : std::max(norm, column.hi);
    }
    const Interval bound = Interval(s) - Interval(norm) - Interval(rounding);
    if (bound.lo > 0) {
      if (estimate) *estimate = lambda;
      return bound.lo;
    }
  }
  return std::nullopt;
}

std::optional<double> smallestSingularValueLowerBound(const SparseMatrix& A, double* estimate) {
  const SparseMatrix At = A.transpose();
  const SparseMatrix M = At * A;
  const SparseMatrix Aabs = A.cwiseAbs();
  SparseMatrix E = SparseMatrix(Aabs.transpose()) * Aabs;
  // |A^T A - fl(A^T A)| <= gamma_c |A|^T |A| <= gamma_c / (1 - gamma_c) fl(|A|^T |A|), c the
  // longest column of A (the products in one entry), plus underflow.
  const Interval g = gammaOf(longestColumn(A) + 2);
  const Interval factor = g / (Interval(1.0) - g);
  const double tiny = static_cast<double>(A.rows() + 2) * std::numeric_limits<double>::min();
  for (int j = 0; j < E.outerSize(); ++j)
    for (SparseMatrix::InnerIterator it(E, j); it; ++it) it.valueRef() = (factor * Interval(it.value()) + Interval(tiny)).hi;
  const std::optional<double> lambda = smallestEigenvalueLowerBound(M, E, estimate);
  if (!lambda || !(*lambda > 0)) return std::nullopt;
  return sqrt(Interval(*lambda)).lo;
}

}  // namespace flexure::engine::verified
