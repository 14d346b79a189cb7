// Branches everywhere (SPEC section 5): the path JSON lists the tangent-cone directions at each
// singular sample, and `track --branch K:J` continues from sample K along direction J. Checked
// on the four-bar made of the pinned unit square, whose flat positions the test works out by
// hand: there the linkage can go on as a parallelogram or fold into a kite.
#include <catch2/catch.hpp>

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli_common.h"

namespace fs = std::filesystem;

using nlohmann::json;
using namespace flexure_cli_test;

namespace {

struct P {
  double x, y;
};
P at(const json& sample, int v) { return {sample[v][0].get<double>(), sample[v][1].get<double>()}; }
double dist(P a, P b) { return std::hypot(a.x - b.x, a.y - b.y); }

// The four-bar 1-2-3-4 with 1 and 2 pinned: bars 2-3, 3-4, 1-4 (1-2 joins pinned vertices).
// At a configuration p and velocities u3, u4 of the free vertices: the first-order equations
// (each bar's length rate) and, with a self-stress w of the bars (w.J = 0), the second-order
// form sum over bars of w_e |du_e|^2, which vanishes on the tangent cone of a singular point.
struct FourBar {
  P p1, p2, p3, p4;
  // The bars' rows of the rigidity matrix on (u3, u4).
  std::vector<std::vector<double>> rows() const {
    return {{p3.x - p2.x, p3.y - p2.y, 0, 0},
            {p3.x - p4.x, p3.y - p4.y, p4.x - p3.x, p4.y - p3.y},
            {0, 0, p4.x - p1.x, p4.y - p1.y}};
  }
};

}  // namespace

