// Sticky disk and sphere packings: contact detection and overlap rejection, the located
// contact events, the invariants along the piecewise paths (contacts kept, never an overlap
// beyond the tolerance), the end once rigid, the hypostatic packings of the notes, and bad input.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <random>

#include "engine/fp_traps.h"
#include "engine/systems/sphere_packing.h"
#include "engine/track.h"
#include "engine/rigidity.h"
#include "render/renderer.h"
#include "scenes/catalog.h"
#include "pipeline/pipeline.h"
#include "present/path_output.h"
#include "scenes/scene.h"
#include "../scenes/scene_test_common.h"
#include "../test_common.h"

using namespace flexure;
using test::example;
using test::requireSceneError;
using engine::Matrix;
using engine::Vector;

namespace {



double gap(const Matrix& p, const std::vector<double>& r, int i, int j) {
  return ((p.col(i) - p.col(j)).norm() - r[i] - r[j]) / (r[i] + r[j]);
}

// Checks a sticky path sample by sample: the contacts made so far hold to 1e-10, no other pair
// overlaps by more than the tolerance, and each contact event's pair touches where it is made.
void requireStickyInvariants(const scenes::Scene& s, const engine::DeformationPath& r) {
  const auto& packing = dynamic_cast<const engine::SpherePacking&>(*s.model);
  const auto& sys = packing.system();
  const auto& radii = packing.radii();
  const int n = sys.numVertices();
  std::vector<std::array<int, 2>> contacts = packing.contacts();
  size_t next_event = 0;
  for (size_t k = 0; k < r.samples.size(); ++k) {
    INFO("sample " << k);
    while (next_event < r.events.size() && r.events[next_event].sample <= static_cast<int>(k)) {
      const auto& e = r.events[next_event++];
      if (e.kind != engine::EventKind::Contact) continue;
      REQUIRE(e.vertices.size() == 2);
      REQUIRE(e.sample == static_cast<int>(k));
      contacts.push_back({e.vertices[0], e.vertices[1]});
    }
    const Matrix p = sys.vertexPositions(r.samples[k]);
    for (int i = 0; i < n; ++i)
      for (int j = i + 1; j < n; ++j) {
        const bool touching =
            std::find(contacts.begin(), contacts.end(), std::array<int, 2>{i, j}) != contacts.end();
        const double g = gap(p, radii, i, j);
        if (touching) REQUIRE(std::abs(g) <= 1e-10);
        else REQUIRE(g >= -packing.tolerance());
      }
  }
}

}  // namespace

TEST_CASE("packing: contacts are found within the tolerance and the start snaps onto them", "[engine]") {
  Matrix p(2, 3);
  p << 0, 2 + 5e-7, 0, 0, 0, 3;  // 1-2 touch up to 5e-7 (relative 2.5e-7), 3 is apart
  const engine::SpherePacking packing(p, {1, 1, 1}, {0}, 1e-6);
  REQUIRE(packing.contacts() == std::vector<std::array<int, 2>>{{0, 1}});
  const Matrix s = packing.startPositions();
  CHECK(std::abs((s.col(0) - s.col(1)).norm() - 2) <= 1e-13);
  CHECK((s - p).norm() < 1e-6);
  // A tighter tolerance: no contact, nothing moves.
  const engine::SpherePacking apart(p, {1, 1, 1}, {0}, 1e-8);
  CHECK(apart.contacts().empty());
  CHECK(apart.startPositions() == p);
  // Different radii: 1-3 touch (|(0,0)-(0,3)| = 3 = 1 + 2).
  const engine::SpherePacking mixed(p, {1, 1.0000001, 2}, {}, 1e-6);  // 1-3: 3 = 1 + 2
  CHECK(mixed.contacts().size() == 2);
  CHECK(mixed.isContact(2, 0));
  Matrix q = p;
  q(0, 1) = 1.5;  // 1-2 overlap
  CHECK_THROWS_WITH(engine::SpherePacking(q, {1, 1, 1}, {}, 1e-6, 1),
                    Catch::Contains("disks 1 and 2 overlap: their centres are 1.5 apart, their radii add up to 2"));
  CHECK_THROWS_WITH(engine::SpherePacking(p, {1, -1, 1}, {}), Catch::Contains("radius of vertex 2 must be positive"));
}

TEST_CASE("packing: Jacobians match finite differences, Euclidean motions are trivial", "[engine]") {
  std::mt19937 rng(3);
  for (const char* name : {"disk_packing", "sphere_packing", "hypostatic_packing"}) {
    INFO(name);
    const scenes::Scene s = example(name);
    const auto& sys = s.model->system();
    const Vector x0 = s.model->startCoordinates();
    for (const Vector& x : {x0, Vector(x0 + test::randomVector(rng, sys.numVariables(), 0.05))}) {
      test::requireJacobianMatchesFiniteDifferences(sys, x);
      test::requireSecondDerivativeMatchesFiniteDifferences(sys, x, test::randomVector(rng, sys.numVariables()),
                                                            test::randomVector(rng, sys.numVariables()));
    }
    const Matrix T = engine::trivialFlexes(*s.model, x0, 1e-9);
    CHECK((Matrix(sys.jacobian(x0)) * T).cwiseAbs().maxCoeff() <= 1e-12);
  }
}

