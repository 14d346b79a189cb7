// Sticky disk and sphere packings (engine/systems/sphere_packing.h).
#include "engine/systems/sphere_packing.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "engine/corrector.h"
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
                             double tolerance, int base, const std::vector<Contact>& sticky, bool contacts_at_start)
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
          if (contacts_at_start) sys.addTerm(SquaredDistanceTerm::atStart(i, j, points));
          else sys.addTerm(std::make_unique<SquaredDistanceTerm>(i, j, sum * sum));
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

std::optional<SymmetryGroup> SpherePacking::symmetryGroup() const {
  return SymmetryGroup{SymmetryGroup::Family::Euclidean, system().numVertices(), 0};
}

Geometry SpherePacking::geometry() const {
  Geometry g = Model::geometry();
  g.balls.radii = radii_;
  g.bars.edges = contacts_;
  g.bars.role = Bars::Role::Contact;
  g.vertices.look = Vertices::Look::None;  // the balls show the points
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

double SpherePacking::smallestSlack(const Matrix& positions, Id* which) const {
  Contact pair{};
  const double gap = smallestGap(positions, &pair);
  if (which) *which = pairKey(pair[0], pair[1], static_cast<int>(radii_.size()));
  return gap;
}

std::vector<Inequalities::Id> SpherePacking::active() const {
  std::vector<Id> out;
  for (const auto& [i, j] : contacts_) out.push_back(pairKey(i, j, static_cast<int>(radii_.size())));
  return out;
}

bool SpherePacking::isActive(Id i) const {
  return std::binary_search(contact_keys_.begin(), contact_keys_.end(), i);
}

std::vector<int> SpherePacking::vertices(Id i) const {
  const long long n = static_cast<long long>(radii_.size());
  if (n == 0) return {0, 0};
  return {static_cast<int>(i / n), static_cast<int>(i % n)};
}

std::string SpherePacking::name(Id i) const {
  const std::vector<int> v = vertices(i);
  return std::string(ballsName()) + " " + std::to_string(v[0] + indexBase()) + " and " + std::to_string(v[1] + indexBase());
}

std::shared_ptr<const Model> SpherePacking::withActive(const Matrix& at) const {
  return std::make_shared<SpherePacking>(at, radii_, pinned_, tolerance_, index_base_, contacts_);
}

}  // namespace flexure::engine
