// [system] type = "spherical_disk_packing": caps on the unit sphere (3D points a with abs(a) > 1,
// the cap cut by the plane a.y = 1) whose contacts keep their inversive distances.
#include "engine/systems/spherical_disk_packing.h"
#include "scenes/system_reader.h"
#include "scenes/system_types.h"

namespace flexure::scenes::detail::systems {

namespace {

using engine::Matrix;

std::unique_ptr<engine::Model> buildSphericalDiskPacking(const Reader& r, const toml::table& sys, int base, Matrix p) {
  try {
    const VertexIndexer vi{r, base, static_cast<int>(p.cols())};
    auto contacts = toArrays<2>(readVertexLists(r, sys, "contacts", vi, "a contact", 2, 2));
    return std::make_unique<engine::SphericalDiskPacking>(p, std::move(contacts), readPinned(r, sys, vi), base);
  } catch (const engine::ModelError& e) {
    failAt(r, sys, e);
  }
}

}  // namespace

SystemType sphericalDiskPacking() {
  return {"spherical_disk_packing", {3}, buildSphericalDiskPacking, "inversive distances of the contacts",
          "`contacts` (3D points a, abs(a) > 1: the cap cut by the plane a.y = 1)",
          "Möbius"};
}

}  // namespace flexure::scenes::detail::systems
