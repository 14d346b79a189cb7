// Polytopes with edge-length constraints (engine/systems/polytope.h; convexHullFacets is in
// engine/convex_hull.cpp).
#include "engine/systems/polytope.h"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "engine/systems/common.h"
#include "engine/terms.h"

namespace flexure::engine {

struct Polytope::Built {
  ConstraintSystem system;
  Matrix start;
  std::vector<std::vector<int>> facets;
  std::vector<Edge> edges;
};

using systems_detail::listText;

Polytope::Polytope(const Matrix& points, std::vector<std::vector<int>> facets, const std::vector<int>& pinned,
                   double planarity_tolerance, int base)
    : Polytope([&]() -> Built {
        const int n = static_cast<int>(points.cols());
        const int F = static_cast<int>(facets.size());
        if (points.rows() != 3) throw ModelError("vertices", -1, "a polytope lives in 3D");
        if (F < 4) throw ModelError("facets", -1, "a polytope needs at least 4 facets");
        const double size = extentOf(points);
        // Edges: consecutive vertices of each facet, each in exactly two facets.
        std::map<std::pair<int, int>, std::vector<int>> edge_facets;
        std::vector<int> used(static_cast<size_t>(n), 0);
        for (int f = 0; f < F; ++f) {
          const auto& fv = facets[static_cast<size_t>(f)];
          const std::string name = "facet " + std::to_string(f + 1) + " " + listText(fv, base);
          if (fv.size() < 3) throw ModelError("facets", f, name + " has fewer than 3 vertices");
          std::set<int> distinct(fv.begin(), fv.end());
          if (distinct.size() != fv.size()) throw ModelError("facets", f, name + " lists a vertex twice");
          for (size_t i = 0; i < fv.size(); ++i) {
            const int a = fv[i], b = fv[(i + 1) % fv.size()];
            used[static_cast<size_t>(a)] = 1;
            edge_facets[std::minmax(a, b)].push_back(f);
          }
        }
        std::vector<Edge> edges;
        for (const auto& [e, fs] : edge_facets) {
          const std::string name = "edge [" + std::to_string(e.first + base) + ", " + std::to_string(e.second + base) + "]";
          if (fs.size() == 1)
            throw ModelError("facets", fs[0], name + " of facet " + std::to_string(fs[0] + 1) +
                                                  " is in no other facet: the facets do not close up");
          if (fs.size() > 2 || fs[0] == fs[1])
            throw ModelError("facets", fs.back(), name + " is in more than two facets");
          if ((points.col(e.first) - points.col(e.second)).norm() <= 1e-12 * size)
            throw ModelError("facets", fs[0], name + " has length 0");
          edges.push_back({e.first, e.second});
        }
        for (int v = 0; v < n; ++v)
          if (!used[static_cast<size_t>(v)])
            throw ModelError("vertices", v, "vertex " + std::to_string(v + base) + " is in no facet");
        const int E = static_cast<int>(edges.size());
        if (n - E + F != 2)
          throw ModelError("facets", -1, "Euler's formula fails: V - E + F = " + std::to_string(n) + " - " +
                                             std::to_string(E) + " + " + std::to_string(F) + " = " +
                                             std::to_string(n - E + F) + ", not 2 (edges come from the facets)");
        // Unit normals, outward from the centroid, by a least-squares plane through each facet.
        const Eigen::Vector3d centre = points.rowwise().mean();
        Matrix start(3, n + F);
        start.leftCols(n) = points;
        for (int f = 0; f < F; ++f) {
          const auto& fv = facets[static_cast<size_t>(f)];
          Matrix P(3, static_cast<Eigen::Index>(fv.size()));
          for (size_t i = 0; i < fv.size(); ++i) P.col(static_cast<Eigen::Index>(i)) = points.col(fv[i]);
          const Eigen::Vector3d c = P.rowwise().mean();
          Eigen::JacobiSVD<Matrix> svd(P.colwise() - c, Eigen::ComputeFullU);
          const Eigen::Vector3d s = svd.singularValues().head(3);
          const std::string name = "facet " + std::to_string(f + 1) + " " + listText(fv, base);
          if (s[1] <= 1e-9 * size) throw ModelError("facets", f, name + " is degenerate: its vertices are collinear");
          Eigen::Vector3d nf = svd.matrixU().col(2);
          double worst = 0;
          int worst_v = fv[0];
          for (int v : fv) {
            const double off = std::abs(nf.dot(points.col(v) - c));
            if (off > worst) worst = off, worst_v = v;
          }
          if (worst > planarity_tolerance * size) {
            throw ModelError("facets", f, name + " is not planar: vertex " + std::to_string(worst_v + base) + " is " +
                                              shortNumber(worst) + " away from the best plane through its vertices");
          }
          if (nf.dot(c - centre) < 0) nf = -nf;
          start.col(n + f) = size * nf;  // normals of length `size`: every variable a length
        }
        ConstraintSystem sys(3, n, n + F);
        for (int v : pinned) sys.pin(v);
        for (const auto& e : edges)
          sys.addTerm(SquaredDistanceTerm::atStart(e[0], e[1], points));
        for (int f = 0; f < F; ++f) {
          const auto& fv = facets[static_cast<size_t>(f)];
          for (size_t i = 1; i < fv.size(); ++i)
            sys.addTerm(std::make_unique<FacetPlaneTerm>(n + f, fv[0], fv[i], f,
                                                         size * (points.col(fv[i]) - points.col(fv[0])).norm()));
          sys.addTerm(std::make_unique<UnitNormTerm>(n + f, f, size));
        }
        sys.finalize(start);
        return Built{std::move(sys), std::move(start), std::move(facets), std::move(edges)};
      }()) {}

Polytope::Polytope(Built&& b)
    : Model(std::move(b.system), std::move(b.start)), facets_(std::move(b.facets)), edges_(std::move(b.edges)) {}

std::optional<SymmetryGroup> Polytope::symmetryGroup() const {
  return SymmetryGroup{SymmetryGroup::Family::Euclidean, system().numVertices(), static_cast<int>(facets_.size())};
}

Geometry Polytope::geometry() const {
  Geometry g = Model::geometry();
  g.bars.edges = edges_;
  g.facets.polygons = facets_;
  return g;
}

}  // namespace flexure::engine
