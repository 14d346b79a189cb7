// End-to-end: the flexure binary on the example scenes, checked against SPEC field by field.
#include <catch2/catch.hpp>

#include <algorithm>
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "render/video.h"
#include "cli_common.h"

namespace fs = std::filesystem;
using nlohmann::json;
namespace render = flexure::render;
using namespace flexure_cli_test;

namespace {

struct Expected {
  const char* scene;
  int dimension, vertices, pinned, variables, equations, rank, trivial, nontrivial, stresses;
  bool inf_rigid;
  const char* rigid;
};

// Counts for every example scene (notes section 5.1 where the reference records them).
const Expected kExpected[] = {
    {"bricard_octahedron", 3, 6, 0, 18, 12, 11, 6, 1, 1, false, "flexible"},
    {"collinear_triangle", 2, 3, 0, 6, 3, 2, 3, 1, 1, false, "rigid"},
    {"coned_cube", 3, 9, 0, 27, 20, 19, 6, 2, 1, false, "flexible"},
    {"double_watt", 2, 11, 3, 16, 15, 14, 0, 2, 1, false, "flexible"},
    {"flexible_prestress_stable_component", 2, 6, 2, 8, 7, 6, 0, 2, 1, false, "flexible"},
    {"k24", 2, 6, 0, 12, 8, 8, 3, 1, 0, false, "flexible"},
    {"k4_edge", 2, 5, 2, 6, 6, 5, 0, 1, 1, false, "flexible"},
    {"rigid_prestress_stable", 2, 5, 2, 6, 6, 5, 0, 1, 1, false, "rigid"},
    {"rigid_test", 2, 7, 0, 14, 11, 11, 3, 0, 0, true, "rigid"},
    {"square", 2, 4, 0, 8, 4, 4, 3, 1, 0, false, "flexible"},
    {"square_pinned", 2, 4, 2, 4, 3, 3, 0, 1, 0, false, "flexible"},
    {"three_frustum", 2, 6, 3, 6, 6, 5, 0, 1, 1, false, "rigid"},
    {"three_prism", 2, 6, 2, 8, 8, 7, 0, 1, 1, false, "flexible"},
    {"triangle", 2, 3, 0, 6, 3, 3, 3, 0, 0, true, "rigid"},
    {"two_prism", 2, 6, 0, 12, 9, 8, 3, 1, 1, false, "flexible"},
};

}  // namespace

TEST_CASE("cli: analyze --json on every example scene follows SPEC section 3", "[cli][slow]") {
  for (const Expected& e : kExpected) {
    INFO(e.scene);
    const Result r = run("analyze " + example(e.scene) + " --json");
    REQUIRE(r.status == 0);
    CHECK(r.err.empty());
    const json j = json::parse(r.out);
    CHECK(j.at("system") == "framework");
    CHECK(j.at("dimension") == e.dimension);
    CHECK(j.at("vertices") == e.vertices);
    CHECK(j.at("pinned") == e.pinned);
    CHECK(j.at("variables") == e.variables);
    CHECK(j.at("equations") == e.equations);
    CHECK(j.at("rigidity_rank") == e.rank);
    CHECK(j.at("trivial_inf_flexes") == e.trivial);
    CHECK(j.at("nontrivial_inf_flexes") == e.nontrivial);
    CHECK(j.at("stress_dim") == e.stresses);
    CHECK(j.at("stress_dim") == e.equations - e.rank);
    CHECK(j.at("inf_rigid") == e.inf_rigid);
    CHECK(j.at("rigid") == e.rigid);
    for (const char* key : {"prestress_stable", "second_order_rigid"})
      CHECK((j.at(key).is_boolean() || j.at(key).is_null()));
    // How the second-order questions were decided, with the seed and the auto flex.
    const json& so = j.at("second_order");
    CHECK(so.at("seed") == 1);
    CHECK(so.at("auto_flex").size() == static_cast<size_t>(e.nontrivial));
    CHECK(so.at("auto_flex_note").is_string());
    if (j.at("prestress_stable") == true && e.nontrivial > 0) CHECK(so.at("blocking_stress").size() == static_cast<size_t>(e.equations));
    // Bases: one velocity field per nontrivial flex, zero on pinned vertices, unit norm.
    const json& flexes = j.at("nontrivial_flex_basis");
    REQUIRE(flexes.size() == static_cast<size_t>(e.nontrivial));
    for (const json& f : flexes) {
      REQUIRE(f.size() == static_cast<size_t>(e.vertices));
      double norm2 = 0;
      for (const json& v : f) {
        REQUIRE(v.size() == static_cast<size_t>(e.dimension));
        for (double c : v) norm2 += c * c;
      }
      CHECK(norm2 == Approx(1.0));
    }
    CHECK(j.at("stress_basis").size() == static_cast<size_t>(e.stresses));
    CHECK(j.at("equation_labels").size() == static_cast<size_t>(e.equations));
    CHECK(j.at("warnings").empty());
  }
}

TEST_CASE("cli: the text report and the catalog", "[cli]") {
  const Result a = run("analyze " + example("collinear_triangle"));
  CHECK(a.status == 0);
  CHECK_THAT(a.out, Catch::Contains("infinitesimal flexes 4 = 3 trivial + 1 nontrivial"));
  CHECK_THAT(a.out, Catch::Contains("rigid: rigid (prestress stable"));
  const Result c = run("catalog");
  CHECK(c.status == 0);
  CHECK_THAT(c.out, Catch::Contains("double_watt"));
  CHECK_THAT(c.out, Catch::Contains("Cuspidal double Watt mechanism"));
}

