// Every constraint-system type beyond the bar-joint framework (paper appendix B): derivatives
// against finite differences, symmetry generators in the kernel, the rigidity answers of the
// notes, invariants along tracked paths, edge contraction, and bad input with its position.
#include <catch2/catch.hpp>

#include <map>
#include <random>

#include <cmath>
#include <random>

#include <Eigen/Geometry>

#include "engine/contraction.h"
#include "engine/rigidity.h"
#include "engine/systems/polytope.h"
#include "engine/systems/spherical_disk_packing.h"
#include "engine/systems/volume_hypergraph.h"
#include "scenes/catalog.h"
#include "pipeline/pipeline.h"
#include "scenes/scene.h"
#include "../scenes/scene_test_common.h"
#include "../test_common.h"

using namespace flexure;
using test::example;
using test::requireSceneError;
using engine::Matrix;
using engine::Vector;

namespace {


// Positions of every block (vertices, then auxiliary blocks) of sample k.
Matrix blocks(const scenes::Scene& s, const engine::DeformationPath& r, size_t k) {
  return s.model->system().positions(r.samples[k]);
}


const char* kNewTypes[] = {"thales", "square_on_hyperboloid", "octahedral_volumes", "cuboctahedron",
                           "dodecahedron", "cube", "tetrahedron", "octahedron", "icosahedron",
                           "bodyhinge_pyramid", "bodyhinge_squares", "bodybar_cube", "spherical_bricard"};

}  // namespace

TEST_CASE("system types: Jacobians and second derivatives match finite differences", "[scenes][engine]") {
  std::mt19937 rng(7);
  for (const char* name : kNewTypes) {
    INFO(name);
    const scenes::Scene s = example(name);
    const engine::ConstraintSystem& sys = s.model->system();
    // At the start and at a perturbed point (off the constraint set, where nothing cancels).
    const Vector x0 = s.model->startCoordinates();
    for (const Vector& x : {x0, Vector(x0 + test::randomVector(rng, sys.numVariables(), 0.05))}) {
      test::requireJacobianMatchesFiniteDifferences(sys, x);
      test::requireSecondDerivativeMatchesFiniteDifferences(sys, x, test::randomVector(rng, sys.numVariables()),
                                                            test::randomVector(rng, sys.numVariables()));
    }
  }
}

TEST_CASE("system types: the symmetry generators are infinitesimal flexes, at the start and after moving",
          "[scenes][engine]") {
  for (const char* name : kNewTypes) {
    INFO(name);
    const scenes::Scene s = example(name, {"motion.steps=5"});
    const engine::ConstraintSystem& sys = s.model->system();
    const pipeline::Motion m = pipeline::track(s, 5);
    for (const Vector& x : {m.path.samples.front(), m.path.samples.back()}) {
      const Matrix T = engine::trivialFlexes(*s.model, x, 1e-9);
      if (T.cols() == 0) continue;
      const Matrix JT = Matrix(sys.jacobian(x)) * T;
      CHECK(JT.cwiseAbs().maxCoeff() <= 1e-9 * std::max(1.0, Matrix(sys.jacobian(x)).cwiseAbs().maxCoeff()));
    }
  }
}

