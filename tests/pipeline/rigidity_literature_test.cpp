// The rigidity answers of the literature and the notes, through scene files: prestress
// stability, second-order rigidity, "flexible" from a tracked path, and flex = "auto" following
// a flex that no stress blocks.
#include <catch2/catch.hpp>

#include <cmath>
#include <optional>
#include <string>

#include "engine/rigidity.h"
#include "engine/second_order.h"
#include "pipeline/pipeline.h"
#include "scenes/scene.h"
#include "../scenes/scene_test_common.h"

using namespace flexure;
using engine::Verdict;
using test::example;

namespace {

struct Known {
  int nontrivial, stresses;
  std::optional<bool> prestress_stable, second_order_rigid;
  Verdict rigid;
};

void check(const scenes::Scene& s, const Known& k) {
  const engine::RigidityReport r = pipeline::analyze(s);
  INFO(s.title << ": " << r.reason);
  CHECK(r.nontrivial == k.nontrivial);
  CHECK(r.stresses == k.stresses);
  CHECK(r.prestress_stable == k.prestress_stable);
  CHECK(r.second_order_rigid == k.second_order_rigid);
  CHECK(r.rigid == k.rigid);
  CHECK(r.warnings.empty());
}

scenes::Scene framework(const std::string& vertices, const std::string& edges, const std::string& pinned = "[]") {
  return scenes::loadSceneFromString("[system]\ntype = \"framework\"\nvertices = " + vertices + "\nedges = " + edges +
                                         "\npinned = " + pinned + "\n",
                                     "t.toml");
}

// The blocked-flex question decided by the homotopy alone (no sum-of-squares certificate).
engine::BlockedFlexResult::Outcome homotopyAlone(const scenes::Scene& s) {
  const engine::Model& m = *s.model;
  const engine::Vector x = m.startCoordinates();
  const engine::RigidityReport r = pipeline::analyze(s);
  const std::vector<engine::Matrix> forms = engine::stressEnergyForms(m.system(), x, r.flex_basis, r.stress_basis);
  engine::BlockedFlexOptions opt;
  opt.max_sos_flexes = 0;
  const engine::BlockedFlexResult b = engine::findUnblockedFlex(forms, engine::Vector::Ones(r.nontrivial), opt);
  INFO(b.note);
  CHECK(b.failed_paths == 0);
  CHECK(b.paths > 0);
  return b.outcome;
}

const char* kPrismEdges = "[[1,2],[2,3],[1,3],[4,5],[5,6],[4,6],[1,4],[2,5],[3,6]]";

}  // namespace

TEST_CASE("literature: the collinear triangle is prestress stable (paper example 2.5)", "[scenes]") {
  check(example("collinear_triangle"), {1, 1, true, true, Verdict::Rigid});
}

TEST_CASE("literature: the notes' rigid_prestress_stable and 3Prism", "[scenes]") {
  check(example("rigid_prestress_stable"), {1, 1, true, true, Verdict::Rigid});
  // 3Prism: the parallel realization moves.
  check(example("three_prism"), {1, 1, false, false, Verdict::Flexible});
}

TEST_CASE("literature: the 3-prism in its generic, parallel and frustum realizations", "[scenes]") {
  SECTION("generic: infinitesimally rigid") {
    check(framework("[[0,0],[4,0],[1,3],[0.5,5],[5,4.5],[2,7]]", kPrismEdges), {0, 0, true, true, Verdict::Rigid});
  }
  SECTION("parallel connecting bars: a finite motion") {
    check(framework("[[0,0],[1,0],[0.5,1],[0,2],[1,2],[0.5,3]]", kPrismEdges),
          {1, 1, false, false, Verdict::Flexible});
  }
  SECTION("frustum (connecting bars through one point): prestress stable") {
    check(example("three_frustum"), {1, 1, true, true, Verdict::Rigid});
    check(framework("[[1,0],[-0.5,\"sqrt(3)/2\"],[-0.5,\"-sqrt(3)/2\"],[2,0],[-1,\"sqrt(3)\"],[-1,\"-sqrt(3)\"]]",
                    kPrismEdges),
          {1, 1, true, true, Verdict::Rigid});
  }
}

