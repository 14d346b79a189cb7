// [system] type = "angular_framework": angles [i, j, k] (at j) that are kept.
#include "engine/systems/angular_framework.h"
#include "scenes/system_reader.h"
#include "scenes/system_types.h"

namespace flexure::scenes::detail::systems {

namespace {

using engine::Matrix;

std::unique_ptr<engine::Model> buildAngularFramework(const Reader& r, const toml::table& sys, int base, Matrix p) {
  try {
    const VertexIndexer vi{r, base, static_cast<int>(p.cols())};
    auto angles = toArrays<3>(readVertexLists(r, sys, "angles", vi, "an angle", 3, 3));
    return std::make_unique<engine::AngularFramework>(p, std::move(angles), readPinned(r, sys, vi), base);
  } catch (const engine::ModelError& e) {
    failAt(r, sys, e);
  }
}

}  // namespace

SystemType angularFramework() {
  return {"angular_framework", {2, 3}, buildAngularFramework, "angles",
          "`angles = [[i,j,k]]` (the angle at j)",
          "similarities"};
}

}  // namespace flexure::scenes::detail::systems