TEST_CASE("cli: --set overrides a scene key", "[cli]") {
  const Result r = run("analyze " + example("three_prism") + " --json --set system.pinned=[]");
  REQUIRE(r.status == 0);
  const json j = json::parse(r.out);
  CHECK(j.at("trivial_inf_flexes") == 3);
  CHECK(j.at("nontrivial_inf_flexes") == 1);
  CHECK(j.at("stress_dim") == 1);
}

TEST_CASE("cli: track drives an origami fold and names the faces that pass through each other", "[cli]") {
  // A strip of three squares, both valleys folded alike to 90 % (past 120 degrees, where the
  // outer squares meet).
  const fs::path dir = scratchDir("strip");
  std::ofstream(dir / "strip.toml")
      << "[system]\ntype = \"origami\"\nvertices = [[0, 0], [1, 0], [2, 0], [3, 0], [0, 1], [1, 1], [2, 1], [3, 1]]\n"
         "faces = [[1, 2, 6, 5], [2, 3, 7, 6], [3, 4, 8, 7]]\n"
         "creases = [[1, 2], [2, 3], [3, 4], [5, 6], [6, 7], [7, 8], [1, 5], [4, 8], [2, 6], [3, 7]]\n"
         "assignments = \"BBBBBBBBVV\"\n";
  const Result r = run("track " + (dir / "strip.toml").string() + " --set motion.fold_percent=90 --set motion.steps=90 -o " +
                       (dir / "strip.fold").string());
  REQUIRE(r.status == 0);
  CHECK(r.out.find("success: the fold percentage reached its target, 90 %\nsample 67: faces 1 and 3 pass through each "
                   "other\nwrote ") != std::string::npos);
  const json f = json::parse(readFile(dir / "strip.fold"));
  CHECK(f.at("file_frames").size() == 90);
  fs::remove_all(dir);
}

TEST_CASE("cli: bad input exits 1 with FILE:LINE:COLUMN", "[cli]") {
  const fs::path d = scratchDir("bad");
  const fs::path f = d / "bad.toml";
  std::ofstream(f) << "[system]\ntype = \"framework\"\nvertices = [[0,0],[1,0]]\nedges = [[1,3]]\n";
  const Result r = run("analyze " + f.string());
  CHECK(r.status == 1);
  CHECK(r.out.empty());
  CHECK(r.err == f.string() + ":4:13: edge vertex 3 is out of range: vertices are numbered 1..2\n");
  CHECK(run("analyze " + (d / "missing.toml").string()).status == 1);
  CHECK(run("frobnicate").status == 1);
  CHECK(run("analyze").status == 1);
  CHECK(run("analyze " + f.string() + " --bogus").status == 1);
  fs::remove_all(d);
}

TEST_CASE("cli: demo writes the double Watt report and outputs, and an unwritable DIR exits 3", "[cli]") {
  const fs::path d = scratchDir("demo") / "out";
  const Result r = run("demo " + d.string() + " --quiet --set motion.steps=40 --set render.width=240 --set render.height=200");
  REQUIRE(r.status == 0);
  CHECK_THAT(r.out, Catch::Contains("Cuspidal double Watt mechanism"));
  const json j = json::parse(readFile(d / "double_watt_analysis.json"));
  CHECK(j.at("nontrivial_inf_flexes") == 2);
  CHECK(fs::exists(d / "double_watt.toml"));
  CHECK(json::parse(readFile(d / "double_watt_path.json")).at("samples").size() == 41);
  CHECK(readFile(d / "double_watt.png").substr(1, 3) == "PNG");
  CHECK(readFile(d / "double_watt_projection.png").substr(1, 3) == "PNG");
  const render::VideoInfo mp4 = render::probeVideo((d / "double_watt.mp4").string());
  CHECK(mp4.codec == "h264");
  CHECK(mp4.frames == 41);
  CHECK(mp4.width == 240);
  CHECK(mp4.height == 200);
  CHECK(mp4.duration == Approx(41 / 25.0));
  const render::VideoInfo gif = render::probeVideo((d / "double_watt.gif").string());
  CHECK(gif.codec == "gif");
  CHECK(gif.frames == 41);
  CHECK(gif.loop == 0);
  for (const char* f : {"double_watt.mp4", "double_watt.gif", "double_watt_projection.png"})
    CHECK_THAT(r.out, Catch::Contains(std::string("wrote ") + (d / f).string()));
  for (const auto& entry : fs::directory_iterator(d))
    CHECK(entry.path().filename().string().find(".tmp-") == std::string::npos);
  const Result bad = run("demo /proc/flexure-cannot-write-here");
  CHECK(bad.status == 3);
  CHECK_THAT(bad.err, Catch::Contains("cannot"));
  fs::remove_all(d.parent_path());
}

namespace {

const char* kRigidExamples[] = {"triangle", "collinear_triangle", "rigid_prestress_stable", "rigid_test",
                                "three_frustum"};

bool isRigidExample(const std::string& name) {
  for (const char* r : kRigidExamples)
    if (name == r) return true;
  return false;
}

}  // namespace

