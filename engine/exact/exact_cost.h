// The exact mode's cost (issue 62), estimated before the work from the matrix's shape, its
// sparsity and its entries' bit sizes, and refused when it exceeds the time budget
// ([analysis] exact_budget) or the memory this process can have. The model's constants were
// calibrated on random frameworks and triangulated grids (bench/exact_budget_bench.cpp,
// docs/benchmarks.md): CPU seconds of this machine class, within 4x of the measured work.
#pragma once

#include <string>
#include <vector>

#include "engine/exact/exact_linear_algebra.h"

namespace flexure::engine::exact {

struct ExactCost {
  double seconds = 0;  // CPU
  double bytes = 0;    // peak memory of the largest step
  std::string detail;  // the steps counted, for the message ("modular rank 1.2 s, dense rank 30 s")
  void add(const std::string& what, double s, double b);
  void add(const ExactCost& other);  // its seconds and details added, the larger peak
};

// The integer-scaled matrix's sizes (each row times the least common multiple of its
// denominators, as the eliminations take it).
struct MatrixShape {
  int rows = 0, cols = 0;
  double nonzeros = 0;
  double mean_bits = 0;    // mean bits of the nonzero integer entries
  double max_row_log = 0;  // log2 of the largest row's Euclidean norm (Hadamard's bound per row)
  double mean_row_log = 0; // the mean over the rows of log2 of their Euclidean norms
};
MatrixShape shapeOf(int m, int n, const std::vector<SparseEntry>& entries);

// The work of modularRankLowerBound with this column order: an upper estimate of its fill
// from the envelope of the rows, in units of the elimination's inner step.
double modularWork(int m, int n, const std::vector<SparseEntry>& entries, const std::vector<int>& column_order);

ExactCost modularRankCost(const MatrixShape& s, double work);
// The dense elimination of FLINT (fmpz_mat_rref by multimodular rref and a Dixon solve) of the
// rows x cols matrix of rank r: its rank, or with `null_space` also its null space;
// `transposed`: the matrix is J^T (rows: the variables), whose solve is slower.
ExactCost denseEliminationCost(const MatrixShape& s, int r, bool null_space, bool transposed);
// The orthogonal projection and the independent columns of a null space of `k` columns of
// `bits`-bit integers of length n, against t trivial flexes.
ExactCost basisCost(int n, int k, int t, double bits);
// The second-order step (exact_rigidity.cpp: decidePrestress) with k nontrivial flexes and s
// stresses of `bits`-bit integers, m equations: the stress-energy forms (k^2 s m products) and
// the exact LDL^T of each candidate stress's form.
ExactCost secondOrderCost(int m, int k, int s, double bits);
// The Hadamard bound, in bits, of the null space's entries of a matrix of this shape and rank r.
double nullSpaceBits(const MatrixShape& s, int r);

// Throws ResourceError with the estimate when `cost` exceeds `budget_seconds` of CPU or the
// memory this process can have; `what` names the work ("the exact analysis of 1,800 variables
// and 1,800 equations").
void requireExactBudget(const std::string& what, const ExactCost& cost, double budget_seconds);

}  // namespace flexure::engine::exact
