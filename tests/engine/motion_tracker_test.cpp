#include <catch2/catch.hpp>
#include <cmath>

#include "engine/motion_tracker.h"
#include "engine/rigidity.h"
#include "engine/systems/framework.h"
#include "../test_common.h"

using namespace flexure;
using engine::Framework;
using engine::Matrix;
using engine::DeformationPath;
using engine::TrackStatus;
using engine::Vector;

namespace {

using test::makeFramework;

// Tracks from the start along coefficients `c` in the canonical basis (empty: "auto").
DeformationPath track(const Framework& f, std::vector<double> c, int steps, double step_size) {
  const engine::RigidityReport rep = engine::analyzeRigidity(f, f.startCoordinates());
  Vector coeff = rep.auto_flex;
  if (!c.empty()) coeff = Eigen::Map<Vector>(c.data(), static_cast<Eigen::Index>(c.size()));
  engine::TrackerOptions opt;
  opt.steps = steps;
  opt.step_size = step_size;
  const Vector dir = rep.nontrivial > 0 ? Vector(rep.flex_basis * coeff) : Vector::Zero(rep.variables);
  return engine::trackMotion(f, f.startCoordinates(), dir, opt);
}

// Every sample satisfies the constraints to 1e-10 relative to the squared edge lengths, and
// consecutive samples are within 25 % of the step everywhere (issue 20: an animation must not
// stall before a singular point), except the step into a sample that lands on a singular point
// and the first step from a start that is one (the first step is always a sample).
void requireGoodPath(const Framework& f, const DeformationPath& r, double step_size) {
  const auto& sys = f.system();
  for (const Vector& x : r.samples)
    REQUIRE(sys.residuals(x).cwiseAbs().maxCoeff() <= 1e-10 * sys.residualScale());
  CHECK(r.summary.max_residual <= 1e-10 * sys.residualScale());
  for (size_t i = 0; i + 1 < r.samples.size(); ++i) {
    bool into_event = false;
    for (const auto& e : r.events) into_event |= e.sample == static_cast<int>(i) + 1 || (i == 0 && e.sample == 0);
    if (into_event) continue;
    const double d = (r.samples[i + 1] - r.samples[i]).norm();
    INFO("step " << i);
    CHECK(d == Approx(step_size).epsilon(0.25));
  }
}

Framework doubleWatt() {
  return makeFramework({{0, 0}, {1, 0}, {2, 1}, {1, 2}, {3, 2}, {4, 2}, {5, 2}, {7, 2}, {6, 1}, {7, 0}, {8, 0}},
              {{1, 2}, {2, 3}, {2, 4}, {3, 9}, {3, 4}, {3, 5}, {4, 5}, {5, 6}, {6, 7}, {7, 8}, {7, 9},
               {8, 9}, {8, 10}, {9, 10}, {10, 11}},
              {1, 6, 11});
}

}  // namespace

TEST_CASE("tracker: the cuspidal double Watt runs 500 steps through its cusp around its orbit",
          "[engine][tracker]") {
  const Framework f = doubleWatt();
  const DeformationPath r = track(f, {}, 500, 0.05);
  REQUIRE(r.summary.status == TrackStatus::Success);
  CHECK(r.summary.steps_done == 500);
  requireGoodPath(f, r, 0.05);
  // The orbit closes: far into the path the mechanism comes back to its start (the cusp) ...
  int back = -1;
  for (size_t i = 100; i < r.samples.size(); ++i)
    if ((r.samples[i] - r.samples[0]).norm() < 0.01) back = static_cast<int>(i);
  REQUIRE(back > 100);
  // ... and leaves it again on the other branch: a cusp event there, and the path goes on.
  bool cusp = false;
  for (const auto& e : r.events) cusp |= std::abs(e.sample - back) <= 3 && e.detail.find("cusp") != std::string::npos;
  CHECK(cusp);
  CHECK((r.samples.back() - r.samples[0]).norm() > 0.5);
  // Through the cusp means round the orbit again (sample back + k near sample k), not back the
  // way it came (sample back + k near sample back - k): a corrector that solved its steps
  // differently once turned round there, and the checks above did not see it.
  for (int k : {20, 60, 100}) {
    if (back + k >= static_cast<int>(r.samples.size())) break;
    INFO("k = " << k);
    const Vector& x = r.samples[static_cast<size_t>(back + k)];
    CHECK((x - r.samples[static_cast<size_t>(k)]).norm() < 0.1);
    CHECK((x - r.samples[static_cast<size_t>(back - k)]).norm() > 0.3);
  }
}

TEST_CASE("tracker: the pinned four-bar passes its flat configurations on the parallelogram branch",
          "[engine][tracker]") {
  const Framework f = makeFramework({{0, 0}, {1, 0}, {1, 1}, {0, 1}}, {{1, 2}, {2, 3}, {3, 4}, {1, 4}}, {1, 2});
  const DeformationPath r = track(f, {1}, 357, 0.025);
  REQUIRE(r.summary.status == TrackStatus::Success);
  requireGoodPath(f, r, 0.025);
  double min_y = 1, max_x = 0;
  int flat_events = 0;
  for (const auto& e : r.events) flat_events += e.kind == engine::EventKind::Singularity;
  for (const Vector& x : r.samples) {
    // free coordinates: x3 y3 x4 y4. Parallelogram branch: p4 - p3 = p1 - p2 = (-1, 0).
    CHECK(std::abs(x[2] - x[0] + 1) < 1e-9);
    CHECK(std::abs(x[3] - x[1]) < 1e-9);
    min_y = std::min(min_y, x[1]);
    max_x = std::max(max_x, x[0]);
  }
  // A full turn: vertex 3 went through both flat positions (2, 0) and (0, 0).
  CHECK(min_y < -0.99);
  CHECK(max_x > 1.99);
  CHECK(flat_events == 2);
}

