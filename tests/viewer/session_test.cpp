#include "viewer/session.h"

#include <sys/stat.h>

#include <fstream>

#include <catch2/catch.hpp>
#include <chrono>
#include <thread>

#include "render/image.h"
#include "present/path_output.h"
#include "present/text.h"
#include "pipeline/pipeline.h"
#include "scenes/scene.h"
#include "tests/viewer/viewer_test_common.h"

using namespace flexure;
using flexure::test::ScratchScene;

namespace {

render::Image decode(const std::vector<std::uint8_t>& png) { return render::decodePng(png); }

std::string replaced(std::string s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  REQUIRE(at != std::string::npos);
  return s.replace(at, from.size(), to);
}

bool exists(const std::string& f) {
  struct stat st {};
  return ::stat(f.c_str(), &st) == 0;
}

// A session on `s` with `steps` steps, its first computation done.
std::unique_ptr<viewer::Session> loaded(const ScratchScene& s, int steps) {
  viewer::SessionOptions o;
  o.overrides = {"motion.steps=" + std::to_string(steps)};
  auto session = std::make_unique<viewer::Session>(s.path, o);
  REQUIRE(session->waitIdle(30));
  return session;
}

}  // namespace

TEST_CASE("Session: loads, renders any sample, follows the file, keeps the last good state on errors", "[viewer]") {
  ScratchScene s("double_watt");
  const auto owner = loaded(s, 60);
  viewer::Session& session = *owner;
  auto st = session.state();
  REQUIRE(st["loaded"].is_object());
  CHECK(st["loaded"]["samples"] == 61);
  CHECK(st["loaded"]["title"] == "Cuspidal double Watt mechanism");
  CHECK(st["loaded"]["nontrivial"] == 2);
  CHECK(st["error"].is_null());
  CHECK(st["loaded"]["report"]["rigid"] == "flexible");
  const auto generation = st["loaded"]["generation"].get<std::uint64_t>();

  viewer::FrameRequest q;
  q.width = 320, q.height = 240;
  const render::Image a = decode(session.framePng(q));
  CHECK(a.width == 320);
  CHECK(a.height == 240);
  q.sample = 60;
  const render::Image b = decode(session.framePng(q));
  CHECK(a.rgba != b.rgba);
  q.sample = 100000;  // past the end: the last sample
  CHECK(decode(session.framePng(q)).rgba == b.rgba);
  q.options.labels = false;
  CHECK(decode(session.framePng(q)).rgba != b.rgba);
  const render::Image p0 = decode(session.projectionPng(0, 300, 300)), p1 = decode(session.projectionPng(60, 300, 300));
  CHECK(p0.width == 300);
  CHECK(p0.rgba != p1.rgba);  // the marker moved

  SECTION("an unchanged file is not recomputed") {
    CHECK_FALSE(session.checkFile());
    s.write(s.text);  // same text, new time stamp
    CHECK_FALSE(session.checkFile());
  }
  SECTION("an edit recomputes") {
    s.write(replaced(s.text, "Cuspidal double Watt mechanism", "Edited"));
    CHECK(session.checkFile());
    REQUIRE(session.waitIdle(30));
    st = session.state();
    CHECK(st["loaded"]["title"] == "Edited");
    CHECK(st["loaded"]["generation"].get<std::uint64_t>() > generation);
  }
  SECTION("a syntax error is shown with its line, column and text; the last good state stays") {
    const std::string broken = replaced(s.text, "edges = [[1,2]", "edges = [[1,,2]");
    s.write(broken);
    CHECK(session.checkFile());
    REQUIRE(session.waitIdle(30));
    st = session.state();
    REQUIRE(st["error"].is_object());
    CHECK(st["error"]["file"] == s.path);
    CHECK(st["error"]["line"] == 7);
    CHECK(st["error"]["column"] == 13);  // the second comma
    CHECK(st["error"]["line_text"].get<std::string>().rfind("edges = [[1,,2]", 0) == 0);
    CHECK(st["loaded"]["generation"] == generation);
    CHECK(decode(session.framePng(q)).width == 320);  // frames still come from the last good state
    s.write(s.text);
    CHECK(session.checkFile());
    REQUIRE(session.waitIdle(30));
    CHECK(session.state()["error"].is_null());
  }
  SECTION("content that used to crash the viewer is an error like any other") {
    std::string deep = "[a";
    for (int i = 0; i < 31000; ++i) deep += ".a";
    s.write(deep + "]\n");
    CHECK(session.checkFile());
    REQUIRE(session.waitIdle(30));
    st = session.state();
    REQUIRE(st["error"].is_object());
    CHECK_THAT(st["error"]["message"].get<std::string>(), Catch::Contains("nested more than 64 levels deep"));
    // A long line of multi-byte characters with an error at its end: the shown line may be cut
    // inside a character; the state must still serialize (it answered 500 on every poll).
    s.write("title = \"x\"\n" + std::string(399, ' ') + "\xe2\x9c\x93 = = 1\n");
    CHECK(session.checkFile());
    REQUIRE(session.waitIdle(30));
    REQUIRE(session.state()["error"].is_object());
    CHECK_NOTHROW(session.state().dump());  // strict: the shown line is valid UTF-8
    CHECK_NOTHROW(present::jsonText(session.state()));
    CHECK(session.state()["loaded"]["generation"] == generation);  // the last good state stays
  }
  SECTION("a save that truncates first: the empty file is waited for, and reported once it stays empty") {
    s.write("");
    CHECK_FALSE(session.checkFile());
    CHECK(session.state()["error"].is_null());
    CHECK(session.state()["read_error"].is_null());
    s.write(replaced(s.text, "Cuspidal double Watt mechanism", "Saved"));
    CHECK(session.checkFile());
    REQUIRE(session.waitIdle(30));
    CHECK(session.state()["loaded"]["title"] == "Saved");
    s.write("");
    CHECK_FALSE(session.checkFile());
    std::this_thread::sleep_for(std::chrono::milliseconds(600));
    CHECK(session.checkFile());
    REQUIRE(session.waitIdle(30));
    REQUIRE(session.state()["error"].is_object());
    CHECK_THAT(session.state()["error"]["message"].get<std::string>(), Catch::Contains("[system]"));
  }
  SECTION("a file that goes away and comes back") {
    REQUIRE(std::remove(s.path.c_str()) == 0);
    CHECK_FALSE(session.checkFile());
    CHECK(session.state()["read_error"].is_string());
    s.write(s.text);
    session.checkFile();
    CHECK(session.state()["read_error"].is_null());
  }
}

