#include "engine/motion_tracker.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <functional>
#include <memory>
#include <optional>
#include <sstream>
#include <string>

#include "engine/random.h"
#include "engine/flex_space.h"

namespace flexure::engine {

namespace {

// What the tracker knows about an accepted sample. Large (sparse) systems keep no basis of
// the flex space: a basis of ker J is N x (N - rank) and every product with it costs N k^2
// (1.3e9 multiply-adds at 111 flexes and 10^5 variables, ten times the sparse QR). What the
// tracker does with the flex space it does to one vector at a time, with the sample QR's
// seminormal equations (projectOntoKernel, 0.004-0.009 s at 10^5 variables) and the trivial
// flexes T; its corrections need no basis either (damped normal equations, see randomization).
struct Point {
  Vector x;
  std::unique_ptr<JacobianFactorization> fac;
  Matrix B;          // orthonormal basis of the nontrivial flexes, N x k (dense only)
  Matrix T;          // orthonormal basis of the trivial flexes, inside ker J (sparse only)
  int flexes = 0;    // k, the number of nontrivial flexes
  double rho = 1.0;  // smallest kept / largest singular value: small near a singularity (dense)

  bool sparse() const { return !fac->dense(); }
  // The orthogonal projection of u onto the nontrivial flexes.
  Vector projectNontrivial(const Vector& u) const {
    if (!sparse()) return B * (B.transpose() * u);
    Vector w = fac->projectOntoKernel(u);
    return w - T * (T.transpose() * w);
  }
};

// The point's factorization and flex space: dense, the nontrivial flexes' basis; sparse,
// the trivial flexes inside ker J and the count of the others (N - rank - t), no basis.
Point analyzePoint(const Model& model, const FactorizationOptions& options, const Vector& x, const Point* from) {
  Point p;
  p.x = x;
  FactorizationOptions fo = orderedFor(options, model.system());
  if (from && from->fac) fo.expected_rank = from->fac->rank();
  const SparseMatrix J = model.system().jacobian(x);
  p.fac = std::make_unique<JacobianFactorization>(J, fo);
  const Matrix T = trivialFlexes(model, x, options.rank_tolerance);
  if (p.sparse()) {
    // The trivial flexes are the symmetries that keep every constraint: exactly inside ker J
    // (|J t| at rounding level). Those that break one (|J t| of the order of J) are not flexes.
    p.T = T;
    if (T.cols() > 0) {
      const Eigen::JacobiSVD<Matrix> svd(Matrix(J * T), Eigen::ComputeFullV);
      const Vector& s = svd.singularValues();
      int broken = 0;
      while (broken < s.size() && s[broken] > std::sqrt(options.rank_tolerance) * p.fac->sigmaMax()) ++broken;
      p.T = T * svd.matrixV().rightCols(T.cols() - broken);
    }
    p.flexes = std::max(0, p.fac->cols() - p.fac->rank() - static_cast<int>(p.T.cols()));
    // No conditioning (rho = 1): a sparse QR's |R_ii| only bound the singular values from
    // above, and rounding along chains of dependent equations moves the smallest by orders of
    // magnitude between regular neighbours (1.5e-4, 4.4e-9, 2.2e-5 at three samples of a
    // sheared 224 x 224 grid): no dips are read from them (events there come from the flex
    // dimension and the strategies).
    return p;
  }
  p.B = nontrivialPartFast(p.fac->kernel(), T);
  p.flexes = static_cast<int>(p.B.cols());
  p.rho = p.fac->sigmaMax() > 0 ? p.fac->sigmaSmallestKept() / p.fac->sigmaMax() : 1.0;
  return p;
}

// The correction policy: how a predicted point is corrected onto the constraints, with the
// reduction of the equations drawn afresh for each move.
class CorrectionPolicy {
 public:
  CorrectionPolicy(const ConstraintSystem& sys, const CorrectorOptions& opt, std::uint64_t seed)
      : sys_(sys), opt_(opt), rng_(seed) {}

  // The reduction of the corrections of the next move, made at p (the current point).
  void reduceAt(const Point& p) { red_ = randomization(p); }

