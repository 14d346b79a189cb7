// Exact linear algebra over the rationals for the exact mode: ranks and null spaces by FLINT's
// integer matrices (each row scaled to integers, which changes neither the rank nor the null
// space; FLINT eliminates fraction-free or multimodularly, so entries do not grow as in naive
// rational elimination), and the small dense steps (products, projections, definiteness) in
// GMP rationals.
#pragma once

#include <vector>

#include "engine/exact/rational.h"

namespace flexure::engine::exact {

// The rank of A.
int rank(const RationalMatrix& A);
// A basis of {x : A x = 0}, as the columns of an A.cols x k matrix (integer entries).
RationalMatrix nullSpace(const RationalMatrix& A);
// A's columns that are independent (the pivot columns of its reduced echelon form), in order.
RationalMatrix independentColumns(const RationalMatrix& A);

RationalMatrix transpose(const RationalMatrix& A);
RationalMatrix multiply(const RationalMatrix& A, const RationalMatrix& B);
// The part of the columns of K orthogonal to the column space of T (T of full column rank):
// K - T (T^T T)^-1 T^T K, exactly.
RationalMatrix orthogonalToColumns(const RationalMatrix& K, const RationalMatrix& T);
// Whether the symmetric Q is positive definite: every pivot of its symmetric elimination
// (Q = L D L^T without pivoting) positive. An empty matrix is positive definite.
bool positiveDefinite(const RationalMatrix& Q);

// The rank of the m x n matrix given by its nonzero entries (row, column, value) (repeated
// entries add up); with `null_space`, also a basis of its null space (n x k, integer entries).
// The dense integer matrix it builds has m x n entries.
struct SparseEntry {
  int row, column;
  Rational value;
};
int sparseRank(int m, int n, const std::vector<SparseEntry>& entries, RationalMatrix* null_space = nullptr);

// The rank modulo the prime 2^61 - 1 of the same matrix with each row scaled to integers, by
// sparse elimination with the columns taken in `column_order` (a permutation of 0..n-1; a
// banded order keeps the fill small): a lower bound of the rank over the rationals (a minor
// that is nonzero modulo p is a nonzero integer), equal to it unless p divides every largest
// nonzero minor. Memory: the echelon rows' fill.
int modularRankLowerBound(int m, int n, const std::vector<SparseEntry>& entries, const std::vector<int>& column_order);

}  // namespace flexure::engine::exact