TEST_CASE("cli: track on every example scene writes a valid path", "[cli][slow]") {
  const fs::path d = scratchDir("track");
  for (const Expected& e : kExpected) {
    INFO(e.scene);
    const fs::path out = d / (std::string(e.scene) + ".json");
    const Result r = run("track " + example(e.scene) + " --quiet -o " + out.string());
    const json j = json::parse(readFile(out));
    if (isRigidExample(e.scene)) {
      CHECK(r.status == 2);
      CHECK(j.at("status") == "stopped_early");
      CHECK_FALSE(j.at("reason").get<std::string>().empty());
      CHECK(j.at("samples").size() == 1);
      continue;
    }
    REQUIRE(r.status == 0);
    CHECK_THAT(r.out, Catch::Contains(": success"));
    CHECK(j.at("status") == "success");
    CHECK(j.at("steps_done") == j.at("steps_requested"));
    CHECK(j.at("samples").size() == j.at("steps_done").get<size_t>() + 1);
    CHECK(j.at("dimension") == e.dimension);
    CHECK(j.at("seed") == 1);
    // Residuals at most 1e-10 relative to the squared edge lengths.
    CHECK(j.at("max_residual").get<double>() <= 1e-10 * j.at("residual_scale").get<double>());
    const json& s0 = j.at("samples")[0];
    for (const json& s : j.at("samples")) {
      REQUIRE(s.size() == static_cast<size_t>(e.vertices));
      for (const json& p : s) REQUIRE(p.size() == static_cast<size_t>(e.dimension));
    }
    // Pinned vertices stay where they are (the last sample against the first).
    const json& last = j.at("samples").back();
    int unmoved = 0;
    for (int v = 0; v < e.vertices; ++v) unmoved += last[v] == s0[v];
    CHECK(unmoved >= e.pinned);
    for (const json& ev : j.at("events")) {
      CHECK(ev.at("sample").get<int>() >= 0);
      CHECK(ev.at("kind") == "singularity");
    }
  }
  fs::remove_all(d);
}

TEST_CASE("cli: a sticky packing that becomes rigid succeeds, says why and keeps its path", "[cli]") {
  const fs::path d = scratchDir("sticky");
  const fs::path out = d / "disks.json";
  const Result r = run("track " + example("disk_packing") + " --quiet -o " + out.string());
  CHECK(r.status == 0);
  CHECK_THAT(r.out, Catch::Contains("tracked 148/250 steps") && Catch::Contains("success: the packing became rigid at sample 148"));
  const json j = json::parse(readFile(out));
  CHECK(j.at("status") == "success");
  CHECK_THAT(j.at("reason").get<std::string>(), Catch::Contains("disks 1 and 4 touched"));
  CHECK(j.at("samples").size() == 149);
  CHECK(j.at("system") == "sphere_packing");
  int contacts = 0;
  for (const json& ev : j.at("events"))
    if (ev.at("kind") == "contact") {
      ++contacts;
      CHECK(ev.at("pair").size() == 2);
    }
  CHECK(contacts == 2);
  fs::remove_all(d);
}

TEST_CASE("cli: track is deterministic and writes CSV", "[cli]") {
  const fs::path d = scratchDir("det");
  const std::string scene = example("double_watt");
  REQUIRE(run("track " + scene + " --quiet --set motion.steps=80 -o " + (d / "a.json").string()).status == 0);
  REQUIRE(run("track " + scene + " --quiet --set motion.steps=80 -o " + (d / "b.json").string()).status == 0);
  // The same path; only the command in the provenance names another file.
  json a = json::parse(readFile(d / "a.json")), b = json::parse(readFile(d / "b.json"));
  CHECK(a.at("flexure").at("command") != b.at("flexure").at("command"));
  a.erase("flexure");
  b.erase("flexure");
  CHECK(a == b);
  REQUIRE(run("track " + scene + " --quiet --set motion.steps=80 -o " + (d / "p.csv").string()).status == 0);
  std::istringstream csv(readFile(d / "p.csv"));
  std::string header, line;
  std::getline(csv, header);
  CHECK(header == "sample,x1,y1,x2,y2,x3,y3,x4,y4,x5,y5,x6,y6,x7,y7,x8,y8,x9,y9,x10,y10,x11,y11");
  int rows = 0;
  while (std::getline(csv, line)) ++rows;
  CHECK(rows == 81);
  // Without -o the JSON goes to stdout.
  const Result r = run("track " + scene + " --quiet --set motion.steps=5");
  CHECK(r.status == 0);
  CHECK(json::parse(r.out).at("samples").size() == 6);
  fs::remove_all(d);
}

TEST_CASE("cli: track input errors", "[cli]") {
  const Result r = run("track " + example("square") + " --set motion.flex=[1,2]");
  CHECK(r.status == 1);
  CHECK_THAT(r.err, Catch::Contains("--set motion.flex=[1,2]:1:5: flex has 2 coefficient(s), but the start "
                                    "configuration has 1 nontrivial infinitesimal flex(es)"));
  const fs::path d = scratchDir("flexcount");
  std::ofstream(d / "s.toml") << "[system]\ntype = \"framework\"\nvertices = [[0,0],[1,0],[1,1],[0,1]]\n"
                                 "edges = [[1,2],[2,3],[3,4],[1,4]]\npinned = [1,2]\n[motion]\nflex = [1, 0]\n";
  const Result f = run("track " + (d / "s.toml").string());
  CHECK(f.status == 1);
  CHECK(f.err == (d / "s.toml").string() +
                     ":7:8: flex has 2 coefficient(s), but the start configuration has 1 nontrivial "
                     "infinitesimal flex(es)\n");
  fs::remove_all(d);
  CHECK(run("track " + example("square") + " -o out.txt").status == 1);
}

