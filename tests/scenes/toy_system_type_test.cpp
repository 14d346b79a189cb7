// A system type added from outside the library, as a new room is: its model (engine side), its
// reader (scene side) and one registry line, all in this file, and nothing else. The toy type
// "toy_chain" is a chain of bars between consecutive vertices, closed unless its own key
// `open = true` says so. flexure's reader, key checks, rigidity analysis and drawing layers then
// take it like any other type; the counts are checked against Maxwell's count, by hand.
#include <catch2/catch.hpp>

#include "engine/model.h"
#include "engine/rigidity.h"
#include "engine/terms.h"
#include "scenes/scene.h"
#include "scenes/system_reader.h"
#include "scenes/system_types.h"
#include "scenes/toml_reader.h"

using namespace flexure;
using engine::Matrix;

namespace {

// The model: bars between consecutive vertices at their start lengths; Euclidean motions.
class ToyChain final : public engine::Model {
 public:
  ToyChain(const Matrix& p, bool open, const std::vector<int>& pinned)
      : Model(build(p, open, pinned), p), open_(open) {}
  std::string typeName() const override { return "toy_chain"; }
  Matrix symmetryGenerators(const Matrix& q) const override {
    return engine::euclideanGenerators(q, system().numVertices());
  }
  engine::Geometry geometry() const override {
    engine::Geometry g = Model::geometry();
    const int n = system().numVertices();
    for (int v = 0; v + 1 < n + (open_ ? 0 : 1); ++v) g.bars.edges.push_back({v, (v + 1) % n});
    return g;
  }

 private:
  static engine::ConstraintSystem build(const Matrix& p, bool open, const std::vector<int>& pinned) {
    const int n = static_cast<int>(p.cols());
    engine::ConstraintSystem sys(static_cast<int>(p.rows()), n, n);
    for (int v : pinned) sys.pin(v);
    for (int v = 0; v + 1 < n + (open ? 0 : 1); ++v) sys.addTerm(engine::SquaredDistanceTerm::atStart(v, (v + 1) % n, p));
    sys.finalize(p);
    return sys;
  }
  bool open_;
};

// The reader: the shared readers for pins; its own key `open`.
std::unique_ptr<engine::Model> buildToyChain(const scenes::detail::Reader& r, const toml::table& sys, int base,
                                             Matrix p) {
  const scenes::detail::VertexIndexer vi{r, base, static_cast<int>(p.cols())};
  return std::make_unique<ToyChain>(p, scenes::detail::optionalFlag(r, sys, "open"), scenes::detail::readPinned(r, sys, vi));
}

scenes::detail::SystemType toyChain() {
  return {"toy_chain", {2, 3}, buildToyChain, "bars between consecutive vertices", "`open`", "Euclidean", {"open"}};
}

const char* kSquare = R"(
[system]
type = "toy_chain"
vertices = [[0, 0], [2, 0], [2, 1], [0, 1]]
)";

}  // namespace

TEST_CASE("system types: a toy type added by one registry line is read and checked and analysed and drawn", "[scenes]") {
  CHECK_THROWS_WITH(scenes::loadSceneFromString(kSquare, "toy.toml"),
                    Catch::Contains("unknown or unsupported system type 'toy_chain'"));
  {
    const scenes::detail::ExtraSystemType registered(toyChain());  // the one registry line
    CHECK_THROWS_AS(scenes::detail::ExtraSystemType(toyChain()), std::invalid_argument);
    const auto names = scenes::systemTypeNames();
    CHECK(std::find(names.begin(), names.end(), "toy_chain") != names.end());

    // A closed quadrilateral in the plane: 8 coordinates, 4 bars, 3 Euclidean motions, so
    // 8 - 4 - 3 = 1 nontrivial flex (the four-bar linkage) and no stress.
    const scenes::Scene closed = scenes::loadSceneFromString(kSquare, "toy.toml");
    REQUIRE(closed.model->typeName() == "toy_chain");
    const auto rc = engine::analyzeRigidity(*closed.model, closed.model->startCoordinates());
    CHECK(rc.rank == 4);
    CHECK(rc.nontrivial == 1);
    CHECK(closed.model->geometry().bars.edges.size() == 4);
    CHECK(closed.model->quadraticConstraints());

    // Open (its own key): 3 bars, 8 - 3 - 3 = 2 flexes. Pinning vertex 1 (the shared key,
    // numbered from 1) leaves 6 coordinates and 3 bars: 3 flexes, one of them trivial (the
    // rotation about the pin), 2 nontrivial.
    const scenes::Scene open = scenes::loadSceneFromString(std::string(kSquare) + "open = true\n", "toy.toml");
    const auto ro = engine::analyzeRigidity(*open.model, open.model->startCoordinates());
    CHECK(ro.nontrivial == 2);
    CHECK(open.model->geometry().bars.edges.size() == 3);
    const scenes::Scene pinned =
        scenes::loadSceneFromString(std::string(kSquare) + "open = true\npinned = [1]\n", "toy.toml");
    const auto rp = engine::analyzeRigidity(*pinned.model, pinned.model->startCoordinates());
    CHECK(rp.rank == 3);
    CHECK(rp.trivial == 1);
    CHECK(rp.nontrivial == 2);

    // The key check knows its keys: a misspelt one is refused with a suggestion.
    CHECK_THROWS_WITH(scenes::loadSceneFromString(std::string(kSquare) + "opne = true\n", "toy.toml"),
                      Catch::Contains("opne") && Catch::Contains("open"));
  }
  CHECK_THROWS_WITH(scenes::loadSceneFromString(kSquare, "toy.toml"),
                    Catch::Contains("unknown or unsupported system type 'toy_chain'"));
}