  // The randomized (dense) or damped (sparse) corrector first; if it fails (a stress of a
  // singular point that does not persist nearby makes Lambda F = 0 larger than F = 0), plain
  // minimum-norm Gauss-Newton.
  bool converge(const Vector& guess, Vector& y) const {
    CorrectorResult r = correct(sys_, guess, opt_, red_);
    if (r.status != CorrectorStatus::Converged && !red_.empty())
      r = correct(sys_, guess, opt_);
    y = r.x;
    return r.status == CorrectorStatus::Converged;
  }

  // Like converge, but keeping the guess's distance from the point `from` (small systems):
  // the strategies' moves leave a singular point where branches pass close to each other, and
  // there the plain corrector falls onto whichever branch is nearest, often the incoming one.
  bool convergeAway(const Point& from, const Vector& guess, Vector& y) const {
    const double r = (guess - from.x).norm();  // the sphere lives in all the variables
    if (from.sparse() || !(r > 0)) return converge(guess, y);
    const Sphere sphere{from.x, r};
    CorrectorResult c = correct(sys_, guess, opt_, red_, nullptr, &sphere);
    if (c.status != CorrectorStatus::Converged && !red_.empty())
      c = correct(sys_, guess, opt_, {}, nullptr, &sphere);
    y = c.x;
    return c.status == CorrectorStatus::Converged;
  }

 private:
  // Paper Prop. 4.3: with s stresses at the last sample, steps solve Lambda F = 0 for a
  // seeded Gaussian (m - s) x m matrix Lambda. Large (sparse) systems keep sparse: the steps
  // solve the damped normal equations of all of F (see EquationReduction::damping), whose
  // factorization is kept from correction to correction while its chord steps converge fast.
  EquationReduction randomization(const Point& p) {
    EquationReduction red;
    if (p.sparse()) {
      red.damping = kDamping;
      red.normal_equations = normal_equations_;
      return red;
    }
    const int m = sys_.numEquations(), s = m - p.fac->rank();
    if (s <= 0 || m - s <= 0) return red;
    red.lambda.resize(m - s, m);
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < m - s; ++i) red.lambda(i, j) = rng_.gaussian();
    red.lambda /= std::sqrt(static_cast<double>(m));
    return red;
  }

  // The damping of the sparse steps' normal equations, relative to the largest diagonal entry
  // of J^T J (~|J|^2 / 2). Far above the rounding of J^T J and of its LDL^T factorization, so
  // that the factorization stays positive definite on ker J, and above the squared singular
  // values that a guess off the constraints adds (noise of 1e-6 per coordinate on a 30 x 30
  // grid: the correction's part along the tangent space is 0.5 % of it with 1e-11, 4 % with
  // 1e-12, 21 % with 1e-13). Below most squared singular values that count, so that the steps
  // are Gauss-Newton's: relative to sigma_max^2 the smallest kept is 6.7e-6 on a 40 x 40 grid
  // braced every other row and 2.4e-8 on a 40 x 40 grid braced sparsely (2 flexes), falling
  // like n^-5.7 with the side: about 1e-12 at 224, extrapolated. There the softest directions'
  // steps are shortened tenfold; the chord steps converge all the same (1e-11, 1e-12 and 1e-13
  // track the benchmarks alike).
  static constexpr double kDamping = 1e-11;

  const ConstraintSystem& sys_;
  CorrectorOptions opt_;
  Random rng_;
  EquationReduction red_;
  std::shared_ptr<NormalEquations> normal_equations_ = EquationReduction::keptNormalEquations();
};

// What the samples saw of singular points: per sample, the conditioning rho (smallest kept /
// largest singular value) and the flex dimension, the least and the largest over the hidden
// probes since the sample before; the singularities read from them.
class Conditioning {
 public:
  // The start, a sample of its own.
  void start(double rho, int dims) {
    rho_.push_back(rho);
    dims_.push_back(dims);
  }
  // A probe (hidden until it becomes a sample) saw rho and dims.
  void see(double rho, int dims) {
    pending_rho_ = std::min(pending_rho_, rho);
    pending_dims_ = std::max(pending_dims_, dims);
  }
  // A sample is recorded: it takes what its probes saw.
  void sample() {
    rho_.push_back(pending_rho_);
    dims_.push_back(pending_dims_);
    pending_rho_ = std::numeric_limits<double>::infinity();
    pending_dims_ = 0;
  }

