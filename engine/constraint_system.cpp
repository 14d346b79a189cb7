#include "engine/constraint_system.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace flexure::engine {

ConstraintSystem::ConstraintSystem(int dimension, int num_vertices, int num_blocks)
    : dimension_(dimension), num_vertices_(num_vertices), num_blocks_(num_blocks),
      pinned_(static_cast<size_t>(num_blocks), 0) {
  if (dimension < 1) throw std::invalid_argument("dimension must be positive");
  if (num_vertices < 0 || num_blocks < num_vertices)
    throw std::invalid_argument("block counts are inconsistent");
  kind_.assign(static_cast<size_t>(num_blocks), BlockKind::Direction);
  std::fill(kind_.begin(), kind_.begin() + num_vertices, BlockKind::Point);
}

int ConstraintSystem::numPinned() const {
  return static_cast<int>(std::count(pinned_.begin(), pinned_.begin() + num_vertices_, 1));
}

void ConstraintSystem::pin(int block) {
  if (finalized_) throw std::logic_error("pin() after finalize()");
  if (block < 0 || block >= num_blocks_) throw std::invalid_argument("pinned block out of range");
  pinned_[block] = 1;
}

void ConstraintSystem::setBlockKind(int block, BlockKind kind) {
  if (finalized_) throw std::logic_error("setBlockKind() after finalize()");
  if (block < num_vertices_ || block >= num_blocks_)
    throw std::invalid_argument("only an auxiliary block (not a vertex) takes a kind");
  if (kind == BlockKind::Point) throw std::invalid_argument("points are the vertex blocks");
  kind_[static_cast<size_t>(block)] = kind;
}

int ConstraintSystem::freeCoordinatesOf(int block) const {
  if (pinned_[block]) return 0;
  return kind_[static_cast<size_t>(block)] == BlockKind::Scalar ? 1 : dimension_;
}

void ConstraintSystem::addTerm(std::unique_ptr<ConstraintTerm> term) {
  if (finalized_) throw std::logic_error("addTerm() after finalize()");
  std::vector<int> b = term->blocks();
  for (int block : b)
    if (block < 0 || block >= num_blocks_)
      throw std::invalid_argument("constraint names a block out of range");
  std::sort(b.begin(), b.end());
  if (std::adjacent_find(b.begin(), b.end()) != b.end())
    throw std::invalid_argument("constraint names the same block twice");
  terms_.push_back(std::move(term));
}

void ConstraintSystem::finalize(const Matrix& positions) {
  if (finalized_) throw std::logic_error("finalize() called twice");
  if (positions.rows() != dimension_ || positions.cols() != num_blocks_)
    throw std::invalid_argument("positions must be d x numBlocks");
  const int d = dimension_;
  pinned_positions_ = positions;
  var_index_.assign(static_cast<size_t>(num_blocks_) * d, -1);
  num_variables_ = 0;
  for (int b = 0; b < num_blocks_; ++b) {
    if (b == num_vertices_) num_configuration_variables_ = num_variables_;
    for (int k = 0; k < freeCoordinatesOf(b); ++k) var_index_[b * d + k] = num_variables_++;
  }
  if (num_blocks_ == num_vertices_) num_configuration_variables_ = num_variables_;

  std::vector<Eigen::Triplet<double>> triplets;
  std::vector<std::vector<long>> entry_ids;
  long next_entry = 0;
  num_equations_ = 0;
  for (int t = 0; t < static_cast<int>(terms_.size()); ++t) {
    const ConstraintTerm& term = *terms_[t];
    bool touches_free = false;
    for (int b : term.blocks()) touches_free |= !pinned_[b];
    if (!touches_free) continue;
    const int rows = term.numResiduals();
    const int cols = static_cast<int>(term.blocks().size()) * d;
    active_.push_back(t);
    row_offset_.push_back(num_equations_);
    std::vector<long> ids(static_cast<size_t>(rows) * cols, -1);
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c) {
        const int var = var_index_[term.blocks()[c / d] * d + c % d];
        if (var < 0) continue;
        ids[r * cols + c] = next_entry;
        triplets.emplace_back(num_equations_ + r, var, static_cast<double>(next_entry));
        ++next_entry;
      }
    entry_ids.push_back(std::move(ids));
    num_equations_ += rows;
    max_local_ = std::max(max_local_, cols);
    max_rows_ = std::max(max_rows_, rows);
  }
  // Build the pattern with the entry number as value, then read back where each entry landed.
  pattern_.resize(num_equations_, num_variables_);
  pattern_.setFromTriplets(triplets.begin(), triplets.end());
  pattern_.makeCompressed();
  std::vector<int> slot_of_entry(static_cast<size_t>(next_entry), -1);
  for (int k = 0; k < pattern_.nonZeros(); ++k)
    slot_of_entry[static_cast<size_t>(pattern_.valuePtr()[k])] = k;
  value_slot_.clear();
  for (const auto& ids : entry_ids) {
    std::vector<int> slots(ids.size(), -1);
    for (size_t i = 0; i < ids.size(); ++i)
      if (ids[i] >= 0) slots[i] = slot_of_entry[static_cast<size_t>(ids[i])];
    value_slot_.push_back(std::move(slots));
  }
  std::fill(pattern_.valuePtr(), pattern_.valuePtr() + pattern_.nonZeros(), 0.0);
  if (std::max(num_variables_, num_equations_) > kOrderedAbove)
    factorization_order_ = std::make_shared<const std::vector<int>>(geometricOrder(pinned_positions_));
  finalized_ = true;
}

