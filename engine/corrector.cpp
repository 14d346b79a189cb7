#include "engine/corrector.h"

#include <stdexcept>
#include <string>

#include <Eigen/Dense>
#include <Eigen/SPQRSupport>

#include "engine/sparse_qr.h"
#include <Eigen/SparseCholesky>
#include <iostream>  // Eigen's MetisSupport reports METIS's errors on std::cerr without including it
#include <Eigen/MetisSupport>

#include <cmath>
#include <limits>
#include <optional>

namespace flexure::engine {

const char* toString(CorrectorStatus s) {
  switch (s) {
    case CorrectorStatus::Converged: return "converged";
    case CorrectorStatus::MaxIterations: return "no convergence within the iteration limit";
    case CorrectorStatus::LineSearchFailed: return "the line search found no decrease";
  }
  return "unknown";
}

// argmin || [J; E^T] d - [b; 0] ||, E the identity columns of the gauge coordinates:
// [J; E^T] has full column rank, so this is the solution of the normal equations
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
  // f applied to the factorization in use (the two differ in their ordering's type only).
  template <class F>
  auto withLdlt(F&& f) {
    return nested_dissection_ ? f(nd_) : f(ldlt_);
  }

  // Keeps the factorization only while the gauge and lift coordinates and the damping stay
  // the same.
  void use(const std::vector<int>& gauge, const std::vector<int>& lift, double damping) {
    if (gauge == gauge_ && lift == lift_ && damping == damping_) return;
    gauge_ = gauge;
    lift_ = lift;
    damping_ = damping;
    analysed_ = factored_ = false;
  }
  bool factored() const { return factored_; }

  Vector solve(const SparseMatrix& J, const Vector& b, bool refactor, bool by_qr = false) {
    return solve(J, b, Matrix(0, J.cols()), Vector(), refactor, by_qr);
  }

  // With dense rows U^T (k x N) below J and their right-hand side c: the normal equations are
  // (A + U U^T - F F^T) d = J^T b + U c with A = J^T J + E E^T + F F^T, sparse and nonsingular
  // (E the gauge's and F the lift's identity columns), solved by Woodbury's identity on A's
  // factorization: a row touching every vertex (a fold percentage) does not fill its factor.
  // by_qr: SuiteSparseQR of [J; E^T; rows] directly (a step of the normal equations failed).
  Vector solve(const SparseMatrix& J, const Vector& b, const Matrix& rows, const Vector& c, bool refactor,
               bool by_qr = false) {
    const std::vector<int>& lift = lift_;
    if (by_qr) return leastSquares(J, b, rows, c);
    if (refactor || !factored_) {
      Jt_ = J.transpose();
      M_ = Jt_ * J;
      if (damping_ > 0) {
        SparseMatrix D(J.cols(), J.cols());
        D.setIdentity();
        M_ += mu(J) * D;
      }
      for (int i : gauge_) M_.coeffRef(i, i) += 1.0;
      for (int i : lift) M_.coeffRef(i, i) += 1.0;
      factored_ = withLdlt([&](auto& ldlt) {
        if (!analysed_) ldlt.analyzePattern(M_);
        ldlt.factorize(M_);
        return ldlt.info() == Eigen::Success;
      });
      analysed_ = true;
    }
    // Damped: a chord step's right-hand side is J0^T b, J0 the factored iterate's Jacobian, so
    // that it lies in the row space of J0. With the current J's, its part on the factored
    // kernel (|J - J0| |b|) would come back multiplied by 1 / mu.
    const Vector rhs = (damping_ > 0 ? Vector(Jt_ * b) : Vector(J.transpose() * b)) + rows.transpose() * c;
    const Eigen::Index k = rows.rows(), f = static_cast<Eigen::Index>(lift.size());
    // W = [U, F], C = diag(I_k, -I_f).
    Matrix W = Matrix::Zero(J.cols(), k + f);
    W.leftCols(k) = rows.transpose();
    for (Eigen::Index i = 0; i < f; ++i) W(lift[static_cast<size_t>(i)], k + i) = 1.0;
    Vector C = Vector::Ones(k + f);
    C.tail(f).setConstant(-1.0);
    if (factored_) {
      Vector d = withLdlt([&](auto& ldlt) -> Vector { return ldlt.solve(rhs); });
      if (k + f > 0) {
        const Matrix AW = withLdlt([&](auto& ldlt) -> Matrix { return ldlt.solve(W); });
        Matrix S = W.transpose() * AW;
        S.diagonal() += C;  // C^-1 = C
        d -= AW * S.fullPivLu().solve(Vector(W.transpose() * d));
      }
      // Accept when the pivots were sound: the result solves the normal equations (of the
      // factored iterate) to a small backward error, |r| <= 1e-8 (|M| |d| + |rhs|). Not
      // relative to |rhs| alone: soft modes make |d| >> |rhs| / |M| with a sound factorization
      // (that test sent every step of a 224 x 224 grid with 2 flexes to the QR, 0.56 s each).
      // A step that is still poor fails its line search, and correct() takes it again by QR.
      const Vector r = M_ * d + W * C.asDiagonal() * (W.transpose() * d) - rhs;
      const double size = M_.diagonal().maxCoeff() + (k ? rows.colwise().squaredNorm().maxCoeff() : 0.0);
      if (d.allFinite() && r.norm() <= 1e-8 * std::max(size * d.norm() + rhs.norm(), 1e-300)) return d;
      factored_ = false;
    }
    return leastSquares(J, b, rows, c);
  }

