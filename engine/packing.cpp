#include "engine/packing.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "engine/corrector.h"
#include "engine/rigidity.h"
#include "engine/terms.h"

namespace flexure::engine {

struct SpherePacking::Built {
  ConstraintSystem system;
  Matrix start;
  std::vector<double> radii;
  std::vector<Contact> contacts;
  std::vector<int> pinned;
  double tolerance;
  int base;
};

namespace {

long long pairKey(int i, int j, int n) {
  if (i > j) std::swap(i, j);
  return static_cast<long long>(i) * n + j;
}

}  // namespace

SpherePacking::SpherePacking(const Matrix& points, std::vector<double> radii, const std::vector<int>& pinned,
                             double tolerance, int base, const std::vector<Contact>& sticky)
    : SpherePacking([&]() -> Built {
        const int d = static_cast<int>(points.rows()), n = static_cast<int>(points.cols());
        if (d != 2 && d != 3) throw ModelError("vertices", -1, "a sphere packing lives in 2D (disks) or 3D (spheres)");
        const char* balls = d == 2 ? "disks" : "spheres";
        if (static_cast<int>(radii.size()) != n)
          throw ModelError("radii", -1, "radii has " + std::to_string(radii.size()) + " entries for " +
                                            std::to_string(n) + " vertices");
        for (int i = 0; i < n; ++i)
          if (!(radii[static_cast<size_t>(i)] > 0) || !std::isfinite(radii[static_cast<size_t>(i)]))
            throw ModelError("radii", i, "the radius of vertex " + std::to_string(i + base) + " must be positive");
        if (!(tolerance > 0 && tolerance < 0.1))
          throw ModelError("tolerance", -1, "the contact tolerance must be in (0, 0.1), relative to r_i + r_j");
        std::vector<long long> forced;
        for (const auto& [i, j] : sticky) {
          if (i < 0 || j < 0 || i >= n || j >= n || i == j) throw std::invalid_argument("bad sticky contact");
          forced.push_back(pairKey(i, j, n));
        }
        std::sort(forced.begin(), forced.end());
        std::vector<Contact> contacts;
        for (int i = 0; i < n; ++i)
          for (int j = i + 1; j < n; ++j) {
            const double sum = radii[static_cast<size_t>(i)] + radii[static_cast<size_t>(j)];
            const double dist = (points.col(i) - points.col(j)).norm();
            const double gap = (dist - sum) / sum;
            if (std::binary_search(forced.begin(), forced.end(), pairKey(i, j, n)) || std::abs(gap) <= tolerance) {
              contacts.push_back({i, j});
            } else if (gap < 0) {
              throw ModelError("vertices", j,
                               std::string(balls) + " " + std::to_string(i + base) + " and " + std::to_string(j + base) +
                                   " overlap: their centres are " + shortNumber(dist) + " apart, their radii add up to " +
                                   shortNumber(sum));
            }
          }
        ConstraintSystem sys(d, n, n);
        for (int v : pinned) sys.pin(v);
        for (const auto& [i, j] : contacts) {
          const double sum = radii[static_cast<size_t>(i)] + radii[static_cast<size_t>(j)];
          sys.addTerm(std::make_unique<SquaredDistanceTerm>(i, j, sum * sum));
        }
        sys.finalize(points);
        // Touching within the tolerance: move onto exact contact.
        Matrix start = points;
        const Vector x = sys.freeCoordinates(points);
        const Vector F = sys.residuals(x);
        if (F.size() && F.cwiseAbs().maxCoeff() > 1e-13 * sys.residualScale()) {
          CorrectorOptions opt;
          opt.max_iterations = 100;
          const CorrectorResult r = correct(sys, x, opt);
          if (r.status != CorrectorStatus::Converged)
            throw ModelError("vertices", -1,
                             std::string("the touching ") + balls + " cannot all be put in exact contact near the given "
                                 "centres (" + toString(r.status) + ")");
          start = sys.positions(r.x);
        }
        return Built{std::move(sys), std::move(start), std::move(radii), std::move(contacts), pinned, tolerance, base};
      }()) {}

SpherePacking::SpherePacking(Built&& b)
    : Model(std::move(b.system), std::move(b.start)), radii_(std::move(b.radii)), contacts_(std::move(b.contacts)),
      pinned_(std::move(b.pinned)), tolerance_(b.tolerance), index_base_(b.base) {
  for (const auto& [i, j] : contacts_) contact_keys_.push_back(pairKey(i, j, static_cast<int>(radii_.size())));
  std::sort(contact_keys_.begin(), contact_keys_.end());
}

Matrix SpherePacking::symmetryGenerators(const Matrix& positions) const {
  return euclideanGenerators(positions, system().numVertices());
}

Geometry SpherePacking::geometry() const {
  Geometry g = Model::geometry();
  g.radii = radii_;
  g.bars = contacts_;
  return g;
}

bool SpherePacking::isContact(int i, int j) const {
  return std::binary_search(contact_keys_.begin(), contact_keys_.end(), pairKey(i, j, static_cast<int>(radii_.size())));
}

double SpherePacking::smallestGap(const Matrix& positions, Contact* pair) const {
  const int n = static_cast<int>(radii_.size());
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      const double sum = radii_[static_cast<size_t>(i)] + radii_[static_cast<size_t>(j)];
      const double d2 = (positions.col(i) - positions.col(j)).squaredNorm();
      // Cheap reject: far apart compared with the best gap so far.
      if (best < std::numeric_limits<double>::infinity() && d2 > sum * sum * (1 + best) * (1 + best)) continue;
      const double gap = (std::sqrt(d2) - sum) / sum;
      if (gap < best && !isContact(i, j)) {
        best = gap;
        if (pair) *pair = {i, j};
      }
    }
  return best;
}

