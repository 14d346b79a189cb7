// Direct manipulation: a vertex pulled towards a target, the rest of the system following on
// its constraint set (paper sections 3-4: each move is the wanted displacement projected onto
// the tangent space, then the corrector), and the tangent cone at a singular point: the
// directions of the branches that meet there, from the second-order equations on the kernel.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "engine/corrector.h"
#include "engine/model.h"

namespace flexure::engine {

struct TangentConeOptions {
  // Singular values below loose_tolerance * sigma_max count as zero: at a sample near (not on)
  // a singular point the kernel of the singular point is still seen.
  double loose_tolerance = 1e-3;
  int starts = 48;          // seeded starting points of the search for each direction
  std::uint64_t seed = 1;
  // Each direction b is kept only if the corrector, asked for a point at distance
  // probe * extent from x in direction b (on a sphere about x), finds one whose secant makes
  // an angle below acos(min_cos) with b: the branch is there, not just in the equations.
  double probe = 2e-3;
  double min_cos = 0.95;
  int dense_limit = 1200;   // more free coordinates: not computed (a dense SVD is needed)
  CorrectorOptions corrector;
};

struct TangentCone {
  bool computed = false;       // false: the system is too large (note says so)
  int kernel_dimension = 0;    // nontrivial flexes at loose tolerance
  int stresses = 0;            // the cokernel at loose tolerance
  double sigma_ratio = 0;      // smallest nonzero singular value counted as zero / sigma_max
  // Unit directions (free coordinates), one per half-branch leaving x: b and -b are listed
  // separately, each verified by a step. A smooth point with one flex has two.
  std::vector<Vector> directions;
  // Per direction: the point on its branch where the check landed (about probe * extent away):
  // two arms that leave a cusp along one tangent are told apart by it.
  std::vector<Vector> landings;
  bool branched = false;       // found from second-order equations (branches that cross)
  std::string note;            // how the directions were found
};

// The tangent cone of the constraint set at x, modulo trivial motions.
TangentCone tangentCone(const Model& model, const Vector& x, const TangentConeOptions& options = {});

// A point of the constraint set at distance h from x (on a sphere about x, so that the
// corrector lands on the branch of `direction` and not on the nearest one) whose secant makes
// an angle below acos(0.8) with `direction`; h halved up to 7 times; nothing when none is found.
std::optional<Vector> branchStep(const ConstraintSystem& system, const Vector& x, const Vector& direction, double h,
                                 const CorrectorOptions& options = {});

// The singular point a path passed near sample `at`, between the samples `before` and `after`:
// on the curve through the three (a quadratic, each point corrected onto the constraint set),
// the point where the Jacobian's r-th singular value relative to its largest is smallest, r
// its rank at the two neighbours (golden-section search, `evaluations` points). `at` itself
// when no point of the curve is more singular, or the corrector fails there. Dense: for
// systems of at most a few hundred free coordinates (TangentConeOptions::dense_limit).
Vector locateSingularPoint(const Model& model, const Vector& before, const Vector& at, const Vector& after,
                           const CorrectorOptions& options = {}, int evaluations = 24);

struct DragOptions {
  // A move takes no vertex further than this fraction of the configuration's extent (near a
  // singular point: the whole move, free coordinates, 2-norm); a longer wish is walked in
  // several moves, at most max_moves (the caller may ask again from where it stopped).
  double max_move = 0.05;
  int max_moves = 60;
  // The vertex has arrived within tolerance (world units; the caller passes e.g. a quarter
  // pixel); it is held when a move would bring it less than held_gain of the way.
  double tolerance = 1e-9;
  double held_gain = 1e-3;
  // A direction in which the vertex moves, per unit of the whole figure's motion, less than
  // this fraction of its easiest direction counts as blocked (first order; a pointer a pixel off
  // the vertex's curve would otherwise swing the figure far to reach it).
  double weak_direction = 0.05;
  // No vertex moves more than this many times the wish's length in one move.
  double swing = 10;
  // Near a singular point (a singular value below singular_ratio * sigma_max that is not
  // zero), the move follows the tangent-cone direction closest to the wish.
  double singular_ratio = 2e-3;
  // The number of nontrivial flexes at a regular point (e.g. at the start of the path): more
  // at x means x is a singular point. Negative: unknown.
  int regular_flexes = -1;
  CorrectorOptions corrector;
  FactorizationOptions factorization;
  TangentConeOptions cone;
};

// An equation that keeps the vertex from its target: its weight in the stress that balances the
// pull (the least-squares solution of J^T w = the wish's row-space part), scaled so that the
// largest is 1 in absolute value.
struct Holding {
  int equation = -1;
  std::string label;
  double weight = 0;
  std::vector<int> vertices;  // the vertices of its term (0-based)
};

struct DragResult {
  Vector x;                  // free coordinates where the drag ended
  double residual = 0;       // ||F(x)||_inf
  double remaining = 0;      // distance from the vertex to the target (world units)
  int moves = 0;
  int branch_choices = 0;    // moves that chose a tangent-cone direction at a singular point
  bool reached = false;
  std::vector<Holding> held;  // when not reached: what holds it (largest weights first)
  std::string stop;          // "reached", "held by the constraints", "move limit", ...
};

// Pulls vertex `vertex` (0-based; not pinned) of the configuration x towards `target`
// (dimension() values). Throws std::invalid_argument for a pinned or unknown vertex.
DragResult dragVertex(const Model& model, const Vector& x, int vertex, const Vector& target,
                      const DragOptions& options = {});

}  // namespace flexure::engine