TEST_CASE("cli: render writes a PNG of the start or of a sample and is deterministic", "[cli]") {
  const fs::path d = scratchDir("render");
  const std::string scene = example("double_watt") + " --quiet --set render.width=200 --set render.height=160";
  const Result a = run("render " + scene + " -o " + (d / "a.png").string());
  REQUIRE(a.status == 0);
  CHECK(a.out.find("(200x160, sample 0") != std::string::npos);
  const std::string png = readFile(d / "a.png");
  REQUIRE(png.size() > 100);
  CHECK(png.substr(1, 3) == "PNG");
  REQUIRE(run("render " + scene + " -o " + (d / "b.png").string()).status == 0);
  CHECK(readFile(d / "b.png") == png);
  // A later sample, with its flex and trace, differs from the start.
  const Result s = run("render " + scene + " --sample 20 --flex --set render.trace=true -o " + (d / "s.png").string());
  REQUIRE(s.status == 0);
  CHECK(s.out.find("sample 20") != std::string::npos);
  CHECK(readFile(d / "s.png") != png);
  // A path JSON is a scene: its samples drawn as they are (the same picture as tracking anew),
  // analyzed, written back, animated. A vector figure and a filmstrip of it.
  REQUIRE(run("track " + scene + " --set motion.steps=40 -o " + (d / "p.json").string()).status == 0);
  REQUIRE(run("render " + scene + " --set motion.steps=40 --sample 20 -o " + (d / "t.png").string()).status == 0);
  const Result pj = run("render " + (d / "p.json").string() + " --quiet --sample 20 -o " + (d / "u.png").string());
  REQUIRE(pj.status == 0);
  CHECK(readFile(d / "u.png") == readFile(d / "t.png"));
  CHECK(run("analyze " + (d / "p.json").string() + " --json").out.find("\"nontrivial_inf_flexes\": 2") != std::string::npos);
  REQUIRE(run("track " + (d / "p.json").string() + " --quiet -o " + (d / "q.csv").string()).status == 0);
  const std::string csv = readFile(d / "q.csv");
  CHECK(std::count(csv.begin(), csv.end(), '\n') == 42);  // header + 41 samples
  // An edge contraction's scene names no steps (it stops at its target): read back, its path is
  // whole, not cut at the default 100 steps.
  REQUIRE(run("track dodecahedron --quiet -o " + (d / "c.json").string()).status == 0);
  const size_t contracted = json::parse(readFile(d / "c.json")).at("samples").size();
  REQUIRE(contracted > 101);
  REQUIRE(run("track " + (d / "c.json").string() + " --quiet -o " + (d / "c.csv").string()).status == 0);
  const std::string rows = readFile(d / "c.csv");
  CHECK(static_cast<size_t>(std::count(rows.begin(), rows.end(), '\n')) == contracted + 1);
  const Result strip = run("render " + (d / "p.json").string() + " --quiet --samples 0,20,40 -o " + (d / "strip.svg").string());
  REQUIRE(strip.status == 0);
  CHECK(strip.out.find("(600x160, samples 0,20,40") != std::string::npos);
  CHECK(readFile(d / "strip.svg").rfind("<?xml", 0) == 0);
  // A solid for 3D printing: 15 tubes and 11 spheres in binary STL.
  const Result solid = run("render " + scene + " --sample 10 -o " + (d / "s.stl").string());
  REQUIRE(solid.status == 0);
  CHECK(solid.out.find("(26 parts, ") != std::string::npos);
  CHECK(fs::file_size(d / "s.stl") > 84);
  CHECK((fs::file_size(d / "s.stl") - 84) % 50 == 0);
  CHECK(run("render " + scene + " --samples 1,2 -o " + (d / "s.obj").string()).status == 1);
  CHECK(run("render " + scene + " --sample 3 --samples 1,2 -o " + (d / "v.png").string()).status == 1);
  CHECK(run("render " + scene + " --samples 1,x -o " + (d / "v.png").string()).status == 1);
  // A rigid scene cannot reach sample 3: exit 2, the start is rendered and kept.
  const Result r = run("render " + example("rigid_test") + " --quiet --sample 3 -o " + (d / "r.png").string());
  CHECK(r.status == 2);
  CHECK(r.err.find("stopped at sample 0") != std::string::npos);
  CHECK(fs::exists(d / "r.png"));
  // Wrong extension: exit 1; a missing folder is created; an unwritable place: exit 3, no file.
  CHECK(run("render " + scene + " -o " + (d / "x.jpg").string()).status == 1);
  CHECK(run("render " + scene + " --quiet -o " + (d / "missing" / "x.png").string()).status == 0);
  CHECK(fs::exists(d / "missing" / "x.png"));
  const Result nowhere = run("render " + scene + " -o /proc/flexure-nowhere/x.png");
  CHECK(nowhere.status == 3);
  CHECK_THAT(nowhere.err, Catch::Contains("cannot create directory /proc/flexure-nowhere"));
  fs::remove_all(d);
}