// ---------------------------------------------------------------------------------------------

namespace {

// The point of the corrected chord from x0 (no overlap) to x1 (an overlap) where the first pair
// comes into contact: bisection on the smallest gap until it is in [0, tol / 10] (or x0 itself
// when it is already that close). Empty when the corrector fails or the gap does not close.
Vector locateContact(const SpherePacking& p, const Vector& x0, const Vector& x1, const CorrectorOptions& copt) {
  const ConstraintSystem& sys = p.system();
  const double close = 0.1 * p.tolerance();
  if (p.smallestGap(sys.positions(x0)) <= close) return x0;
  double lo = 0, hi = 1;
  for (int it = 0; it < 80; ++it) {
    const double mid = 0.5 * (lo + hi);
    const CorrectorResult r = correct(sys, x0 + mid * (x1 - x0), copt);
    if (r.status != CorrectorStatus::Converged) return {};
    const double g = p.smallestGap(sys.positions(r.x));
    if (g >= 0 && g <= close) return r.x;
    (g < 0 ? hi : lo) = mid;
  }
  return {};
}

std::string pairText(const SpherePacking& p, const SpherePacking::Contact& c) {
  return std::string(p.ballsName()) + " " + std::to_string(c[0] + p.indexBase()) + " and " +
         std::to_string(c[1] + p.indexBase());
}

}  // namespace

TrackResult trackStickyPacking(const SpherePacking& packing, const Vector& direction, const TrackerOptions& options,
                               const StepCallback& on_step) {
  TrackResult out;
  out.samples.push_back(packing.startCoordinates());
  out.summary.steps_requested = options.steps;
  out.summary.seed = options.seed;
  std::unique_ptr<SpherePacking> owned;  // the packing with the contacts found so far
  const SpherePacking* cur = &packing;
  Vector dir = direction;
  int done = 0;
  auto finish = [&](TrackStatus status, std::string reason) {
    out.summary.status = status;
    out.summary.reason = std::move(reason);
    out.summary.steps_done = static_cast<int>(out.samples.size()) - 1;
    return std::move(out);
  };
  auto residual = [&](const SpherePacking& p, const Vector& x) {
    const Vector F = p.system().residuals(x);
    return F.size() ? F.cwiseAbs().maxCoeff() : 0.0;
  };
  while (true) {
    TrackerOptions opt = options;
    opt.steps = options.steps - done;
    opt.sample_offset = done;
    const double tol = cur->tolerance();
    opt.admissible = [&](const Vector& y) { return cur->smallestGap(cur->system().positions(y)) >= -tol; };
    StepCallback cb;
    if (on_step) cb = [&, base = done](int s, int) { return on_step(base + s, options.steps); };
    TrackResult seg = trackMotion(*cur, out.samples.back(), dir, opt, cb);
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
        reason += " (after " + std::to_string(owned->contacts().size() - packing.contacts().size()) + " new contact(s))";
      return finish(seg.summary.status, reason);
    }
    // An overlap at the next sample: find where the first pair touches and make it a contact.
    const Vector x0 = out.samples.back(), x1 = seg.outside;  // copies: samples grows below
    SpherePacking::Contact first{};
    cur->smallestGap(cur->system().positions(x1), &first);
    CorrectorOptions copt = options.corrector;
    const Vector xc = locateContact(*cur, x0, x1, copt);
    if (xc.size() == 0)
      return finish(TrackStatus::StoppedEarly, "could not locate the contact of " + pairText(*cur, first) +
                                                   " after sample " + std::to_string(done) +
                                                   " (the corrector failed on the chord to the overlap)");
    std::vector<SpherePacking::Contact> contacts = cur->contacts();
    std::unique_ptr<SpherePacking> next;
    try {
      next = std::make_unique<SpherePacking>(cur->system().positions(xc), cur->radii(), cur->pinned(), tol,
                                             cur->indexBase(), contacts);
    } catch (const std::exception& e) {
      return finish(TrackStatus::StoppedEarly, "the contact of " + pairText(*cur, first) + " after sample " +
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
    std::string added;
    for (const auto& c : next->contacts())
      if (!cur->isContact(c[0], c[1])) {
        out.events.push_back({done, "contact", pairText(*next, c) + " touch", {c[0], c[1]}});
        added += (added.empty() ? "" : ", ") + pairText(*next, c);
      }
    const Vector secant = x1 - x0;
    owned = std::move(next);
    cur = owned.get();
    if (on_step && !on_step(done, options.steps)) return finish(TrackStatus::StoppedByCallback, "stopped on request");
    if (done >= options.steps) return finish(TrackStatus::Success, "");
    RigidityOptions ro;
    ro.rank_tolerance = options.factorization.rank_tolerance;
    ro.dense_limit = options.factorization.dense_limit;
    ro.max_second_order_size = 0;
    ro.motion_check_steps = 0;
    const RigidityReport rep = analyzeRigidity(*cur, xs, ro);
    if (rep.nontrivial == 0)
      return finish(TrackStatus::StoppedEarly, "the packing became rigid at sample " + std::to_string(done) +
                                                   " when " + added +
                                                   " touched: no nontrivial infinitesimal flex is left");
    // Go on in the direction of travel, as far as the new contacts allow.
    dir = rep.flex_basis * (rep.flex_basis.transpose() * secant);
    if (dir.norm() < 1e-6 * secant.norm()) dir = rep.flex_basis * rep.auto_flex;
  }
}

}  // namespace flexure::engine