TEST_CASE("tracker: full runs of K_{2 4} the 3-prism the Bricard octahedron and the coned cube",
          "[engine][tracker]") {
  SECTION("K_{2,4}") {
    const Framework f = makeFramework({{0, 0}, {0, 1}, {1, -1}, {1, 0}, {1, 1}, {1, 2}},
                             {{1, 3}, {1, 4}, {1, 5}, {1, 6}, {2, 3}, {2, 4}, {2, 5}, {2, 6}});
    const DeformationPath r = track(f, {1}, 500, 0.025);
    REQUIRE(r.summary.status == TrackStatus::Success);
    requireGoodPath(f, r, 0.025);
  }
  SECTION("pinned 3-prism") {
    const double s3 = std::sqrt(3.0);
    const Framework f = makeFramework({{0, 0}, {0, 1}, {s3 / 2, 0.5}, {1.05, 0}, {1.05, 1}, {1.05 + s3 / 2, 0.5}},
                             {{1, 2}, {1, 3}, {2, 3}, {4, 5}, {5, 6}, {4, 6}, {1, 4}, {2, 5}, {3, 6}}, {1, 4});
    const DeformationPath r = track(f, {-1}, 27, 0.025);
    REQUIRE(r.summary.status == TrackStatus::Success);
    requireGoodPath(f, r, 0.025);
  }
  SECTION("Bricard octahedron") {
    const Framework f = makeFramework({{0, 0, -1}, {-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, {0, 0, 1}},
                             {{1, 2}, {1, 3}, {1, 4}, {1, 5}, {2, 6}, {3, 6}, {4, 6}, {5, 6}, {2, 4}, {4, 3}, {3, 5}, {5, 2}});
    const DeformationPath r = track(f, {1}, 200, 0.02);
    REQUIRE(r.summary.status == TrackStatus::Success);
    requireGoodPath(f, r, 0.02);
  }
  SECTION("coned cube, auto flex (not blocked by its stress)") {
    const Framework f = makeFramework({{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1}, {-1, -1, 1}, {1, -1, 1},
                              {1, 1, 1}, {-1, 1, 1}, {0, 0, 1.65}},
                             {{1, 2}, {2, 3}, {3, 4}, {1, 4}, {1, 5}, {2, 6}, {3, 7}, {4, 8}, {5, 6}, {6, 7},
                              {7, 8}, {5, 8}, {1, 9}, {2, 9}, {3, 9}, {4, 9}, {5, 9}, {6, 9}, {7, 9}, {8, 9}});
    const DeformationPath r = track(f, {}, 500, 0.02);
    REQUIRE(r.summary.status == TrackStatus::Success);
    requireGoodPath(f, r, 0.02);
  }
}

TEST_CASE("tracker: a rigid start stops at once with a reason", "[engine][tracker]") {
  SECTION("infinitesimally rigid triangle") {
    const Framework f = makeFramework({{0, 0}, {1, 0}, {0.5, 0.8}}, {{1, 2}, {2, 3}, {1, 3}});
    const DeformationPath r = track(f, {}, 50, 0.01);
    CHECK(r.summary.status == TrackStatus::StoppedEarly);
    CHECK(r.summary.steps_done == 0);
    CHECK_THAT(r.summary.reason, Catch::Contains("infinitesimally rigid"));
  }
  SECTION("prestress stable collinear triangle: the flex is blocked") {
    const Framework f = makeFramework({{0, 0}, {1, 0}, {2, 0}}, {{1, 2}, {2, 3}, {1, 3}});
    const DeformationPath r = track(f, {1}, 50, 0.01);
    CHECK(r.summary.status == TrackStatus::StoppedEarly);
    CHECK(r.summary.steps_done == 0);
    CHECK_THAT(r.summary.reason, Catch::Contains("does not move"));
  }
}

TEST_CASE("tracker: the same scene and seed give the same path bit for bit", "[engine][tracker]") {
  const Framework f = doubleWatt();
  const DeformationPath a = track(f, {}, 60, 0.05), b = track(f, {}, 60, 0.05);
  REQUIRE(a.samples.size() == b.samples.size());
  for (size_t i = 0; i < a.samples.size(); ++i) CHECK(a.samples[i] == b.samples[i]);
}

TEST_CASE("tracker: a stop requested by the callback keeps the samples so far", "[engine][tracker]") {
  const Framework f = makeFramework({{0, 0}, {1, 0}, {1, 1}, {0, 1}}, {{1, 2}, {2, 3}, {3, 4}, {1, 4}}, {1, 2});
  const engine::RigidityReport rep = engine::analyzeRigidity(f, f.startCoordinates());
  engine::TrackerOptions opt;
  opt.steps = 100;
  opt.step_size = 0.02;
  const DeformationPath r = engine::trackMotion(f, f.startCoordinates(), rep.flex_basis.col(0), opt,
                                            [](int done, int) { return done < 10; });
  CHECK(r.summary.status == TrackStatus::StoppedByCallback);
  CHECK(r.samples.size() == 11);
}