TEST_CASE("system types: rigidity counts and answers", "[scenes][engine]") {
  struct Row {
    const char* name;
    int trivial, nontrivial, stresses;
    bool inf_rigid;
  };
  // The polytope answers are those of the notes' section 5.2 (Cauchy's theorem for the
  // simplicial ones; the cube and the cuboctahedron are flexible); the hyperboloid's isometries
  // are the rotations about z only (the reference counts 2 "trivial" flexes: the rigid motions
  // tangent to the surface at the four vertices, not isometries of the surface).
  const Row rows[] = {
      {"tetrahedron", 6, 0, 0, true},         {"octahedron", 6, 0, 0, true},
      {"icosahedron", 6, 0, 0, true},         {"cube", 6, 3, 3, false},
      {"cuboctahedron", 6, 3, 3, false},      {"thales", 0, 1, 0, false},
      {"square_on_hyperboloid", 1, 3, 0, false}, {"octahedral_volumes", 5, 2, 0, false},
      {"spherical_bricard", 3, 1, 1, false},  {"bodyhinge_pyramid", 6, 2, 0, false},
      // Two square plates joined by four parallel bars: parallel lines span only 3 of the 6
      // screw directions, so the top plate keeps 3 motions (2 shears and a twist) and the bars
      // carry 1 stress. (The paper's complete graph on each flat plate gave 4 and 2: a flat K_4
      // flexes out of its plane in 3D.)
      {"bodybar_cube", 6, 3, 1, false},
      // The notes' section 5.2 polytopes, facets from the convex hull: the simplicial and the
      // other infinitesimally rigid ones, and the flexible zonotopes and Minkowski sums (the
      // truncated icosahedron's 5 flexes and 5 stresses are the notes' counts).
      {"truncated_tetrahedron", 6, 0, 0, true},  {"truncated_cube", 6, 0, 0, true},
      {"icosidodecahedron", 6, 0, 0, true},      {"tetrakis_hexahedron", 6, 0, 0, true},
      {"triakis_tetrahedron", 6, 0, 0, true},    {"truncated_icosahedron", 6, 5, 5, false},
      {"truncated_octahedron", 6, 5, 5, false},  {"rhombic_dodecahedron", 6, 5, 5, false},
      {"small_rhombicuboctahedron", 6, 6, 6, false}, {"great_rhombicuboctahedron", 6, 5, 5, false},
      {"rhombic_triacontahedron", 6, 9, 9, false},
  };
  for (const Row& r : rows) {
    INFO(r.name);
    const engine::RigidityReport rep = pipeline::analyze(example(r.name));
    CHECK(rep.trivial == r.trivial);
    CHECK(rep.nontrivial == r.nontrivial);
    CHECK(rep.stresses == r.stresses);
    CHECK(rep.inf_rigid == r.inf_rigid);
    CHECK(rep.warnings.empty());
    if (r.inf_rigid) CHECK(rep.rigid == engine::Verdict::Rigid);
  }
  // The dodecahedron: not infinitesimally rigid (notes 5.2), 6 trivial flexes.
  const engine::RigidityReport dod = pipeline::analyze(example("dodecahedron"));
  CHECK_FALSE(dod.inf_rigid);
  CHECK(dod.trivial == 6);
  CHECK(dod.nontrivial > 0);
}

