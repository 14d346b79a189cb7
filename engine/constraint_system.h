// A geometric constraint system in the sense of the paper (section 2): blocks of d coordinates
// (the vertices, then auxiliary vectors such as facet normals), a list of constraint terms over
// them, and a set of pinned vertices whose coordinates are constants rather than variables.
//
// The variable vector x holds the free coordinates block-major: for block b = 0..B-1 and
// coordinate k = 0..d-1, x[variableIndex(b, k)], skipping pinned blocks. Terms fill their
// residuals and their rows of a sparse Jacobian whose pattern is fixed once by finalize().
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <string>
#include <vector>

#include "engine/term_list.h"

namespace flexure::engine {

using Vector = Eigen::VectorXd;
using Matrix = Eigen::MatrixXd;
using SparseMatrix = Eigen::SparseMatrix<double>;  // column-major, as the sparse QR wants

// One constraint term: numResiduals() residuals over a fixed list of distinct blocks. Local
// coordinates are the term's blocks' coordinates, block-major (blocks().size() * d values).
//
// Each term writes its formula once, as `template <class T> void residual(const T* x0,
// const T* x, int d, T* r) const` (engine/terms.h; x0 the start's local coordinates, from which
// it computes the parameters the start decides), in any arithmetic: double, HyperDual (its
// derivatives, engine/jet.h), intervals, rationals. Evaluators other than the double fast path reach it
// through accept() and the one term list (engine/term_list.h). The double path below is that
// formula times rowWeight(), with derivatives written by hand for speed; tests compare the two.
class ConstraintTerm {
 public:
  virtual ~ConstraintTerm() = default;

  virtual int numResiduals() const = 0;
  // The residuals' degree as polynomials in the local coordinates (the largest over the rows),
  // or -1 where a residual is not a polynomial (it takes a root): what decides whether the
  // second-order theory for quadratic systems applies and whether exact arithmetic can evaluate
  // the term.
  virtual int degree(int d) const = 0;
  // A positive factor the double evaluation applies to every residual of the term (a scale that
  // gives rows of different kinds comparable sizes). It changes neither the rank nor the zero
  // set; the formula (residual<T>) leaves it out, so exact and interval evaluations do not
  // carry an irrational or rounded scale.
  virtual double rowWeight() const { return 1.0; }
  // visitor.visit(*this): the dispatch of the term list.
  virtual void accept(TermVisitor& visitor) const = 0;
  // Writes rowWeight() times the residuals and, if jacobian != nullptr, the row-major
  // numResiduals() x (blocks*d) local Jacobian of those.
  virtual void evaluate(const double* x, int d, double* residuals, double* jacobian) const = 0;
  // out[i] = u^T H_i w for the Hessian H_i of residual i in local coordinates: the second
  // directional derivative used for accelerations, stress energies and blocked flexes.
  virtual void secondDerivative(const double* x, const double* u, const double* w, int d,
                                double* out) const = 0;
  // Magnitude of the quantities the residuals compare (e.g. the squared length of an edge):
  // tolerances on residuals are relative to it.
  virtual double residualScale() const { return 1.0; }
  // Short human-readable name of residual `row`, with 0-based block numbers, e.g. "edge 0-4".
  virtual std::string label(int row, int index_base) const = 0;

  const std::vector<int>& blocks() const { return blocks_; }

 protected:
  explicit ConstraintTerm(std::vector<int> blocks) : blocks_(std::move(blocks)) {}

 private:
  std::vector<int> blocks_;
};

// What a block of coordinates is. Every block has d coordinates in the positions matrix;
// a Scalar uses the first (the others are constants, not variables). The kind is what
// generators, drawing and the symmetry groups read: points move with translations and
// rotations, directions and lattice vectors with rotations only, scalars with neither.
enum class BlockKind {
  Point,      // a vertex (the first numVertices() blocks, and only they)
  Direction,  // an auxiliary vector: a facet normal, an orientation frame's axis
  Lattice,    // a lattice vector of a periodic framework
  Scalar,     // one number: an auxiliary length, a contact parameter
};

class ConstraintSystem {
 public:
  // `num_blocks` blocks of `dimension` coordinates; the first `num_vertices` are vertices.
  ConstraintSystem(int dimension, int num_vertices, int num_blocks);
  ConstraintSystem(ConstraintSystem&&) = default;
  ConstraintSystem& operator=(ConstraintSystem&&) = default;

  // Building. Throws std::invalid_argument on misuse (bad block numbers, repeated blocks).
  // Any block can be pinned (a vertex, a normal, a lattice vector, a scalar): its coordinates
  // are then constants.
  void pin(int block);
  // The kind of a non-vertex block (Direction by default; vertices are Points and stay so).
  void setBlockKind(int block, BlockKind kind);
  void addTerm(std::unique_ptr<ConstraintTerm> term);
  // Fixes the variables, the pinned values (taken from `positions`, d x numBlocks) and the
  // Jacobian pattern. Terms whose blocks are all pinned are kept aside as inactive: they are
  // constants, and they do not count as equations.
  void finalize(const Matrix& positions);

