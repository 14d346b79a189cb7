// [system] type = "sphere_packing": disks (2D) or spheres (3D) of given radii; touching pairs
// keep touching and new contacts stick.
#include "engine/systems/sphere_packing.h"
#include "scenes/system_reader.h"
#include "scenes/system_types.h"

namespace flexure::scenes::detail::systems {

namespace {

using engine::Matrix;

std::unique_ptr<engine::Model> buildSpherePacking(const Reader& r, const toml::table& sys, int base, Matrix p) {
  try {
    const int n = static_cast<int>(p.cols());
    const VertexIndexer vi{r, base, n};
    const toml::node* rn = sys.get("radii");
    const toml::node* one = sys.get("radius");
    if (rn && one) r.fail(*one, "give either radii (one per vertex) or radius (the same for all), not both");
    if (!rn && !one) r.require(sys, "radii", "[system] (sphere_packing; or one 'radius' for all)");
    std::vector<double> radii;
    if (one) {
      const double v = r.number(*one, "radius");
      if (!(v > 0)) r.fail(*one, "radius must be positive");
      radii.assign(static_cast<size_t>(n), v);
    } else {
      const FlatArray ra(r, *rn, "radii");
      if (static_cast<int>(ra.size()) != n)
        ra.fail("radii has " + std::to_string(ra.size()) + " entries for " + std::to_string(n) + " vertices");
      for (size_t i = 0; i < ra.size(); ++i) radii.push_back(ra.number(i, "a radius"));
    }
    double tolerance = 1e-6;
    if (const toml::node* tn = sys.get("tolerance")) tolerance = r.number(*tn, "tolerance");
    return std::make_unique<engine::SpherePacking>(p, std::move(radii), readPinned(r, sys, vi), tolerance, base);
  } catch (const engine::ModelError& e) {
    failAt(r, sys, e);
  }
}

}  // namespace

SystemType spherePacking() {
  return {"sphere_packing", {2, 3}, buildSpherePacking, "touching pairs keep touching; new contacts stick",
          "`radii` (or one `radius`), `tolerance` (2D disks, 3D spheres)",
          "Euclidean"};
}

}  // namespace flexure::scenes::detail::systems