TEST_CASE("system types: invariants hold along the tracked paths", "[scenes][engine]") {
  SECTION("Thales: vertex 3 stays on the circle over the diameter, with a right angle") {
    const scenes::Scene s = example("thales");
    const pipeline::Motion m = pipeline::track(s, s.motion.steps);
    REQUIRE(m.path.summary.status == engine::TrackStatus::Success);
    double moved = 0;
    for (size_t k = 0; k < m.path.samples.size(); ++k) {
      const Matrix p = blocks(s, m.path, k);
      const Eigen::Vector2d a = p.col(0), b = p.col(1), c = p.col(2);
      CHECK(std::abs(c.norm() - 1.0) <= 1e-10);
      CHECK(std::abs((a - c).dot(b - c)) <= 1e-10);
      moved = std::max(moved, (c - Eigen::Vector2d(blocks(s, m.path, 0).col(2))).norm());
    }
    CHECK(moved > 1.0);  // it really goes round
  }
  SECTION("hyperboloid: every vertex stays on x^2 + y^2 - z^2 = 1, bars keep their lengths") {
    const scenes::Scene s = example("square_on_hyperboloid", {"motion.steps=120"});
    const pipeline::Motion m = pipeline::track(s, 120);
    REQUIRE(m.path.summary.status == engine::TrackStatus::Success);
    const Matrix p0 = blocks(s, m.path, 0);
    for (size_t k = 0; k < m.path.samples.size(); ++k) {
      const Matrix p = blocks(s, m.path, k);
      for (int v = 0; v < 4; ++v)
        CHECK(std::abs(p(0, v) * p(0, v) + p(1, v) * p(1, v) - p(2, v) * p(2, v) - 1) <= 1e-10);
      for (auto [a, b] : {std::pair{0, 1}, {1, 2}, {2, 3}, {0, 3}})
        CHECK(std::abs((p.col(a) - p.col(b)).norm() - (p0.col(a) - p0.col(b)).norm()) <= 1e-10);
    }
  }
  SECTION("volume hypergraph: signed areas hold") {
    const scenes::Scene s = example("octahedral_volumes", {"motion.steps=150"});
    const pipeline::Motion m = pipeline::track(s, 150);
    REQUIRE(m.path.summary.status == engine::TrackStatus::Success);
    const auto& simplices = dynamic_cast<const engine::VolumeHypergraph&>(*s.model).simplices();
    auto area = [](const Matrix& p, const std::vector<int>& t) {
      const Eigen::Vector2d u = p.col(t[1]) - p.col(t[0]), w = p.col(t[2]) - p.col(t[0]);
      return u.x() * w.y() - u.y() * w.x();
    };
    const Matrix p0 = blocks(s, m.path, 0);
    for (size_t k = 0; k < m.path.samples.size(); ++k)
      for (const auto& t : simplices) CHECK(std::abs(area(blocks(s, m.path, k), t) - area(p0, t)) <= 1e-10);
    CHECK((blocks(s, m.path, m.path.samples.size() - 1) - p0).norm() > 0.1);
  }
  SECTION("spherical disk packing: inversive distances hold with their sign") {
    const scenes::Scene s = example("spherical_bricard", {"motion.steps=100"});
    const pipeline::Motion m = pipeline::track(s, 100);
    REQUIRE(m.path.summary.status == engine::TrackStatus::Success);
    const auto& model = dynamic_cast<const engine::SphericalDiskPacking&>(*s.model);
    const int contacts[12][2] = {{0, 1}, {0, 2}, {0, 3}, {0, 4}, {1, 2}, {1, 3}, {2, 4}, {3, 4}, {1, 5}, {2, 5}, {3, 5}, {4, 5}};
    for (size_t k = 0; k < m.path.samples.size(); ++k) {
      const Matrix p = blocks(s, m.path, k);
      for (int c = 0; c < 12; ++c) {
        const Vector a = p.col(contacts[c][0]), b = p.col(contacts[c][1]);
        const double I = (a.dot(b) - 1) / std::sqrt((a.squaredNorm() - 1) * (b.squaredNorm() - 1));
        CHECK(std::abs(I - model.inversiveDistances()[static_cast<size_t>(c)]) <= 1e-10);
        CHECK(I * model.inversiveDistances()[static_cast<size_t>(c)] > 0);  // the sign is kept
      }
    }
  }
  SECTION("polytope: facets stay planar and edges keep their lengths") {
    const scenes::Scene s = example("cuboctahedron", {"motion.steps=60"});
    const pipeline::Motion m = pipeline::track(s, 60);
    REQUIRE(m.path.summary.status == engine::TrackStatus::Success);
    const auto& poly = dynamic_cast<const engine::Polytope&>(*s.model);
    const Matrix p0 = blocks(s, m.path, 0);
    for (size_t k = 0; k < m.path.samples.size(); ++k) {
      const Matrix p = blocks(s, m.path, k);
      for (const auto& f : poly.facets()) {
        // planarity without the normal: every vertex on the plane of the first three
        const Eigen::Vector3d a = p.col(f[0]), n = (Eigen::Vector3d(p.col(f[1])) - a).cross(Eigen::Vector3d(p.col(f[2])) - a).normalized();
        for (int v : f) CHECK(std::abs(n.dot(Eigen::Vector3d(p.col(v)) - a)) <= 1e-10);
      }
      for (const auto& e : poly.edges())
        CHECK(std::abs((p.col(e[0]) - p.col(e[1])).norm() - (p0.col(e[0]) - p0.col(e[1])).norm()) <= 1e-10);
    }
    CHECK((blocks(s, m.path, m.path.samples.size() - 1) - p0).leftCols(12).norm() > 0.1);
  }
}