TEST_CASE("literature: a cone over the cube's 1-skeleton moves", "[scenes]") {
  check(example("coned_cube"), {2, 1, false, false, Verdict::Flexible});
}

TEST_CASE("literature: second-order rigid but not prestress stable (Connelly and Whiteley 1996)", "[scenes]") {
  const scenes::Scene s = example("connelly_whiteley");
  check(s, {2, 2, false, true, Verdict::Rigid});
  CHECK(pipeline::analyze(s).stress_margin <= 1e-8);  // no stress is positive on every flex
  CHECK(homotopyAlone(s) == engine::BlockedFlexResult::Outcome::AllBlocked);
}

TEST_CASE("literature: Bricard's octahedra flex", "[scenes]") {
  check(example("bricard_octahedron"), {1, 1, false, false, Verdict::Flexible});
}

TEST_CASE("literature: the hypostatic sphere packings of the notes are prestress stable", "[scenes]") {
  check(example("hypostatic_packing"), {1, 1, true, true, Verdict::Rigid});
  check(example("hypostatic_packing_10"), {2, 1, true, true, Verdict::Rigid});
}

TEST_CASE("literature: the double Watt at its cusp moves", "[scenes]") {
  check(example("double_watt"), {2, 1, false, false, Verdict::Flexible});
}

TEST_CASE("literature: dodecahedron and truncated icosahedron are second-order rigid, not prestress stable "
          "(notes 5.2)",
          "[scenes]") {
  for (const char* name : {"dodecahedron", "truncated_icosahedron"}) {
    INFO(name);
    const scenes::Scene s = example(name);
    check(s, {5, 5, false, true, Verdict::Rigid});
    CHECK(homotopyAlone(s) == engine::BlockedFlexResult::Outcome::AllBlocked);
  }
}

TEST_CASE("literature: flexible polytopes (notes 5.2)", "[scenes]") {
  check(example("truncated_octahedron"), {5, 5, false, false, Verdict::Flexible});
  check(example("cube"), {3, 3, false, false, Verdict::Flexible});
}

TEST_CASE("literature: without quadratic constraints nothing second-order is claimed, a motion still is",
          "[scenes]") {
  const engine::RigidityReport r = pipeline::analyze(example("spherical_bricard"));
  CHECK_FALSE(r.prestress_stable.has_value());
  CHECK_FALSE(r.second_order_rigid.has_value());
  CHECK(r.rigid == Verdict::Flexible);
  CHECK(r.motion_check_change > 1e-3);
}

TEST_CASE("literature: motion_check_steps = 0 leaves a non-second-order-rigid framework undecided", "[scenes]") {
  const engine::RigidityReport r = pipeline::analyze(example("three_prism", {"analysis.motion_check_steps=0"}));
  CHECK(r.second_order_rigid == false);
  CHECK(r.rigid == Verdict::Unknown);
}

TEST_CASE("literature: flex = \"auto\" follows a flex that no stress blocks, and it moves", "[scenes]") {
  // Two flexes and one stress: the stress of the collinear triangle 1-2-3 blocks its middle
  // vertex's flex; the homotopy finds the other, vertex 6 turning about vertex 1.
  const scenes::Scene s = example("flexible_prestress_stable_component", {"motion.flex=\"auto\"", "motion.steps=10"});
  const pipeline::Motion m = pipeline::track(s, 10);
  INFO(m.path.flex_choice);
  CHECK_THAT(m.path.flex_choice, Catch::Contains("no stress blocks"));
  REQUIRE(m.path.samples.size() == 11);
  const engine::Model& model = *s.model;
  const engine::Vector a = model.congruenceInvariants(model.system().positions(m.path.samples.front()));
  const engine::Vector b = model.congruenceInvariants(model.system().positions(m.path.samples.back()));
  CHECK((a - b).cwiseAbs().maxCoeff() > 1e-2);
  CHECK(m.path.summary.max_residual < 1e-9);
}