 private:
  Vector leastSquares(const SparseMatrix& J, const Vector& b, const Matrix& rows, const Vector& c) const {
    if (rows.rows() == 0) return leastSquaresQR(J, b);
    Vector bc(b.size() + c.size());
    bc << b, c;
    return leastSquaresQR(appendRows(J, rows), bc);
  }

  Vector leastSquaresQR(const SparseMatrix& J, const Vector& b) const {
    // Below J: the gauge's identity rows, or sqrt(mu) I for the damping (its least-squares
    // solution is the damped normal equations').
    const int below = damping_ > 0 ? static_cast<int>(J.cols()) : static_cast<int>(gauge_.size());
    SparseMatrix A(J.rows() + below, J.cols());
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(static_cast<size_t>(J.nonZeros()) + static_cast<size_t>(below));
    for (int c = 0; c < J.outerSize(); ++c)
      for (SparseMatrix::InnerIterator it(J, c); it; ++it) t.emplace_back(it.row(), it.col(), it.value());
    for (size_t i = 0; i < gauge_.size(); ++i)
      t.emplace_back(static_cast<int>(J.rows() + i), gauge_[i], 1.0);
    if (damping_ > 0) {
      const double root = std::sqrt(mu(J));
      for (int i = 0; i < J.cols(); ++i) t.emplace_back(static_cast<int>(J.rows()) + i, i, root);
    }
    A.setFromTriplets(t.begin(), t.end());
    A.makeCompressed();
    Eigen::SPQR<SparseMatrix> qr;
    factorSparseQR(qr, A);
    Vector rhs = Vector::Zero(A.rows());
    rhs.head(J.rows()) = b;
    return qr.solve(rhs);
  }

  // The absolute damping: damping_ times the largest diagonal entry of J^T J (the largest
  // squared column norm of J), for the normal equations and their QR alike.
  double mu(const SparseMatrix& J) const {
    double size = 0.0;
    for (int c = 0; c < J.outerSize(); ++c) size = std::max(size, J.col(c).squaredNorm());
    return damping_ * std::max(size, 1e-300);
  }