TEST_CASE("system types: convex-hull facets", "[engine]") {
  // The hull of the truncated icosahedron: 12 pentagons and 20 hexagons, outward and planar.
  const scenes::Scene s = example("truncated_icosahedron");
  const auto& poly = dynamic_cast<const engine::Polytope&>(*s.model);
  const Matrix p = s.model->startPositions();
  int pentagons = 0, hexagons = 0;
  for (const auto& f : poly.facets()) {
    pentagons += f.size() == 5;
    hexagons += f.size() == 6;
    const Eigen::Vector3d a = p.col(f[0]), b = p.col(f[1]), c = p.col(f[2]);
    const Eigen::Vector3d n = (b - a).cross(c - b);
    CHECK(n.dot(a) > 0);  // counter-clockwise seen from outside (the centre is the origin)
  }
  CHECK(pentagons == 12);
  CHECK(hexagons == 20);
  CHECK(poly.edges().size() == 90);
  // Bad vertex sets.
  Matrix q(3, 5);
  q << 0, 1, 0, 0, 0.2, 0, 0, 1, 0, 0.2, 0, 0, 0, 1, 0.2;  // vertex 5 inside
  CHECK_THROWS_WITH(engine::convexHullFacets(q), Catch::Contains("vertex 5 is inside the convex hull"));
  q.col(4) << 0.5, 0.5, 0;  // on the edge [2, 3]
  CHECK_THROWS_WITH(engine::convexHullFacets(q), Catch::Contains("vertex 5 is on the convex hull's boundary"));
  q.row(2).setZero();  // all in a plane
  CHECK_THROWS_WITH(engine::convexHullFacets(q), Catch::Contains("coplanar"));
  requireSceneError("[system]\ntype = \"polytope\"\nfacets = \"hul\"\nvertices = [[0,0,0],[1,0,0],[0,1,0],[0,0,1]]\n", 3, 10,
               "facets must be a list of vertex cycles or \"hull\"");
  requireSceneError("[system]\ntype = \"polytope\"\nfacets = \"hull\"\nvertices = [[0,0,0],[1,0,0],[0,1,0],[0,0,1],[0.1,0.1,0.1]]\n",
               4, 45, "vertex 5 is inside the convex hull");
}

TEST_CASE("system types: the convex hull of 3,000 points (Qhull) is a closed triangulated sphere", "[engine]") {
  // 3,000 random points on the unit sphere: every one is a corner, every facet a triangle,
  // every edge in two facets, and V - E + F = 2. (The O(n^4) hull took hours here.)
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g;
  const int n = 3000;
  Matrix p(3, n);
  for (int i = 0; i < n; ++i) p.col(i) = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
  const auto facets = engine::convexHullFacets(p);
  std::map<std::pair<int, int>, int> edges;
  std::vector<char> used(n, 0);
  for (const auto& f : facets) {
    REQUIRE(f.size() == 3);
    const Eigen::Vector3d a = p.col(f[0]), b = p.col(f[1]), c = p.col(f[2]);
    CHECK((b - a).cross(c - b).dot(a + b + c) > 0);  // outward
    for (size_t k = 0; k < 3; ++k) {
      ++edges[std::minmax(f[k], f[(k + 1) % 3])];
      used[static_cast<size_t>(f[k])] = 1;
    }
  }
  for (const auto& [e, count] : edges) CHECK(count == 2);
  CHECK(std::count(used.begin(), used.end(), 1) == n);
  CHECK(n - static_cast<int>(edges.size()) + static_cast<int>(facets.size()) == 2);
  // A point added inside, or on a facet: named.
  Matrix q(3, n + 1);
  q.leftCols(n) = p;
  q.col(n) = 0.5 * p.col(0);
  CHECK_THROWS_WITH(engine::convexHullFacets(q), Catch::Contains("vertex 3001 is inside the convex hull"));
  const auto& t = facets[0];
  q.col(n) = (p.col(t[0]) + p.col(t[1]) + p.col(t[2])) / 3;
  CHECK_THROWS_WITH(engine::convexHullFacets(q), Catch::Contains("vertex 3001 is on the convex hull's boundary"));
}

