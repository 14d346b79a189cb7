// [system] type = "origami": a sheet of faces and creases (a crease pattern in the plane or a
// folded state in 3D), each crease assigned B, M, V, F, U or J.
#include <cctype>
#include <cmath>

#include "engine/systems/origami.h"
#include "scenes/scene.h"
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

// [motion] fold_percent (every mountain and valley toward a fold percentage), or fold_crease
// with fold_angle (one crease to an angle).
void readFoldDrive(const Reader& r, const toml::table& t, const engine::Model& model, int base, MotionSettings& m) {
  const auto& origami = static_cast<const engine::Origami&>(model);  // the registry found its type
  const toml::node* fc = t.get("fold_crease");
  const toml::node* fa = t.get("fold_angle");
  const toml::node* fp = t.get("fold_percent");
  if (fp) {
    const double v = r.number(*fp, "fold_percent");
    if (!(v >= 0 && v <= 100)) r.fail(*fp, "fold_percent is a percentage of the full fold, in [0, 100]");
    bool any = false;
    for (const engine::Crease& c : origami.edges())
      any = any || (c.left >= 0 && c.right >= 0 && (c.assignment == 'M' || c.assignment == 'V'));
    if (!any) r.fail(*fp, "fold_percent needs mountain (M) or valley (V) creases, and this sheet has none");
    m.fold_percent = v;
  } else {
    if (!fc) r.fail(*fa, "fold_angle needs fold_crease = [i, j], the crease to fold");
    if (!fa) r.fail(*fc, "fold_crease needs fold_angle, the angle to fold it to (degrees, + valley)");
    const auto [i, j] = vertexPair(r, *fc, "fold_crease", base, model.system().numVertices());
    const std::string name = "[" + std::to_string(i + base) + ", " + std::to_string(j + base) + "]";
    int found = -1;
    for (size_t e = 0; e < origami.edges().size(); ++e) {
      const engine::Crease& c = origami.edges()[e];
      if (std::minmax(c.a, c.b) == std::minmax(i, j)) found = static_cast<int>(e);
    }
    if (found < 0) r.fail(*fc, name + " is not an edge of the sheet");
    const engine::Crease& c = origami.edges()[static_cast<size_t>(found)];
    if (c.left < 0 || c.right < 0) r.fail(*fc, name + " is on the sheet's boundary: only a crease between two faces folds");
    if (origami.panelOfFace()[static_cast<size_t>(c.left)] == origami.panelOfFace()[static_cast<size_t>(c.right)])
      r.fail(*fc, name + " is a " + std::string(1, c.assignment) + " edge inside a rigid panel: it does not fold");
    const double deg = r.number(*fa, "fold_angle");
    if (!(deg >= -180 && deg <= 180)) r.fail(*fa, "fold_angle is degrees in [-180, 180] (+ valley, - mountain)");
    m.fold_crease = found;
    m.fold_angle = deg * M_PI / 180;
  }
}

}  // namespace

SystemType origami() {
  return {"origami", {2, 3}, buildOrigami,
          "rigid panels (faces joined by F and J creases) hinged at the shared creases; mountain and valley "
          "creases keep their sense",
          "`faces`, `creases`, `assignments` (FOLD's letters; 2D or 3D)", "Euclidean", {}, readFoldDrive};
}

}  // namespace flexure::scenes::detail::systems