TEST_CASE("packing: the 2D sticky disks make two contacts and end rigid", "[engine][scenes]") {
  const scenes::Scene s = example("disk_packing");
  const pipeline::Motion m = pipeline::track(s, s.motion.steps);
  const auto& r = m.path;
  INFO(r.summary.briefReport());
  REQUIRE(r.summary.status == engine::TrackStatus::Success);  // the motion is over, as designed
  CHECK_THAT(r.summary.reason, Catch::Contains("the packing became rigid at sample 148") &&
                                   Catch::Contains("disks 1 and 4 touched"));
  CHECK(r.samples.size() == 149);
  CHECK(r.summary.steps_done == 148);
  std::vector<std::pair<int, std::vector<int>>> contacts;
  for (const auto& e : r.events)
    if (e.kind == engine::EventKind::Contact) contacts.push_back({e.sample, e.vertices});
  REQUIRE(contacts.size() == 2);
  CHECK(contacts[0].second == std::vector<int>{1, 3});
  CHECK(contacts[1] == std::pair<int, std::vector<int>>{148, {0, 3}});
  CHECK(r.summary.max_residual < 1e-10);
  requireStickyInvariants(s, r);
  // Regular spacing between the events; the located contact is closer to its predecessor.
  for (size_t k = 1; k < r.samples.size(); ++k) {
    const double d = (r.samples[k] - r.samples[k - 1]).norm();
    const bool contact = std::any_of(contacts.begin(), contacts.end(), [&](auto& c) { return c.first == int(k); });
    if (contact) CHECK(d <= 1.3 * s.motion.step_size);
    else CHECK(std::abs(d - s.motion.step_size) <= 0.06 * s.motion.step_size);
  }
  // The path JSON names the pairs (SPEC section 3), numbered from 1.
  const auto j = present::pathJson(s, r);
  CHECK(j["status"] == "success");
  CHECK_THAT(j["reason"].get<std::string>(), Catch::Contains("became rigid at sample 148"));
  bool found = false;
  for (const auto& e : j["events"])
    if (e["kind"] == "contact" && e["sample"] == 148) found = e["pair"] == nlohmann::ordered_json({1, 4});
  CHECK(found);
  // Deterministic.
  const pipeline::Motion again = pipeline::track(s, s.motion.steps);
  REQUIRE(again.path.samples.size() == r.samples.size());
  CHECK(again.path.samples.back() == r.samples.back());
}

TEST_CASE("packing: the 3D sticky spheres end rigid as a tetrahedron", "[engine][scenes]") {
  const scenes::Scene s = example("sphere_packing");
  const pipeline::Motion m = pipeline::track(s, s.motion.steps);
  const auto& r = m.path;
  INFO(r.summary.briefReport());
  REQUIRE(r.summary.status == engine::TrackStatus::Success);
  CHECK_THAT(r.summary.reason, Catch::Contains("became rigid"));
  CHECK(r.samples.size() < 200);
  int contacts = 0;
  for (const auto& e : r.events) contacts += e.kind == engine::EventKind::Contact;
  CHECK(contacts == 3);  // 2-3, 2-4, 3-4: all six pairs touch at the end
  requireStickyInvariants(s, r);
  const auto& packing = dynamic_cast<const engine::SpherePacking&>(*s.model);
  const Matrix last = s.model->system().vertexPositions(r.samples.back());
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) CHECK(std::abs(gap(last, packing.radii(), i, j)) <= 1e-10);
  // The contact graph drawn at the end has all six pairs.
  CHECK(r.geometryAt(static_cast<int>(r.samples.size()) - 1).bars.edges.size() == 6);
  CHECK(r.geometryAt(0).bars.edges.size() == 3);
  // One segment per sample where contacts were made (two pairs may touch at once), each a
  // packing with the contacts made by then.
  std::vector<int> contact_samples;
  for (const auto& e : r.events)
    if (e.kind == engine::EventKind::Contact && (contact_samples.empty() || contact_samples.back() != e.sample))
      contact_samples.push_back(e.sample);
  REQUIRE(r.segments.size() == contact_samples.size() + 1);
  CHECK(&r.modelAt(0) == s.model.get());
  for (size_t i = 1; i < r.segments.size(); ++i) {
    const auto& later = dynamic_cast<const engine::SpherePacking&>(*r.segments[i].model);
    CHECK(r.segments[i].first_sample == contact_samples[i - 1]);
    size_t made = 0;
    for (const auto& e : r.events) made += e.kind == engine::EventKind::Contact && e.sample <= r.segments[i].first_sample;
    CHECK(later.contacts().size() == packing.contacts().size() + made);
    CHECK(&r.modelAt(r.segments[i].first_sample) == &later);
    const engine::Vector F = later.system().residuals(r.samples[static_cast<size_t>(r.segments[i].first_sample)]);
    CHECK(F.cwiseAbs().maxCoeff() <= 1e-10);
  }
}