TEST_CASE("cli: the four-bar's flat positions list their two branches, and --branch follows the other one", "[cli]") {
  const fs::path d = scratchDir("branch");
  const std::string path = (d / "p.json").string();
  REQUIRE(run("track square_pinned --quiet -o " + path).status == 0);
  const json p = json::parse(readFile(path));
  int flat = -1;
  for (const json& e : p.at("events")) {
    if (e.at("kind") != "singularity") continue;
    const int k = e.at("sample");
    INFO("sample " << k);
    REQUIRE(e.at("directions").is_array());
    const json& dirs = e["directions"];
    // Two branches cross: four half-branch directions, in two opposite pairs.
    REQUIRE(dirs.size() == 4);
    const FourBar f{at(p["samples"][k], 0), at(p["samples"][k], 1), at(p["samples"][k], 2), at(p["samples"][k], 3)};
    // Flat: every vertex on the x-axis (within a step of the sample).
    for (P q : {f.p3, f.p4}) CHECK(std::abs(q.y) < 0.03);
    // The self-stress of the flat position: w1 r1 + w2 r2 + w3 r3 = 0, from the rows' x parts.
    const auto r = f.rows();
    const double w1 = 1.0, w2 = -w1 * r[0][0] / r[1][0], w3 = -w2 * r[1][2] / r[2][2];
    int paths = 0, backs = 0, others = 0;
    for (size_t i = 0; i < dirs.size(); ++i) {
      const json& v = dirs[i];
      CHECK(std::hypot(v[0][0].get<double>(), v[0][1].get<double>()) == 0.0);  // pinned
      CHECK(std::hypot(v[1][0].get<double>(), v[1][1].get<double>()) == 0.0);
      const double u[4] = {v[2][0], v[2][1], v[3][0], v[3][1]};
      CHECK(std::abs(std::hypot(std::hypot(u[0], u[1]), std::hypot(u[2], u[3])) - 1.0) < 1e-9);  // unit
      for (const auto& row : r) {
        double s = 0;
        for (int c = 0; c < 4; ++c) s += row[c] * u[c];
        CHECK(std::abs(s) < 0.05);  // first order, at the sample (the cone is the singular point's)
      }
      const double q = w1 * (u[0] * u[0] + u[1] * u[1]) + w2 * (std::pow(u[2] - u[0], 2) + std::pow(u[3] - u[1], 2)) +
                       w3 * (u[2] * u[2] + u[3] * u[3]);
      CHECK(std::abs(q) < 0.05 * (std::abs(w1) + std::abs(w2) + std::abs(w3)));  // second order
      const std::string kind = e.at("direction_kinds")[i];
      paths += kind == "path", backs += kind == "back", others += kind == "other";
      // The path goes on as a parallelogram (u3 = u4); the other branch is a kite, one free
      // vertex resting on a pinned one.
      if (kind != "other") CHECK(std::hypot(u[0] - u[2], u[1] - u[3]) < 1e-6);
      else CHECK(std::min(std::hypot(u[0], u[1]), std::hypot(u[2], u[3])) < 1e-6);
    }
    CHECK(paths == 1);
    CHECK(backs == 1);
    CHECK(others == 2);
    if (dist(f.p3, f.p1) < 0.03) flat = k;  // vertex 3 on vertex 1
  }
  REQUIRE(flat > 0);
  // The kite: from there, vertex 3 rests on vertex 1 and vertex 4 turns about it; every bar
  // keeps its length on every sample.
  int kite = -1;
  for (const json& e : p["events"])
    if (e["sample"] == flat)
      for (size_t i = 0; i < 4; ++i)
        if (e["direction_kinds"][i] == "other" && e["directions"][i][3][1].get<double>() > 0.5) kite = static_cast<int>(i);
  REQUIRE(kite >= 0);
  const std::string branch = (d / "b.json").string();
  const Result b = run("track square_pinned --quiet --branch " + std::to_string(flat) + ":" + std::to_string(kite) +
                       " -o " + branch);
  REQUIRE(b.status == 0);
  const json q = json::parse(readFile(branch));
  CHECK_THAT(q.at("flex_choice").get<std::string>(),
             Catch::Contains("from sample " + std::to_string(flat) + " along branch direction " + std::to_string(kite)));
  const json& s = q.at("samples");
  REQUIRE(s.size() == p["samples"].size());
  for (int k = 0; k < flat; ++k) CHECK(s[k] == p["samples"][k]);  // the same path up to there
  double turned = 0;
  for (size_t k = static_cast<size_t>(flat); k < s.size(); ++k) {
    const P p1 = at(s[k], 0), p2 = at(s[k], 1), p3 = at(s[k], 2), p4 = at(s[k], 3);
    CHECK(dist(p3, p1) < 1e-6);  // the singular point is located to about 1e-8
    CHECK(std::abs(dist(p2, p3) - 1) < 1e-9);
    CHECK(std::abs(dist(p3, p4) - 1) < 1e-9);
    CHECK(std::abs(dist(p1, p4) - 1) < 1e-9);
    turned = std::max(turned, std::abs(std::atan2(p4.y, p4.x) - std::atan2(at(s[flat], 3).y, at(s[flat], 3).x)));
  }
  CHECK(turned > 1.0);
  // Wrong choices, said at the key.
  const Result none = run("track square_pinned --quiet --branch " + std::to_string(flat) + ":4");
  CHECK(none.status == 1);
  CHECK_THAT(none.err, Catch::Contains("branch: sample " + std::to_string(flat) + " has 4 branch direction(s) (0..3)"));
  CHECK_THAT(run("track square_pinned --branch 3").err, Catch::Contains("--branch needs K:J"));
  CHECK_THAT(run("track square_pinned --branch 9999:0").err, Catch::Contains("the sample must be between 0 and steps (357)"));
  // At a regular sample: the two directions of the one flex, forward and back.
  const Result regular = run("track square_pinned --quiet --set motion.steps=20 --branch 10:0");
  REQUIRE(regular.status == 0);
  CHECK(json::parse(regular.out).at("samples").size() == 21);
  fs::remove_all(d);
}