  std::vector<int> gauge_, lift_;
  double damping_ = 0.0;  // relative to the largest diagonal entry of J^T J
  SparseMatrix Jt_, M_;    // J^T and the normal matrix of the factored iterate
  bool nested_dissection_;
  Eigen::SimplicialLDLT<SparseMatrix> ldlt_;
  Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower, Eigen::MetisOrdering<int>> nd_;
  bool analysed_ = false, factored_ = false;
};

std::shared_ptr<NormalEquations> EquationReduction::keptNormalEquations() {
  return std::make_shared<NormalEquations>(/*nested_dissection=*/true);
}

namespace {

// The minimum-norm least-squares solution of J d = b over J's numerical range. Small systems:
// a complete orthogonal decomposition (column-pivoted QR, then an RZ step on the rank rows),
// a few microseconds on the double Watt's 15 x 16 Jacobian where a full SVD takes ~40; its
// rank decision is |R_ii| > rank_tolerance * |R_11|. Large: the sparse rank-revealing QR.
Vector minNormStep(const SparseMatrix& J, const Vector& b, const FactorizationOptions& opt) {
  if (std::max(J.rows(), J.cols()) > opt.dense_limit || J.rows() == 0 || J.cols() == 0)
    return JacobianFactorization(J, opt).solveMinNorm(b);
  Eigen::CompleteOrthogonalDecomposition<Matrix> cod;
  cod.setThreshold(opt.rank_tolerance);  // before compute: the RZ step uses the rank
  cod.compute(Matrix(J));
  return cod.solve(b);
}

}  // namespace

CorrectorResult correctChord(const ConstraintSystem& sys, const Vector& start, const JacobianFactorization& fac,
                             double tol, double floor, int max_iterations) {
  CorrectorResult res;
  res.x = start;
  Vector& y = res.x;
  Vector F = sys.residuals(y);
  double r = F.size() ? F.cwiseAbs().maxCoeff() : 0.0;
  std::vector<Vector> dy, dg;
  Vector y_prev, g_prev;
  bool accurate = false;
  for (res.iterations = 0; res.iterations < max_iterations && r > tol; ++res.iterations) {
    const Vector g = accurate ? Vector(-fac.solveMinNorm(F)) : Vector(-fac.solveSeminormal(F));
    if (res.iterations > 0 && y_prev.size() > 0) {
      dy.push_back(y - y_prev), dg.push_back(g - g_prev);
      if (dy.size() > 5) dy.erase(dy.begin()), dg.erase(dg.begin());
    }
    y_prev = y, g_prev = g;
    Vector next = y + g;
    if (!dg.empty()) {
      Matrix G(g.size(), static_cast<Eigen::Index>(dg.size())), Y(G.rows(), G.cols());
      for (size_t j = 0; j < dg.size(); ++j) {
        G.col(static_cast<Eigen::Index>(j)) = dg[j];
        Y.col(static_cast<Eigen::Index>(j)) = dy[j];
      }
      const Vector gamma = G.colPivHouseholderQr().solve(g);
      if (gamma.allFinite()) next -= (Y + G) * gamma;
    }
    Vector Fn = sys.residuals(next);
    double rn = Fn.cwiseAbs().maxCoeff();
    if (!(rn < r) && !dg.empty()) {
      next = y + g;
      Fn = sys.residuals(next);
      rn = Fn.cwiseAbs().maxCoeff();
      dy.clear(), dg.clear();
    }
    if (!(rn < r)) {
      if (accurate || fac.dense() || r <= floor) break;
      // The seminormal equations' rounding floor (their condition number is squared): the
      // last iterations take the QR's Q.
      accurate = true;
      dy.clear(), dg.clear(), y_prev.resize(0);
      continue;
    }
    if (rn > 0.25 * r) dy.clear(), dg.clear();  // stagnating: restart the acceleration
    y = std::move(next), F = std::move(Fn), r = rn;
  }
  res.residual = r;
  res.status = r <= tol || r <= floor ? CorrectorStatus::Converged
               : res.iterations >= max_iterations ? CorrectorStatus::MaxIterations
                                                  : CorrectorStatus::LineSearchFailed;
  return res;
}