std::vector<int> ConstraintSystem::geometricOrder(const Matrix& p) const {
  const int d = dimension_;
  std::vector<int> vertices;
  for (int b = 0; b < num_vertices_; ++b)
    if (!pinned_[b]) vertices.push_back(b);
  const auto key = [&](int k, int b) { return std::isnan(p(k, b)) ? INFINITY : p(k, b); };  // a strict weak order
  // Reading order: by the last coordinate, then the one before... (row by row in the plane; a
  // grid's generator usually writes it so, and AMD's ties then follow the rows).
  std::stable_sort(vertices.begin(), vertices.end(), [&](int a, int b) {
    for (int k = d - 1; k >= 0; --k)
      if (key(k, a) != key(k, b)) return key(k, a) < key(k, b);
    return false;
  });
  std::vector<int> order;
  order.reserve(static_cast<size_t>(num_variables_));
  for (int b : vertices)
    for (int k = 0; k < freeCoordinatesOf(b); ++k) order.push_back(var_index_[b * d + k]);
  for (int v = num_configuration_variables_; v < num_variables_; ++v) order.push_back(v);
  return order;
}

std::vector<std::string> ConstraintSystem::equationLabels(int index_base) const {
  std::vector<std::string> labels;
  for (int t : active_)
    for (int r = 0; r < terms_[t]->numResiduals(); ++r)
      labels.push_back(terms_[t]->label(r, index_base));
  return labels;
}

namespace {
// The active term (index into active) holding equation `row`, and the row within it.
std::pair<size_t, int> termOfRow(const std::vector<int>& row_offset, int row) {
  const auto it = std::upper_bound(row_offset.begin(), row_offset.end(), row);
  const size_t a = static_cast<size_t>(it - row_offset.begin()) - 1;
  return {a, row - row_offset[a]};
}
}  // namespace

std::string ConstraintSystem::equationLabel(int row, int index_base) const {
  const auto [a, r] = termOfRow(row_offset_, row);
  return terms_[static_cast<size_t>(active_[a])]->label(r, index_base);
}

std::vector<int> ConstraintSystem::equationVertices(int row) const {
  std::vector<int> out;
  for (int b : terms_[static_cast<size_t>(active_[termOfRow(row_offset_, row).first])]->blocks())
    if (b < num_vertices_) out.push_back(b);
  return out;
}

double ConstraintSystem::residualScale() const {
  double scale = 0.0;
  for (int t : active_) scale = std::max(scale, terms_[t]->residualScale());
  return scale > 0 ? scale : 1.0;
}

int ConstraintSystem::polynomialDegree() const {
  int degree = 0;
  for (int t : active_) {
    const int k = terms_[t]->degree(dimension_);
    if (k < 0) return -1;
    degree = std::max(degree, k);
  }
  return degree;
}

