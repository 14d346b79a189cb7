// The rigidity answers of the literature and the notes, through scene files: prestress
// stability, second-order rigidity, "flexible" from a tracked path, and flex = "auto" following
// a flex that no stress blocks.
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <cstdio>
#include <optional>
#include <vector>
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

namespace {

// Six points of the plane (x, y) as a K_{3,3} (odd against even), in the plane, and carried to
// the unit sphere by central projection from its centre (the plane z = 1 touching it): the
// correspondence of Pogorelov (Saliola and Whiteley, 2007) under which infinitesimal rigidity,
// prestress stability and second-order rigidity are the same (Connelly and Whiteley 1996: they
// are projective invariants). A conic of the plane goes to a spherical conic.
std::string k33Text(const std::vector<std::array<double, 2>>& p, bool sphere) {
  std::string v = "[";
  char buf[128];
  for (const auto& q : p) {
    const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + 1.0);
    if (sphere)
      std::snprintf(buf, sizeof buf, "[%.17g, %.17g, %.17g],", q[0] / n, q[1] / n, 1.0 / n);
    else
      std::snprintf(buf, sizeof buf, "[%.17g, %.17g],", q[0], q[1]);
    v += buf;
  }
  v.back() = ']';
  const std::string edges = "[[1,2],[1,4],[1,6],[3,2],[3,4],[3,6],[5,2],[5,4],[5,6]]";
  return sphere ? "[system]\ntype = \"framework_on_surface\"\nsurface = \"x^2 + y^2 + z^2 - 1\"\nvertices = " + v +
                      "\nedges = " + edges + "\n"
                : "[system]\ntype = \"framework\"\nvertices = " + v + "\nedges = " + edges + "\n";
}

scenes::Scene onSurface(const std::string& surface, const std::string& vertices, const std::string& edges) {
  return scenes::loadSceneFromString("[system]\ntype = \"framework_on_surface\"\nsurface = \"" + surface +
                                         "\"\nvertices = " + vertices + "\nedges = " + edges + "\n",
                                     "s.toml");
}

}  // namespace

TEST_CASE("literature: K33 on a conic in the plane and on the sphere is prestress stable", "[scenes]") {
  // Bolker and Roth: K_{3,3} with its six vertices on a conic has one nontrivial flex and one
  // stress; the stress's energy is definite on the flex (prestress stable, hence rigid).
  std::vector<std::array<double, 2>> ellipse;
  for (double a : {0.3, 1.2, 2.0, 3.5, 4.4, 5.6}) ellipse.push_back({2 * std::cos(a), std::sin(a)});
  for (bool sphere : {false, true}) {
    INFO((sphere ? "on the unit sphere" : "in the plane"));
    const scenes::Scene s = scenes::loadSceneFromString(k33Text(ellipse, sphere), "k33.toml");
    CHECK(s.model->quadraticConstraints());
    check(s, {1, 1, true, true, Verdict::Rigid});
  }
  // Off the conic (one vertex moved): infinitesimally rigid in both, no stress.
  std::vector<std::array<double, 2>> generic = ellipse;
  generic[0][0] *= 1.1;
  for (bool sphere : {false, true}) {
    const engine::RigidityReport r = pipeline::analyze(scenes::loadSceneFromString(k33Text(generic, sphere), "k.toml"));
    CHECK(r.inf_rigid);
    CHECK(r.stresses == 0);
  }
  // Dixon's first mechanism (the two classes on perpendicular lines, a degenerate conic) and its
  // image on the sphere (two perpendicular great circles): neither prestress stable nor
  // second-order rigid, and both move.
  const std::vector<std::array<double, 2>> dixon = {{-1.3, 0}, {0, -0.8}, {0.6, 0}, {0, 0.5}, {1.9, 0}, {0, 1.4}};
  for (bool sphere : {false, true}) {
    INFO((sphere ? "on the unit sphere" : "in the plane"));
    check(scenes::loadSceneFromString(k33Text(dixon, sphere), "dixon.toml"), {1, 1, false, false, Verdict::Flexible});
  }
}

TEST_CASE("literature: frameworks on quadrics get second-order verdicts, other surfaces none", "[scenes]") {
  // Quadrics (degree at most 2, however written): the second-order theory applies.
  const char* quadrics[][2] = {{"x^2 + y^2 + z^2 - 1", "[[1,0,0]]"},
                               {"x^2/4 + y^2 + z^2/9 - 1", "[[2,0,0]]"},
                               {"x^2 + y^2 - z^2 - 1", "[[1,0,0]]"},
                               {"x^2 + y^2 - 1", "[[0,1,5]]"},
                               {"(x - 1)*(y + 2) - z", "[[1,-2,0]]"},
                               {"(x + y)^2 - 2*x*y - y^2 - 1 + 0*z", "[[1,3,0]]"}};
  for (const auto& q : quadrics) {
    INFO(q[0]);
    CHECK(onSurface(q[0], q[1], "[]").model->quadraticConstraints());
  }
  const char* others[][2] = {{"x^3 + y^2 + z^2 - 1", "[[1,0,0]]"},
                             {"(x^2 + y^2 + z^2 + 3)^2 - 16*(x^2 + y^2)", "[[1,0,0]]"},
                             {"sin(x) + y^2 + z^2 - sin(1)", "[[1,0,0]]"},
                             {"x^2 + y^2 + z^2 - 1 + 1e-3*x*y*z", "[[1,0,0]]"}};
  for (const auto& q : others) {
    INFO(q[0]);
    CHECK_FALSE(onSurface(q[0], q[1], "[]").model->quadraticConstraints());
  }
}
