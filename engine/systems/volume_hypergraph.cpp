// Volume hypergraphs (engine/systems/volume_hypergraph.h).
#include "engine/systems/volume_hypergraph.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <set>

#include "engine/systems/common.h"
#include "engine/terms.h"

namespace flexure::engine {

using systems_detail::listText;

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
    sys.addTerm(std::make_unique<SimplexVolumeTerm>(sv, vol, std::max(std::abs(vol), std::pow(longest, d)), 1.0,
                                                  /*target_from_start=*/true));
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

VolumeHypergraph::VolumeHypergraph(const Matrix& points, std::vector<std::vector<int>> simplices,
                                   const std::vector<int>& pinned, int base)
    : Model(volumeSystem(points, simplices, pinned, base), points), simplices_(std::move(simplices)) {}

std::optional<SymmetryGroup> VolumeHypergraph::symmetryGroup() const {
  return SymmetryGroup{SymmetryGroup::Family::EquiAffine, system().numVertices(), 0};
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
  g.bars.edges = uniqueBars(simplices_);
  g.bars.role = Bars::Role::Outline;
  g.simplices.list = simplices_;
  return g;
}

}  // namespace flexure::engine