  // Singularities the path went through without needing a strategy: the flex space is larger
  // than at both neighbours, or the conditioning dips sharply (a rank drop the samples
  // straddled).
  void markDips(std::vector<TrackEvent>& events) const {
    const int n = static_cast<int>(rho_.size());
    auto has_event_near = [&](int k) {
      for (const auto& e : events)
        if (std::abs(e.sample - k) <= 1) return true;
      return false;
    };
    for (int k = 0; k < n; ++k) {
      const int dl = k > 0 ? dims_[k - 1] : -1, dr = k + 1 < n ? dims_[k + 1] : -1;
      std::ostringstream detail;
      bool singular = false;
      if (dims_[k] > std::max(dl, dr) && (dl >= 0 || dr >= 0)) {
        detail << "the flex space has dimension " << dims_[k] << " here, "
               << std::max(dl, dr) << " next to it";
        singular = true;
      } else if (k > 0 && k + 1 < n && isDip(k)) {
        detail.precision(2);
        detail << "rank drop: sigma_min/sigma_max = " << rho_[k] << ", a local minimum well below "
               << "its neighbours";
        singular = true;
      }
      if (singular && !has_event_near(k)) events.push_back({k, EventKind::Singularity, detail.str(), {}, {}, {}});
    }
    std::sort(events.begin(), events.end(),
              [](const TrackEvent& a, const TrackEvent& b) { return a.sample < b.sample; });
  }

  // rho has a sharp local minimum at k: the samples straddle a rank drop. A linear dip
  // sigma ~ |t - t0| gives rho_k / rho_{k+-3} <= 0.2; smooth variation does not come close.
  bool isDip(int k) const {
    const int n = static_cast<int>(rho_.size());
    const int lo = std::max(0, k - 3), hi = std::min(n - 1, k + 3);
    for (int j = lo; j <= hi; ++j)
      if (j != k && rho_[j] <= rho_[k]) return false;
    return rho_[k] < 0.35 * std::min(rho_[lo], rho_[hi]) && lo < k && hi > k;
  }

 private:
  std::vector<double> rho_;
  std::vector<int> dims_;
  double pending_rho_ = std::numeric_limits<double>::infinity();
  int pending_dims_ = 0;
};

CorrectorOptions ordered(CorrectorOptions c, const ConstraintSystem& sys) {
  c.factorization = orderedFor(c.factorization, sys);
  return c;
}

class Tracker {
 public:
  Tracker(const Model& model, const TrackerOptions& opt, const StepCallback& cb)
      : model_(model), sys_(model.system()), opt_(opt), cb_(cb), policy_(sys_, ordered(opt.corrector, sys_), opt.seed), L_(opt.step_size),
        nc_(sys_.numConfigurationVariables()) {}

  DeformationPath run(const Vector& start, const Vector& direction) {
    if (const std::optional<std::string> why = begin(start, direction)) return stop(*why);
    // Every move is a probe; a probe becomes a sample when it lies a step from the last sample
    // (or on a singular point). So the samples are evenly spaced, and the short moves that
    // approach a singular point stay hidden. Each move advances by at least 2^-max_halvings
    // steps or passes a singular point: the bound on moves only guards against a stall.
    const long max_moves = 64L * opt_.steps + 1000;
    for (long moves = 0; static_cast<int>(out_.samples.size()) <= opt_.steps; ++moves)
      if (std::optional<DeformationPath> done = step(moves, max_moves)) return std::move(*done);
    finish();
    out_.summary.status = TrackStatus::Success;
    return std::move(out_);
  }

