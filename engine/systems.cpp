#include "engine/systems.h"

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <algorithm>
#include <Eigen/SVD>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <random>
#include <set>

#include "engine/corrector.h"

namespace flexure::engine {

namespace {

std::string listText(const std::vector<int>& f, int base) {
  std::string s = "[";
  for (size_t i = 0; i < f.size(); ++i) s += (i ? ", " : "") + std::to_string(f[i] + base);
  return s + "]";
}

// Bars of a framework-like system, deduplicated: each pair once, else a ModelError at `key`.
void addEdge(std::map<std::pair<int, int>, std::string>& seen, int a, int b, const std::string& owner,
             const std::string& key, int item, int base) {
  const auto e = std::minmax(a, b);
  if (a == b) throw ModelError(key, item, owner + " joins vertex " + std::to_string(a + base) + " to itself");
  auto it = seen.find(e);
  if (it != seen.end())
    throw ModelError(key, item, owner + " repeats the pair [" + std::to_string(e.first + base) + ", " +
                                    std::to_string(e.second + base) + "] of " + it->second);
  seen[e] = owner;
}

void requireDistinct(const Matrix& p, int a, int b, const std::string& key, int item, int base, const std::string& what) {
  if ((p.col(a) - p.col(b)).norm() <= 1e-12 * extentOf(p))
    throw ModelError(key, item, what + ": vertices " + std::to_string(a + base) + " and " + std::to_string(b + base) +
                                    " coincide");
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Body-hinge and body-bar frameworks

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
              sys.addTerm(std::make_unique<SquaredDistanceTerm>(
                  basis[i], basis[j], (points.col(basis[i]) - points.col(basis[j])).squaredNorm()));
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
                sys.addTerm(std::make_unique<SquaredDistanceTerm>(v, w, (points.col(v) - points.col(w)).squaredNorm()));
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
          sys.addTerm(std::make_unique<SquaredDistanceTerm>(a, c, (points.col(a) - points.col(c)).squaredNorm()));
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

int BodyFramework::bodyHolding(int a, int b) const {
  for (size_t k = 0; k < bodies_.size(); ++k) {
    const auto& body = bodies_[k];
    if (std::find(body.begin(), body.end(), a) != body.end() && std::find(body.begin(), body.end(), b) != body.end())
      return static_cast<int>(k);
  }
  return -1;
}

Matrix BodyFramework::symmetryGenerators(const Matrix& positions) const {
  return euclideanGenerators(positions, system().numVertices());
}

Geometry BodyFramework::geometry() const {
  Geometry g = Model::geometry();
  g.bars = drawn_;
  g.facets = bodies_;
  return g;
}

// ---------------------------------------------------------------------------------------------
// Angular frameworks

namespace {

// The cosine and sine of angle (i, j, k) at j (2D: signed, from the cross product; 3D: the
// sine is nonnegative).
std::array<double, 2> angleCosSin(const Matrix& p, int i, int j, int k) {
  const Vector u = p.col(i) - p.col(j), w = p.col(k) - p.col(j);
  const double nu = u.norm(), nw = w.norm();
  const double c = u.dot(w) / (nu * nw);
  const double s = p.rows() == 2 ? (u[0] * w[1] - u[1] * w[0]) / (nu * nw) : std::sqrt(std::max(0.0, 1 - c * c));
  return {c, s};
}

ConstraintSystem angularSystem(const Matrix& p, const std::vector<AngularFramework::Angle>& angles,
                               const std::vector<int>& pinned, int base) {
  const int d = static_cast<int>(p.rows()), n = static_cast<int>(p.cols());
  if (d != 2 && d != 3) throw ModelError("vertices", -1, "an angular framework lives in 2D or 3D");
  if (angles.empty()) throw ModelError("angles", -1, "angles is empty");
  ConstraintSystem sys(d, n, n);
  for (int v : pinned) sys.pin(v);
  std::set<std::array<int, 3>> seen;
  for (size_t a = 0; a < angles.size(); ++a) {
    const auto [i, j, k] = angles[a];
    const int item = static_cast<int>(a);
    const std::string name = "angle [" + std::to_string(i + base) + ", " + std::to_string(j + base) + ", " +
                             std::to_string(k + base) + "]";
    if (i == j || j == k || i == k) throw ModelError("angles", item, name + " repeats a vertex");
    if (!seen.insert({std::min(i, k), j, std::max(i, k)}).second)
      throw ModelError("angles", item, name + " is given twice");
    requireDistinct(p, i, j, "angles", item, base, name);
    requireDistinct(p, k, j, "angles", item, base, name);
    const auto [c, s] = angleCosSin(p, i, j, k);
    if (d == 3 && s < 1e-6)
      throw ModelError("angles", item, name + " is 0 or 180 degrees; in 3D the angle constraint is singular there");
    sys.addTerm(std::make_unique<AngleTerm>(i, j, k, c, s, (p.col(i) - p.col(j)).norm() * (p.col(k) - p.col(j)).norm()));
  }
  sys.finalize(p);
  return sys;
}

std::vector<std::array<int, 2>> uniqueBars(const std::vector<std::vector<int>>& cycles) {
  std::set<std::pair<int, int>> seen;
  std::vector<std::array<int, 2>> out;
  for (const auto& c : cycles)
    for (size_t i = 0; i < c.size(); ++i)
      for (size_t j = i + 1; j < c.size(); ++j)
        if (seen.insert(std::minmax(c[i], c[j])).second) out.push_back({c[i], c[j]});
  return out;
}

}  // namespace

AngularFramework::AngularFramework(const Matrix& points, std::vector<Angle> angles, const std::vector<int>& pinned,
                                   int base)
    : Model(angularSystem(points, angles, pinned, base), points), angles_(std::move(angles)) {
  for (const auto& [i, j, k] : angles_) start_cos_sin_.push_back(angleCosSin(points, i, j, k));
}

int AngularFramework::turnedAngle(const Vector& x) const {
  if (system().dimension() != 2) return -1;
  const Matrix p = system().vertexPositions(x);
  for (size_t a = 0; a < angles_.size(); ++a) {
    const auto [i, j, k] = angles_[a];
    const Vector u = p.col(i) - p.col(j), w = p.col(k) - p.col(j);
    // |u||w| cos(theta - theta0): positive while the angle is the start's, whatever the arms.
    const auto [c, s] = start_cos_sin_[a];
    if (!(c * u.dot(w) + s * (u[0] * w[1] - u[1] * w[0]) > 0)) return static_cast<int>(a);
  }
  return -1;
}

std::function<bool(const Vector&)> AngularFramework::admissibleFrom(const Vector&) const {
  if (system().dimension() != 2) return {};
  return [this](const Vector& y) { return turnedAngle(y) < 0; };
}

std::string AngularFramework::outsideReason(const Vector& y, int index_base) const {
  const int e = turnedAngle(y);
  if (e < 0) return {};
  const auto [i, j, k] = angles_[static_cast<size_t>(e)];
  return "angle [" + std::to_string(i + index_base) + ", " + std::to_string(j + index_base) + ", " +
         std::to_string(k + index_base) + "] would turn by 180 degrees next (a vertex passes through its apex " +
         std::to_string(j + index_base) + ", where the angle is undefined)";
}

Matrix AngularFramework::symmetryGenerators(const Matrix& positions) const {
  return similarityGenerators(positions, system().numVertices());
}

Vector AngularFramework::congruenceInvariants(const Matrix& positions) const {
  const Vector d = Model::congruenceInvariants(positions);
  const double mean = d.size() ? d.mean() : 0.0;
  return mean > 0 ? Vector(d / mean) : d;
}

Geometry AngularFramework::geometry() const {
  Geometry g = Model::geometry();
  std::set<std::pair<int, int>> seen;
  for (const auto& [i, j, k] : angles_)
    for (auto e : {std::minmax(i, j), std::minmax(k, j)})
      if (seen.insert(e).second) g.bars.push_back({e.first, e.second});
  for (const auto& [i, j, k] : angles_) g.angles.push_back({i, j, k});
  return g;
}

// ---------------------------------------------------------------------------------------------
// Volume hypergraphs

namespace {

ConstraintSystem volumeSystem(const Matrix& p, const std::vector<std::vector<int>>& simplices,
                              const std::vector<int>& pinned, int base) {
  const int d = static_cast<int>(p.rows()), n = static_cast<int>(p.cols());
  if (d != 2 && d != 3) throw ModelError("vertices", -1, "a volume hypergraph lives in 2D or 3D");
  if (simplices.empty()) throw ModelError("simplices", -1, "simplices is empty");
  const double L = extentOf(p);
  ConstraintSystem sys(d, n, n);
  for (int v : pinned) sys.pin(v);
  std::set<std::vector<int>> seen;
  for (size_t s = 0; s < simplices.size(); ++s) {
    const auto& sv = simplices[s];
    const int item = static_cast<int>(s);
    const std::string name = "simplex " + std::to_string(s + 1) + " " + listText(sv, base);
    if (static_cast<int>(sv.size()) != d + 1)
      throw ModelError("simplices", item, name + " has " + std::to_string(sv.size()) + " vertices; in " +
                                              std::to_string(d) + "D a simplex has " + std::to_string(d + 1));
    std::vector<int> sorted = sv;
    std::sort(sorted.begin(), sorted.end());
    if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end())
      throw ModelError("simplices", item, name + " lists a vertex twice");
    if (!seen.insert(sorted).second) throw ModelError("simplices", item, name + " is given twice");
    Matrix E(d, d);
    for (int i = 0; i < d; ++i) E.col(i) = p.col(sv[static_cast<size_t>(i + 1)]) - p.col(sv[0]);
    const double vol = E.determinant();
    double longest = 0;
    for (int i = 0; i < d; ++i) longest = std::max(longest, E.col(i).norm());
    if (std::abs(vol) <= 1e-12 * std::pow(L, d))
      throw ModelError("simplices", item, name + " has volume 0 (its vertices are affinely dependent): "
                                                 "its orientation, which the constraint keeps, is undefined");
    sys.addTerm(std::make_unique<SimplexVolumeTerm>(sv, vol, std::max(std::abs(vol), std::pow(longest, d))));
  }
  sys.finalize(p);
  return sys;
}

}  // namespace

VolumeHypergraph::VolumeHypergraph(const Matrix& points, std::vector<std::vector<int>> simplices,
                                   const std::vector<int>& pinned, int base)
    : Model(volumeSystem(points, simplices, pinned, base), points), simplices_(std::move(simplices)) {}

Matrix VolumeHypergraph::symmetryGenerators(const Matrix& positions) const {
  return equiAffineGenerators(positions, system().numVertices());
}

Vector VolumeHypergraph::congruenceInvariants(const Matrix& positions) const {
  const int d = system().dimension(), n = system().numVertices();
  std::vector<double> out;
  std::vector<int> idx(static_cast<size_t>(d + 1));
  for (int i = 0; i <= d; ++i) idx[static_cast<size_t>(i)] = i;
  Matrix E(d, d);
  while (n > d && out.size() < 20000) {
    for (int i = 0; i < d; ++i) E.col(i) = positions.col(idx[static_cast<size_t>(i + 1)]) - positions.col(idx[0]);
    out.push_back(E.determinant());
    // Next (d + 1)-subset in lexicographic order.
    int i = d;
    while (i >= 0 && idx[static_cast<size_t>(i)] == n - 1 - (d - i)) --i;
    if (i < 0) break;
    ++idx[static_cast<size_t>(i)];
    for (int j = i + 1; j <= d; ++j) idx[static_cast<size_t>(j)] = idx[static_cast<size_t>(j - 1)] + 1;
  }
  return Eigen::Map<const Vector>(out.data(), static_cast<Eigen::Index>(out.size()));
}

Geometry VolumeHypergraph::geometry() const {
  Geometry g = Model::geometry();
  g.bars = uniqueBars(simplices_);
  g.simplices = simplices_;
  return g;
}

// ---------------------------------------------------------------------------------------------
// Spherical disk packings

namespace {

double lorentz(const Vector& a, const Vector& b) { return a.dot(b) - 1.0; }

}  // namespace

SphericalDiskPacking::SphericalDiskPacking(const Matrix& points, std::vector<Contact> contacts,
                                           const std::vector<int>& pinned, int base)
    : Model(
          [&]() {
            const int n = static_cast<int>(points.cols());
            if (points.rows() != 3) throw ModelError("vertices", -1, "a spherical disk packing lives in 3D");
            for (int v = 0; v < n; ++v)
              if (!(points.col(v).norm() > 1.0 + 1e-9))
                throw ModelError("vertices", v, "vertex " + std::to_string(v + base) + " has norm " +
                                                    shortNumber(points.col(v).norm()) +
                                                    "; a cap is a point a with |a| > 1 (the plane a.y = 1)");
            if (contacts.empty()) throw ModelError("contacts", -1, "contacts is empty");
            ConstraintSystem sys(3, n, n);
            for (int v : pinned) sys.pin(v);
            std::map<std::pair<int, int>, std::string> seen;
            for (size_t c = 0; c < contacts.size(); ++c) {
              const auto [a, b] = contacts[c];
              addEdge(seen, a, b, "contact " + std::to_string(c + 1), "contacts", static_cast<int>(c), base);
              const Vector pa = points.col(a), pb = points.col(b);
              const double I = lorentz(pa, pb) / std::sqrt(lorentz(pa, pa) * lorentz(pb, pb));
              sys.addTerm(std::make_unique<InversiveDistanceTerm>(a, b, I));
            }
            sys.finalize(points);
            return sys;
          }(),
          points),
      contacts_(std::move(contacts)) {
  for (const auto& [a, b] : contacts_) {
    const Vector pa = points.col(a), pb = points.col(b);
    inversive_.push_back(lorentz(pa, pb) / std::sqrt(lorentz(pa, pa) * lorentz(pb, pb)));
  }
}

Matrix SphericalDiskPacking::symmetryGenerators(const Matrix& positions) const {
  return moebiusGenerators(positions, system().numVertices());
}

Vector SphericalDiskPacking::congruenceInvariants(const Matrix& positions) const {
  const int n = system().numVertices();
  std::vector<double> out;
  for (int a = 0; a < n; ++a)
    for (int b = a + 1; b < n; ++b) {
      const Vector pa = positions.col(a), pb = positions.col(b);
      out.push_back(lorentz(pa, pb) / std::sqrt(lorentz(pa, pa) * lorentz(pb, pb)));
    }
  return Eigen::Map<const Vector>(out.data(), static_cast<Eigen::Index>(out.size()));
}

Geometry SphericalDiskPacking::geometry() const {
  Geometry g = Model::geometry();
  g.bars = contacts_;
  g.caps = true;
  return g;
}

// ---------------------------------------------------------------------------------------------
// Frameworks on surfaces

struct FrameworkOnSurface::Built {
  ConstraintSystem system;
  Matrix start;
  std::vector<Edge> edges;
  std::shared_ptr<const ScalarField> surface;
  Matrix killing;
  Eigen::Vector3d centre;
  double scale;
  bool quadratic;
};

namespace {

// Newton's method along the gradient: the nearby point of f = 0 (false if it does not converge).
bool projectOntoSurface(const ScalarField& f, Eigen::Vector3d& x, double scale) {
  for (int it = 0; it < 60; ++it) {
    double v, g[3];
    f.evaluate(x.data(), &v, g, nullptr);
    const Eigen::Vector3d grad(g[0], g[1], g[2]);
    const double gn = grad.squaredNorm();
    if (!std::isfinite(v) || !(gn > 0)) return false;
    if (std::abs(v) <= 1e-13 * std::sqrt(gn) * std::max(scale, 1e-300)) return true;
    x -= v * grad / gn;
  }
  return false;
}

// True when f is a polynomial of degree at most 2 (a sphere, an ellipsoid, a hyperboloid, a
// cylinder, a cone or a pair of planes written as a quadric): its Hessian is the same at every
// point, and f equals its second-order Taylor expansion about the vertices' centre. Checked at
// points sampled around the vertices (a fixed seed) to rounding relative to the size of the
// terms; an expression is analytic, so a constant Hessian on these points is a constant Hessian.
bool isQuadricField(const ScalarField& f, const Matrix& points, double extent) {
  const Eigen::Vector3d centre = points.rowwise().mean();
  // Sampled within the framework's extent (one vertex: within its distance from the origin).
  const double scale = extent > 1e-250 ? extent : std::max(centre.norm(), 1.0);
  double f0, g0[3], h0[9];
  f.evaluate(centre.data(), &f0, g0, h0);
  const Eigen::Vector3d grad0(g0[0], g0[1], g0[2]);
  const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> H0(h0);
  if (!std::isfinite(f0) || !grad0.allFinite() || !H0.allFinite()) return false;
  std::mt19937_64 rng(0x9aad);
  std::normal_distribution<double> gauss(0.0, 1.0);
  for (int k = 0; k < 24; ++k) {
    const Eigen::Vector3d r = scale * Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng));
    const Eigen::Vector3d x = (k < points.cols() ? Eigen::Vector3d(points.col(k)) : centre) + r;
    const Eigen::Vector3d dx = x - centre;
    double fx, gx[3], hx[9];
    f.evaluate(x.data(), &fx, gx, hx);
    const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> Hx(hx);
    if (!std::isfinite(fx) || !Hx.allFinite()) return false;
    const double h_size = std::max(H0.cwiseAbs().maxCoeff(), Hx.cwiseAbs().maxCoeff());
    if ((Hx - H0).cwiseAbs().maxCoeff() > 1e-9 * h_size) return false;
    const double lin = grad0.dot(dx), quad = 0.5 * dx.dot(H0 * dx);
    const double size = std::abs(f0) + std::abs(lin) + std::abs(quad) + std::abs(fx);
    if (std::abs(fx - (f0 + lin + quad)) > 1e-9 * size) return false;
  }
  return true;
}

// Killing fields omega x (p - centre) + t (as (L omega, t)) tangent to the surface at points
// sampled near the vertices: the null space of the tangency conditions.
Matrix surfaceIsometries(const ScalarField& f, const Matrix& points, double scale) {
  const Eigen::Vector3d centre = points.rowwise().mean();
  std::mt19937_64 rng(0x5eed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::vector<Eigen::Vector3d> samples;
  const int per_vertex = std::max(8, 240 / static_cast<int>(points.cols()));
  for (int v = 0; v < points.cols(); ++v) {
    samples.push_back(points.col(v));
    for (int k = 0; k < per_vertex; ++k) {
      Eigen::Vector3d x = points.col(v);
      for (int c = 0; c < 3; ++c) x[c] += 0.5 * scale * gauss(rng);
      if (projectOntoSurface(f, x, scale) && (x - Eigen::Vector3d(points.col(v))).norm() < 4 * scale) samples.push_back(x);
    }
  }
  Matrix A(static_cast<Eigen::Index>(samples.size()), 6);
  for (size_t i = 0; i < samples.size(); ++i) {
    double v, g[3];
    f.evaluate(samples[i].data(), &v, g, nullptr);
    Eigen::Vector3d grad(g[0], g[1], g[2]);
    grad /= grad.norm();
    const Eigen::Vector3d r = (samples[i] - centre) / scale;
    A.block(static_cast<Eigen::Index>(i), 0, 1, 3) = r.cross(grad).transpose();  // grad . (omega x r)
    A.block(static_cast<Eigen::Index>(i), 3, 1, 3) = grad.transpose();
  }
  Eigen::JacobiSVD<Matrix> svd(A, Eigen::ComputeFullV);
  const Vector& s = svd.singularValues();
  int rank = 0;
  while (rank < s.size() && s[rank] > 1e-7 * s[0]) ++rank;
  return svd.matrixV().rightCols(6 - rank);
}

}  // namespace

FrameworkOnSurface::FrameworkOnSurface(const Matrix& points, std::vector<Edge> edges, const std::vector<int>& pinned,
                                       std::shared_ptr<const ScalarField> surface, bool project_start, int base)
    : FrameworkOnSurface([&]() -> Built {
        const int n = static_cast<int>(points.cols());
        if (points.rows() != 3) throw ModelError("vertices", -1, "a framework on a surface lives in 3D");
        const double L = std::max(extentOf(points), 1e-300);
        std::map<std::pair<int, int>, std::string> seen;
        for (size_t e = 0; e < edges.size(); ++e) {
          addEdge(seen, edges[e][0], edges[e][1], "edge " + std::to_string(e + 1), "edges", static_cast<int>(e), base);
          requireDistinct(points, edges[e][0], edges[e][1], "edges", static_cast<int>(e), base,
                          "edge " + std::to_string(e + 1));
        }
        std::vector<char> is_pinned(static_cast<size_t>(n), 0);
        for (int v : pinned) is_pinned[static_cast<size_t>(v)] = 1;
        auto build = [&](const Matrix& p) {
          ConstraintSystem sys(3, n, n);
          for (int v : pinned) sys.pin(v);
          for (const auto& e : edges)
            sys.addTerm(std::make_unique<SquaredDistanceTerm>(e[0], e[1], (points.col(e[0]) - points.col(e[1])).squaredNorm()));
          for (int v = 0; v < n; ++v) {
            double f, g[3];
            surface->evaluate(p.col(v).data(), &f, g, nullptr);
            const double gn = Eigen::Vector3d(g[0], g[1], g[2]).norm();
            if (!std::isfinite(f) || !std::isfinite(gn))
              throw ModelError("vertices", v, "the surface " + surface->text() + " is not finite at vertex " +
                                                  std::to_string(v + base));
            if (!(gn > 0))
              throw ModelError("vertices", v, "the surface " + surface->text() + " has zero gradient at vertex " +
                                                  std::to_string(v + base) + " (a singular point)");
            sys.addTerm(std::make_unique<SurfaceTerm>(v, surface, L * L, L / gn));
          }
          sys.finalize(p);
          return sys;
        };
        // Distance of each vertex from the surface, to first order |f| / |grad f|.
        auto offSurface = [&](const Matrix& p, int v) {
          double f, g[3];
          surface->evaluate(p.col(v).data(), &f, g, nullptr);
          return std::abs(f) / Eigen::Vector3d(g[0], g[1], g[2]).norm();
        };
        ConstraintSystem sys = build(points);
        Matrix start = points;
        for (int v = 0; v < n; ++v) {
          const double off = offSurface(points, v);
          if (off <= 1e-9 * L) continue;
          const std::string where = "vertex " + std::to_string(v + base) + " is about " + shortNumber(off) +
                                    " away from the surface " + surface->text();
          if (is_pinned[static_cast<size_t>(v)])
            throw ModelError("vertices", v, where + "; a pinned vertex must lie on it");
          if (!project_start)
            throw ModelError("vertices", v, where + " (set [system] project_start = true to move the start onto it)");
        }
        if (project_start) {
          CorrectorOptions opt;
          opt.max_iterations = 100;
          const CorrectorResult r = correct(sys, sys.freeCoordinates(points), opt);
          if (r.status != CorrectorStatus::Converged)
            throw ModelError("vertices", -1, "project_start: no configuration with these bar lengths on the surface " +
                                                 surface->text() + " was found near the start (" + toString(r.status) + ")");
          start = sys.positions(r.x);
          sys = build(start);
        }
        Matrix killing = surfaceIsometries(*surface, start, L);
        const Eigen::Vector3d centre = start.rowwise().mean();
        const bool quadratic = isQuadricField(*surface, start, L);
        return Built{std::move(sys), std::move(start), std::move(edges), std::move(surface), std::move(killing),
                     centre, L, quadratic};
      }()) {}

FrameworkOnSurface::FrameworkOnSurface(Built&& b)
    : Model(std::move(b.system), std::move(b.start)), edges_(std::move(b.edges)), surface_(std::move(b.surface)),
      killing_(std::move(b.killing)), centre_(b.centre), scale_(b.scale), quadratic_(b.quadratic) {}

Matrix FrameworkOnSurface::symmetryGenerators(const Matrix& positions) const {
  const int d = 3, blocks = static_cast<int>(positions.cols()), n = system().numVertices();
  Matrix g = Matrix::Zero(static_cast<Eigen::Index>(blocks) * d, killing_.cols());
  for (int j = 0; j < killing_.cols(); ++j) {
    const Eigen::Vector3d omega = killing_.col(j).head(3) / scale_, t = killing_.col(j).tail(3);
    for (int i = 0; i < n; ++i)
      g.block(i * d, j, d, 1) = omega.cross(Eigen::Vector3d(positions.col(i)) - centre_) + t;
    const double norm = g.col(j).norm();
    if (norm > 0) g.col(j) /= norm;
  }
  return g;
}

Geometry FrameworkOnSurface::geometry() const {
  Geometry g = Model::geometry();
  g.bars = edges_;
  g.surface = surface_.get();
  return g;
}

}  // namespace flexure::engine