  int dimension() const { return dimension_; }
  int numVertices() const { return num_vertices_; }
  int numBlocks() const { return num_blocks_; }
  // Pinned vertices (pinned auxiliary blocks are not counted).
  int numPinned() const;
  bool isPinned(int block) const { return pinned_[block]; }
  BlockKind blockKind(int block) const { return kind_[static_cast<size_t>(block)]; }
  // The coordinates of a block that are variables: d, 1 for a Scalar, 0 when pinned.
  int freeCoordinatesOf(int block) const;
  int numVariables() const { return num_variables_; }
  // The free coordinates of the vertices: the first numConfigurationVariables() entries of x
  // (vertex blocks come first). The rest are auxiliary (facet normals): not the configuration,
  // so not what a step of a motion is measured on.
  int numConfigurationVariables() const { return num_configuration_variables_; }
  int numEquations() const { return num_equations_; }
  // Index of coordinate k of block b in x, or -1 if the block is pinned.
  int variableIndex(int block, int k) const { return var_index_[block * dimension_ + k]; }

  const std::vector<std::unique_ptr<ConstraintTerm>>& terms() const { return terms_; }
  const std::vector<int>& activeTerms() const { return active_; }
  std::vector<std::string> equationLabels(int index_base) const;
  // The label of one equation, and the vertices of its term (without labelling them all).
  std::string equationLabel(int row, int index_base) const;
  std::vector<int> equationVertices(int row) const;
  // The largest residualScale() of the active terms (1 if there are none).
  double residualScale() const;
  // The largest degree() of the active terms as polynomials; -1 if one of them is not a
  // polynomial (0 when there are none).
  int polynomialDegree() const;
  // An order of the variables that depends on the geometry, not on how the input numbered the
  // vertices: the vertices' coordinates sorted by the start position (in reading order: by
  // the last coordinate, then the one before; ties by number), then the other blocks' in their order. Sparse factorizations use it (with the
  // equations sorted by their variables in that order) so that their fill, their rank evidence
  // and their time do not depend on the order of the input's vertices and terms. Null for
  // small systems (their factorization is a dense SVD). order[i] is the variable placed i-th.
  const std::shared_ptr<const std::vector<int>>& factorizationOrder() const { return factorization_order_; }
  static constexpr int kOrderedAbove = 200;  // variables or equations
  // That order for the block positions p (d x numBlocks).
  std::vector<int> geometricOrder(const Matrix& p) const;
  // The first row of active term i (an index into activeTerms()).
  int rowOffset(int i) const { return row_offset_[static_cast<size_t>(i)]; }

  // Conversions between block positions (d x numBlocks) and free coordinates.
  Vector freeCoordinates(const Matrix& positions) const;
  Matrix positions(const Eigen::Ref<const Vector>& x) const;
  // The first numVertices() columns of positions(x): what is drawn and written.
  Matrix vertexPositions(const Eigen::Ref<const Vector>& x) const { return positions(x).leftCols(num_vertices_); }
  // A velocity field on free coordinates as a d x numBlocks matrix (pinned blocks zero).
  Matrix velocityField(const Eigen::Ref<const Vector>& v) const;

  // Residuals of the active terms (numEquations() values).
  void residuals(const Eigen::Ref<const Vector>& x, Eigen::Ref<Vector> out) const;
  Vector residuals(const Eigen::Ref<const Vector>& x) const;
  // Largest |residual| over every term, inactive ones included, at full block positions.
  double maxResidualAllTerms(const Matrix& positions) const;
  // A numEquations() x numVariables() matrix with the fixed pattern (values unspecified).
  const SparseMatrix& jacobianPattern() const { return pattern_; }
  // Refills the values of J, which must have the pattern of jacobianPattern().
  void jacobian(const Eigen::Ref<const Vector>& x, SparseMatrix& J) const;
  SparseMatrix jacobian(const Eigen::Ref<const Vector>& x) const;
  // out[i] = u^T H_i w over the active equations; u, w are displacements of the free coordinates.
  Vector secondDerivative(const Eigen::Ref<const Vector>& x, const Eigen::Ref<const Vector>& u,
                          const Eigen::Ref<const Vector>& w) const;
  // The spectral norm of each active equation's Hessian over the free coordinates, at x: the
  // largest |u^T H_i u| over unit displacements u. An equation whose `rows` entry is 0 gets 0
  // (not computed); rows == nullptr computes all. A scale for second derivatives that depends on
  // neither the flexes nor the stresses (stress energies are measured against it).
  Vector hessianNorms(const Eigen::Ref<const Vector>& x, const std::vector<char>* rows = nullptr) const;

 private:
  void gather(const ConstraintTerm& t, const Eigen::Ref<const Vector>& x, double* out) const;
  void gatherDisplacement(const ConstraintTerm& t, const Eigen::Ref<const Vector>& v,
                          double* out) const;

  int dimension_;
  int num_vertices_;
  int num_blocks_;
  bool finalized_ = false;
  std::vector<char> pinned_;
  std::vector<BlockKind> kind_;
  std::vector<int> var_index_;  // block*d + k -> variable or -1
  Matrix pinned_positions_;     // d x numBlocks; only pinned columns are meaningful
  int num_variables_ = 0;
  int num_configuration_variables_ = 0;
  int num_equations_ = 0;
  std::vector<std::unique_ptr<ConstraintTerm>> terms_;
  std::vector<int> active_;       // indices into terms_
  std::vector<int> row_offset_;   // per active term
  std::vector<std::vector<int>> value_slot_;  // per active term: local entry -> J value index or -1
  SparseMatrix pattern_;
  std::shared_ptr<const std::vector<int>> factorization_order_;
  int max_local_ = 0;  // largest blocks*d of a term
  int max_rows_ = 0;
};

// J with the rows of a dense matrix (as many columns as J) below it, sparse (zeros dropped): a
// Jacobian with extra scalar equations.
SparseMatrix appendRows(const SparseMatrix& J, const Matrix& rows);

}  // namespace flexure::engine