TEST_CASE("Session: motion controls recompute, are checked, and are saved into the scene text", "[viewer]") {
  ScratchScene s("double_watt");
  const auto owner = loaded(s, 40);
  viewer::Session& session = *owner;

  viewer::MotionControls c;
  c.steps = 25;
  c.step_size = 0.04;
  c.flex = std::vector<double>{1, 0};
  c.seed = 9;
  session.setControls(c);
  REQUIRE(session.waitIdle(30));
  auto st = session.state();
  CHECK(st["loaded"]["samples"] == 26);
  CHECK(st["loaded"]["motion"]["step_size"] == 0.04);
  CHECK(st["loaded"]["motion"]["seed"] == 9);
  CHECK(st["loaded"]["motion"]["flex_note"] == "given");
  CHECK(st["controls"]["steps"] == 25);

  SECTION("bad controls are refused and change nothing") {
    viewer::MotionControls bad;
    bad.steps = -1;
    CHECK_THROWS_AS(session.setControls(bad), std::invalid_argument);
    bad = {};
    bad.step_size = 0;
    CHECK_THROWS_AS(session.setControls(bad), std::invalid_argument);
    bad = {};
    bad.flex = std::vector<double>{1, 2, 3};  // the double Watt has 2 flexes
    CHECK_THROWS_WITH(session.setControls(bad), Catch::Contains("2 coefficient"));
    bad = {};
    bad.steps = 100001;
    CHECK_THROWS_AS(session.setControls(bad), std::invalid_argument);
    CHECK(session.state()["controls"]["steps"] == 25);
  }
  SECTION("the controls outlive a file edit") {
    s.write(replaced(s.text, "Cuspidal double Watt mechanism", "Edited"));
    CHECK(session.checkFile());
    REQUIRE(session.waitIdle(30));
    CHECK(session.state()["loaded"]["samples"] == 26);
  }
  SECTION("reset goes back to the file's motion") {
    session.resetControls();
    REQUIRE(session.waitIdle(30));
    CHECK(session.state()["loaded"]["samples"] == 41);
    CHECK(session.state()["controls"]["steps"].is_null());
  }
  SECTION("save as: the scene's text with the motion written in, only beside the scene") {
    const std::string text = session.sceneText();
    CHECK(text.find("steps = 25") != std::string::npos);
    CHECK(text.find("step_size = 0.04") != std::string::npos);
    CHECK(text.find("flex = [1.0, 0.0]") != std::string::npos);
    CHECK(text.find("# ") != std::string::npos);  // the file's comments
    const scenes::Scene saved = scenes::loadSceneFromString(text, "saved.toml");
    CHECK(saved.motion.steps == 25);
    CHECK(saved.motion.seed == 9);

    for (const std::string bad : {"../up.toml", "/tmp/abs.toml", "sub/x.toml", ".hidden.toml", "x.txt", "", ".toml",
                                  "a..toml", "-x.toml", "x.toml/", "x\n.toml"}) {
      INFO(bad);
      CHECK_THROWS_AS(session.saveAs(bad, true), std::invalid_argument);
    }
    CHECK_FALSE(exists(s.dir + "/../up.toml"));
    const std::string file = session.saveAs("mine.toml", false);
    CHECK(file == s.dir + "/mine.toml");
    CHECK(ScratchScene::read(file) == text);
    CHECK_THROWS_WITH(session.saveAs("mine.toml", false), Catch::Contains("exists"));
    CHECK(session.saveAs("mine.toml", true) == file);
  }
}

