// Spherical disk packings (engine/systems/spherical_disk_packing.h).
#include "engine/systems/spherical_disk_packing.h"

#include <cmath>
#include <map>

#include "engine/systems/common.h"
#include "engine/terms.h"

namespace flexure::engine {

using systems_detail::addEdge;

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

std::optional<SymmetryGroup> SphericalDiskPacking::symmetryGroup() const {
  return SymmetryGroup{SymmetryGroup::Family::Moebius, system().numVertices(), 0};
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
  g.bars.edges = contacts_;
  g.bars.role = Bars::Role::Apex;
  g.caps.on = true;
  g.vertices.look = Vertices::Look::None;  // the caps show the points
  return g;
}

}  // namespace flexure::engine