TEST_CASE("cli: animate writes MP4 and GIF with one frame per sample", "[cli]") {
  const fs::path d = scratchDir("animate");
  const std::string scene = example("k24") + " --quiet --set motion.steps=24 --set render.width=161 --set render.height=120";
  const Result a = run("animate " + scene + " -o " + (d / "k.mp4").string());
  REQUIRE(a.status == 0);
  CHECK_THAT(a.out, Catch::Contains("25 frames, 162x120, 25 fps"));  // even width for yuv420p
  const render::VideoInfo mp4 = render::probeVideo((d / "k.mp4").string());
  CHECK(mp4.frames == 25);
  CHECK(mp4.width == 162);
  CHECK(mp4.pixel_format == "yuv420p");
  CHECK(mp4.duration == Approx(1.0));
  // frame_step: every 4th sample and the last one; the GIF at gif_size.
  const Result g = run("animate " + scene + " --set render.frame_step=4 --set render.gif_size=80 -o " +
                       (d / "k.gif").string());
  REQUIRE(g.status == 0);
  const render::VideoInfo gif = render::probeVideo((d / "k.gif").string());
  CHECK(gif.frames == 7);
  CHECK(gif.width == 80);
  CHECK(gif.height == 60);
  CHECK(gif.loop == 0);
  // Deterministic.
  REQUIRE(run("animate " + scene + " -o " + (d / "k2.mp4").string()).status == 0);
  CHECK(readFile(d / "k.mp4") == readFile(d / "k2.mp4"));
  // 3D with a turning camera.
  const Result c = run("animate " + example("coned_cube") +
                       " --quiet --set motion.steps=10 --set render.width=120 --set render.height=120 "
                       "--set render.rotate=true --set render.rotation_frames=4 -o " + (d / "c.mp4").string());
  REQUIRE(c.status == 0);
  const render::VideoInfo cube = render::probeVideo((d / "c.mp4").string());
  CHECK(cube.frames == 11);
  CHECK(cube.first.rgba != cube.last.rgba);
  // Bad extension: 1; a missing directory is created; an unwritable place: 3 and nothing left.
  CHECK(run("animate " + scene + " -o " + (d / "k.avi").string()).status == 1);
  CHECK(run("animate " + scene + " -o " + (d / "sub" / "k.gif").string()).status == 0);
  CHECK(run("animate " + scene + " -o /proc/flexure-x/k.mp4").status == 3);
  for (const auto& e : fs::recursive_directory_iterator(d))
    CHECK(e.path().filename().string().find(".tmp-") == std::string::npos);
  // A rigid scene animates its one configuration and says it stopped early.
  const Result r = run("animate " + example("rigid_test") + " --quiet --set render.width=64 --set render.height=64 -o " +
                       (d / "r.mp4").string());
  CHECK(r.status == 2);
  CHECK(render::probeVideo((d / "r.mp4").string()).frames == 1);
  fs::remove_all(d);
}

TEST_CASE("cli: project writes the plot and its data, seeded", "[cli]") {
  const fs::path d = scratchDir("project");
  const std::string scene = example("double_watt") + " --quiet --set motion.steps=60 --set render.width=300 --set render.height=300";
  const Result a = run("project " + scene + " --seed 5 -o " + (d / "p.png").string() + " --data " + (d / "p.csv").string());
  REQUIRE(a.status == 0);
  CHECK_THAT(a.out, Catch::Contains("projection seed 5"));
  const std::string csv = readFile(d / "p.csv");
  CHECK(csv.rfind("path,sample,p1,p2\n1,0,", 0) == 0);
  CHECK(std::count(csv.begin(), csv.end(), '\n') == 62);
  const std::string png = readFile(d / "p.png");
  REQUIRE(run("project " + scene + " --seed 5 -o " + (d / "q.png").string()).status == 0);
  CHECK(readFile(d / "q.png") == png);
  REQUIRE(run("project " + scene + " --seed 6 -o " + (d / "r.png").string() + " --data " + (d / "r.csv").string()).status == 0);
  CHECK(readFile(d / "r.png") != png);
  CHECK(readFile(d / "r.csv") != csv);
  // The seed defaults to [projection] seed, then [motion] seed.
  CHECK_THAT(run("project " + scene + " -o " + (d / "s.png").string()).out, Catch::Contains("projection seed 1"));
  CHECK_THAT(run("project " + scene + " --set projection.seed=9 -o " + (d / "s.png").string()).out,
             Catch::Contains("projection seed 9"));
  // The animated projection.
  REQUIRE(run("project " + scene + " --set render.frame_step=10 -o " + (d / "p.gif").string()).status == 0);
  CHECK(render::probeVideo((d / "p.gif").string()).frames == 7);
  CHECK(run("project " + scene + " -o " + (d / "p.txt").string()).status == 1);
  CHECK(run("project " + scene + " --seed -3").status == 1);
  fs::remove_all(d);
}

