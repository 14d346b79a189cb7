#include "engine/interval/verified.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
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
      norm = std::max(norm, row.hi);
    }
    const Interval bound = Interval(s) - Interval(norm);
    if (bound.lo > 0) return bound.lo;
  }
  return std::nullopt;
}

}  // namespace flexure::engine::verified
