// The exact mode of the rigidity analysis (issue 44, SPEC section 5): at a start whose
// coordinates are rationals, the rank of the rigidity matrix, the infinitesimal flexes, the
// trivial ones, the equilibrium stresses and, for quadratic systems, prestress stability,
// computed in exact rational arithmetic through the same term formulas as the double analysis
// (engine/evaluate_in.h), so that special positions floating point cannot see are decided.
#pragma once

#include <optional>
#include <stdexcept>
#include <string>

#include "engine/exact/rational.h"
#include "engine/model.h"
#include "engine/rigidity.h"

namespace flexure::engine::exact {

// A model or start the exact mode cannot take, with the reason (irrational data, a symmetry
// group known only numerically, a non-polynomial term, a start that is not an exact solution).
class Refusal : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

struct ExactAnalysis {
  int variables = 0, equations = 0, rank = 0, inf_flexes = 0, trivial = 0, nontrivial = 0, stresses = 0;
  bool inf_rigid = false;
  std::optional<bool> prestress_stable;  // proved either way; unset: not decided exactly
  std::optional<bool> flexible;          // proved either way; unset: not decided exactly
  std::string note;                      // how the second-order question was decided (or why not)
  // Bases when they were formed (second-order step): N x nontrivial (orthogonal to the trivial
  // flexes) and m x stresses (equations without their double row weights), integer entries.
  RationalMatrix flex_basis, stress_basis;
  RationalMatrix blocking_stress;        // m x 1 when prestress stability was proved
  double seconds = 0;                    // CPU time of the exact analysis
  // The estimate made before the eliminations (engine/exact/exact_cost.h): CPU seconds, bytes.
  double estimated_seconds = 0, estimated_bytes = 0;
};

struct ExactOptions {
  int index_base = 1;                  // vertex numbers in messages
  // The bases (dense integer null spaces of N x N and m x m) and the second-order step are
  // formed up to these sizes; beyond them the counts are exact and the rest is not decided.
  int max_basis_size = 4000;
  int max_second_order_size = 30;      // nontrivial flexes and stresses
  // A rank that the modular lower bound does not settle needs a dense rational elimination of
  // at most this many entries (variables x equations).
  double max_dense_entries = 5e7;
  // The work is estimated before it starts (engine/exact/exact_cost.h) and refused with a
  // ResourceError when it would take more than this many CPU seconds or more memory than the
  // process can have ([analysis] exact_budget).
  double budget_seconds = 60;
};

// The exact analysis at `points` (d x numVertices, rationals: the scene's vertices). Throws
// Refusal with the reason when the model cannot be analysed exactly. `numeric`, the double
// analysis of the same start, supplies candidate stresses and flexes that are then checked
// exactly (nothing it says is taken without proof).
ExactAnalysis analyzeExact(const Model& model, const RationalMatrix& points, const RigidityReport* numeric,
                           const ExactOptions& options = {});

// A basis of the trivial flexes (free coordinates x t) at the block positions `pos`
// (block-major, rationals): the symmetry group's generators that fix the pinned blocks, on the
// free coordinates. Refusal when the model's group is only known numerically.
RationalMatrix trivialFlexBasis(const Model& model, const std::vector<Rational>& pos);

// The model's start vertices as rationals when only their doubles are known: each the shortest
// decimal that reads back as it (a decimal written with at most 15 significant digits).
RationalMatrix pointsFromDoubles(const Model& model);

// The double report with the exact analysis's counts, decisions and certificate; where they
// differ from the floating-point counts (a special position), the bases are the exact ones and
// the verdict is only what the exact analysis proves.
void applyExact(RigidityReport& rep, const ExactAnalysis& exact);

}  // namespace flexure::engine::exact
