// Body-hinge and body-bar frameworks (engine/systems/body_framework.h).
#include "engine/systems/body_framework.h"

#include <Eigen/Dense>
#include <algorithm>
#include <limits>
#include <set>

#include "engine/systems/common.h"
#include "engine/terms.h"

namespace flexure::engine {

using systems_detail::listText;
using systems_detail::requireDistinct;

struct BodyFramework::Built {
  ConstraintSystem system;
  Matrix start;
  std::vector<std::vector<int>> bodies;
  std::vector<Edge> drawn;
};

namespace {

// Distance of q from the affine span of the points `basis` (columns of p).
double distanceFromSpan(const Matrix& p, const std::vector<int>& basis, const Vector& q) {
  const Vector o = p.col(basis[0]);
  if (basis.size() == 1) return (q - o).norm();
  Matrix A(p.rows(), static_cast<Eigen::Index>(basis.size()) - 1);
  for (size_t j = 1; j < basis.size(); ++j) A.col(static_cast<Eigen::Index>(j) - 1) = p.col(basis[j]) - o;
  const Eigen::HouseholderQR<Matrix> qr(A);
  const Matrix Q = qr.householderQ() * Matrix::Identity(A.rows(), A.cols());
  const Vector r = (q - o) - Q * (Q.transpose() * (q - o));
  return r.norm();
}

// Affine weights (summing to 1) of q in the frame of `basis`: least squares over the span.
std::vector<double> affineWeights(const Matrix& p, const std::vector<int>& basis, const Vector& q) {
  const Eigen::Index k = static_cast<Eigen::Index>(basis.size()), d = p.rows();
  Matrix A(d + 1, k);
  Vector b(d + 1);
  for (Eigen::Index j = 0; j < k; ++j) A.col(j) << p.col(basis[static_cast<size_t>(j)]), 1.0;
  b << q, 1.0;
  const Vector w = A.colPivHouseholderQr().solve(b);
  return std::vector<double>(w.data(), w.data() + w.size());
}

}  // namespace

BodyFramework::BodyFramework(std::string type_name, const Matrix& points, std::vector<std::vector<int>> bodies,
                             const std::vector<Edge>& bars, const std::vector<int>& pinned, int base)
    : BodyFramework(type_name, [&]() -> Built {
        const int d = static_cast<int>(points.rows()), n = static_cast<int>(points.cols());
        if (d != 2 && d != 3) throw ModelError("vertices", -1, "bodies live in 2D or 3D");
        if (bodies.empty()) throw ModelError("bodies", -1, "bodies is empty");
        ConstraintSystem sys(d, n, n);
        for (int v : pinned) sys.pin(v);
        std::vector<Edge> drawn;
        std::vector<int> used(static_cast<size_t>(n), 0);
        // The bodies each vertex is in, so far.
        std::vector<std::vector<int>> member(static_cast<size_t>(n));
        auto someBodyHolds = [&](const std::vector<int>& vs) {
          // Is there an earlier body containing all of vs? Then their relative position is fixed.
          for (int b : member[static_cast<size_t>(vs[0])]) {
            bool all = true;
            for (size_t i = 1; i < vs.size() && all; ++i) {
              const auto& m = member[static_cast<size_t>(vs[i])];
              all = std::find(m.begin(), m.end(), b) != m.end();
            }
            if (all) return true;
          }
          return false;
        };
        for (size_t b = 0; b < bodies.size(); ++b) {
          const auto& bv = bodies[b];
          const int item = static_cast<int>(b);
          const std::string name = "body " + std::to_string(b + 1) + " " + listText(bv, base);
          if (bv.empty()) throw ModelError("bodies", item, name + " has no vertices");
          if (std::set<int>(bv.begin(), bv.end()).size() != bv.size())
            throw ModelError("bodies", item, name + " lists a vertex twice");
          double diam = 0.0;
          for (size_t i = 0; i < bv.size(); ++i)
            for (size_t j = i + 1; j < bv.size(); ++j) {
              requireDistinct(points, bv[i], bv[j], "bodies", item, base, name);
              diam = std::max(diam, (points.col(bv[i]) - points.col(bv[j])).norm());
            }
          // The body's frame: a simplex of its vertices spanning its affine hull, built greedily.
          // Vertices already in earlier bodies first (bars between two vertices that an earlier
          // body holds are then left out: that body fixes their distance already, and a hinge
          // adds no dependency of its own), and among those the farthest from the span so far,
          // unless that is thin next to the others.
          std::vector<int> basis;
          std::vector<char> in_basis(bv.size(), 0);
          const double flat = 1e-9 * std::max(diam, extentOf(points) * 1e-300);
          // Any vertex starts the frame (its distance from the empty span counts as infinite:
          // a unit stand-in lay below `flat` for bodies 1e9 across and left the frame empty).
          const double unspanned = std::numeric_limits<double>::infinity();
          while (basis.size() < static_cast<size_t>(d) + 1 && basis.size() < bv.size()) {
            int best = -1, best_prior = -1;
            double best_dist = 0.0, far = 0.0;
            for (size_t i = 0; i < bv.size(); ++i) {
              if (in_basis[i]) continue;
              const double dist = basis.empty() ? unspanned : distanceFromSpan(points, basis, points.col(bv[i]));
              far = std::max(far, dist);
            }
            if (far <= flat) break;  // the span is the body's affine hull
            for (size_t i = 0; i < bv.size(); ++i) {
              if (in_basis[i]) continue;
              const double dist = basis.empty() ? unspanned : distanceFromSpan(points, basis, points.col(bv[i]));
              if (dist <= flat || dist < 0.05 * far) continue;  // thin: a poorly conditioned frame
              const int prior = member[static_cast<size_t>(bv[i])].empty() ? 0 : 1;
              if (prior > best_prior || (prior == best_prior && dist > best_dist)) {
                best = static_cast<int>(i);
                best_prior = prior;
                best_dist = dist;
              }
            }
            in_basis[static_cast<size_t>(best)] = 1;
            basis.push_back(bv[static_cast<size_t>(best)]);
          }
          for (size_t i = 0; i < basis.size(); ++i)
            for (size_t j = i + 1; j < basis.size(); ++j) {
              if (someBodyHolds({basis[i], basis[j]})) continue;
              sys.addTerm(SquaredDistanceTerm::atStart(basis[i], basis[j], points));
            }
          const int a = static_cast<int>(basis.size()) - 1;  // the body's affine dimension
          for (size_t i = 0; i < bv.size(); ++i) {
            if (in_basis[i]) continue;
            const int v = bv[i];
            std::vector<int> frame = basis;
            frame.insert(frame.begin(), v);
            if (someBodyHolds(frame)) continue;  // an earlier body holds v in this frame already
            std::vector<char> held(basis.size(), 0);
            bool any_held = false;
            for (size_t j = 0; j < basis.size(); ++j) any_held |= (held[j] = someBodyHolds({v, basis[j]})) != 0;
            if (!any_held || (a == 1 && d == 3)) {
              // v as an affine combination of the frame: d linear equations.
              sys.addTerm(std::make_unique<AffineCombinationTerm>(d, frame, affineWeights(points, basis, points.col(v)),
                                                                  diam, "body " + std::to_string(b + 1)));
              continue;
            }
            // An earlier body holds v's distance to part of the frame: v by its distances to a
            // of the frame's points (those first, then the others; v well off their span), and
            // in the frame's hyperplane when the body is flat, so that the held distances are
            // not imposed twice.
            std::vector<int> anchors;
            int best_held = -1;
            double best_dist = -1.0, widest = 0.0;
            std::vector<std::pair<std::vector<int>, int>> subsets;
            for (int skip = 0; skip <= a; ++skip) {  // the a-point subsets of the a + 1 frame points
              std::vector<int> sub;
              int h = 0;
              for (int j = 0; j <= a; ++j)
                if (j != skip) sub.push_back(basis[static_cast<size_t>(j)]), h += held[static_cast<size_t>(j)];
              widest = std::max(widest, distanceFromSpan(points, sub, points.col(v)));
              subsets.push_back({sub, h});
            }
            for (const auto& [sub, h] : subsets) {
              const double dist = distanceFromSpan(points, sub, points.col(v));
              if (dist < 0.1 * widest) continue;
              if (h > best_held || (h == best_held && dist > best_dist)) anchors = sub, best_held = h, best_dist = dist;
            }
            for (int w : anchors)
              if (!someBodyHolds({v, w}))
                sys.addTerm(SquaredDistanceTerm::atStart(v, w, points));
            if (a < d) {
              std::vector<int> simplex = basis;
              simplex.push_back(v);
              sys.addTerm(std::make_unique<SimplexVolumeTerm>(simplex, 0.0, diam * diam, d == 3 ? 1.0 / diam : 1.0));
            }
          }
          for (size_t i = 0; i < bv.size(); ++i) {
            used[static_cast<size_t>(bv[i])] = 1;
            if (bv.size() > 1 && (bv.size() > 2 || i == 0)) drawn.push_back({bv[i], bv[(i + 1) % bv.size()]});
          }
          for (int v : bv) member[static_cast<size_t>(v)].push_back(item);
        }
        std::set<std::pair<int, int>> seen;
        for (size_t k = 0; k < bars.size(); ++k) {
          const auto [a, c] = bars[k];
          const std::string name = "bar " + std::to_string(k + 1);
          if (a == c) throw ModelError("bars", static_cast<int>(k), name + " joins vertex " + std::to_string(a + base) + " to itself");
          if (!seen.insert(std::minmax(a, c)).second)
            throw ModelError("bars", static_cast<int>(k), name + " repeats the pair [" + std::to_string(std::min(a, c) + base) +
                                                              ", " + std::to_string(std::max(a, c) + base) + "]");
          for (int body : member[static_cast<size_t>(a)]) {
            const auto& m = member[static_cast<size_t>(c)];
            if (std::find(m.begin(), m.end(), body) != m.end())
              throw ModelError("bars", static_cast<int>(k),
                               name + " joins vertices " + std::to_string(a + base) + " and " + std::to_string(c + base) +
                                   " of body " + std::to_string(body + 1) + ", which holds their distance already");
          }
          requireDistinct(points, a, c, "bars", static_cast<int>(k), base, name);
          used[static_cast<size_t>(a)] = used[static_cast<size_t>(c)] = 1;
          sys.addTerm(SquaredDistanceTerm::atStart(a, c, points));
          drawn.push_back({a, c});
        }
        for (int v = 0; v < n; ++v)
          if (!used[static_cast<size_t>(v)])
            throw ModelError("vertices", v, "vertex " + std::to_string(v + base) + " is in no body and on no bar");
        sys.finalize(points);
        return Built{std::move(sys), points, std::move(bodies), std::move(drawn)};
      }()) {}

BodyFramework::BodyFramework(std::string type_name, Built&& b)
    : Model(std::move(b.system), std::move(b.start)), type_(std::move(type_name)), bodies_(std::move(b.bodies)),
      drawn_(std::move(b.drawn)) {}

int BodyFramework::rigidPartHolding(int a, int b) const {
  for (size_t k = 0; k < bodies_.size(); ++k) {
    const auto& body = bodies_[k];
    if (std::find(body.begin(), body.end(), a) != body.end() && std::find(body.begin(), body.end(), b) != body.end())
      return static_cast<int>(k);
  }
  return -1;
}

std::optional<SymmetryGroup> BodyFramework::symmetryGroup() const {
  return SymmetryGroup{SymmetryGroup::Family::Euclidean, system().numVertices(), 0};
}

Geometry BodyFramework::geometry() const {
  Geometry g = Model::geometry();
  g.bars.edges = drawn_;
  g.facets.polygons = bodies_;
  return g;
}

}  // namespace flexure::engine
