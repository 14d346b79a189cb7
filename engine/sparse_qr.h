// SuiteSparseQR through Eigen, the one way the engine calls it: the memory its ordering needs
// estimated from the matrix's counts first (refused with the estimate: engine/resources.h),
// SuiteSparse's own messages kept off standard output, and the status checked afterwards (an
// allocation that failed inside SuiteSparse is a ResourceError, never a factorization used
// half-made).
#pragma once

#include <Eigen/SPQRSupport>
#include <Eigen/SparseCore>

namespace flexure::engine {

// Factors A (compressed) into `qr` with the AMD ordering and `tolerance` (< 0: SuiteSparseQR's
// default). Throws ResourceError.
void factorSparseQR(Eigen::SPQR<Eigen::SparseMatrix<double>>& qr, const Eigen::SparseMatrix<double>& A,
                    double tolerance = -1);

}  // namespace flexure::engine