TEST_CASE("cli: run writes every [[output]] from one tracked path", "[cli]") {
  const fs::path d = scratchDir("run");
  {
    std::ofstream f(d / "scene.toml");
    f << "title = \"Pinned square\"\n[system]\ntype = \"catalog\"\nname = \"square_pinned\"\n"
         "[motion]\nsteps = 20\nstep_size = 0.05\n[render]\nwidth = 120\nheight = 100\n"
         "title = \"Θ ∈ [0, π]\"\nsubtitle = \"\"\n"
         "[[output]]\nfile = \"out/path.csv\"\n[[output]]\nfile = \"out/frame.png\"\nsample = 20\nflex = true\n"
         "[[output]]\nfile = \"out/anim.gif\"\n[[output]]\nfile = \"out/proj.png\"\nkind = \"projection\"\n"
         "[[output]]\nfile = \"out/strip.svg\"\nsamples = [0, 10, 20]\n"
         "[[output]]\nfile = \"out/proj.svg\"\nkind = \"projection\"\n";
  }
  const std::string cmd = "run scene.toml --quiet";  // from its folder: the names as written
  const std::string cwd = fs::current_path().string();
  fs::current_path(d);
  const Result r = run(cmd);
  fs::current_path(cwd);
  REQUIRE(r.status == 0);
  for (const char* f : {"out/path.csv", "out/frame.png", "out/anim.gif", "out/proj.png", "out/strip.svg", "out/proj.svg"}) {
    CHECK(fs::exists(d / f));
    CHECK_THAT(r.out, Catch::Contains(std::string("wrote ") + f));
  }
  // [[output]] samples: a filmstrip, three panels of the square's four joints.
  CHECK_THAT(r.out, Catch::Contains("samples 0,10,20"));
  const std::string strip = readFile(d / "out/strip.svg");
  size_t joints = 0;
  for (size_t at = strip.find("class=\"joint"); at != std::string::npos; at = strip.find("class=\"joint", at + 1)) ++joints;
  CHECK(joints == 12);
  // [render] title and an empty subtitle: the plot's heading is the title alone.
  const std::string plot = readFile(d / "out/proj.svg");
  CHECK_THAT(plot, Catch::Contains(">Θ ∈ [0, π]</text>"));
  CHECK_THAT(plot, !Catch::Contains("random orthonormal projection"));
  CHECK(render::probeVideo((d / "out/anim.gif").string()).frames == 21);
  const std::string path_csv = readFile(d / "out/path.csv");
  CHECK(std::count(path_csv.begin(), path_csv.end(), '\n') == 22);
  // Errors in [[output]] are scene errors with their position.
  {
    std::ofstream f(d / "bad.toml");
    f << "[system]\ntype = \"catalog\"\nname = \"square\"\n[[output]]\nfile = \"x.mp4\"\nkind = \"path\"\n";
  }
  const Result bad = run("run " + (d / "bad.toml").string());
  CHECK(bad.status == 1);
  CHECK_THAT(bad.err, Catch::Contains("bad.toml:5:8: a path output cannot be written as '.mp4'"));
  {
    std::ofstream f(d / "none.toml");
    f << "[system]\ntype = \"catalog\"\nname = \"square\"\n";
  }
  CHECK(run("run " + (d / "none.toml").string()).status == 1);
  fs::remove_all(d);
}

TEST_CASE("cli: Ctrl-C during an animation exits 130 and leaves no file", "[cli][slow]") {
  const fs::path d = scratchDir("interrupt");
  const fs::path out = d / "long.mp4";
  // Long enough to be interrupted while encoding (about 4 s on this machine).
  const std::string cmd = std::string(FLEXURE_BINARY) + " animate " + example("double_watt") +
                          " --quiet --set motion.steps=1000 -o " + out.string() + " >/dev/null 2>" +
                          (d / "err.txt").string() + " & pid=$!; sleep 1.5; kill -INT $pid; wait $pid; echo $?";
  CHECK(shellOutput(cmd) == "130\n");
  CHECK_THAT(readFile(d / "err.txt"), Catch::Contains("interrupted"));
  CHECK_FALSE(fs::exists(out));
  for (const auto& e : fs::directory_iterator(d)) CHECK(e.path().filename().string().find(".tmp-") == std::string::npos);
  fs::remove_all(d);
}

TEST_CASE("cli: a full disk (file-size limit) fails the write with exit 3 and leaves nothing", "[cli]") {
  const fs::path d = scratchDir("full");
  const std::string scene = example("double_watt") + " --quiet --set motion.steps=100 --set render.width=400 "
                            "--set render.height=400";
  for (const std::string out : {"x.json", "x.png", "x.mp4", "x.gif"}) {
    const std::string command = out == "x.json" ? "track" : out == "x.png" ? "render" : "animate";
    // ulimit -f counts 1024-byte blocks: 8 KB is less than any of these files.
    const std::string cmd = "ulimit -f 8; " + std::string(FLEXURE_BINARY) + " " + command + " " + scene + " -o " +
                            (d / out).string() + " >/dev/null 2>" + (d / "err.txt").string() + "; echo $?";
    INFO(out);
    CHECK(shellOutput(cmd) == "3\n");
    CHECK_THAT(readFile(d / "err.txt"), Catch::Contains("cannot write " + (d / out).string()));
    CHECK_FALSE(fs::exists(d / out));
    for (const auto& e : fs::directory_iterator(d))
      CHECK(e.path().filename().string().find(".tmp-") == std::string::npos);
  }
  fs::remove_all(d);
}

