#include "scenes/scene_edit.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <sstream>
#include <limits>

#include "scenes/catalog.h"
#include "scenes/scene.h"

using namespace flexure;

namespace {

toml::table parse(const std::string& text) { return toml::parse(text, std::string("t.toml")); }

}  // namespace

TEST_CASE("withKeys replaces values in place and keeps comments and layout", "[scene_edit]") {
  const std::string text =
      "# my mechanism\ntitle = \"x\"\n\n[motion]\nsteps = 500   # plenty\nflex = [1,\n  0]  # two flexes\n"
      "step_size = 0.05\n\n[render]\nwidth = 300\n";
  const std::string out = scenes::withKeys(text, {"motion.steps=80", "motion.flex=[0.5, -0.25]"});
  CHECK(out ==
        "# my mechanism\ntitle = \"x\"\n\n[motion]\nsteps = 80   # plenty\nflex = [0.5, -0.25]  # two flexes\n"
        "step_size = 0.05\n\n[render]\nwidth = 300\n");
}

TEST_CASE("withKeys adds a missing key under its table, or a new table", "[scene_edit]") {
  const std::string text = "title = \"x\"\n[motion]\nsteps = 5\n[render]\nwidth = 3\n";
  SECTION("under the existing header, in the order given") {
    const std::string out = scenes::withKeys(text, {"motion.seed=7", "motion.step_size=0.02"});
    CHECK(out == "title = \"x\"\n[motion]\nseed = 7\nstep_size = 0.02\nsteps = 5\n[render]\nwidth = 3\n");
  }
  SECTION("a new table at the end") {
    const std::string out = scenes::withKeys(text, {"analysis.seed=3", "analysis.rank_tolerance=1e-8"});
    CHECK(out == text + "\n[analysis]\nseed = 3\nrank_tolerance = 1e-8\n");
  }
  SECTION("a top-level key before the first table") {
    const std::string out = scenes::withKeys("# c\n[motion]\nsteps = 5\n", {"index_base=0"});
    CHECK(out == "# c\nindex_base = 0\n[motion]\nsteps = 5\n");
  }
  SECTION("a bare word becomes a string, as with --set") {
    const std::string out = scenes::withKeys(text, {"motion.flex=auto"});
    CHECK(parse(out)["motion"]["flex"].value<std::string>() == "auto");
  }
}

TEST_CASE("withKeys: a key given twice takes its last value", "[scene_edit]") {
  const std::string text = "[motion] # m\nsteps = 5\n";
  CHECK(scenes::withKeys(text, {"motion.steps=40", "motion.seed=1", "motion.steps=25"}) ==
        "[motion] # m\nseed = 1\nsteps = 25\n");
}

TEST_CASE("withKeys falls back to the library's own text when an in-place edit would not read back", "[scene_edit]") {
  // An inline table cannot take a new line under it.
  const std::string text = "title = \"x\"\nmotion = { steps = 5 }\n";
  const std::string out = scenes::withKeys(text, {"motion.seed=3"});
  const toml::table t = parse(out);
  CHECK(t["motion"]["steps"].value<int>() == 5);
  CHECK(t["motion"]["seed"].value<int>() == 3);
  CHECK(t["title"].value<std::string>() == "x");
}

TEST_CASE("withKeys on every example scene reads back as the --set overrides would", "[scene_edit]") {
  const std::vector<std::string> sets = {"motion.steps=17", "motion.seed=5", "analysis.seed=2"};
  for (const auto& e : scenes::catalog()) {
    INFO(e.name);
    const std::string out = scenes::withKeys(e.text, sets);
    toml::table expected = parse(e.text);
    for (const auto& s : sets) scenes::applyOverride(expected, s);
    std::ostringstream a, b;
    a << toml::toml_formatter(parse(out));
    b << toml::toml_formatter(expected);
    CHECK(a.str() == b.str());
    // Comments survive (every example has some).
    if (e.text.find('#') != std::string::npos) CHECK(out.find('#') != std::string::npos);
  }
}

TEST_CASE("withKeys rejects malformed assignments and text that is not TOML", "[scene_edit]") {
  CHECK_THROWS_AS(scenes::withKeys("a = 1\n", {"novalue"}), scenes::SceneError);
  CHECK_THROWS_AS(scenes::withKeys("a = 1\n", {"a..b=1"}), scenes::SceneError);
  CHECK_THROWS_AS(scenes::withKeys("a = [1,\n", {"a=1"}), scenes::SceneError);
  CHECK_THROWS_AS(scenes::withKeys("a = 1\n", {"a.b=1"}), scenes::SceneError);  // a is not a table
}

TEST_CASE("tomlNumber round-trips doubles and stays a float", "[scene_edit]") {
  for (double x : {0.1, -2.5, 3.0, 1e-300, 0.7071067811865476, 123456789.0, 5e-324}) {
    const std::string s = scenes::tomlNumber(x);
    INFO(s);
    const toml::table t = parse("v = " + s);
    REQUIRE(t["v"].is_floating_point());
    CHECK(t["v"].value<double>() == x);
  }
  CHECK(scenes::tomlNumber(3.0) == "3.0");
  CHECK(parse("v = " + scenes::tomlNumber(std::numeric_limits<double>::infinity()))["v"].value<double>() ==
        std::numeric_limits<double>::infinity());
}
