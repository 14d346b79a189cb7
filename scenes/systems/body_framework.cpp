// [system] type = "body_hinge" and "body_bar": rigid bodies (vertex lists; shared vertices are
// hinges), and for body_bar the bars between them.
#include "engine/systems/body_framework.h"
#include "scenes/system_reader.h"
#include "scenes/system_types.h"

namespace flexure::scenes::detail::systems {

namespace {

using engine::Matrix;

std::unique_ptr<engine::Model> buildBodies(const std::string& type, const Reader& r, const toml::table& sys,
                                           int base, Matrix p) {
  const size_t any = static_cast<size_t>(-1);
  try {
    const VertexIndexer vi{r, base, static_cast<int>(p.cols())};
    auto bodies = readVertexLists(r, sys, "bodies", vi, "a body", 1, any);
    auto bars = toArrays<2>(readVertexLists(r, sys, "bars", vi, "a bar", 2, 2, type == "body_bar"));
    return std::make_unique<engine::BodyFramework>(type, p, std::move(bodies), bars, readPinned(r, sys, vi), base);
  } catch (const engine::ModelError& e) {
    failAt(r, sys, e);
  }
}

std::unique_ptr<engine::Model> buildBodyHinge(const Reader& r, const toml::table& sys, int base, Matrix p) {
  return buildBodies("body_hinge", r, sys, base, std::move(p));
}

std::unique_ptr<engine::Model> buildBodyBar(const Reader& r, const toml::table& sys, int base, Matrix p) {
  return buildBodies("body_bar", r, sys, base, std::move(p));
}

}  // namespace

SystemType bodyHinge() {
  return {"body_hinge", {2, 3}, buildBodyHinge, "each body rigid",
          "`bodies` (vertex lists; shared vertices are hinges)",
          "Euclidean"};
}

SystemType bodyBar() {
  return {"body_bar", {2, 3}, buildBodyBar, "bodies rigid and bar lengths",
          "`bodies`, `bars`",
          "Euclidean"};
}

}  // namespace flexure::scenes::detail::systems
