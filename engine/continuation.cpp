#include "engine/continuation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Dense>

#include "engine/factorization.h"

namespace flexure::engine {

DeformationPath continueParameter(const Vector& start, const ParameterSteps& kind, const ContinuationSchedule& sch,
                                  const StepCallback& on_step) {
  if (!(sch.step > 0)) throw std::invalid_argument("the continuation step must be positive");
  DeformationPath out;
  out.samples.push_back(start);
  const double c0 = sch.start, span = sch.target - c0;
  const double needed_steps = std::ceil(std::abs(span) / sch.step - 1e-9);
  if (!(needed_steps <= std::numeric_limits<int>::max()) && sch.max_steps < 0)
    throw std::invalid_argument("the continuation needs more than 2^31 steps; give a larger step or a step limit");
  const int needed = static_cast<int>(std::min<double>(needed_steps, std::numeric_limits<int>::max()));
  const int steps = sch.max_steps >= 0 ? std::min(sch.max_steps, needed) : needed;
  out.summary.steps_requested = steps;
  out.summary.seed = 0;
  auto valueAt = [&](int k) { return k >= needed ? sch.target : c0 + (span > 0 ? 1 : -1) * sch.step * k; };
  const auto text = [&](double c) { return kind.valueText ? kind.valueText(c) : std::to_string(c); };
  double worst = kind.residual(start, c0);
  double last_distance = -1;  // between the last two samples
  double c_prev = c0;
  Vector x_prev = start, x_prev2;
  out.summary.status = TrackStatus::Success;
  for (int k = 1; k <= steps; ++k) {
    const double c_target = valueAt(k);
    // Reach c_target from c_prev, in sub-steps when a step fails or jumps.
    double c_from = c_prev;
    Vector x_from = x_prev;
    int halvings = 0;
    double frac = 1.0;
    bool failed = false;
    while (c_from != c_target) {
      const double c_to = frac >= 1.0 ? c_target : c_from + frac * (c_target - c_from);
      // The secant through the last two samples, scaled to this parameter step; the kind's
      // first-order step where there is none (or inside a halved step).
      Vector predicted = x_prev2.size() && c_from == c_prev
                             ? Vector(x_from + (x_prev - x_prev2) * ((c_to - c_from) / (c_prev - valueAt(k - 2))))
                             : Vector(x_from + kind.tangent(x_from, c_from, c_to));
      if (kind.adjust) predicted = kind.adjust(x_from, predicted);
      const CorrectorResult r = kind.correct(x_from, predicted, c_to);
      const double moved = (r.x - x_from).norm();
      const double expected = last_distance > 0 ? last_distance * std::abs(c_to - c_from) / sch.step : -1;
      const bool jumped = expected > 0 && moved > 8.0 * expected + 1e-12;
      if (r.status == CorrectorStatus::Converged && !jumped) {
        x_from = r.x;
        c_from = c_to;
        frac = 1.0;
        continue;
      }
      ++out.summary.rejected_steps;
      if (++halvings > sch.max_halvings) {
        failed = true;
        out.summary.status = TrackStatus::StoppedEarly;
        out.summary.reason = "no converged step from " + kind.parameter + " " + text(c_from) + " toward " +
                             text(c_target) + " after " + std::to_string(sch.max_halvings) + " halvings (" +
                             (jumped ? "the corrector jumped" : toString(r.status)) + ")";
        break;
      }
      frac *= 0.5;
    }
    if (failed) break;
    if (kind.admissible && !kind.admissible(x_from)) {
      out.summary.status = TrackStatus::LeftAdmissibleSet;
      out.summary.reason = "the next sample left the admissible set";
      out.outside = x_from;
      break;
    }
    last_distance = (x_from - x_prev).norm();
    x_prev2 = x_prev;
    x_prev = x_from;
    c_prev = c_target;
    worst = std::max(worst, kind.residual(x_from, c_target));
    out.samples.push_back(x_from);
    if (on_step && !on_step(k, steps)) {
      out.summary.status = TrackStatus::StoppedByCallback;
      out.summary.reason = "stopped on request";
      break;
    }
  }
  out.summary.steps_done = static_cast<int>(out.samples.size()) - 1;
  out.summary.max_residual = worst;
  if (out.summary.status == TrackStatus::Success)
    out.summary.reason = steps < needed ? "" : "the " + kind.parameter + " reached its target, " + text(sch.target);
  return out;
}

DeformationPath driveQuantity(const Model& model, const Vector& start, const DrivenQuantity& q, double target,
                              const DriveOptions& opt, const StepCallback& on_step) {
  const ConstraintSystem& sys = model.system();
  if (opt.steps < 0) throw std::invalid_argument("a drive takes a nonnegative number of steps");
  if (!std::isfinite(target)) throw std::invalid_argument("the drive's target is not a finite number");
  const double c0 = q.value(start);
  if (opt.steps == 0) {  // the start alone
    DeformationPath out;
    out.samples.push_back(start);
    out.summary.status = TrackStatus::Success;
    out.summary.reason.clear();
    out.summary.max_residual = sys.numEquations() ? sys.residuals(start).cwiseAbs().maxCoeff() : 0.0;
    return out;
  }
  ParameterSteps kind;
  kind.parameter = q.name;
  kind.valueText = q.valueText;
  kind.admissible = opt.admissible;
  const Vector held0 = q.held ? q.held(start) : Vector();
  // The rows of the equations beside F: the driven quantity, then the held ones.
  const auto extraRows = [&](const Vector& x) {
    const Matrix h = q.held_gradients ? q.held_gradients(x) : Matrix(0, x.size());
    Matrix rows(1 + h.rows(), x.size());
    rows.row(0) = q.gradient(x).transpose();
    rows.bottomRows(h.rows()) = h;
    return rows;
  };
  kind.tangent = [&](const Vector& x, double from, double to) -> Vector {
    if (q.first_direction.size() == x.size() && from == c0 && x == start) {
      const double rate = q.gradient(x).dot(q.first_direction);
      if (std::abs(rate) > 1e-12 * q.gradient(x).norm() * q.first_direction.norm())
        return q.first_direction * ((to - from) / rate);
    }
    // The least displacement with J dx = 0, g . dx = to - from and the held quantities' rates 0.
    const JacobianFactorization fac(appendRows(sys.jacobian(x), extraRows(x)), orderedFor(opt.corrector.factorization, sys));
    Vector b = Vector::Zero(fac.rows());
    b[sys.numEquations()] = to - from;
    return fac.solveMinNorm(b);
  };
  // The tangent space K of the solution set at x (rigid motions included): the kernel of
  // [J; g; held], as the part of ker J (KJ) that the extra rows do not move. Factoring J alone
  // keeps a row touching every vertex (a fold percentage) out of the sparse QR. Kept for the
  // last point asked: a step's adjustment and its corrections (halvings included) start from
  // the same point.
  struct Tangents {
    Vector at;
    Matrix K, KJ;
    EquationReduction gauge;  // for large systems (below)
  } memo;
  const auto tangentsAt = [&](const Vector& x) -> const Tangents& {
    if (memo.at.size() == x.size() && memo.at == x) return memo;
    memo = Tangents{x, Matrix(), Matrix(), {}};
    const JacobianFactorization fac(sys.jacobian(x), orderedFor(opt.corrector.factorization, sys));
    memo.KJ = fac.kernel();
    memo.K = memo.KJ;
    // (Eigen 3.4's JacobiSVD crashes on a matrix without rows: those cases are taken apart.)
    const Matrix rows = memo.KJ.cols() > 0 ? extraRows(x) : Matrix();
    if (memo.KJ.cols() > 0 && rows.rows() > 0) {
      Eigen::JacobiSVD<Matrix> svd(Matrix(rows * memo.KJ), Eigen::ComputeFullV);
      const Vector& sv = svd.singularValues();
      const double scale = std::max(sv.size() ? sv[0] : 0.0, rows.rowwise().norm().maxCoeff());
      Eigen::Index rank = 0;
      while (rank < sv.size() && sv[rank] > opt.corrector.factorization.rank_tolerance * scale) ++rank;
      memo.K = memo.KJ * svd.matrixV().rightCols(memo.KJ.cols() - rank);
    }
    // Large systems stay sparse: the corrector's steps hold one gauge coordinate per direction
    // of K, as the tracker's do, and the redundant equations of a sheet's vertices do no harm;
    // the lift's coordinates cover the rest of ker J, pivoted on the directions W in ker J
    // that leave the gauge coordinates still.
    const Matrix& K = memo.K;
    const Matrix& KJ = memo.KJ;
    EquationReduction& red = memo.gauge;
    if (K.cols() > 0) {
      const Eigen::ColPivHouseholderQR<Matrix> qr(K.transpose());
      for (Eigen::Index i = 0; i < K.cols(); ++i) red.gauge.push_back(qr.colsPermutation().indices()[i]);
    }
    if (KJ.cols() > K.cols()) {
      const Eigen::Index f = KJ.cols() - K.cols();
      Matrix W = KJ;  // no gauge coordinate (K is empty: the drive leaves no freedom): all of ker J
      if (!red.gauge.empty()) {
        Matrix B(static_cast<Eigen::Index>(red.gauge.size()), KJ.cols());
        for (size_t i = 0; i < red.gauge.size(); ++i) B.row(static_cast<Eigen::Index>(i)) = KJ.row(red.gauge[i]);
        const Eigen::JacobiSVD<Matrix> svd(B, Eigen::ComputeFullV);
        W = KJ * svd.matrixV().rightCols(f);
      }
      const Eigen::ColPivHouseholderQR<Matrix> qr(W.transpose());
      for (Eigen::Index i = 0; i < f; ++i) red.lift.push_back(qr.colsPermutation().indices()[i]);
    }
    return memo;
  };
  const bool large = std::max(sys.numEquations(), sys.numVariables()) > opt.corrector.factorization.dense_limit;
  // Where the constraints leave no freedom to adjust (the kernel of [J; g; held] folds nothing:
  // one degree of freedom), the factorization is skipped for the next kRecheck steps.
  constexpr int kRecheck = 25;
  int skip = 0;
  if (q.rates)
    kind.adjust = [&](const Vector& x, const Vector& predicted) -> Vector {
      // Not the first step along first_direction: at a flat state, first order has motions the
      // sheet does not.
      if (q.first_direction.size() == x.size() && x == start) return predicted;
      if (skip > 0) {
        --skip;
        return predicted;
      }
      // Plus the combination K a of the first-order motions that keep everything (the kernel K
      // of [J; g; held]) whose rates R (d + K a) come closest to s p.
      const Matrix& K = tangentsAt(x).K;
      const Matrix R = q.rates(x);
      const Vector d = predicted - x;
      Matrix M(R.rows(), K.cols() + 1);
      M << R * K, -q.proportions;
      // Rigid motions fold nothing: their columns of R K are rounding, cut by the threshold.
      Eigen::CompleteOrthogonalDecomposition<Matrix> cod;
      cod.setThreshold(opt.corrector.factorization.rank_tolerance);
      cod.compute(M);
      if (cod.rank() <= 1) skip = kRecheck;  // only the proportions' column: nothing to adjust
      const Vector a = cod.solve(Vector(-R * d));
      return predicted + K * a.head(K.cols());
    };
  kind.correct = [&](const Vector& x_from, const Vector& guess, double c) {
    ExtraEquations eq;
    eq.values = [&](const Vector& x) {
      const Vector h = q.held ? Vector(q.held(x) - held0) : Vector();
      Vector v(1 + h.size());
      v << q.value(x) - c, h;
      return Vector(q.units * v);
    };
    eq.gradients = [&](const Vector& x) { return Matrix(q.units * extraRows(x)); };
    return correct(sys, guess, opt.corrector, large ? tangentsAt(x_from).gauge : EquationReduction{}, nullptr, nullptr, &eq);
  };
  kind.residual = [&](const Vector& x, double c) {
    const Vector f = sys.residuals(x);
    double worst = std::max(f.size() ? f.cwiseAbs().maxCoeff() : 0.0, std::abs(q.units * (q.value(x) - c)));
    if (q.held && held0.size()) worst = std::max(worst, q.units * (q.held(x) - held0).cwiseAbs().maxCoeff());
    return worst;
  };
  ContinuationSchedule sch;
  sch.start = c0;
  sch.target = target;
  sch.step = std::abs(target - c0) / opt.steps;
  sch.max_halvings = opt.max_halvings;
  if (!(sch.step > 0)) {  // already there
    DeformationPath out;
    out.samples.push_back(start);
    out.summary.status = TrackStatus::Success;
    out.summary.reason = "the " + q.name + " is at its target already";
    out.summary.max_residual = kind.residual(start, c0);
    return out;
  }
  return continueParameter(start, kind, sch, on_step);
}

}  // namespace flexure::engine
