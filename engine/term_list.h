// The one list of constraint terms (engine/terms.h). Every evaluator that is not the double fast
// path visits a term through it: the finite-difference tests, the evaluation in another
// arithmetic (engine/evaluate_in.h) and, through them, the exact and interval back ends. A new
// term is added here once; ConstraintTerm::accept is pure virtual and TermVisitor has a visit
// for each entry, so a term missing from the list does not compile.
#pragma once

#define FLEXURE_TERMS(X)   \
  X(SquaredDistanceTerm)   \
  X(FacetPlaneTerm)        \
  X(UnitNormTerm)          \
  X(AffineCombinationTerm) \
  X(FramePointTerm)        \
  X(SimplexVolumeTerm)     \
  X(AngleTerm)             \
  X(InversiveDistanceTerm) \
  X(SurfaceTerm)

namespace flexure::engine {

#define FLEXURE_DECLARE_TERM(Term) class Term;
FLEXURE_TERMS(FLEXURE_DECLARE_TERM)
#undef FLEXURE_DECLARE_TERM

// Double dispatch on the concrete term: one visit per entry of FLEXURE_TERMS.
class TermVisitor {
 public:
  virtual ~TermVisitor() = default;
#define FLEXURE_VISIT_TERM(Term) virtual void visit(const Term& term) = 0;
  FLEXURE_TERMS(FLEXURE_VISIT_TERM)
#undef FLEXURE_VISIT_TERM
};

}  // namespace flexure::engine
