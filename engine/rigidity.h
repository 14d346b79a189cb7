// First-order rigidity analysis at a configuration (paper section 2 and appendix A):
// rank of the Jacobian (rigidity matrix), infinitesimal flexes, the trivial ones among them,
// a canonical orthonormal basis of the nontrivial flexes, equilibrium stresses, and the
// second-order certificates that follow exactly from them.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <limits>
#include <vector>

#include "engine/flex_space.h"
#include "engine/model.h"

namespace flexure::engine {

struct RigidityOptions {
  // A singular value sigma of the Jacobian counts as nonzero when
  // sigma > rank_tolerance * sigma_max (sigma_max = the largest singular value).
  double rank_tolerance = 1e-9;
  // Dense SVD when max(equations, variables) <= dense_limit; sparse QR otherwise.
  int dense_limit = 500;
  // With sparse QR, the stress basis costs a second factorization; it is formed only for at
  // most this many stresses.
  int max_sparse_stress_basis = 500;
  // The flex and stress bases are formed only when they have at most this many entries
  // (their dimensions are always reported).
  long max_basis_entries = 20'000'000;
  // Bases are put in canonical form (canonicalBasis) when that costs at most this many flops;
  // a larger stress basis is not reported, a larger flex basis is reported as computed.
  double max_canonical_work = 4e9;
  // Second-order certificates are computed when the flex and stress counts are at most this.
  int max_second_order_size = 60;
  // The stress-energy forms are relative to the largest energy a unit stress can give a unit
  // displacement (see stressEnergyForms); a form counts as definite beyond this, and a flex as
  // unblocked when every form is below it.
  double form_tolerance = 1e-8;
  // The blocked-flex homotopy (3^k paths for k flexes) runs for at most this many flexes.
  int max_homotopy_flexes = 6;
  // The homotopy's random start system and perturbation, and the motion check's tracker.
  std::uint64_t seed = 1;
  // When nothing is proved, a path of this many steps along the auto flex is tracked and
  // "flexible" reported if it leaves the congruence class (0: no check).
  int motion_check_steps = 8;
  // A "rigid" from second-order theory: this many corrected steps along each nontrivial flex
  // and the auto flex, which must stay in the trivial orbit (0: no check).
  int second_order_check_steps = 4;
  // Only the counts (rank, flexes, trivial motions, stresses, inf_rigid): no bases, no second
  // order, no motion check (a sweep that asks for nothing else). The verdict is then "rigid" when
  // infinitesimally rigid, "unknown" otherwise.
  bool counts_only = false;
};

enum class Verdict { Rigid, Flexible, Unknown };
const char* toString(Verdict v);

struct RigidityReport {
  int variables = 0;
  int equations = 0;
  int rank = 0;
  int inf_flexes = 0;         // dim ker J
  int trivial = 0;            // dim of the trivial flexes (symmetries fixing the pins)
  int nontrivial = 0;         // inf_flexes - trivial
  int stresses = 0;           // dim coker J = equations - rank
  bool inf_rigid = false;
  std::optional<bool> prestress_stable;    // unset: not decided by this analysis
  std::optional<bool> second_order_rigid;  // unset: not decided by this analysis
  Verdict rigid = Verdict::Unknown;
  std::string reason;         // why `rigid` is what it is, one sentence

  // The initial direction for flex = "auto" (coefficients in flex_basis, unit length), and how
  // it was chosen: with no stress every flex extends, so the equal combination; with stresses
  // a flex that no stress blocks (paper 4.4), the one closest to the equal combination, when
  // there is one; otherwise the equal combination.
  Vector auto_flex;
  std::string auto_flex_note;

  // Second-order details. stress_margin: prestress stable: the smallest eigenvalue of the
  // blocking stress's energy on the flexes (relative, stress of unit length); otherwise an
  // upper bound of it over all stresses. NaN when not computed.
  double stress_margin = std::numeric_limits<double>::quiet_NaN();
  Vector blocking_stress;             // prestress stable: the stress (equation space, unit)
  int homotopy_paths = 0;             // paths of the blocked-flex homotopy (0: not run)
  std::string blocked_flex_note;      // how the blocked-flex question was decided
  double motion_check_change = std::numeric_limits<double>::quiet_NaN();  // relative, NaN: not run
  // A "rigid" from second-order theory is checked by moving: a few corrected steps along each
  // nontrivial basis flex (both ways) and the auto flex. A move that leaves the trivial orbit at
  // rounding-level residual contradicts the certificate: the verdict is then "flexible" and
  // `contradiction` says what happened (empty: none; it must never happen).
  int second_order_moves = 0;         // directions tried (0: not run)
  std::string contradiction;

  // Numerics of the rank decision.
  std::string method;                 // "dense SVD" or "sparse QR"
  double tolerance = 0;               // the absolute threshold that was used
  double sigma_max = 0;               // largest singular value (|R_ii| estimate for sparse QR)
  double sigma_smallest_kept = 0;     // smallest value counted as nonzero (0 if rank 0)
  double sigma_largest_dropped = 0;   // largest value counted as zero (0 if none)
  std::vector<std::string> warnings;

  // The exact mode (engine/exact/exact_rigidity.h): the counts and decisions above were
  // computed in rational arithmetic. `certificate` (exact mode, or analyze --certify in interval
  // arithmetic: engine/interval/certify.h) says what is proved (true or false: proved; unset:
  // not proved either way), with the reason.
  bool exact = false;
  struct Certificate {
    std::optional<bool> inf_rigid, flexible, prestress_stable;
    std::string reason;
    // analyze --certify: a proved lower bound of the rigidity matrix's smallest singular value
    // on the complement of the trivial flexes (NaN: none).
    double sigma_lower_bound = std::numeric_limits<double>::quiet_NaN();
    // Whether this proves `verdict`: rigid by infinitesimal rigidity or prestress stability,
    // flexible by a proved flexibility.
    bool proves(Verdict verdict) const {
      return verdict == Verdict::Rigid ? (inf_rigid == true || prestress_stable == true)
                                       : verdict == Verdict::Flexible && flexible == true;
    }
  };
  std::optional<Certificate> certificate;

  // Bases (free-coordinate space for flexes, equation space for stresses), orthonormal columns.
  Matrix trivial_basis;               // N x trivial
  Matrix flex_basis;                  // N x nontrivial, canonical (see canonicalBasis)
  Matrix stress_basis;                // m x stresses, canonical
  bool flex_basis_computed = false;
  bool stress_basis_computed = false;
};

RigidityReport analyzeRigidity(const Model& model, const Vector& x,
                               const RigidityOptions& options = {});

}  // namespace flexure::engine
