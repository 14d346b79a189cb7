// Attached points ([system] attached = [[v, a, b(, c)], ...]): a vertex held in the frame of
// others adds no degree of freedom, keeps its frame coordinates along every tracked path, and
// follows the curves kinematics knows; bad attachments are reported at the item.
#include <catch2/catch.hpp>

#include <cmath>
#include <string>

#include <Eigen/Geometry>

#include "engine/rigidity.h"
#include "pipeline/pipeline.h"
#include "scenes/scene.h"
#include "../scenes/scene_test_common.h"

using namespace flexure;
using engine::Matrix;

namespace {

scenes::Scene scene(const std::string& system, int steps = 100) {
  return scenes::loadSceneFromString("[system]\ntype = \"framework\"\n" + system + "\n[motion]\nsteps = " +
                                         std::to_string(steps) + "\nstep_size = 0.05\n",
                                     "t.toml");
}

Matrix at(const scenes::Scene& s, const engine::DeformationPath& p, size_t k) {
  return s.model->system().positions(p.samples[k]);
}

}  // namespace

TEST_CASE("attached: every coupler point of a parallelogram linkage moves on a circle of the crank's radius",
          "[scenes]") {
  // Ground 1-2 (pinned), cranks 1-3 and 2-4 of length 1, coupler 3-4 parallel to the ground: the
  // coupler translates, so each of its points describes the crank circle translated (a classical
  // fact of the parallelogram four-bar). Vertex 5 is a coupler point off the bar.
  const std::string base = "vertices = [[0,0],[2,0],[0,1],[2,1],[1.3,1.6]]\nedges = [[1,3],[2,4],[3,4]]\n"
                           "pinned = [1,2]\n";
  const scenes::Scene plain = scene("vertices = [[0,0],[2,0],[0,1],[2,1]]\nedges = [[1,3],[2,4],[3,4]]\npinned = [1,2]");
  const scenes::Scene s = scene(base + "attached = [[5,3,4]]");
  const engine::RigidityReport r0 = pipeline::analyze(plain), r = pipeline::analyze(s);
  CHECK(r.nontrivial == r0.nontrivial);
  CHECK(r.nontrivial == 1);
  CHECK(r.stresses == 0);
  CHECK(r.trivial == r0.trivial);
  const pipeline::Motion m = pipeline::track(s, 100);
  REQUIRE(m.path.summary.status == engine::TrackStatus::Success);
  CHECK(m.path.summary.max_residual < 1e-12);
  const Eigen::Vector2d centre(1.3, 0.6);  // the start point of 5 minus the start crank vector (0, 1)
  double swept = 0;
  for (size_t k = 0; k < m.path.samples.size(); ++k) {
    const Matrix p = at(s, m.path, k);
    CHECK(std::abs((Eigen::Vector2d(p.col(4)) - centre).norm() - 1.0) <= 1e-10);
    // Its coordinates in the coupler's frame are those of the start: (0.65, 0.3) of 3 -> 4.
    const Eigen::Vector2d e = p.col(3) - p.col(2), q = Eigen::Vector2d(p.col(4)) - Eigen::Vector2d(p.col(2));
    CHECK(std::abs(q.dot(e) / e.squaredNorm() - 0.65) <= 1e-10);
    CHECK(std::abs((e.x() * q.y() - e.y() * q.x()) / e.squaredNorm() - 0.3) <= 1e-10);
    swept = std::max(swept, (Eigen::Vector2d(p.col(4)) - Eigen::Vector2d(1.3, 1.6)).norm());
  }
  CHECK(swept > 1.0);  // it really goes round
  // Drawn joined to its frame: the coupler triangle.
  CHECK(s.model->geometry().bars.edges.size() == 5);
}

TEST_CASE("attached: a ternary link joined to a dyad keeps one degree of freedom (Watt's six-bar)", "[scenes]") {
  // A four-bar 1-3-4-2 whose coupler carries point 5 (a ternary link 3-4-5); a dyad 5-7-6 ties
  // it to the ground at 6: 7 vertices, 3 pinned, 8 variables, 5 bars + 2 attachment equations.
  const scenes::Scene s = scene(
      "vertices = [[0,0],[3,0],[0.4,1.2],[2.6,1.5],[1.6,2.6],[4,2.5],[3.1,3.4]]\n"
      "edges = [[1,3],[2,4],[3,4],[5,7],[6,7]]\npinned = [1,2,6]\nattached = [[5,3,4]]",
      60);
  const engine::RigidityReport r = pipeline::analyze(s);
  CHECK(r.nontrivial == 1);
  CHECK(r.stresses == 0);
  const pipeline::Motion m = pipeline::track(s, 60);
  REQUIRE(m.path.samples.size() == 61);
  CHECK(m.path.summary.max_residual < 1e-12);
  const Matrix p0 = at(s, m.path, 0);
  for (size_t k = 0; k < m.path.samples.size(); ++k) {
    const Matrix p = at(s, m.path, k);
    // The ternary link is rigid: its three sides keep their lengths.
    CHECK(std::abs((p.col(4) - p.col(2)).norm() - (p0.col(4) - p0.col(2)).norm()) <= 1e-10);
    CHECK(std::abs((p.col(4) - p.col(3)).norm() - (p0.col(4) - p0.col(3)).norm()) <= 1e-10);
  }
  CHECK((at(s, m.path, 60).col(4) - p0.col(4)).norm() > 0.3);
}