TEST_CASE("Session: the certify control certifies the path and the state says which steps", "[viewer]") {
  ScratchScene s("coupler_curve");
  const auto owner = loaded(s, 30);
  viewer::Session& session = *owner;
  CHECK(session.state()["loaded"]["certificate"].is_null());
  viewer::MotionControls c;
  c.certify = true;
  session.setControls(c);
  REQUIRE(session.waitIdle(60));
  auto st = session.state();
  CHECK(st["controls"]["certify"] == true);
  CHECK(st["loaded"]["motion"]["certify"] == true);
  const auto& cert = st["loaded"]["certificate"];
  REQUIRE(cert.is_object());
  // The crank-rocker's coupler curve is smooth and far from singular points: every step.
  CHECK(cert["certified"] == true);
  CHECK(cert["samples"].size() == 31);
  CHECK(cert["steps"].size() == 30);
  for (const auto& step : cert["steps"]) CHECK(step == true);
  CHECK(session.sceneText().find("certify = true") != std::string::npos);
  c.certify = false;
  session.setControls(c);
  REQUIRE(session.waitIdle(60));
  CHECK(session.state()["loaded"]["certificate"].is_null());
}

TEST_CASE("Session: an unreadable scene file is an error at once", "[viewer]") {
  CHECK_THROWS_AS(viewer::Session("/nonexistent/scene.toml"), scenes::SceneError);
}

TEST_CASE("Session: a scene that is wrong from the start is shown as an error, and loads once fixed", "[viewer]") {
  ScratchScene s("triangle");
  const std::string good = s.text;
  s.write("title = 3\n");
  viewer::Session session(s.path);
  REQUIRE(session.waitIdle(30));
  auto st = session.state();
  CHECK(st["loaded"].is_null());
  CHECK(st["error"]["line"] == 1);
  CHECK(session.framePng({}).empty());
  s.write(good);
  CHECK(session.checkFile());
  REQUIRE(session.waitIdle(30));
  CHECK(session.state()["loaded"].is_object());
}

TEST_CASE("Session: a catalog name shows the entry, once, with nothing to watch", "[viewer]") {
  viewer::SessionOptions o;
  o.overrides = {"motion.steps=20"};
  viewer::Session session("k24", o);
  REQUIRE(session.waitIdle(30));
  const auto st = session.state();
  REQUIRE(st["loaded"].is_object());
  CHECK(st["loaded"]["title"] == "Complete bipartite graph K_{2,4} in a flexible realization");
  CHECK(st["loaded"]["samples"] == 21);
  CHECK(st["read_error"].is_null());
  CHECK_FALSE(session.checkFile());  // no file: nothing to reload
  CHECK_THAT(session.sceneText(), Catch::Contains("[system]"));
}

TEST_CASE("Session: a mesh and a path JSON given as SCENE show the system they stand for", "[viewer]") {
  const ScratchScene s("double_watt");
  // A path JSON written by track: its scene (the viewer tracks it again: the same path).
  const std::string json = s.dir + "/path.json";
  {
    const scenes::Scene scene = scenes::loadScene(s.path, {"motion.steps=30"});
    present::writePath(scene, pipeline::track(scene, 30).path, json);
  }
  viewer::SessionOptions o;
  {
    viewer::Session session(json, o);
    REQUIRE(session.waitIdle(30));
    const auto st = session.state();
    REQUIRE(st["loaded"].is_object());
    CHECK(st["loaded"]["title"] == "Cuspidal double Watt mechanism");
    CHECK(st["loaded"]["samples"] == 31);  // the file's scene holds its steps
    CHECK(st["error"].is_null());
  }
  // An OFF mesh: the polytope it reads.
  const std::string off = s.dir + "/box.off";
  std::ofstream(off) << "OFF\n8 6 0\n0 0 0\n2 0 0\n2 1 0\n0 1 0\n0 0 1\n2 0 1\n2 1 1\n0 1 1\n"
                        "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n";
  o.overrides = {"motion.steps=5"};
  viewer::Session mesh(off, o);
  REQUIRE(mesh.waitIdle(30));
  const auto st = mesh.state();
  REQUIRE(st["loaded"].is_object());
  CHECK(st["loaded"]["type"] == "polytope");
  CHECK(st["loaded"]["title"] == "box.off");
  CHECK_THAT(mesh.sceneText(), Catch::Contains("from = 'box.off'"));
}