  // The start: its sample, flex space, tangent and acceleration. Why the path cannot start,
  // if it cannot.
  std::optional<std::string> begin(const Vector& start, const Vector& direction) {
    out_.summary.steps_requested = opt_.steps;
    out_.summary.seed = opt_.seed;
    out_.summary.reason.clear();
    cur_ = analyzePoint(model_, opt_.factorization, start, nullptr);
    out_.samples.push_back(start);
    conditioning_.start(cur_.rho, cur_.flexes);
    if (cur_.flexes == 0) {
      return "the start configuration has no nontrivial infinitesimal flex: it is "
             "infinitesimally rigid and cannot move";
    }
    v_ = cur_.projectNontrivial(direction);
    if (v_.norm() < 1e-9 * std::max(direction.norm(), 1e-300))
      return "the initial direction is not a nontrivial infinitesimal flex of the start";
    v_ = unit(v_);
    a_ = acceleration(cur_, v_);
    h_ = L_;
    walked_.push_back(start);
    return std::nullopt;
  }

  // One move (moves made before it: `moves`): the first step, or a regular step, or a
  // singularity strategy. The path when the tracking ends with it; nothing while it goes on.
  std::optional<DeformationPath> step(long moves, long max_moves) {
    policy_.reduceAt(cur_);
    const bool at_start = out_.samples.size() == 1 && !hidden_;
    bool moved = false;
    if (moves >= max_moves) {
      recordHidden();
      return stop("no progress: " + std::to_string(moves) + " moves made " +
                  std::to_string(out_.samples.size() - 1) + " steps");
    }
    if (at_start) {
      moved = firstStep();
    } else {
      // After a short move of a strategy (the first step, a singular point passed), the rest
      // of the step; while approaching a singular point, whole steps, shortened as they fail.
      const Attempt at = regularStep(opt_.max_turn_cos, resume_ ? L_ - chordFromSample(cur_.x) : L_);
      if (at.ok) accept(at.y, at.h, /*transport=*/true, "");
      moved = at.ok || passSingularity();
    }
    if (!moved) {
      recordHidden();
      std::ostringstream why;
      if (at_start)
        why << "the start does not move: every attempt along the flex and against it converged "
               "back to the start (the flex is blocked; the system is probably rigid)";
      else
        why << "stuck at sample " << out_.samples.size() - 1 + opt_.sample_offset
            << ": no converged step without a jump, and no singularity strategy (smaller steps, "
               "quadratic predictor, cusp) left it";
      return stop(why.str());
    }
    if (outside_.size() > 0) {
      recordHidden();
      finish();
      out_.summary.status = TrackStatus::LeftAdmissibleSet;
      out_.summary.reason = "the next sample left the admissible set";
      out_.outside = std::move(outside_);
      return std::move(out_);
    }
    if (!recorded_) return std::nullopt;
    recorded_ = false;
    const int sample = static_cast<int>(out_.samples.size()) - 1;
    if (cb_ && !cb_(sample, opt_.steps)) {
      finish();
      out_.summary.status = TrackStatus::StoppedByCallback;
      out_.summary.reason = "stopped on request";
      return std::move(out_);
    }
    return std::nullopt;
  }

 private:
  struct Attempt {
    bool ok = false;
    Vector y;
    double h = 0;
  };

  // The acceleration of the curve through p with velocity v (paper eq. 4.4): the minimum-norm
  // solution of J a = -(v^T H_i v)_i, from the constraints' true second derivatives. Sparse:
  // by the seminormal equations (no product with the QR's Q; the predictor it feeds is
  // corrected anyway).
  Vector acceleration(const Point& p, const Vector& v) const {
    return -p.fac->solveSeminormal(sys_.secondDerivative(p.x, v, v));
  }

  // The point of the walk an arc length s behind the current point (the walk's oldest point
  // if it is shorter), or nothing if the walk has no length.
  std::optional<Vector> pointBehind(double s) const {
    double left = s;
    for (size_t i = walked_.size(); i-- > 1;) {
      const Vector seg = walked_[i - 1] - walked_[i];
      const double l = length(seg);
      if (l >= left) return Vector(walked_[i] + (left / l) * seg);
      left -= l;
    }
    if (walked_.size() < 2) return std::nullopt;
    return walked_.front();
  }

  Vector predictor(const Vector& dir, const Vector& acc, double h) const {
    Vector p = h * dir;
    // The quadratic term only where it is a small correction (near a singularity a can blow up).
    if (acc.size() == dir.size() && acc.allFinite() && 0.5 * h * h * length(acc) <= 0.25 * h)
      p += 0.5 * h * h * acc;
    return p;
  }

