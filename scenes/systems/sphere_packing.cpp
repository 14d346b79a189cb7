// [system] type = "sphere_packing": disks (2D) or spheres (3D) of given radii; touching pairs
// keep touching and new contacts stick.
#include <optional>

#include "engine/systems/sphere_packing.h"
#include "scenes/exact_number.h"
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
    std::vector<engine::Rational> exact_radii;  // the exact mode: the radii as written
    std::optional<FlatArray> ra;
    if (one) {
      const double v = r.number(*one, "radius");
      if (!(v > 0)) r.fail(*one, "radius must be positive");
      radii.assign(static_cast<size_t>(n), v);
      if (r.exact()) exact_radii.assign(static_cast<size_t>(n), exactNumber(r, *one, "radius"));
    } else {
      ra.emplace(r, *rn, "radii");
      if (static_cast<int>(ra->size()) != n)
        ra->fail("radii has " + std::to_string(ra->size()) + " entries for " + std::to_string(n) + " vertices");
      for (size_t i = 0; i < ra->size(); ++i) radii.push_back(ra->number(i, "a radius"));
      if (r.exact())
        for (size_t i = 0; i < ra->size(); ++i) exact_radii.push_back(ra->exact(i, "a radius"));
    }
    double tolerance = 1e-6;
    if (const toml::node* tn = sys.get("tolerance")) tolerance = r.number(*tn, "tolerance");
    if (!r.exact()) return std::make_unique<engine::SpherePacking>(p, std::move(radii), readPinned(r, sys, vi), tolerance, base);
    // The exact mode: every contact must hold exactly at the rational centres and radii as
    // written; the contacts then keep the start's distances, which are those exactly ((0.1 +
    // 0.1)^2 in double is not 1/25).
    auto packing = std::make_unique<engine::SpherePacking>(p, std::move(radii), readPinned(r, sys, vi), tolerance, base,
                                                           std::vector<engine::SpherePacking::Contact>{}, true);
    const engine::RationalMatrix q = exactStart(r, p);
    for (const auto& [i, j] : packing->contacts()) {
      const engine::Rational sum = exact_radii[static_cast<size_t>(i)] + exact_radii[static_cast<size_t>(j)];
      if (squaredDistance(q, i, j) == sum * sum) continue;
      const std::string message = std::string(packing->ballsName()) + " " + std::to_string(i + base) + " and " +
                                  std::to_string(j + base) + " touch within the tolerance but not exactly: their centres' "
                                  "squared distance at the rational coordinates is not (r_" + std::to_string(i + base) +
                                  " + r_" + std::to_string(j + base) + ")^2; the exact mode analyses exact contacts only";
      if (ra) ra->fail(static_cast<size_t>(j), message);
      r.fail(*one, message);
    }
    return packing;
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