TEST_CASE("system types: hull facets merge coplanar triangles into polygons", "[engine]") {
  // A cube and a prism over a regular 40-gon: squares and 40-gons, not triangles.
  Matrix cube(3, 8);
  for (int i = 0; i < 8; ++i) cube.col(i) << (i & 1), (i >> 1 & 1), (i >> 2 & 1);
  const auto cf = engine::convexHullFacets(cube);
  REQUIRE(cf.size() == 6);
  for (const auto& f : cf) CHECK(f.size() == 4);
  const int m = 40;
  Matrix prism(3, 2 * m);
  for (int i = 0; i < m; ++i) {
    const double a = 2 * M_PI * i / m;
    prism.col(i) << std::cos(a), std::sin(a), 0;
    prism.col(m + i) << std::cos(a), std::sin(a), 0.3;
  }
  const auto pf = engine::convexHullFacets(prism);
  REQUIRE(pf.size() == static_cast<size_t>(m + 2));
  int big = 0;
  for (const auto& f : pf) big += f.size() == static_cast<size_t>(m);
  CHECK(big == 2);
}

TEST_CASE("system types: the flexible polytopes of the notes move, keeping edges and facets", "[engine][scenes]") {
  for (const char* name : {"truncated_octahedron", "rhombic_dodecahedron", "small_rhombicuboctahedron"}) {
    INFO(name);
    const scenes::Scene s = example(name, {"motion.steps=15"});
    const pipeline::Motion m = pipeline::track(s, 15);
    INFO(m.path.summary.briefReport());
    REQUIRE(m.path.summary.status == engine::TrackStatus::Success);
    CHECK(m.path.summary.max_residual <= 1e-10 * s.model->system().residualScale());
    // Not a rigid motion: some distance between vertices changes.
    const Matrix a = s.model->system().vertexPositions(m.path.samples.front());
    const Matrix b = s.model->system().vertexPositions(m.path.samples.back());
    double change = 0;
    for (int i = 0; i < a.cols(); ++i)
      for (int j = i + 1; j < a.cols(); ++j)
        change = std::max(change, std::abs((a.col(i) - a.col(j)).norm() - (b.col(i) - b.col(j)).norm()));
    CHECK(change > 0.1 * 15 * s.motion.step_size);
  }
}

TEST_CASE("system types: the dodecahedron's edge contracts to 0.5, every other edge and facet kept",
          "[scenes][engine][slow]") {
  const scenes::Scene s = example("dodecahedron");
  const pipeline::Motion m = pipeline::track(s, s.motion.steps);
  REQUIRE(m.path.summary.status == engine::TrackStatus::Success);
  REQUIRE(m.path.samples.size() == 251);  // (1 - 0.5) / 0.002 steps, no repeated sample
  const auto& poly = dynamic_cast<const engine::Polytope&>(*s.model);
  const Matrix p0 = blocks(s, m.path, 0);
  for (size_t k = 0; k < m.path.samples.size(); ++k) {
    const Matrix p = blocks(s, m.path, k);
    CHECK((p.col(0) - p.col(8)).norm() == Approx(1.0 - 0.002 * static_cast<double>(k)).margin(1e-10));
    for (const auto& e : poly.edges()) {
      if ((e[0] == 0 && e[1] == 8)) continue;
      CHECK(std::abs((p.col(e[0]) - p.col(e[1])).norm() - 1.0) <= 1e-10);
    }
    for (const auto& f : poly.facets()) {
      const Eigen::Vector3d a = p.col(f[0]), n = (Eigen::Vector3d(p.col(f[1])) - a).cross(Eigen::Vector3d(p.col(f[2])) - a).normalized();
      for (int v : f) CHECK(std::abs(n.dot(Eigen::Vector3d(p.col(v)) - a)) <= 1e-10);
    }
  }
  // Deterministic: the same path twice.
  const pipeline::Motion again = pipeline::track(s, s.motion.steps);
  CHECK((again.path.samples.back() - m.path.samples.back()).norm() == 0.0);
}