  // One predictor-corrector move of length ~T along v (T: what is left of the step to the
  // next sample): shortened on failure or jump, rescaled (at most by 2x per try) until its
  // length is T within the spacing tolerance (a fraction of the step L). Moves shorter than T
  // are accepted when longer ones fail: that is how the path approaches a singularity.
  Attempt regularStep(double min_cos, double T) {
    T = std::clamp(T, 0.05 * L_, L_);
    double h = resume_ ? std::min(h_, T) : h_, jumped = std::numeric_limits<double>::infinity();
    int rescales = 0;
    const double h_min = L_ * std::ldexp(1.0, -opt_.max_halvings);
    for (int tries = 0; tries < 4 * (opt_.max_halvings + opt_.max_rescales) && h >= h_min; ++tries) {
      const Vector pred = predictor(v_, a_, h);
      Vector y;
      if (!policy_.converge(cur_.x + pred, y)) {
        ++out_.summary.rejected_steps;
        h *= 0.5;
        continue;
      }
      const Vector s = y - cur_.x;
      const double d = length(s);
      if (d < 1e-3 * L_) return {};  // pulled back onto the point: the path does not go on here
      if (s.dot(pred) / (s.norm() * pred.norm()) < min_cos) {
        ++out_.summary.rejected_steps;
        jumped = h;
        h *= 0.5;
        continue;
      }
      if (std::abs(d - T) <= opt_.spacing_tolerance * L_) return {true, y, h};
      if (rescales < opt_.max_rescales) {
        const double next = h * std::clamp(T / d, 0.5, 2.0);
        if (next < 0.9 * jumped) {
          h = next;
          ++rescales;
          continue;
        }
      }
      if (d <= T + 0.25 * L_) return {true, y, h};
      h *= 0.5;  // too long and no more rescales: shorten
    }
    return {};
  }

  // The first step: along the flex if that makes a step of (nearly) full length, otherwise
  // against it if that does (the reference's "direction is reversed"); otherwise the longer.
  // It is always a sample: a short one means the start is a singular point.
  bool firstStep() {
    if (opt_.first_point) {
      accept(*opt_.first_point, L_, false, "");
      recordHidden();
      return true;
    }
    Attempt fwd = regularStep(0.0, L_);
    if (fwd.ok && length(fwd.y - cur_.x) >= 0.5 * L_) {
      accept(fwd.y, fwd.h, false, "");
      recordHidden();
      return true;
    }
    const Vector v = v_, a = a_;
    v_ = -v;
    a_ = acceleration(cur_, v_);
    h_ = L_;
    Attempt back = regularStep(0.0, L_);
    const double df = fwd.ok ? length(fwd.y - cur_.x) : 0.0, db = back.ok ? length(back.y - cur_.x) : 0.0;
    if (back.ok && db >= df) {
      accept(back.y, back.h, false, "");
      recordHidden();
      if (outside_.size() == 0)
        out_.events.push_back({0, EventKind::Singularity, "the path starts against the flex: it is blocked the other way", {}, {}, {}});
      return true;
    }
    v_ = v;
    a_ = a;
    if (fwd.ok) {
      accept(fwd.y, fwd.h, false, "");
      recordHidden();
      return true;
    }
    return false;
  }

  // Is y away from the path already walked (its last two steps' length, samples and probes)?
  // By length, not by count: near a singular point the last moves are short, and a strategy's
  // move of up to a whole step must not land back on the incoming branch unnoticed.
  bool offWalkedPath(const Vector& y) const {
    const int n = static_cast<int>(walked_.size());
    double best = std::numeric_limits<double>::infinity();
    for (int i = 0; i + 1 < n; ++i) {
      const Vector& p = walked_[i];
      const Vector seg = walked_[i + 1] - p;
      const double t = std::clamp((y - p).dot(seg) / std::max(seg.squaredNorm(), 1e-300), 0.0, 1.0);
      best = std::min(best, length(y - p - t * seg));
    }
    return best > 0.05 * L_;
  }

