// A constraint system evaluated in any arithmetic T through the one term list: each term's
// formula (residual<T>, engine/terms.h) reached by the visitor of engine/term_list.h, its
// derivatives from Dual<T> and HyperDual<T> (engine/jet.h). This is the seam for exact rationals and
// intervals; the double fast path (ConstraintSystem::residuals, ::jacobian) stays separate and
// tests compare the two. Values here carry no row weight (ConstraintTerm::rowWeight()).
#pragma once

#include <vector>

#include "engine/constraint_system.h"
#include "engine/jet.h"
#include "engine/terms.h"

namespace flexure::engine {

namespace evaluate_detail {

// Calls term.residual<T>(x, d, r) on the concrete term.
template <class T>
class ResidualVisitor final : public TermVisitor {
 public:
  ResidualVisitor(const T* x0, const T* x, int d, T* r) : x0_(x0), x_(x), d_(d), r_(r) {}
#define FLEXURE_RESIDUAL_IN(Term) \
  void visit(const Term& term) override { term.template residual<T>(x0_, x_, d_, r_); }
  FLEXURE_TERMS(FLEXURE_RESIDUAL_IN)
#undef FLEXURE_RESIDUAL_IN

 private:
  const T* x0_;
  const T* x_;
  int d_;
  T* r_;
};

}  // namespace evaluate_detail

// The term's residuals at its local coordinates x (blocks().size() * d values), in T, with x0
// the same coordinates at the start (where the parameters the start decides come from).
template <class T>
void termResidual(const ConstraintTerm& term, const T* x0, const T* x, int d, T* r) {
  evaluate_detail::ResidualVisitor<T> visitor(x0, x, d, r);
  term.accept(visitor);
}

// The term's row-major numResiduals() x (blocks * d) local Jacobian at x, in T, one column per
// evaluation in Dual<T>.
// The work vectors are the thread's, and values are assigned into them, not constructed: in GMP
// rationals every construction is an allocation (the exact mode's Jacobian of the 30x30 grid
// spent most of its time in malloc).
template <class T>
void termJacobian(const ConstraintTerm& term, const T* x0, const T* x, int d, T* jacobian) {
  const int n = static_cast<int>(term.blocks().size()) * d, rows = term.numResiduals();
  thread_local std::vector<Dual<T>> h0, h, r;
  if (h0.size() < static_cast<size_t>(n)) h0.resize(static_cast<size_t>(n)), h.resize(static_cast<size_t>(n));
  if (r.size() < static_cast<size_t>(rows)) r.resize(static_cast<size_t>(rows));
  for (int i = 0; i < n; ++i) {
    const size_t k = static_cast<size_t>(i);
    h0[k].v = x0[i], h0[k].a = 0;
    h[k].v = x[i], h[k].a = 0;
  }
  for (int j = 0; j < n; ++j) {
    h[static_cast<size_t>(j)].a = T(1);
    termResidual(term, h0.data(), h.data(), d, r.data());
    h[static_cast<size_t>(j)].a = T(0);
    for (int i = 0; i < rows; ++i) jacobian[i * n + j] = r[static_cast<size_t>(i)].a;
  }
}

// out[i] = u^T H_i w for the Hessian H_i of residual i at x, in T (one evaluation).
template <class T>
void termSecondDerivative(const ConstraintTerm& term, const T* x0, const T* x, const T* u, const T* w, int d,
                          T* out) {
  const int n = static_cast<int>(term.blocks().size()) * d, rows = term.numResiduals();
  std::vector<HyperDual<T>> h0(static_cast<size_t>(n)), h(static_cast<size_t>(n)), r(static_cast<size_t>(rows));
  for (int i = 0; i < n; ++i) h0[static_cast<size_t>(i)] = HyperDual<T>(x0[i]), h[static_cast<size_t>(i)] = HyperDual<T>(x[i], u[i], w[i], T(0));
  termResidual(term, h0.data(), h.data(), d, r.data());
  for (int i = 0; i < rows; ++i) out[i] = r[static_cast<size_t>(i)].ab;
}

// One entry of a Jacobian in T: row (equation), column (free variable), value.
template <class T>
struct JacobianEntry {
  int row, column;
  T value;
};

// The active equations of a finalized system at full block positions in T (block-major: d
// values per block, numBlocks() blocks; pinned blocks at their pinned values), with `start` the
// start configuration in the same layout (where the parameters the start decides come from):
// the residuals (numEquations() values, without row weights) and, if `jacobian` is given, the
// Jacobian over the free variables (entries in row order, in each row by the term's local
// order; an entry whose value is zero in T is kept where the pattern has it).
template <class T>
std::vector<T> evaluateSystemIn(const ConstraintSystem& system, const std::vector<T>& start,
                                const std::vector<T>& positions, std::vector<JacobianEntry<T>>* jacobian = nullptr) {
  const int d = system.dimension();
  std::vector<T> residuals(static_cast<size_t>(system.numEquations()));
  std::vector<T> local0, local, jac;
  if (jacobian) jacobian->clear();
  const std::vector<int>& active = system.activeTerms();
  for (size_t i = 0; i < active.size(); ++i) {
    const ConstraintTerm& t = *system.terms()[static_cast<size_t>(active[i])];
    const int n = static_cast<int>(t.blocks().size()) * d, rows = t.numResiduals();
    local0.resize(static_cast<size_t>(n));
    local.resize(static_cast<size_t>(n));
    int c = 0;
    for (int b : t.blocks())
      for (int k = 0; k < d; ++k, ++c) {
        local0[static_cast<size_t>(c)] = start[static_cast<size_t>(b * d + k)];
        local[static_cast<size_t>(c)] = positions[static_cast<size_t>(b * d + k)];
      }
    const int row0 = system.rowOffset(static_cast<int>(i));
    termResidual(t, local0.data(), local.data(), d, residuals.data() + row0);
    if (!jacobian) continue;
    jac.assign(static_cast<size_t>(rows * n), T(0));
    termJacobian(t, local0.data(), local.data(), d, jac.data());
    for (int r = 0; r < rows; ++r) {
      c = 0;
      for (int b : t.blocks())
        for (int k = 0; k < d; ++k, ++c) {
          const int v = system.variableIndex(b, k);
          if (v >= 0) jacobian->push_back({row0 + r, v, jac[static_cast<size_t>(r * n + c)]});
        }
    }
  }
  return residuals;
}

}  // namespace flexure::engine