TEST_CASE("system types: bad input is named with its position", "[scenes]") {
  requireSceneError("[system]\ntype = \"polytope\"\nvertices = [[0,0,0],[1,0,0],[0,1,0],[0,0,1]]\n"
               "facets = [[1,2,3],[1,2,4],[1,3,4],[2,3]]\n",
               4, 35, "a facet lists at least 3 vertices");
  requireSceneError("[system]\ntype = \"polytope\"\nvertices = [[0,0,0],[1,0,0],[1,1,0.2],[0,1,0],[0.5,0.5,1]]\n"
               "facets = [[1,2,3,4],[1,2,5],[2,3,5],[3,4,5],[4,1,5]]\n",
               4, 11, "facet 1 [1, 2, 3, 4] is not planar");
  requireSceneError("[system]\ntype = \"polytope\"\nvertices = [[0,0,0],[1,0,0],[0,1,0],[0,0,1]]\n"
               "facets = [[1,2,3],[1,2,4],[1,3,4]]\n",
               4, 10, "need");  // fewer than 4 facets
  requireSceneError("[system]\ntype = \"polytope\"\nvertices = [[0,0,0],[1,0,0],[0,1,0],[0,0,1],[1,1,1]]\n"
               "facets = [[1,2,3],[1,2,4],[1,3,4],[2,3,4]]\n",
               3, 45, "vertex 5 is in no facet");
  requireSceneError("[system]\ntype = \"spherical_disk_packing\"\nvertices = [[2,0,0],[0,0.5,0]]\ncontacts = [[1,2]]\n",
               3, 21, "vertex 2 has norm 0.5");
  requireSceneError("[system]\ntype = \"framework_on_surface\"\nvertices = [[1,0,0],[0,1,0.5]]\nedges = [[1,2]]\n"
               "surface = \"x^2 + y^2 + z^2 - 1\"\n",
               3, 21, "vertex 2 is about 0.112 away");
  requireSceneError("[system]\ntype = \"framework_on_surface\"\nvertices = [[1,0,0],[0,1,0]]\nedges = [[1,2]]\n"
               "surface = \"x^2 + y^2 + w - 1\"\n",
               5, 24, "unknown name 'w' (known: x, y, z, pi");
  requireSceneError("[system]\ntype = \"angular_framework\"\nvertices = [[0,0],[1,0],[0,1]]\nangles = [[1,2,1]]\n",
               4, 11, "repeats a vertex");
  requireSceneError("[system]\ntype = \"volume_hypergraph\"\nvertices = [[0,0],[1,0],[0,1],[1,1]]\nsimplices = [[1,2,3,4]]\n",
               4, 14, "has 4 vertices; in 2D a simplex has 3");
  requireSceneError("[system]\ntype = \"volume_hypergraph\"\nvertices = [[0,0],[1,0],[2,0]]\nsimplices = [[1,2,3]]\n",
               4, 14, "has volume 0");
  requireSceneError("[system]\ntype = \"body_bar\"\nvertices = [[0,0,0],[1,0,0],[0,1,0],[0,0,1]]\nbodies = [[1,2,3]]\n"
               "bars = [[1,2]]\n",
               5, 9, "bar 1 joins vertices 1 and 2 of body 1, which holds their distance already");
  requireSceneError("[system]\ntype = \"body_bar\"\nvertices = [[0,0,0],[1,0,0],[0,1,0],[0,0,1]]\nbodies = [[1,2,3]]\n"
               "bars = [[1,4], [4,1]]\n",
               5, 16, "bar 2 repeats the pair [1, 4]");
  requireSceneError("[system]\ntype = \"body_hinge\"\nvertices = [[0,0,0],[1,0,0],[0,1,0],[0,0,1]]\nbodies = [[1,2,3], [4, 2, 4]]\n",
               4, 20, "body 2 [4, 2, 4] lists a vertex twice");
  requireSceneError("[system]\ntype = \"body_hinge\"\nvertices = [[0,0,0],[1,0,0],[0,1,0],[0,0,1]]\nbodies = [[1,2,3], []]\n",
               4, 20, "a body lists at least 1 vertex, this one 0");
  requireSceneError("[system]\ntype = \"catalog\"\nname = \"cube\"\n[motion]\ncontract_edge = [1,7]\ntarget_length = 0.5\n",
               5, 17, "is not an edge");
  requireSceneError("[system]\ntype = \"catalog\"\nname = \"cube\"\n[motion]\ncontract_edge = [1,2]\n",
               5, 17, "needs target_length");
}

