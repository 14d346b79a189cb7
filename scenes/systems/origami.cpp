// [system] type = "origami": a sheet of faces and creases (a crease pattern in the plane or a
// folded state in 3D), each crease assigned B, M, V, F, U or J.
#include <cctype>

#include "engine/systems/origami.h"
#include "scenes/system_reader.h"
#include "scenes/system_types.h"

namespace flexure::scenes::detail::systems {

namespace {

using engine::Matrix;

std::unique_ptr<engine::Model> buildOrigami(const Reader& r, const toml::table& sys, int base, Matrix p) {
  const size_t any = static_cast<size_t>(-1);
  try {
    if (p.rows() == 2) {  // a crease pattern in the plane z = 0
      p.conservativeResize(3, Eigen::NoChange);
      p.row(2).setZero();
    }
    const VertexIndexer vi{r, base, static_cast<int>(p.cols())};
    auto faces = readVertexLists(r, sys, "faces", vi, "a face", 3, any);
    auto creases = toArrays<2>(readVertexLists(r, sys, "creases", vi, "a crease", 2, 2));
    std::string assignments;
    if (const toml::node* an = sys.get("assignments")) {
      assignments = r.string(*an, "assignments");
      if (assignments.size() != creases.size())
        r.fail(*an, "assignments has " + std::to_string(assignments.size()) + " letters for " +
                        std::to_string(creases.size()) + " creases");
      for (char& c : assignments) {
        c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
        if (std::string("BMVFUJ").find(c) == std::string::npos)
          r.fail(*an, std::string("assignments: unknown letter '") + c + "' (B, M, V, F, U or J)");
      }
    } else {
      assignments.assign(creases.size(), 'U');
    }
    std::vector<engine::Crease> edges;
    for (size_t e = 0; e < creases.size(); ++e) {
      engine::Crease c;
      c.a = creases[e][0], c.b = creases[e][1], c.assignment = assignments[e];
      edges.push_back(c);
    }
    return std::make_unique<engine::Origami>(p, std::move(faces), std::move(edges), readPinned(r, sys, vi), base);
  } catch (const engine::ModelError& e) {
    failAt(r, sys, e);
  }
}

}  // namespace

SystemType origami() {
  return {"origami", {2, 3}, buildOrigami,
          "rigid panels (faces joined by F and J creases) hinged at the shared creases; mountain and valley "
          "creases keep their sense",
          "`faces`, `creases`, `assignments` (FOLD's letters; 2D or 3D)", "Euclidean"};
}

}  // namespace flexure::scenes::detail::systems