TEST_CASE("cli: the same square at 1e-12, 1 and 1e12 gives the same analysis and a scaled path", "[cli]") {
  const fs::path d = scratchDir("scale");
  std::vector<json> paths;
  for (const char* s : {"1e-12", "1", "1e12"}) {
    const fs::path f = d / (std::string("sq") + s + ".toml");
    {
      std::ofstream o(f);
      o << "[system]\ntype = \"framework\"\nvertices = [[0,0],[" << s << ",0],[" << s << "," << s << "],[0," << s
        << "]]\nedges = [[1,2],[2,3],[3,4],[4,1]]\n[motion]\nsteps = 20\nstep_size = \"0.05*" << s << "\"\n";
    }
    const json a = json::parse(run("analyze " + f.string() + " --json").out);
    INFO("scale " << s);
    CHECK(a.at("rigidity_rank") == 4);
    CHECK(a.at("trivial_inf_flexes") == 3);
    CHECK(a.at("nontrivial_inf_flexes") == 1);
    CHECK(a.at("rigid") == "flexible");
    REQUIRE(run("track " + f.string() + " --quiet -o " + (d / "p.json").string()).status == 0);
    paths.push_back(json::parse(readFile(d / "p.json")));
    CHECK(paths.back().at("max_residual").get<double>() <= 1e-12 * paths.back().at("residual_scale").get<double>());
  }
  // The same curve, sampled at unit speed: the first steps agree to rounding; later the step
  // control makes slightly different choices within its 5 % band (both correct), so the
  // samples drift apart along the curve by a small fraction of a step.
  for (int k : {0, 2}) {
    const double scale = k == 0 ? 1e-12 : 1e12;
    const auto& a = paths[static_cast<size_t>(k)].at("samples");
    const auto& b = paths[1].at("samples");
    REQUIRE(a.size() == b.size());
    for (size_t i = 0; i < a.size(); ++i)
      for (int v = 0; v < 4; ++v)
        for (int c = 0; c < 2; ++c)
          CHECK(a[i][v][c].get<double>() / scale == Approx(b[i][v][c].get<double>()).margin(i < 3 ? 1e-12 : 2e-3));
  }
  fs::remove_all(d);
}

TEST_CASE("cli: view's input errors exit 1 before serving", "[cli]") {
  Result r = run("view /nonexistent/scene.toml --port 0");
  CHECK(r.status == 1);
  CHECK_THAT(r.err, Catch::Contains("/nonexistent/scene.toml:1:1: cannot open the scene file"));
  for (const char* bad : {"--port", "--port abc", "--port 70000", "--port -1"}) {
    INFO(bad);
    r = run("view " + example("triangle") + " " + bad);
    CHECK(r.status == 1);
    CHECK_THAT(r.err, Catch::Contains("--port needs a port number"));
  }
  r = run("view");
  CHECK(r.status == 1);
  r = run("view " + example("triangle") + " -o x.png");
  CHECK(r.status == 1);
}

TEST_CASE("cli: view prints its address, refuses a port in use, and stops on Ctrl-C with exit 0", "[cli]") {
  const fs::path d = scratchDir("view");
  // A first viewer on a free port; a second one asked for the same port must refuse (not
  // share it: httplib's default SO_REUSEPORT would let it; `timeout` turns that into 124). The
  // address is waited for (up to 30 s: a loaded machine, the sanitizers), not assumed after 1 s.
  const std::string cmd =
      std::string(FLEXURE_BINARY) + " view " + example("triangle") + " --port 0 --quiet >" + (d / "out.txt").string() +
      " 2>" + (d / "err.txt").string() + " & pid=$!; for i in $(seq 1 300); do port=$(sed -n \"s|.*127.0.0.1:\\([0-9]*\\)/.*|\\1|p\" " +
      (d / "out.txt").string() + "); [ -n \"$port\" ] && break; sleep 0.1; done; timeout 20 " + FLEXURE_BINARY + " view " + example("triangle") +
      " --port $port --quiet 2>" + (d / "err2.txt").string() + "; echo second=$?; kill -INT $pid; wait $pid; echo first=$?";
  CHECK(shellOutput(cmd) == "second=1\nfirst=0\n");
  CHECK_THAT(readFile(d / "out.txt"), Catch::Matches("flexure view: http://127\\.0\\.0\\.1:[0-9]+/  \\(.*triangle\\.toml; Ctrl-C stops\\)\n"));
  CHECK_THAT(readFile(d / "err2.txt"), Catch::Contains("cannot listen on 127.0.0.1:"));
  CHECK_THAT(readFile(d / "err.txt"), Catch::Contains("stopped"));
  fs::remove_all(d);
}

TEST_CASE("cli: --help, COMMAND --help and --version, and a usage error is one line and a hint", "[cli]") {
  Result r = run("--help");
  CHECK(r.status == 0);
  for (const char* c : {"analyze", "track", "render", "animate", "project", "run", "demo", "catalog", "view", "--set"})
    CHECK_THAT(r.out, Catch::Contains(c));
  r = run("render --help");
  CHECK(r.status == 0);
  CHECK_THAT(r.out, Catch::Contains("--sample") && Catch::Contains("--flex") && Catch::Contains("-o,--output"));
  CHECK_THAT(r.out, !Catch::Contains("--port"));
  r = run("--version");
  CHECK(r.status == 0);
  CHECK_THAT(r.out, Catch::StartsWith("flexure ") && Catch::Contains("."));
  for (const char* bad : {"", "bogus", "--set a=1 bogus", "analyze " FLEXURE_EXAMPLES_DIR "/triangle.toml --port 3",
                          "render " FLEXURE_EXAMPLES_DIR "/triangle.toml --sample -2", "track --frobnicate"}) {
    INFO(bad);
    r = run(bad);
    CHECK(r.status == 1);
    CHECK(r.out.empty());
    // The message, then one line of hint: never the whole help.
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 2);
    CHECK_THAT(r.err, Catch::StartsWith("flexure: ") && Catch::Contains("--help"));
  }
  CHECK_THAT(run("bogus").err, Catch::Contains("unknown command 'bogus'"));
  // Options before or after the command; --set=KEY=VALUE and --set KEY VALUE alike.
  r = run("--quiet --set motion.steps=3 track " FLEXURE_EXAMPLES_DIR "/double_watt.toml --set=motion.seed=2");
  CHECK(r.status == 0);
  const auto j = nlohmann::json::parse(r.out);
  CHECK(j.at("steps_requested") == 3);
  CHECK(j.at("seed") == 2);
}

