// Second-order rigidity and prestress stability from the stress-energy forms (paper sections
// 2.1 and 4.4). With a basis p_1..p_k of the nontrivial flexes and w_1..w_s of the stresses,
// the forms are M_i(a, b) = w_i^T R(p_a) p_b, and Q_i(l) = l^T M_i l.
//
// - Prestress stable: some combination sum c_i M_i is positive definite. Decided by maximising
//   the smallest eigenvalue of sum c_i M_i over |c| <= 1 (a concave function of c, so a small
//   semidefinite program), solved by a log-barrier interior-point method.
// - Second-order rigid: no real l != 0 with Q_1(l) = .. = Q_s(l) = 0. Decided through the
//   minimum of f(l) = sum Q_i(l)^2 on the unit sphere. First a certificate that it is positive:
//   the largest g with f(l) - g |l|^4 a sum of squares of quadratic forms (a semidefinite
//   program; g > 0 proves every flex blocked). Then all critical points of f on the sphere by
//   homotopy continuation, as the eigenvectors of its gradient (grad f(l) = l, k cubics, 3^k
//   paths), after a generic positive quartic perturbation f + eps sum_j (l^T R_j l)^2 that makes
//   every critical point isolated and nonsingular. The global minimum of the perturbed function
//   is among its real critical points, so if every path was tracked, min f >= min f_eps - eps k;
//   when that is positive no real zero exists. Else the lowest critical points are refined by
//   Gauss-Newton onto Q = 0, |l| = 1, which gives a flex that no stress blocks.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "engine/constraint_system.h"

namespace flexure::engine {

// The forms, divided by the largest value a unit stress's energy can take on a unit
// displacement (sum_i |w_i| |H_i|, the spectral norms of the equations' Hessians; `scale`
// returns it): entries are at most 1 in size for orthonormal flexes, and a form that vanishes
// on the flexes is zero to rounding, whatever the flexes' own second derivatives are.
std::vector<Matrix> stressEnergyForms(const ConstraintSystem& sys, const Vector& x, const Matrix& flexes,
                                      const Matrix& stresses, double* scale = nullptr);

struct PrestressResult {
  bool stable = false;
  // The best combination found (unit length) and the smallest eigenvalue of sum c_i M_i there.
  Vector coefficients;
  double margin = 0;
  // An upper bound of that smallest eigenvalue over all unit c (from the barrier's duality gap).
  double upper_bound = 0;
  int newton_steps = 0;
};

// `tolerance`: a combination counts as positive definite when its smallest eigenvalue exceeds
// this (the forms being normalised as above).
PrestressResult maximizeStressMargin(const std::vector<Matrix>& forms, double tolerance = 1e-8);

struct BlockedFlexOptions {
  std::uint64_t seed = 1;
  int max_flexes = 6;           // the homotopy has 3^k paths; beyond this: undecided
  int max_sos_flexes = 8;       // the sum-of-squares bound is an SDP of size k (k + 1) / 2
  double zero_tolerance = 1e-10;  // max |Q_i(l)| (normalised forms, |l| = 1) of an unblocked flex
};

struct BlockedFlexResult {
  enum class Outcome { AllBlocked, Unblocked, Undecided };
  Outcome outcome = Outcome::Undecided;
  Vector flex;                  // Unblocked: unit coefficients with every Q_i(flex) ~ 0
  double residual = 0;          // max |Q_i(flex)|
  // AllBlocked: a lower bound of the minimum over the unit sphere of sum_j Q_j^2, for an
  // orthonormal basis (Frobenius) of the span of the forms.
  double lower_bound = 0;
  int paths = 0;                // homotopy paths tracked, summed over attempts
  int failed_paths = 0;
  int real_critical_points = 0;
  std::string note;             // how it was decided, one sentence
};

// `target`: among several unblocked flexes found, the one closest to it (up to sign) is returned.
BlockedFlexResult findUnblockedFlex(const std::vector<Matrix>& forms, const Vector& target,
                                    const BlockedFlexOptions& options = {});

}  // namespace flexure::engine
