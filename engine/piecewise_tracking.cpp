#include "engine/piecewise_tracking.h"

#include <algorithm>
#include <memory>
#include <stdexcept>

#include "engine/active_set.h"
#include "engine/corrector.h"
#include "engine/motion_tracker.h"
#include "engine/rigidity.h"

namespace flexure::engine {

namespace {

// The point of the corrected chord from x0 (no overlap) to x1 (an overlap) where the first pair
// comes into contact: bisection on the smallest gap until it is in [0, tol / 10] (or x0 itself
// when it is already that close). Empty when the corrector fails or the gap does not close.
Vector locateContact(const Model& m, const Inequalities& p, const Vector& x0, const Vector& x1,
                     const CorrectorOptions& copt) {
  const ConstraintSystem& sys = m.system();
  const double close = 0.1 * p.tolerance();
  if (p.smallestSlack(sys.positions(x0)) <= close) return x0;
  double lo = 0, hi = 1;
  for (int it = 0; it < 80; ++it) {
    const double mid = 0.5 * (lo + hi);
    const CorrectorResult r = correct(sys, x0 + mid * (x1 - x0), copt);
    if (r.status != CorrectorStatus::Converged) return {};
    const double g = p.smallestSlack(sys.positions(r.x));
    if (g >= 0 && g <= close) return r.x;
    (g < 0 ? hi : lo) = mid;
  }
  return {};
}

// The inequalities of `model`, which must stick.
const Inequalities& stickingOf(const Model& model) {
  const Inequalities* q = model.inequalities();
  if (!q || q->rule() != Inequalities::Rule::Stick)
    throw std::logic_error("trackPiecewise: the " + model.typeName() + " model has no inequalities that stick");
  return *q;
}

}  // namespace

DeformationPath trackPiecewise(const Model& model, const Vector& direction, const TrackerOptions& options,
                               const StepCallback& on_step) {
  const Inequalities& start_set = stickingOf(model);
  DeformationPath out;
  out.samples.push_back(model.startCoordinates());
  out.summary.steps_requested = options.steps;
  out.summary.seed = options.seed;
  out.startOn(model);
  std::shared_ptr<const Model> owned;  // the model with the contacts found so far
  const Model* cur = &model;
  const Inequalities* set = &start_set;  // cur's
  Vector dir = direction;
  int done = 0;
  auto finish = [&](TrackStatus status, std::string reason) {
    out.summary.status = status;
    out.summary.reason = std::move(reason);
    out.summary.steps_done = static_cast<int>(out.samples.size()) - 1;
    return std::move(out);
  };
  auto residual = [&](const Model& p, const Vector& x) {
    const Vector F = p.system().residuals(x);
    return F.size() ? F.cwiseAbs().maxCoeff() : 0.0;
  };
  while (true) {
    TrackerOptions opt = options;
    opt.steps = options.steps - done;
    opt.sample_offset = done;
    const double tol = set->tolerance();
    opt.admissible = [&](const Vector& y) { return set->smallestSlack(cur->system().positions(y)) >= -tol; };
    StepCallback cb;
    if (on_step) cb = [&, base = done](int s, int) { return on_step(base + s, options.steps); };
    DeformationPath seg = trackMotion(*cur, out.samples.back(), dir, opt, cb);
    for (size_t i = 1; i < seg.samples.size(); ++i) out.samples.push_back(std::move(seg.samples[i]));
    for (TrackEvent& e : seg.events) {
      e.sample += done;
      out.events.push_back(std::move(e));
    }
    out.summary.rejected_steps += seg.summary.rejected_steps;
    out.summary.max_residual = std::max(out.summary.max_residual, seg.summary.max_residual);
    done = static_cast<int>(out.samples.size()) - 1;
    if (seg.summary.status != TrackStatus::LeftAdmissibleSet) {
      std::string reason = seg.summary.reason;
      if (seg.summary.status == TrackStatus::StoppedEarly && owned)
        reason += " (after " + std::to_string(set->active().size() - start_set.active().size()) + " new contact(s))";
      return finish(seg.summary.status, reason);
    }
    // An overlap at the next sample: find where the first pair touches and make it a contact.
    const Vector x0 = out.samples.back(), x1 = seg.outside;  // copies: samples grows below
    Inequalities::Id first{};
    set->smallestSlack(cur->system().positions(x1), &first);
    CorrectorOptions copt = options.corrector;
    const Vector xc = locateContact(*cur, *set, x0, x1, copt);
    if (xc.size() == 0)
      return finish(TrackStatus::StoppedEarly, "could not locate the contact of " + set->name(first) +
                                                   " after sample " + std::to_string(done) +
                                                   " (the corrector failed on the chord to the overlap)");
    std::shared_ptr<const Model> next;
    try {
      next = set->withActive(cur->system().positions(xc));
    } catch (const std::exception& e) {
      return finish(TrackStatus::StoppedEarly, "the contact of " + set->name(first) + " after sample " +
                                                   std::to_string(done) + " could not be added: " + e.what());
    }
    const Vector xs = next->startCoordinates();
    if ((xc - x0).norm() == 0) {
      out.samples.back() = xs;  // the last sample was already touching: snap it
    } else {
      out.samples.push_back(xs);
      done += 1;
    }
    out.summary.max_residual = std::max(out.summary.max_residual, residual(*next, xs));
    const Inequalities& next_set = stickingOf(*next);
    std::string added;
    for (const Inequalities::Id c : next_set.active())
      if (!set->isActive(c)) {
        out.events.push_back({done, EventKind::Contact, next_set.name(c) + " touch", next_set.vertices(c), {}, {}});
        added += (added.empty() ? "" : ", ") + next_set.name(c);
      }
    const Vector secant = x1 - x0;
    owned = std::move(next);
    cur = owned.get();
    set = &next_set;
    out.segments.push_back({done, owned});
    if (on_step && !on_step(done, options.steps)) return finish(TrackStatus::StoppedByCallback, "stopped on request");
    if (done >= options.steps) return finish(TrackStatus::Success, "");
    RigidityOptions ro;
    ro.rank_tolerance = options.factorization.rank_tolerance;
    ro.dense_limit = options.factorization.dense_limit;
    ro.max_second_order_size = 0;
    ro.motion_check_steps = 0;
    const RigidityReport rep = analyzeRigidity(*cur, xs, ro);
    if (rep.nontrivial == 0)
      // The motion is over, as it should be: a success, with the reason.
      return finish(TrackStatus::Success, "the packing became rigid at sample " + std::to_string(done) +
                                                   " when " + added +
                                                   " touched: no nontrivial infinitesimal flex is left");
    // Go on in the direction of travel, as far as the new contacts allow.
    dir = rep.flex_basis * (rep.flex_basis.transpose() * secant);
    if (dir.norm() < 1e-6 * secant.norm()) dir = rep.flex_basis * rep.auto_flex;
  }
}

}  // namespace flexure::engine