Vector ConstraintSystem::freeCoordinates(const Matrix& positions) const {
  Vector x(num_variables_);
  for (int b = 0; b < num_blocks_; ++b)
    for (int k = 0; k < dimension_; ++k) {
      const int v = variableIndex(b, k);
      if (v >= 0) x[v] = positions(k, b);
    }
  return x;
}

Matrix ConstraintSystem::positions(const Eigen::Ref<const Vector>& x) const {
  Matrix p = pinned_positions_;
  for (int b = 0; b < num_blocks_; ++b)
    for (int k = 0; k < dimension_; ++k) {
      const int v = variableIndex(b, k);
      if (v >= 0) p(k, b) = x[v];
    }
  return p;
}

Matrix ConstraintSystem::velocityField(const Eigen::Ref<const Vector>& v) const {
  Matrix f = Matrix::Zero(dimension_, num_blocks_);
  for (int b = 0; b < num_blocks_; ++b)
    for (int k = 0; k < dimension_; ++k) {
      const int i = variableIndex(b, k);
      if (i >= 0) f(k, b) = v[i];
    }
  return f;
}

void ConstraintSystem::gather(const ConstraintTerm& t, const Eigen::Ref<const Vector>& x,
                              double* out) const {
  const int d = dimension_;
  int c = 0;
  for (int b : t.blocks())
    for (int k = 0; k < d; ++k, ++c) {
      const int v = var_index_[b * d + k];
      out[c] = v >= 0 ? x[v] : pinned_positions_(k, b);
    }
}

void ConstraintSystem::gatherDisplacement(const ConstraintTerm& t,
                                          const Eigen::Ref<const Vector>& v, double* out) const {
  const int d = dimension_;
  int c = 0;
  for (int b : t.blocks())
    for (int k = 0; k < d; ++k, ++c) {
      const int i = var_index_[b * d + k];
      out[c] = i >= 0 ? v[i] : 0.0;
    }
}

void ConstraintSystem::residuals(const Eigen::Ref<const Vector>& x, Eigen::Ref<Vector> out) const {
  std::vector<double> local(static_cast<size_t>(max_local_));
  for (size_t i = 0; i < active_.size(); ++i) {
    const ConstraintTerm& t = *terms_[active_[i]];
    gather(t, x, local.data());
    t.evaluate(local.data(), dimension_, out.data() + row_offset_[i], nullptr);
  }
}

Vector ConstraintSystem::residuals(const Eigen::Ref<const Vector>& x) const {
  Vector r(num_equations_);
  residuals(x, r);
  return r;
}

double ConstraintSystem::maxResidualAllTerms(const Matrix& positions) const {
  double worst = 0.0;
  std::vector<double> local(static_cast<size_t>(max_local_ > 0 ? max_local_ : 1));
  for (const auto& t : terms_) {
    local.resize(t->blocks().size() * dimension_);
    int c = 0;
    for (int b : t->blocks())
      for (int k = 0; k < dimension_; ++k) local[c++] = positions(k, b);
    std::vector<double> r(static_cast<size_t>(t->numResiduals()));
    t->evaluate(local.data(), dimension_, r.data(), nullptr);
    for (double v : r) worst = std::max(worst, std::isnan(v) ? INFINITY : std::abs(v));
  }
  return worst;
}

void ConstraintSystem::jacobian(const Eigen::Ref<const Vector>& x, SparseMatrix& J) const {
  std::vector<double> local(static_cast<size_t>(max_local_));
  std::vector<double> res(static_cast<size_t>(max_rows_));
  std::vector<double> jac(static_cast<size_t>(max_rows_) * max_local_);
  double* values = J.valuePtr();
  for (size_t i = 0; i < active_.size(); ++i) {
    const ConstraintTerm& t = *terms_[active_[i]];
    gather(t, x, local.data());
    t.evaluate(local.data(), dimension_, res.data(), jac.data());
    const std::vector<int>& slots = value_slot_[i];
    for (size_t e = 0; e < slots.size(); ++e)
      if (slots[e] >= 0) values[slots[e]] = jac[e];
  }
}

SparseMatrix ConstraintSystem::jacobian(const Eigen::Ref<const Vector>& x) const {
  SparseMatrix J = pattern_;
  jacobian(x, J);
  return J;
}

