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
// times cheaper for tall kernels: the tracker calls it at every sample of a small system), in
// another basis: the analysis and the tracker use it; the drag's tangent cone keeps the SVD's.
Matrix nontrivialPartFast(const Matrix& kernel, const Matrix& trivial);

// The canonical orthonormal basis of span(B) (B: N x k with orthonormal columns), independent
// of which basis B is: column 1 is the unit vector of the space that moves coordinate j1 the
// most, where j1 is the coordinate with the largest projection (ties, within a relative 1e-9,
// go to the lowest index); its j1 entry is positive. Column 2 is found the same way in the
// part of the space orthogonal to column 1, and so on. Column i is zero at j1..j(i-1).
Matrix canonicalBasis(const Matrix& B);

}  // namespace flexure::engine
