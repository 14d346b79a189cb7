// [system] type = "polytope": a polyhedron in 3D, its facets given as vertex cycles or as the
// facets of the vertices' convex hull ("hull").
#include "engine/systems/polytope.h"
#include "scenes/system_reader.h"
#include "scenes/system_types.h"

namespace flexure::scenes::detail::systems {

namespace {

using engine::Matrix;

std::unique_ptr<engine::Model> buildPolytope(const Reader& r, const toml::table& sys, int base, Matrix p) {
  const size_t any = static_cast<size_t>(-1);
  try {
    const VertexIndexer vi{r, base, static_cast<int>(p.cols())};
    // facets = "hull": the facets of the vertices' convex hull.
    const toml::node& fn = r.require(sys, "facets", "[system]");
    std::vector<std::vector<int>> facets;
    if (fn.is_string()) {
      if (r.string(fn, "facets") != "hull")
        r.fail(fn, "facets must be a list of vertex cycles or \"hull\" (the facets of the convex hull)");
      facets = engine::convexHullFacets(p, 1e-9, base);
    } else {
      facets = readVertexLists(r, sys, "facets", vi, "a facet", 3, any);
    }
    return std::make_unique<engine::Polytope>(p, std::move(facets), readPinned(r, sys, vi), 1e-8, base);
  } catch (const engine::ModelError& e) {
    failAt(r, sys, e);
  }
}

}  // namespace

SystemType polytope() {
  return {"polytope", {3}, buildPolytope, "edge lengths and facet planarity (a normal per facet, of the polytope's size)",
          "`facets` (cyclic vertex lists, 3D, or `\"hull\"`)",
          "Euclidean, the normals rotating along"};
}

}  // namespace flexure::scenes::detail::systems
