// convexHullFacets (declared in engine/systems/polytope.h): Qhull's hull, O(n log n), merged into planar
// facets with flexure's tolerance and checked for points that are not corners.
#include <libqhull_r/qhull_ra.h>

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numeric>

#include "engine/systems/polytope.h"

namespace flexure::engine {

namespace {

// One Qhull run, freed on every exit path; its messages go to a scratch stream, not stderr.
class Qhull {
 public:
  Qhull(const Matrix& points) : qh_(std::make_unique<qhT>()), err_(std::tmpfile()) {
    qh_zero(qh_.get(), err_);
    // Qhull reads the points in place (ismalloc false): 3 doubles per point, as Eigen stores them.
    static char options[] = "qhull";
    exitcode_ = qh_new_qhull(qh_.get(), 3, static_cast<int>(points.cols()), const_cast<coordT*>(points.data()), False,
                             options, nullptr, err_);
  }
  ~Qhull() {
    int curlong = 0, totlong = 0;
    qh_freeqhull(qh_.get(), !qh_ALL);
    qh_memfreeshort(qh_.get(), &curlong, &totlong);
    if (err_) std::fclose(err_);
  }
  Qhull(const Qhull&) = delete;
  Qhull& operator=(const Qhull&) = delete;
  bool ok() const { return exitcode_ == 0; }
  qhT* get() { return qh_.get(); }

 private:
  std::unique_ptr<qhT> qh_;
  std::FILE* err_;
  int exitcode_ = -1;
};

int find(std::vector<int>& parent, int i) {
  while (parent[static_cast<size_t>(i)] != i) i = parent[static_cast<size_t>(i)] = parent[static_cast<size_t>(parent[static_cast<size_t>(i)])];
  return i;
}

}  // namespace

std::vector<std::vector<int>> convexHullFacets(const Matrix& points, double tolerance, int base) {
  const int n = static_cast<int>(points.cols());
  if (points.rows() != 3) throw ModelError("vertices", -1, "a convex hull needs 3D vertices");
  const double tol = tolerance * std::max(extentOf(points), 1e-300);
  const auto coplanar = [] {
    return ModelError("vertices", -1, "the vertices are coplanar (or fewer than 4): they have no 3D convex hull");
  };
  if (n < 4) throw coplanar();
  {
    // Flat within the tolerance: no hull (Qhull would build a sliver of one).
    const Matrix centred = points.colwise() - points.rowwise().mean();
    const Eigen::JacobiSVD<Matrix> svd(centred * centred.transpose());
    if (std::sqrt(std::max(0.0, svd.singularValues()(2))) <= tol) throw coplanar();
  }
  Qhull hull(points);
  if (!hull.ok()) throw ModelError("vertices", -1, "Qhull could not build the convex hull of the vertices");
  qhT* qh = hull.get();
  auto p = [&](int i) -> Eigen::Vector3d { return points.col(i); };

  // Qhull's facets, numbered; merged with a neighbour when all of the neighbour's vertices lie
  // within tol of the facet's plane (Qhull's own merging is at machine precision).
  std::vector<facetT*> facets;
  facetT* facet;
  FORALLfacets {
    facet->visitid = static_cast<unsigned>(facets.size());
    facets.push_back(facet);
  }
  std::vector<int> parent(facets.size());
  std::iota(parent.begin(), parent.end(), 0);
  const auto within = [&](facetT* plane, facetT* other) {
    vertexT *vertex, **vertexp;
    FOREACHvertex_(other->vertices) {
      const Eigen::Map<const Eigen::Vector3d> x(vertex->point);
      if (std::abs(Eigen::Map<const Eigen::Vector3d>(plane->normal).dot(x) + plane->offset) > tol) return false;
    }
    return true;
  };
  for (facetT* f : facets) {
    facetT *neighbor, **neighborp;
    FOREACHneighbor_(f) {
      if (neighbor->visitid < f->visitid) continue;
      if (Eigen::Map<const Eigen::Vector3d>(f->normal).dot(Eigen::Map<const Eigen::Vector3d>(neighbor->normal)) <= 0) continue;
      if (within(f, neighbor) && within(neighbor, f))
        parent[static_cast<size_t>(find(parent, static_cast<int>(neighbor->visitid)))] = find(parent, static_cast<int>(f->visitid));
    }
  }
  // Each group: its vertices and outward normal.
  std::vector<std::vector<int>> group_vertices(facets.size());
  std::vector<Eigen::Vector3d> group_normal(facets.size(), Eigen::Vector3d::Zero());
  std::vector<char> is_vertex(static_cast<size_t>(n), 0);
  for (facetT* f : facets) {
    const size_t g = static_cast<size_t>(find(parent, static_cast<int>(f->visitid)));
    vertexT *vertex, **vertexp;
    FOREACHvertex_(f->vertices) {
      const int id = qh_pointid(qh, vertex->point);
      group_vertices[g].push_back(id);
      is_vertex[static_cast<size_t>(id)] = 1;
    }
    if (group_normal[g].isZero()) group_normal[g] = Eigen::Map<const Eigen::Vector3d>(f->normal);
  }
  // A point that is not a vertex of Qhull's hull is inside it, or on its boundary.
  for (int m = 0; m < n; ++m) {
    if (is_vertex[static_cast<size_t>(m)]) continue;
    realT dist = 0;
    boolT outside = False;
    qh_findbestfacet(qh, const_cast<coordT*>(points.col(m).data()), qh_ALL, &dist, &outside);
    throw ModelError("vertices", m, "vertex " + std::to_string(m + base) +
                                        (dist >= -tol ? " is on the convex hull's boundary without being a corner of it"
                                                      : " is inside the convex hull of the others"));
  }
  std::vector<std::vector<int>> out;
  for (size_t g = 0; g < facets.size(); ++g) {
    std::vector<int>& on = group_vertices[g];
    if (on.empty()) continue;
    std::sort(on.begin(), on.end());
    on.erase(std::unique(on.begin(), on.end()), on.end());
    const Eigen::Vector3d nrm = group_normal[g];
    // Counter-clockwise about the outward normal, from the centroid.
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int m : on) c += p(m);
    c /= static_cast<double>(on.size());
    const Eigen::Vector3d e1 = (p(on[0]) - c).normalized(), e2 = nrm.cross(e1);
    std::vector<std::pair<double, int>> ang;
    for (int m : on) ang.push_back({std::atan2((p(m) - c).dot(e2), (p(m) - c).dot(e1)), m});
    std::sort(ang.begin(), ang.end());
    std::vector<int> f;
    for (const auto& a : ang) f.push_back(a.second);
    // A point of the facet that is not one of its corners (on an edge or inside it).
    const size_t q = f.size();
    for (size_t t = 0; t < q; ++t) {
      const Eigen::Vector3d a = p(f[(t + q - 1) % q]), b = p(f[t]), d = p(f[(t + 1) % q]);
      if ((b - a).cross(d - b).dot(nrm) <= tol * (d - a).norm())
        throw ModelError("vertices", f[t], "vertex " + std::to_string(f[t] + base) +
                                               " is on the convex hull's boundary without being a corner of it");
    }
    std::rotate(f.begin(), std::min_element(f.begin(), f.end()), f.end());
    out.push_back(std::move(f));
  }
  std::sort(out.begin(), out.end());  // by smallest vertex (each facet lists it first)
  return out;
}

}  // namespace flexure::engine
