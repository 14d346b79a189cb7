// The algebra of flex spaces, below both the tracker and the rigidity analysis: the trivial
// flexes of a model (its symmetries that fix the pins), the nontrivial part of a kernel, and
// canonical orthonormal bases that do not depend on the basis a factorization happened to give.
#pragma once

#include <vector>

#include "engine/model.h"

namespace flexure::engine {

// Orthonormal basis of the column space of M, keeping singular values > rel * sigma_max(M).
Matrix orthonormalColumnSpace(const Matrix& M, double rel);

// Orthonormal basis (N x t) of the trivial flexes at x: the model's symmetry generators
// restricted to the subgroup that fixes every pinned vertex, on the free coordinates.
Matrix trivialFlexes(const Model& model, const Vector& x, double tolerance);

// An orthonormal basis of the part of span(kernel) orthogonal to span(trivial) (both with
// orthonormal columns, trivial inside kernel): the nontrivial flexes, in no particular basis.
Matrix nontrivialPart(const Matrix& kernel, const Matrix& trivial);
// The same space from the k x k Gram matrix of the projected kernel, I - C^T C with C = T^T K,
// one product with the N x k kernel and a Cholesky-QR pass instead of a thin SVD of it (several
// times cheaper for tall kernels: the tracker calls it at every sample), in another basis. The
// drag's tangent cone and the analysis keep the SVD's basis. coefficients (if given): C with
// B = kernel * C (k x columns of B) when B is formed that way (trivial flexes inside the
// kernel, the usual case), so that products of two such bases reduce to their kernels';
// empty otherwise.
Matrix nontrivialPartFast(const Matrix& kernel, const Matrix& trivial, Matrix* coefficients = nullptr);

// The canonical orthonormal basis of span(B) (B: N x k with orthonormal columns), independent
// of which basis B is: column 1 is the unit vector of the space that moves coordinate j1 the
// most, where j1 is the coordinate with the largest projection (ties, within a relative 1e-9,
// go to the lowest index); its j1 entry is positive. Column 2 is found the same way in the
// part of the space orthogonal to column 1, and so on. Column i is zero at j1..j(i-1).
Matrix canonicalBasis(const Matrix& B);

// k coordinates (rows of K, N x k with orthonormal columns) that parametrize span(K): the
// pivots of a column-pivoted QR of K^T, each row at least 1/sqrt(2) as far from the span of
// the rows before it as the farthest one (the greedy choice up to that factor). In blocks: the
// pivots of a block come from the rows with the largest remaining norms while they stay within
// that factor of the largest norm left outside, and all norms are then brought up to date by
// one product K Q (N x k x block), not by a Householder pass over K per pivot: 0.23 s instead
// of Eigen's 1.0 s at 114 flexes and 10^5 variables, the gauge as good (its rows' smallest
// singular value the same on the braced grids). The factor lets blocks pass over the many
// equal norms of a grid, where an exact greedy choice ends a block at every pivot. A K whose
// rows run out of independent directions (numerically deficient) gets Eigen's pivots.
std::vector<int> pivotedCoordinates(const Matrix& K);

}  // namespace flexure::engine