CorrectorResult correct(const ConstraintSystem& sys, const Vector& start, const CorrectorOptions& opt,
                        const EquationReduction& red, const Vector* rhs, const Sphere* sphere,
                        const ExtraEquations* extra) {
  const bool normal = !red.gauge.empty() || red.damping > 0;  // steps by the normal equations
  if (sphere && normal) throw std::invalid_argument("a sphere needs a dense or no equation reduction");
  if (red.lambda.size() > 0 && red.lambda.cols() != sys.numEquations())
    throw std::invalid_argument("the randomization matrix has " + std::to_string(red.lambda.cols()) +
                                " columns for " + std::to_string(sys.numEquations()) + " equations");
  if (start.size() != sys.numVariables())
    throw std::invalid_argument("the start has " + std::to_string(start.size()) + " coordinates for " +
                                std::to_string(sys.numVariables()) + " variables");
  const double tol = opt.residual_tolerance * sys.residualScale();
  CorrectorResult res;
  res.x = start;
  SparseMatrix J = sys.jacobianPattern();
  // Gauge steps' normal equations: the caller's, kept from earlier corrections, or this
  // correction's own (on the stack, and only with a gauge: small systems correct thousands of
  // times without one).
  std::optional<NormalEquations> own;
  NormalEquations* bordered = red.normal_equations.get();
  if (normal) {
    if (!bordered) bordered = &own.emplace();
    bordered->use(red.gauge, red.lift, red.damping);
  }
  bool refactor = !red.normal_equations;
  if (rhs && rhs->size() != sys.numEquations())
    throw std::invalid_argument("the right-hand side has the wrong size");
  // The steps' equations: Lambda F (or F), then the sphere's (|x - c|^2 - r^2) / (2r), whose
  // gradient (x - c)^T / r has unit length on the sphere, times sphere_units, then the extra
  // equation. The sphere's residual is a length; the system's are in its own units
  // (residualScale()): it is taken in those units (relative to the size of the coordinates), in
  // the steps and against the tolerance, so that the same configuration at another scale
  // converges alike.
  const double sphere_units =
      sphere ? sys.residualScale() / std::max({sphere->center.cwiseAbs().maxCoeff(), sphere->radius, 1e-300}) : 0.0;
  // The extra rows' residuals at x (sphere, then the extra equations).
  auto extraResiduals = [&](const Vector& x) {
    const Vector e = extra ? extra->values(x) : Vector();
    Vector r(static_cast<Eigen::Index>(sphere != nullptr) + e.size());
    if (sphere)
      r[0] = sphere_units * ((x - sphere->center).squaredNorm() - sphere->radius * sphere->radius) / (2 * sphere->radius);
    r.tail(e.size()) = e;
    return r;
  };
  auto reduce = [&](const Vector& f, const Vector& x) -> Vector {
    Vector r = red.lambda.size() > 0 ? Vector(red.lambda * f) : f;
    if (!sphere && !extra) return r;
    const Vector e = extraResiduals(x);
    r.conservativeResize(r.size() + e.size());
    r.tail(e.size()) = e;
    return r;
  };
  auto worst = [&](const Vector& f, const Vector& x) {
    double w = f.size() ? f.cwiseAbs().maxCoeff() : 0.0;
    const Vector e = sphere || extra ? extraResiduals(x) : Vector();
    return e.size() ? std::max(w, e.cwiseAbs().maxCoeff()) : w;
  };
  auto residuals = [&](const Vector& x) -> Vector {
    Vector f = sys.residuals(x);
    if (rhs) f -= *rhs;
    return f;
  };
  Vector F = residuals(res.x);
  // The best iterate so far: returned, as converged, when the iteration stalls at the
  // rounding floor below stall_tolerance.
  Vector best_x = res.x;
  double best = std::numeric_limits<double>::infinity();
  auto give_up = [&](CorrectorStatus status) {
    if (best <= opt.stall_tolerance * sys.residualScale()) {
      res.x = best_x;
      res.residual = best;
      res.status = CorrectorStatus::Converged;
    } else {
      res.status = status;
    }
    return res;
  };
  for (res.iterations = 0;; ++res.iterations) {
    res.residual = worst(F, res.x);
    if (!std::isfinite(res.residual)) return give_up(CorrectorStatus::LineSearchFailed);
    if (res.residual < best) best = res.residual, best_x = res.x;
    if (res.residual <= tol) {
      res.status = CorrectorStatus::Converged;
      return res;
    }
    if (res.iterations >= opt.max_iterations) return give_up(CorrectorStatus::MaxIterations);
    sys.jacobian(res.x, J);
    Vector step;
    SparseMatrix Jr;
    const bool reduced = red.lambda.size() > 0 || sphere || extra;
    const Matrix more = extra ? extra->gradients(res.x) : Matrix(0, J.cols());
    if (reduced) {
      // The extra rows below J (or Lambda J, dense): sparse when J is.
      Matrix rows(static_cast<Eigen::Index>(sphere != nullptr) + more.rows(), J.cols());
      if (sphere) rows.row(0) = sphere_units * (res.x - sphere->center).transpose() / sphere->radius;
      rows.bottomRows(more.rows()) = more;
      if (red.lambda.size() > 0) {
        Matrix D(red.lambda.rows() + rows.rows(), J.cols());
        D << red.lambda * Matrix(J), rows;
        Jr = D.sparseView();
      } else {
        Jr = appendRows(J, rows);
      }
    }
    const SparseMatrix& Jt = reduced ? Jr : J;
    const Vector Ft = reduce(F, res.x);
    // Normal-equation steps (gauge or damped) with kept normal equations reuse their
    // factorization (chord steps).
    const bool chord = normal && !refactor && bordered->factored();
    const double phi = Ft.squaredNorm();
    // A chord step is taken whole or not at all: where a stale normal matrix gives a poor
    // direction (soft modes of a flexible grid, whose curvature moved since it was factored),
    // a new factorization is cheaper than the backtracking (8 halvings per correction were
    // typical on a 60 x 60 grid). A gauge step from a new factorization of the normal equations
    // that finds no decrease is taken again by QR (their squared condition number).
    double alpha = 1.0;
    bool accepted = false;
    for (const bool by_qr : {false, true}) {
      if (by_qr && (!normal || chord)) break;
      if (normal) {
        if (extra) {  // no sphere with a gauge: Ft ends with the extra equations' residuals
          step = -bordered->solve(J, F, more, Ft.tail(more.rows()), !chord, by_qr);
        } else {
          step = -bordered->solve(J, F, !chord, by_qr);
        }
      } else {
        step = -minNormStep(Jt, Ft, opt.factorization);
      }
      // Armijo on phi = ||F~||^2 with its directional derivative 2 F~^T J~ step.
      const double g = Ft.dot(Jt * step);
      alpha = 1.0;
      for (int b = 0; g < 0 && b <= (chord ? 0 : opt.max_backtracks); ++b, alpha *= 0.5) {
        const Vector trial = res.x + alpha * step;
        const Vector Fn = residuals(trial);
        if (reduce(Fn, trial).squaredNorm() <= phi + 2.0 * opt.armijo * alpha * g) {
          res.x = trial;
          F = Fn;
          accepted = true;
          break;
        }
      }
      if (accepted) break;
    }
    if (!accepted) {
      if (chord) {
        refactor = true;
        continue;
      }
      return give_up(CorrectorStatus::LineSearchFailed);
    }
    // Kept normal equations serve while a full step lowers the residual by 4 or more; a
    // correction's own are factored at every iterate (Gauss-Newton).
    refactor = !red.normal_equations || alpha < 1.0 || reduce(F, res.x).squaredNorm() > phi / 16.0;
  }
}

}  // namespace flexure::engine
