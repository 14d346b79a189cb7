#include "engine/sparse_qr.h"

#include <cstdarg>
#include <cstdio>
#include <string>

#include "engine/resources.h"

namespace flexure::engine {

namespace {

// SuiteSparse prints through one global function pointer (printf, to standard output, where
// `--json` writes): its messages go to standard error instead, and only ours say what failed.
int printToStderr(const char* format, ...) {
  va_list args;
  va_start(args, format);
  const int n = std::vfprintf(stderr, format, args);
  va_end(args);
  return n;
}
const bool g_print_redirected = [] {
  SuiteSparse_config.printf_func = printToStderr;
  return true;
}();

}  // namespace

void factorSparseQR(Eigen::SPQR<Eigen::SparseMatrix<double>>& qr, const Eigen::SparseMatrix<double>& A,
                    double tolerance) {
  (void)g_print_redirected;
  // SuiteSparseQR orders A's columns by AMD on the pattern of A^T A, which it forms: its entries
  // are at most the sum over A's rows of (entries in the row)^2, 8 bytes of index each, with
  // AMD's workspace about as much again. (The complete graph K_1000 in the plane: 2e9 entries,
  // 32 GB, from an 83 kB graph6 line.)
  double pairs = 0;
  {
    Eigen::VectorXd row_counts = Eigen::VectorXd::Zero(A.rows());
    for (int c = 0; c < A.outerSize(); ++c)
      for (Eigen::SparseMatrix<double>::InnerIterator it(A, c); it; ++it) row_counts[it.row()] += 1;
    pairs = row_counts.squaredNorm();
  }
  const double nnz = static_cast<double>(A.nonZeros());
  requireMemory("the sparse QR of a " + std::to_string(A.rows()) + " x " + std::to_string(A.cols()) +
                    " matrix with " + std::to_string(A.nonZeros()) + " nonzeros (its ordering alone)",
                16.0 * pairs + 40.0 * nnz);
  qr.cholmodCommon()->print = 0;
  qr.setSPQROrdering(SPQR_ORDERING_AMD);
  if (tolerance >= 0) qr.setPivotThreshold(tolerance);
  qr.compute(A);
  if (qr.info() != Eigen::Success) {
    const int status = qr.cholmodCommon()->status;
    const std::string why = status == CHOLMOD_OUT_OF_MEMORY ? "out of memory"
                            : status == CHOLMOD_TOO_LARGE   ? "the problem is too large for its integers"
                                                            : "SuiteSparse status " + std::to_string(status);
    throw ResourceError("the sparse QR of a " + std::to_string(A.rows()) + " x " + std::to_string(A.cols()) +
                        " matrix failed: " + why);
  }
}

}  // namespace flexure::engine