  // Paper 4.3: when regular steps fail, try (1) shorter steps through with the quadratic
  // predictor and a relaxed jump test (nodes, tacnodes), (2) the cusp strategy: back along
  // -v bent by -acceleration onto the other branch, (3) at the start only: the opposite flex.
  bool passSingularity() {
    struct Candidate {
      std::function<Vector(double)> move;  // the predicted move for a length h
      bool cusp;                           // corrected on the sphere of radius |move|
      double min_cos;
      const char* detail;
    };
    std::vector<Candidate> candidates;
    candidates.push_back({[this](double h) { return predictor(v_, a_, h); }, false, 0.5,
                          "passed with shorter steps and the quadratic predictor"});
    // At a cusp the outgoing branch is the mirror image of the incoming one in their common
    // tangent line (x(t) = c + t^2 u + t^3 w + ...: t -> -t flips only the part off u). The
    // line is estimated by the secant from a walk point h/16 behind.
    candidates.push_back({[this](double h) -> Vector {
                            const std::optional<Vector> far = pointBehind(h), near = pointBehind(h / 16);
                            if (!far || !near || (cur_.x - *near).norm() <= 0) return Vector();
                            const Vector t = (cur_.x - *near).normalized(), w = *far - cur_.x;
                            return 2.0 * w.dot(t) * t - w;
                          },
                          true, -1.0, "cusp: left on the mirror image of the incoming branch"});
    if (a_.allFinite() && a_.norm() > 0 && cur_.flexes > 0) {
      for (const bool with_velocity : {true, false}) {
        Vector w = cur_.projectNontrivial((with_velocity ? -v_ : Vector(Vector::Zero(v_.size()))) - unit(a_));
        if (w.norm() <= 1e-9) continue;
        w = unit(w);
        candidates.push_back({[w](double h) { return Vector(h * w); }, true, -1.0,
                              with_velocity ? "cusp: left along -velocity - acceleration" : "cusp: left along -acceleration"});
      }
    }
    for (const Candidate& c : candidates) {
      for (double f : {1.0, 0.5, 0.25, 0.125}) {
        const double h = f * L_;
        const Vector pred = c.move(h);
        if (pred.size() == 0 || !(pred.norm() > 0)) continue;
        Vector y;
        if (!(c.cusp ? policy_.convergeAway(cur_, cur_.x + pred, y) : policy_.converge(cur_.x + pred, y))) continue;
        const Vector s = y - cur_.x;
        if (length(s) < 0.3 * h) continue;
        if (s.dot(pred) / (s.norm() * pred.norm()) < c.min_cos) continue;
        if (!offWalkedPath(y)) continue;
        // The probe at the singular point is a sample, wherever it is: the event's sample.
        recordHidden();
        const int sample = static_cast<int>(out_.samples.size()) - 1;
        accept(y, h, /*transport=*/false, c.detail);
        resume_ = hidden_;
        if (outside_.size() == 0) out_.events.push_back({sample, EventKind::Singularity, c.detail, {}, {}, {}});
        return true;
      }
    }
    return false;
  }

  void accept(const Vector& y, double h, bool transport, const std::string&) {
    if (opt_.admissible && !opt_.admissible(y)) {
      outside_ = y;
      return;
    }
    Point next = analyzePoint(model_, opt_.factorization, y, &cur_);
    const Vector s = y - cur_.x;
    const int k1 = next.flexes;
    const Vector w = transported(next, s, transport);
    cur_ = std::move(next);
    v_ = w;
    a_ = acceleration(cur_, v_);
    h_ = h;
    walkThrough(y);
    // A probe short of the step stays hidden; what it saw (conditioning, flex dimension) goes
    // into the next sample, so that singular points between samples are still marked.
    conditioning_.see(cur_.rho, k1);
    hidden_ = true;
    if (chordFromSample(y) >= (1.0 - kSpacing) * L_) recordHidden();
  }