TEST_CASE("packing: a disk rolling around a pinned one stops at the first contact, located exactly",
          "[engine]") {
  // Disk 3 rolls on pinned disk 1 over the top towards pinned disk 2; the contact is where
  // |p3| = 2 and |p3 - p2| = 2, i.e. p3 = (1.5, sqrt(4 - 1.5^2)).
  Matrix p(2, 3);
  p << 0, 3, -2, 0, 0, 0;
  const engine::SpherePacking packing(p, {1, 1, 1}, {0, 1}, 1e-6, 1);
  const engine::RigidityReport rep = engine::analyzeRigidity(packing, packing.startCoordinates());
  REQUIRE(rep.nontrivial == 1);
  engine::TrackerOptions opt;
  opt.steps = 400;
  opt.step_size = 0.05;
  Vector dir = rep.flex_basis.col(0);
  if (dir(1) < 0) dir = -dir;  // upwards, clockwise over the top towards disk 2
  engine::MotionSpec spec;
  spec.direction = dir;
  // The model says how it is tracked: a packing piecewise, with its contacts.
  const engine::DeformationPath r = engine::track(packing, packing.startCoordinates(), spec, opt);
  INFO(r.summary.briefReport());
  REQUIRE(r.summary.status == engine::TrackStatus::Success);
  CHECK_THAT(r.summary.reason, Catch::Contains("disks 2 and 3 touched"));
  const Matrix end = packing.system().vertexPositions(r.samples.back());
  CHECK((end.col(2) - Eigen::Vector2d(1.5, std::sqrt(4 - 1.5 * 1.5))).norm() < 1e-9);
  CHECK(r.events.back().kind == engine::EventKind::Contact);
}

TEST_CASE("packing: the hypostatic packings of the notes are rigid without being infinitesimally rigid",
          "[engine][scenes]") {
  for (const char* name : {"hypostatic_packing", "hypostatic_packing_10"}) {
    INFO(name);
    const engine::RigidityReport rep = pipeline::analyze(example(name));
    CHECK_FALSE(rep.inf_rigid);
    CHECK(rep.trivial == 6);
    CHECK(rep.nontrivial >= 1);
    CHECK(rep.stresses >= 1);
    CHECK(rep.second_order_rigid == std::optional<bool>(true));
    CHECK(rep.rigid == engine::Verdict::Rigid);
  }
}

TEST_CASE("packing: bad input is named with its position", "[scenes]") {
  requireSceneError("[system]\ntype = \"sphere_packing\"\nvertices = [[0,0],[1.5,0]]\nradius = 1\n", 3, 19,
               "disks 1 and 2 overlap: their centres are 1.5 apart, their radii add up to 2");
  requireSceneError("[system]\ntype = \"sphere_packing\"\nvertices = [[0,0,0],[3,0,0],[0,1,0]]\nradius = 1\n", 3, 29,
               "spheres 1 and 3 overlap");
  requireSceneError("[system]\ntype = \"sphere_packing\"\nvertices = [[0,0],[2,0]]\nradii = [1, 0]\n", 4, 13,
               "the radius of vertex 2 must be positive");
  requireSceneError("[system]\ntype = \"sphere_packing\"\nvertices = [[0,0],[2,0]]\nradii = [1]\n", 4, 9,
               "radii has 1 entries for 2 vertices");
  requireSceneError("[system]\ntype = \"sphere_packing\"\nvertices = [[0,0],[2,0]]\nradius = -1\n", 4, 10,
               "radius must be positive");
  requireSceneError("[system]\ntype = \"sphere_packing\"\nvertices = [[0,0],[2,0]]\nradius = 1\nradii = [1, 1]\n", 4, 10,
               "either radii");
  requireSceneError("[system]\ntype = \"sphere_packing\"\nvertices = [[0,0],[2,0]]\n", 1, 1, "needs the key 'radii'");
  requireSceneError("[system]\ntype = \"sphere_packing\"\nvertices = [[0,0],[2,0]]\nradius = 1\ntolerance = 0.5\n", 5, 13,
               "contact tolerance must be in (0, 0.1)");
}

TEST_CASE("packing: flex arrows at a later sample respect the contacts made by then", "[scenes]") {
  const scenes::Scene s = example("disk_packing", {"render.width=200", "render.height=200"});
  const pipeline::Motion m = pipeline::track(s, s.motion.steps);
  const engine::MaskedFloatingPointTraps mesa;  // llvmpipe's shaders compute with NaNs
  render::Renderer renderer;
  const std::string file = "packing_test_flex.png";
  // At the start: 2 nontrivial flexes, arrows. At sample 148 the four disks are rigid.
  CHECK_THAT(present::writeFrame(s, &m.path, 0, true, file, renderer).summary, !Catch::Contains("no nontrivial"));
  CHECK_THAT(present::writeFrame(s, &m.path, 148, true, file, renderer).summary,
             Catch::Contains("no nontrivial infinitesimal flex there"));
  std::remove(file.c_str());
}