// Issue 41: projecting a driven motion (an edge contraction, a fold drive) of a system with
// nontrivial flexes read flex coefficients that a driven path does not have (a segfault in the
// CLI, the viewer and Python). Its projection is the driven path, its arrow the first step.
TEST_CASE("system types: driven motions project (contraction, fold drive), with both directions asked", "[pipeline]") {
  const std::string square =
      "[system]\ntype = \"framework\"\nvertices = [[0,0],[1,0],[1,1],[0,1]]\nedges = [[1,2],[2,3],[3,4],[4,1]]\n"
      "pinned = [1,2]\n[motion]\ncontract_edge = [3, 4]\ntarget_length = 0.8\nstep_size = 0.01\n";
  std::vector<scenes::Scene> scenes;
  scenes.push_back(scenes::loadSceneFromString(square, "t.toml"));
  scenes.push_back(scenes::loadSceneFromString(square + "[projection]\nboth_directions = true\nflex_arrows = true\n", "t.toml"));
  scenes.push_back(example("dodecahedron", {"motion.steps=20", "projection.both_directions=true"}));
  scenes.push_back(example("miura_ori", {"motion.fold_percent=50", "motion.steps=10"}));
  for (const scenes::Scene& s : scenes) {
    INFO(s.title);
    pipeline::Study study(s);
    const pipeline::Motion& m = study.motion();
    REQUIRE(m.rep.nontrivial > 0);
    REQUIRE(m.path.flex.empty());  // driven: no flex coefficients
    const auto& paths = study.projectionPaths();
    REQUIRE(paths.size() == 1);
    CHECK(paths[0].samples.size() == m.path.samples.size());  // the driven path, forward only
    CHECK(paths[0].start == 0);
    REQUIRE(paths[0].flex.size() == s.model->system().numVariables());
    CHECK(paths[0].flex.norm() == Approx(1.0));
    CHECK(paths[0].flex.dot(m.path.samples[1] - m.path.samples[0]) > 0);
    CHECK(paths[0].label == m.path.flex_choice);
  }
  // Other flexes asked for in [projection] are followed as motions along them, not driven.
  const scenes::Scene more = scenes::loadSceneFromString(
      "[system]\ntype = \"framework\"\nvertices = [[0,0],[1,0],[1.3,0.9],[0.5,1.5],[-0.3,0.9]]\n"
      "edges = [[1,2],[2,3],[3,4],[4,5],[5,1]]\npinned = [1,2]\n"
      "[motion]\ncontract_edge = [3, 4]\ntarget_length = 0.8\nstep_size = 0.01\nsteps = 10\n"
      "[projection]\nflexes = [[1, 0], [0, 1]]\n",
      "t.toml");
  pipeline::Study study(more);
  const auto& paths = study.projectionPaths();
  REQUIRE(paths.size() == 2);
  for (const auto& p : paths) {
    CHECK(p.samples.size() == 11);
    CHECK(p.label.rfind("flex ", 0) == 0);
  }
}

