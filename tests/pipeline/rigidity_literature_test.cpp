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

namespace {

// An angular framework on a polygon with every angle fixed (angle i-1, i, i+1 at each vertex).
scenes::Scene angledPolygon(const std::vector<std::array<double, 2>>& p) {
  std::string v = "[", a = "[";
  const int n = static_cast<int>(p.size());
  char buf[96];
  for (int i = 0; i < n; ++i) {
    std::snprintf(buf, sizeof buf, "%s[%.17g, %.17g]", i ? ", " : "", p[static_cast<size_t>(i)][0], p[static_cast<size_t>(i)][1]);
    v += buf;
    a += (i ? ", [" : "[") + std::to_string((i + n - 1) % n + 1) + ", " + std::to_string(i + 1) + ", " +
         std::to_string((i + 1) % n + 1) + "]";
  }
  return scenes::loadSceneFromString(
      "[system]\ntype = \"angular_framework\"\nvertices = " + v + "]\nangles = " + a + "]\n", "t.toml");
}

}  // namespace

// Issue 41: the rectangles of a shape class form a one-parameter family, and so do the
// parallelograms: every quadrilateral with its four angles fixed flexes (n - 3 = 1 nontrivial
// flex modulo similarities, one stress from the angle sum). The stress-energy forms vanish on
// these flexes; they were divided by the flexes' own second derivatives, which are exactly zero
// here (the motion is linear), so that rounding noise of 1e-17 read as "prestress stable".
TEST_CASE("literature: a polygon with every angle fixed flexes, whatever its shape (issue 41)", "[scenes]") {
  const double c = std::cos(0.35), s = std::sin(0.35);
  auto rot = [&](std::vector<std::array<double, 2>> p, double scale) {
    for (auto& q : p) q = {scale * (c * q[0] - s * q[1]) + 0.3, scale * (s * q[0] + c * q[1]) - 0.4};
    return p;
  };
  const std::vector<std::vector<std::array<double, 2>>> quads = {
      // The rectangle, exactly as reported.
      {{0.3, -0.4}, {2.3666199682642337, 0.354375176401993}, {1.920852818572147, 1.5755597031035857},
       {-0.14576714969208676, 0.8211845267015926}},
      {{0, 0}, {3, 0}, {4, 1.5}, {1, 1.5}},  // the parallelogram
      {{0, 0}, {1, 0}, {1, 1}, {0, 1}},      // a square
      {{0, 0}, {2.2, 0.1}, {1.7, 1.9}, {-0.3, 1.2}},
      rot({{0, 0}, {2, 0}, {2, 0.5}, {0, 0.5}}, 1e-3),
      rot({{0, 0}, {5, 0}, {6, 2}, {1, 2}}, 1e4),
  };
  for (const auto& q : quads) {
    const scenes::Scene sc = angledPolygon(q);
    INFO("quadrilateral " << q[1][0] << ", " << q[1][1] << ", ...");
    check(sc, {1, 1, false, false, Verdict::Flexible});
    CHECK(pipeline::analyze(sc).contradiction.empty());
  }
  // Regular and random polygons with 5 and 6 vertices: n - 3 flexes, one stress.
  for (const int n : {5, 6}) {
    std::vector<std::array<double, 2>> regular, wobbly;
    for (int i = 0; i < n; ++i) {
      const double t = 2 * M_PI * i / n;
      regular.push_back({std::cos(t), std::sin(t)});
      wobbly.push_back({(1 + 0.2 * std::sin(3.1 * i)) * std::cos(t), (1 + 0.2 * std::sin(3.1 * i)) * std::sin(t)});
    }
    for (const auto& p : {regular, wobbly}) {
      INFO(n << " vertices");
      check(angledPolygon(p), {n - 3, 1, false, false, Verdict::Flexible});
    }
  }
}

// The safety net behind every second-order "rigid": a certificate made wrong on purpose (every
// form counts as positive definite) is contradicted by the moves along the flexes, and the
// verdict is "flexible", with the contradiction said. On the prestress stable examples the same
// moves stay in the orbit: no contradiction.
TEST_CASE("literature: a second-order 'rigid' is checked by moving along every flex", "[scenes]") {
  const scenes::Scene rect = angledPolygon({{0, 0}, {3, 0}, {3, 1}, {0, 1}});
  engine::RigidityOptions wrong = scenes::rigidityOptions(rect);
  wrong.form_tolerance = -1.0;  // a zero form counts as positive definite
  const engine::RigidityReport r = engine::analyzeRigidity(*rect.model, rect.model->startCoordinates(), wrong);
  INFO(r.reason);
  CHECK(r.rigid == Verdict::Flexible);
  CHECK_THAT(r.contradiction, Catch::Contains("second-order theory said rigid (prestress stable"));
  CHECK(r.second_order_moves >= 1);
  CHECK(r.warnings.size() == 1);
  CHECK_FALSE(r.prestress_stable.has_value());
  for (const char* name : {"collinear_triangle", "rigid_prestress_stable", "connelly_whiteley", "dodecahedron",
                           "hypostatic_packing", "hypostatic_packing_10", "truncated_icosahedron"}) {
    INFO(name);
    const engine::RigidityReport e = pipeline::analyze(example(name));
    CHECK(e.rigid == Verdict::Rigid);
    REQUIRE(e.nontrivial > 0);
    CHECK(e.second_order_moves == 2 * e.nontrivial + 1);
    CHECK(e.contradiction.empty());
  }
}