  // The unit tangent at `next`, the point reached by the secant s from the current one: the
  // current tangent transported there (transport), else the secant's part in its flex space.
  Vector transported(const Point& next, const Vector& s, bool transport) const {
    Vector w;
    const int k0 = cur_.flexes, k1 = next.flexes;
    if (k1 > 0 && transport && k0 == k1 && !next.sparse() && !cur_.sparse()) {
      // Vector transport (paper 4.2): the Procrustes rotation aligning the old tangent frame
      // with the new one, applied to the old tangent.
      Eigen::JacobiSVD<Matrix> svd(Matrix(next.B.transpose() * cur_.B), Eigen::ComputeFullU | Eigen::ComputeFullV);
      const Matrix O = svd.matrixU() * svd.matrixV().transpose();
      w = next.B * (O * (cur_.B.transpose() * v_));
    } else if (k1 > 0 && transport && k0 == k1) {
      // Large systems: the old tangent projected onto the new flex space, the discrete form of
      // parallel transport on the constraint manifold (the covariant derivative is the tangent
      // part of the derivative). It agrees with the Procrustes transport to second order in
      // the step, and needs no basis of either flex space.
      w = next.projectNontrivial(v_);
    } else if (k1 > 0) {
      w = next.projectNontrivial(s);  // after a singularity: follow the secant
    }
    if (w.size() == 0 || w.norm() < 1e-6 * s.norm()) w = s;
    w = unit(w);
    if (w.dot(s) < 0) w = -w;
    return w;
  }

  // y joins the walk, of which the shortest tail at least two steps long is kept.
  void walkThrough(const Vector& y) {
    walked_.push_back(y);
    // Keep the shortest tail of the walk that is at least two steps long.
    double tail = 0.0;
    size_t first = walked_.size() - 1;
    while (first > 0 && tail < 2.0 * L_) {
      tail += length(walked_[first] - walked_[first - 1]);
      --first;
    }
    walked_.erase(walked_.begin(), walked_.begin() + static_cast<std::ptrdiff_t>(first));
  }

  // Spacing of samples: within kSpacing * L of the step L, except at a singular point.
  static constexpr double kSpacing = 0.25;

  double chordFromSample(const Vector& x) const { return length(x - out_.samples.back()); }

  // Steps are measured on the configuration (the vertices' free coordinates), not on
  // auxiliary variables such as a polytope's facet normals: a step of h moves the vertices by
  // h, as it does for the framework of the same edges. A displacement of the auxiliary
  // variables alone (no free vertex) is measured on all of them.
  double length(const Vector& s) const {
    if (nc_ == s.size()) return s.norm();
    const double c = s.head(nc_).norm();
    return c > 1e-12 * s.norm() ? c : s.norm();
  }
  // s scaled to length 1.
  Vector unit(const Vector& s) const { return s / length(s); }

  // The current point becomes a sample (if it is not one already).
  void recordHidden() {
    if (!hidden_) return;
    out_.samples.push_back(cur_.x);
    conditioning_.sample();
    hidden_ = false;
    resume_ = false;
    recorded_ = true;
  }

  void finish() {
    out_.summary.steps_done = static_cast<int>(out_.samples.size()) - 1;
    double worst = 0.0;
    for (const Vector& x : out_.samples) {
      const Vector F = sys_.residuals(x);
      if (F.size()) worst = std::max(worst, F.cwiseAbs().maxCoeff());
    }
    out_.summary.max_residual = worst;
    conditioning_.markDips(out_.events);
  }

  DeformationPath stop(const std::string& reason) {
    finish();
    out_.summary.status = TrackStatus::StoppedEarly;
    out_.summary.reason = reason;
    return std::move(out_);
  }

  const Model& model_;
  const ConstraintSystem& sys_;
  TrackerOptions opt_;
  StepCallback cb_;
  CorrectionPolicy policy_;
  double L_;
  int nc_;  // the configuration's variables: the first nc_ of x
  DeformationPath out_;
  Point cur_;
  Vector v_, a_;
  Vector outside_;  // an inadmissible sample: the path ends before it
  double h_ = 0;
  std::vector<Vector> walked_;  // the last two steps' length of points moved through
  bool hidden_ = false;         // cur_ is a probe, not (yet) a sample
  bool resume_ = false;         // cur_ is a strategy's short move: the next move completes the step
  bool recorded_ = false;       // a sample was added since the loop last looked
  Conditioning conditioning_;
};

}  // namespace

DeformationPath trackMotion(const Model& model, const Vector& start, const Vector& direction,
                        const TrackerOptions& options, const StepCallback& on_step) {
  return Tracker(model, options, on_step).run(start, direction);
}

}  // namespace flexure::engine
