// Angular frameworks (engine/systems/angular_framework.h).
#include "engine/systems/angular_framework.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "engine/systems/common.h"
#include "engine/terms.h"

namespace flexure::engine {

using systems_detail::requireDistinct;

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

std::optional<SymmetryGroup> AngularFramework::symmetryGroup() const {
  return SymmetryGroup{SymmetryGroup::Family::Similarity, system().numVertices(), 0};
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
      if (seen.insert(e).second) g.bars.edges.push_back({e.first, e.second});
  for (const auto& [i, j, k] : angles_) g.angles.triples.push_back({i, j, k});
  return g;
}

}  // namespace flexure::engine