// Issue 41: a step of h moves the configuration by h for every system type. A polytope's facet
// normals (auxiliary variables) do not count: Bricard's octahedron as a polytope of eight
// triangles and as the framework of its edges travel the same arc, 200 steps of 0.02 = 4.
TEST_CASE("system types: a polytope's step is measured on its vertices, as its framework's", "[pipeline]") {
  const std::string v = "vertices = [[0,0,-1],[-1,-1,0],[1,-1,0],[1,1,0],[-1,1,0],[0,0,1]]\n";
  const std::string motion = "[motion]\nsteps = 200\nstep_size = 0.02\n";
  const scenes::Scene poly = scenes::loadSceneFromString(
      "[system]\ntype = \"polytope\"\n" + v +
          "facets = [[1,2,4],[1,4,3],[1,3,5],[1,5,2],[6,2,4],[6,4,3],[6,3,5],[6,5,2]]\n" + motion,
      "p.toml");
  const scenes::Scene frame = scenes::loadSceneFromString(
      "[system]\ntype = \"framework\"\n" + v +
          "edges = [[1,2],[1,3],[1,4],[1,5],[2,6],[3,6],[4,6],[5,6],[2,4],[4,3],[3,5],[5,2]]\n" + motion,
      "f.toml");
  for (const scenes::Scene* s : {&poly, &frame}) {
    INFO(s->type);
    const pipeline::Motion m = pipeline::track(*s, 200);
    REQUIRE(m.path.summary.status == engine::TrackStatus::Success);
    const engine::ConstraintSystem& sys = s->model->system();
    double arc = 0;
    for (size_t i = 1; i < m.path.samples.size(); ++i) {
      // The vertices' displacement, computed from the positions (not from the variables).
      const double d = (sys.vertexPositions(m.path.samples[i]) - sys.vertexPositions(m.path.samples[i - 1])).norm();
      CHECK(d == Approx(0.02).epsilon(0.05));
      arc += d;
    }
    CHECK(arc == Approx(4.0).epsilon(0.01));
  }
}

// Found by the valid-scene fuzzer (issue 41): the 2D angle equation |u||w| sin(theta0 - theta)
// also holds at theta0 + 180 degrees, which a path reached by moving a vertex through the
// angle's apex (the angle went from +90 to -90 degrees, "success", residual 0). The motion ends
// before that sample, and says why.
TEST_CASE("system types: an angular framework's path ends where a vertex would pass through an apex", "[pipeline]") {
  const scenes::Scene s = scenes::loadSceneFromString(
      "[system]\ntype = \"angular_framework\"\nvertices = [[0,0],[0.05,0],[0,1]]\nangles = [[2,1,3]]\npinned = [1,3]\n"
      "[motion]\nsteps = 10\nstep_size = 0.01\nflex = [-1]\n",
      "flip.toml");
  const pipeline::Motion m = pipeline::track(s, 10);
  CHECK(m.path.summary.status == engine::TrackStatus::Success);
  CHECK_THAT(m.path.summary.reason, Catch::Contains("angle [2, 1, 3] would turn by 180 degrees next"));
  REQUIRE(m.path.samples.size() >= 2);
  REQUIRE(m.path.samples.size() < 11);
  for (const Vector& x : m.path.samples) {
    const Matrix p = s.model->system().vertexPositions(x);
    const Eigen::Vector2d u = p.col(1) - p.col(0), w = p.col(2) - p.col(0);
    CHECK(std::atan2(u[0] * w[1] - u[1] * w[0], u.dot(w)) == Approx(M_PI / 2).margin(1e-9));  // the start's angle
  }
}
