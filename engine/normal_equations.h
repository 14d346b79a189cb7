// Damped, bordered normal equations of a sparse Jacobian, factored by a sparse LDL^T and kept:
// the steps of the corrector (gauge coordinates, or a damping; engine/corrector.cpp) and the
// chord steps of a drag's move (a damping; engine/drag.cpp).
#pragma once

#include <vector>

#include <Eigen/SparseCholesky>
#include <iostream>  // Eigen's MetisSupport reports METIS's errors on std::cerr without including it
#include <Eigen/MetisSupport>

#include "engine/constraint_system.h"

namespace flexure::engine {

// The normal matrix of J: M = J^T J + mu I + E E^T + F F^T, with mu = damping times the largest
// diagonal entry of J^T J (the largest squared column norm of J; no term when damping is 0), E
// the identity columns of the gauge coordinates and F those of the lift coordinates. Each
// caller passes its own damping (use()).
//
// As the corrector's: argmin || [J; E^T] d - [b; 0] ||, E the identity columns of the gauge
// coordinates: [J; E^T] has full column rank, so this is the solution of the normal equations
// (J^T J + E E^T) d = J^T b, a sparse positive definite system whose Cholesky pattern is
// analysed once per correction (the sparse Gauss-Newton of Ceres' SPARSE_NORMAL_CHOLESKY).
// When the factorization breaks down (the bordered system is nearly singular, close to a
// singularity of the path) it falls back to SuiteSparseQR of [J; E^T].
// Without `refactor`, the last factorization serves again (a chord step: the normal matrix of
// an earlier iterate, or of an earlier correction, the right-hand side J^T b of this one; damped,
// J0^T b with J0 the factored iterate's Jacobian, see solve), a
// descent direction all the same.
// Kept across corrections (the tracker's), the pattern is ordered by METIS's nested dissection:
// its analysis costs 5 times AMD's (0.25 s against 0.05 s at 10^5 variables) but it serves as
// long as the gauge and damping do (the tracker's damping: the whole path), and its factor
// fills less: a factorization of the 224 x 224 grids'
// normal matrix takes 0.34 s instead of 0.57 s (111 flexes) and 0.25 s instead of 0.35 s (2).
// A correction of its own (edge contraction, drives, drags) analyses at every correction and
// keeps AMD, whose analysis is the cheaper one there (0.002 s against 0.010 s at 7,200).
class NormalEquations {
 public:
  explicit NormalEquations(bool nested_dissection = false) : nested_dissection_(nested_dissection) {}

  // Keeps the factorization only while the gauge and lift coordinates and the damping stay
  // the same.
  void use(const std::vector<int>& gauge, const std::vector<int>& lift, double damping);
  bool factored() const { return factored_; }

  // Forms the normal matrix at J and factors it (the pattern analysed once while use() keeps
  // it); returns factored().
  bool factor(const SparseMatrix& J);

  // Damped: the factored system's solution for the right-hand side J0^T b, J0 the factored
  // Jacobian, as is (no check of its backward error; the caller's iteration tests the
  // residual): the chord steps of a drag's move.
  Vector solveFactored(const Vector& b);

  Vector solve(const SparseMatrix& J, const Vector& b, bool refactor, bool by_qr = false) {
    return solve(J, b, Matrix(0, J.cols()), Vector(), refactor, by_qr);
  }

  // With dense rows U^T (k x N) below J and their right-hand side c: the normal equations are
  // (A + U U^T - F F^T) d = J^T b + U c with A = J^T J + E E^T + F F^T, sparse and nonsingular
  // (E the gauge's and F the lift's identity columns), solved by Woodbury's identity on A's
  // factorization: a row touching every vertex (a fold percentage) does not fill its factor.
  // by_qr: SuiteSparseQR of [J; E^T; rows] directly (a step of the normal equations failed).
  Vector solve(const SparseMatrix& J, const Vector& b, const Matrix& rows, const Vector& c, bool refactor,
               bool by_qr = false);

 private:
  // f applied to the factorization in use (the two differ in their ordering's type only).
  template <class F>
  auto withLdlt(F&& f) {
    return nested_dissection_ ? f(nd_) : f(ldlt_);
  }
  // The factored solution with dense rows and the lift taken out by Woodbury's identity, if
  // its backward error is small; nothing otherwise.
  bool solveWoodbury(const Matrix& rows, const Vector& rhs, Vector& d);
  Vector leastSquares(const SparseMatrix& J, const Vector& b, const Matrix& rows, const Vector& c) const;
  Vector leastSquaresQR(const SparseMatrix& J, const Vector& b) const;
  // The absolute damping: damping_ times the largest diagonal entry of J^T J (the largest
  // squared column norm of J), for the normal equations and their QR alike.
  double mu(const SparseMatrix& J) const;

  std::vector<int> gauge_, lift_;
  double damping_ = 0.0;  // relative to the largest diagonal entry of J^T J
  SparseMatrix Jt_, M_;    // J^T and the normal matrix of the factored iterate
  bool nested_dissection_;
  Eigen::SimplicialLDLT<SparseMatrix> ldlt_;
  Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower, Eigen::MetisOrdering<int>> nd_;
  bool analysed_ = false, factored_ = false;
};

}  // namespace flexure::engine
