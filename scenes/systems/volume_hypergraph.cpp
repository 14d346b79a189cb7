// [system] type = "volume_hypergraph": simplices of d + 1 vertices whose signed volumes are kept.
#include "engine/systems/volume_hypergraph.h"
#include "scenes/system_reader.h"
#include "scenes/system_types.h"

namespace flexure::scenes::detail::systems {

namespace {

using engine::Matrix;

std::unique_ptr<engine::Model> buildVolumeHypergraph(const Reader& r, const toml::table& sys, int base, Matrix p) {
  try {
    const VertexIndexer vi{r, base, static_cast<int>(p.cols())};
    auto simplices = readVertexLists(r, sys, "simplices", vi, "a simplex", 3, 4);
    return std::make_unique<engine::VolumeHypergraph>(p, std::move(simplices), readPinned(r, sys, vi), base);
  } catch (const engine::ModelError& e) {
    failAt(r, sys, e);
  }
}

}  // namespace

SystemType volumeHypergraph() {
  return {"volume_hypergraph", {2, 3}, buildVolumeHypergraph, "signed simplex volumes",
          "`simplices` (d + 1 vertices each, 2D or 3D)",
          "equi-affine"};
}

}  // namespace flexure::scenes::detail::systems