TEST_CASE("attached: in 3D, on a bar's line or in a triangle's frame, no reflection, no extra freedom", "[scenes]") {
  // A tetrahedron with a point at a third of edge 1-2 and a point off face 1-2-3: still
  // infinitesimally rigid with the 6 Euclidean motions.
  const scenes::Scene tet = scene(
      "vertices = [[0,0,0],[3,0,0],[0,2,0],[0,0,2],[1,0,0],[1,1,1.5]]\n"
      "edges = [[1,2],[1,3],[1,4],[2,3],[2,4],[3,4]]\nattached = [[5,1,2],[6,1,2,3]]");
  const engine::RigidityReport rt = pipeline::analyze(tet);
  CHECK(rt.inf_rigid);
  CHECK(rt.trivial == 6);
  CHECK(rt.stresses == 0);
  // Two triangles on a hinge 1-2 (pinned): each turns about the hinge, 2 flexes, one of them the
  // trivial turn of everything about the pinned axis. Vertex 5 rides
  // on triangle 1-2-3, off its plane; along the motion it keeps its distances to 1, 2, 3 and the
  // side of the plane it is on.
  const scenes::Scene hinge = scene(
      "vertices = [[0,0,0],[2,0,0],[1,1.5,0],[1,0,1.5],[1.4,0.8,0.7]]\n"
      "edges = [[1,2],[1,3],[2,3],[1,4],[2,4]]\npinned = [1,2]\nattached = [[5,1,2,3]]",
      40);
  const engine::RigidityReport rh = pipeline::analyze(hinge);
  CHECK(rh.trivial == 1);
  CHECK(rh.nontrivial == 1);
  CHECK(rh.stresses == 0);
  const pipeline::Motion m = pipeline::track(hinge, 40);
  REQUIRE(m.path.samples.size() == 41);
  CHECK(m.path.summary.max_residual < 1e-12);
  const Matrix p0 = at(hinge, m.path, 0);
  auto volume = [](const Matrix& p) {
    const Eigen::Vector3d a = p.col(0), b = p.col(1), c = p.col(2), v = p.col(4);
    return (b - a).cross(c - a).dot(v - a);
  };
  for (size_t k = 0; k < m.path.samples.size(); ++k) {
    const Matrix p = at(hinge, m.path, k);
    for (int f : {0, 1, 2}) CHECK(std::abs((p.col(4) - p.col(f)).norm() - (p0.col(4) - p0.col(f)).norm()) <= 1e-10);
    CHECK(std::abs(volume(p) - volume(p0)) <= 1e-10);
  }
  CHECK((at(hinge, m.path, 40).col(4) - p0.col(4)).norm() > 0.1);
}

TEST_CASE("attached: bad attachments are reported at the item", "[scenes]") {
  const std::string head = "[system]\ntype = \"framework\"\n";
  const std::string sq2 = "vertices = [[0,0],[1,0],[1,1],[0,1]]\nedges = [[1,2],[2,3],[3,4]]\n";
  test::requireSceneError(head + sq2 + "attached = [[4,4,1]]\n", 5, 13, "own frame");
  test::requireSceneError(head + sq2 + "pinned = [4]\nattached = [[4,1,2]]\n", 6, 13, "pinned vertex cannot be attached");
  test::requireSceneError(head + sq2 + "attached = [[4,1,2],[4,2,3]]\n", 5, 21, "attached twice");
  test::requireSceneError(head + sq2 + "attached = [[4,1]]\n", 5, 13, "3 to 4 vertices");
  test::requireSceneError(head + sq2 + "attached = [[4,1,2,3,1]]\n", 5, 13, "3 to 4 vertices");
  test::requireSceneError(head + sq2 + "attached = [[4,1,9]]\n", 5, 18, "out of range");
  test::requireSceneError(head + "vertices = [[0,0],[1,0],[2,0],[0,1]]\nedges = [[1,2],[2,3]]\nattached = [[4,1,2,3]]\n",
                          5, 13, "collinear");
  test::requireSceneError(head + "vertices = [[0,0,0],[1,0,0],[0,1,0]]\nedges = [[1,2]]\nattached = [[3,1,2]]\n", 5, 13,
                          "must lie on their line");
  test::requireSceneError(head + "vertices = [[0,0],[0,0],[1,1]]\nedges = [[1,3]]\nattached = [[3,1,2]]\n", 5, 13,
                          "coincide");
  test::requireSceneError("[system]\ntype = \"body_hinge\"\nvertices = [[0,0],[1,0],[0,1]]\nbodies = [[1,2,3]]\n"
                          "attached = [[3,1,2]]\n",
                          5, 1, "attached");
}