Vector ConstraintSystem::secondDerivative(const Eigen::Ref<const Vector>& x,
                                          const Eigen::Ref<const Vector>& u,
                                          const Eigen::Ref<const Vector>& w) const {
  Vector out(num_equations_);
  std::vector<double> lx(static_cast<size_t>(max_local_)), lu(lx.size()), lw(lx.size());
  for (size_t i = 0; i < active_.size(); ++i) {
    const ConstraintTerm& t = *terms_[active_[i]];
    gather(t, x, lx.data());
    gatherDisplacement(t, u, lu.data());
    gatherDisplacement(t, w, lw.data());
    t.secondDerivative(lx.data(), lu.data(), lw.data(), dimension_, out.data() + row_offset_[i]);
  }
  return out;
}

Vector ConstraintSystem::hessianNorms(const Eigen::Ref<const Vector>& x, const std::vector<char>* rows) const {
  Vector out = Vector::Zero(num_equations_);
  const int d = dimension_;
  std::vector<double> lx(static_cast<size_t>(max_local_)), eu(lx.size()), ew(lx.size()), h(static_cast<size_t>(max_rows_));
  for (size_t i = 0; i < active_.size(); ++i) {
    const ConstraintTerm& t = *terms_[active_[i]];
    const int nr = t.numResiduals(), row = row_offset_[i];
    bool wanted = !rows;
    for (int r = 0; r < nr && !wanted; ++r) wanted = (*rows)[static_cast<size_t>(row + r)] != 0;
    if (!wanted) continue;
    // The free local coordinates: a pinned block's coordinates are constants.
    std::vector<int> free;
    for (size_t c = 0; c < t.blocks().size() * static_cast<size_t>(d); ++c)
      if (var_index_[static_cast<size_t>(t.blocks()[c / static_cast<size_t>(d)]) * d + c % static_cast<size_t>(d)] >= 0)
        free.push_back(static_cast<int>(c));
    const int n = static_cast<int>(free.size());
    gather(t, x, lx.data());
    std::vector<Matrix> H(static_cast<size_t>(nr), Matrix::Zero(n, n));
    std::fill(eu.begin(), eu.end(), 0.0);
    std::fill(ew.begin(), ew.end(), 0.0);
    for (int a = 0; a < n; ++a) {
      eu[static_cast<size_t>(free[a])] = 1.0;
      for (int b = a; b < n; ++b) {
        ew[static_cast<size_t>(free[b])] = 1.0;
        t.secondDerivative(lx.data(), eu.data(), ew.data(), d, h.data());
        for (int r = 0; r < nr; ++r) H[static_cast<size_t>(r)](a, b) = H[static_cast<size_t>(r)](b, a) = h[static_cast<size_t>(r)];
        ew[static_cast<size_t>(free[b])] = 0.0;
      }
      eu[static_cast<size_t>(free[a])] = 0.0;
    }
    for (int r = 0; r < nr; ++r)
      if (n > 0)
        out[row + r] = Eigen::SelfAdjointEigenSolver<Matrix>(H[static_cast<size_t>(r)], Eigen::EigenvaluesOnly)
                           .eigenvalues()
                           .cwiseAbs()
                           .maxCoeff();
  }
  return out;
}

SparseMatrix appendRows(const SparseMatrix& J, const Matrix& rows) {
  if (rows.cols() != J.cols()) throw std::invalid_argument("appended rows need as many columns as the Jacobian");
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(static_cast<size_t>(J.nonZeros() + rows.size()));
  for (int c = 0; c < J.outerSize(); ++c)
    for (SparseMatrix::InnerIterator it(J, c); it; ++it) t.emplace_back(it.row(), it.col(), it.value());
  for (Eigen::Index r = 0; r < rows.rows(); ++r)
    for (Eigen::Index c = 0; c < rows.cols(); ++c)
      if (rows(r, c) != 0) t.emplace_back(static_cast<int>(J.rows() + r), static_cast<int>(c), rows(r, c));
  SparseMatrix out(J.rows() + rows.rows(), J.cols());
  out.setFromTriplets(t.begin(), t.end());
  return out;
}

}  // namespace flexure::engine