TEST_CASE("cli: flexure loads nothing that draws and hands the drawing commands to flexure-draw beside it", "[cli]") {
  // The libraries that draw (OpenGL, video, fonts, PNG, HTTP) are not among flexure's own.
  const std::string needed = shellOutput("readelf -d " FLEXURE_BINARY " | grep NEEDED");
  CHECK_THAT(needed, Catch::Contains("libc.so"));
  for (const char* lib : {"OSMesa", "avcodec", "avformat", "freetype", "png16", "httplib", "GL", "cairo"}) {
    INFO(lib);
    CHECK_THAT(needed, !Catch::Contains(lib));
  }
  // Handed on: the same output as flexure-draw's, and the same exit status.
  const fs::path dir = scratchDir("lean");
  Result r = run("render " FLEXURE_EXAMPLES_DIR "/triangle.toml -o " + (dir / "t.png").string());
  CHECK(r.status == 0);
  CHECK(fs::file_size(dir / "t.png") > 1000);
  CHECK(run("render " FLEXURE_EXAMPLES_DIR "/triangle.toml -o " + (dir / "t.svg").string()).status == 0);
  CHECK(run("render " FLEXURE_EXAMPLES_DIR "/triangle.toml -o " + (dir / "t.bmp").string()).status == 1);
  // Alone (flexure-draw missing): analyze and track still work; a drawing command says why.
  fs::copy_file(FLEXURE_BINARY, dir / "flexure");
  const std::string alone = (dir / "flexure").string();
  CHECK(shellOutput(alone + " analyze " FLEXURE_EXAMPLES_DIR "/triangle.toml >/dev/null; echo $?") == "0\n");
  CHECK(shellOutput(alone + " --quiet track " FLEXURE_EXAMPLES_DIR "/double_watt.toml --set motion.steps=3 | head -c 1; echo $?") ==
        "{0\n");
  const std::string err = shellOutput(alone + " render " FLEXURE_EXAMPLES_DIR "/triangle.toml -o " +
                                      (dir / "u.png").string() + " 2>&1; echo $?");
  CHECK_THAT(err, Catch::Contains("flexure-draw") && Catch::EndsWith("3\n"));
  CHECK(!fs::exists(dir / "u.png"));
  fs::remove_all(dir);
}

TEST_CASE("cli: a catalog name is a scene, a catalog system keeps its entry's settings, defaults never collide",
          "[cli]") {
  const Result a = run("analyze k24 --json");
  REQUIRE(a.status == 0);
  const json j = json::parse(a.out);
  CHECK(j.at("scene") == "catalog:k24");
  CHECK(j.at("title") == "Complete bipartite graph K_{2,4} in a flexible realization");
  CHECK(run("analyze catalog:k24").status == 0);
  const Result missing = run("analyze k2");
  CHECK(missing.status == 1);
  CHECK_THAT(missing.err, Catch::Contains("nor is it a catalog entry: unknown catalog name 'k2' (did you mean 'k24'?)"));
  const fs::path d = scratchDir("catalog");
  const std::string bin = FLEXURE_BINARY;
  // A file of that name wins over the catalog entry.
  std::ofstream(d / "k24") << "title = \"my own k24\"\n[system]\ntype = \"framework\"\n"
                              "vertices = [[0,0],[1,0],[0,1]]\nedges = [[1,2],[2,3],[1,3]]\n";
  CHECK_THAT(shellOutput("cd " + d.string() + " && " + bin + " analyze k24"), Catch::Contains("my own k24"));
  // [system] type = "catalog": the entry's title and [motion] keys under the scene's own.
  std::ofstream(d / "c.toml") << "[system]\ntype = \"catalog\"\nname = \"double_watt\"\n[motion]\nsteps = 7\n";
  REQUIRE(run("track " + (d / "c.toml").string() + " -o " + (d / "c.json").string()).status == 0);
  const json p = json::parse(readFile(d / "c.json"));
  CHECK(p.at("title") == "Cuspidal double Watt mechanism");
  CHECK(p.at("steps_requested") == 7);
  CHECK(p.at("step_size") == 0.05);
  // render and project by default: STEM.png and STEM_projection.png, side by side.
  std::ofstream(d / "s.toml") << readFile(example("k24"));
  shellOutput("cd " + d.string() + " && " + bin + " render s.toml --quiet --set motion.steps=5 && " + bin +
              " project s.toml --quiet --set motion.steps=5 --set render.width=200 --set render.height=200");
  CHECK(fs::exists(d / "s.png"));
  CHECK(fs::exists(d / "s_projection.png"));
  CHECK(readFile(d / "s.png") != readFile(d / "s_projection.png"));
  fs::remove_all(d);
}
