// A path JSON holds its structure and its scene, and loads back as a scene whose motion is the
// stored path: the same samples (vertex positions bit for bit), events and analysis, for every
// kind of model (auxiliary facet normals, sticky contacts, edge contraction, a mesh read by
// `from`); files that are not a path of their scene are refused at the array and index.
#include <catch2/catch.hpp>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "pipeline/pipeline.h"
#include "present/path_output.h"
#include "scenes/catalog.h"
#include "scenes/scene.h"
#include "../scenes/scene_test_common.h"

using namespace flexure;
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("flexure_path_file_test_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d / name;
}

void writeText(const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }

// Tracks `scene`, writes the path JSON, loads it back and compares.
void roundTrip(const scenes::Scene& scene, int steps, const std::string& name) {
  INFO(name);
  const pipeline::Motion m = pipeline::track(scene, steps);
  const fs::path file = scratch(name + ".json");
  present::writePath(scene, m.path, file.string());
  const json written = json::parse(std::ifstream(file));
  const scenes::Scene back = scenes::loadScene(file.string());
  REQUIRE(back.given);
  CHECK(back.type == scene.type);
  CHECK(back.title == scene.title);
  const pipeline::Motion again = pipeline::track(back, back.motion.steps);
  REQUIRE(again.path.samples.size() == m.path.samples.size());
  const auto& sys = scene.model->system();
  for (size_t k = 0; k < m.path.samples.size(); ++k)
    CHECK(back.model->system().vertexPositions(again.path.samples[k]) == sys.vertexPositions(m.path.samples[k]));
  CHECK(again.path.events.size() == m.path.events.size());
  CHECK(again.path.summary.max_residual <= 1e-9 * sys.residualScale());
  // Written again, the path is the same file (but for the max residual, now measured on the
  // rounded coordinates, and the flex choice note).
  json rewritten = present::pathJson(back, again.path);
  json original = written;
  for (json* j : {&rewritten, &original}) j->erase("max_residual");
  // Which flexure wrote it: the same build, and no command line (a library call) for either.
  CHECK(rewritten.at("flexure") == original.at("flexure"));
  CHECK(rewritten == original);
  // The analysis of the start is the scene's.
  CHECK(pipeline::analyze(back).rank == pipeline::analyze(scene).rank);
}

}  // namespace

TEST_CASE("path file: the path JSON holds the structure and the scene", "[pipeline][path]") {
  const scenes::Scene scene = test::example("double_watt", {"motion.steps=20"});
  const pipeline::Motion m = pipeline::track(scene, 20);
  const json j = present::pathJson(scene, m.path);
  CHECK(j["structure"]["vertices"] == 11);
  CHECK(j["structure"]["edges"].size() == 15);
  CHECK(j["structure"]["edges"][0] == json::array({1, 2}));
  CHECK(j["structure"]["pinned"] == json::array({1, 6, 11}));
  CHECK(j["structure"]["index_base"] == 1);
  const std::string text = j["scene"];
  CHECK(text.find("[system]") != std::string::npos);
  CHECK(text.find("steps = 20") != std::string::npos);  // the override is part of the scene
  CHECK(text.find("[[output]]") == std::string::npos);
  // A polytope: its facets.
  const scenes::Scene cube = test::example("cube", {"motion.steps=3"});
  const json c = present::pathJson(cube, pipeline::track(cube, 3).path);
  CHECK(c["structure"]["facets"].size() == 6);
  CHECK(c["structure"]["edges"].size() == 12);
}

TEST_CASE("path file: paths load back as their scene and samples, for every kind of model", "[pipeline][path]") {
  roundTrip(test::example("double_watt", {"motion.steps=60"}), 60, "double_watt");
  roundTrip(test::example("truncated_octahedron", {"motion.steps=30"}), 30, "truncated_octahedron");  // normals
  roundTrip(test::example("disk_packing", {"motion.steps=160"}), 160, "disk_packing");  // contacts
  roundTrip(test::example("dodecahedron", {"motion.steps=20"}), 20, "dodecahedron");    // edge contraction
  // A contracted edge whose two vertices also share a facet-plane equation (found by the
  // valid-scene fuzzer: only the distance equation follows the contraction).
  roundTrip(scenes::loadSceneFromString("[system]\ntype = \"polytope\"\nvertices = [[0,0,0],[1,0,0],[0,1,0],[0,0,1]]\n"
                                        "facets = [[1,3,2],[1,2,4],[2,3,4],[1,4,3]]\n[motion]\ncontract_edge = [1, 2]\n"
                                        "target_length = 0.8\nstep_size = 0.05\n",
                                        "tetrahedron.toml"),
            4, "contracted_tetrahedron");
  // A hull polytope whose nearly flat facets turn fast as an edge contracts: the normals of a
  // sample are found from the previous sample's by damped Gauss-Newton steps (the full step
  // overshot: residual 0.15, then 0.21, and the path was refused).
  roundTrip(scenes::loadSceneFromString("[system]\ntype = \"polytope\"\nvertices = [[0.7610516358678897, 0.5723543901244311, 0.3957746863053603], [0.6053718899601465, -0.6151586193600357, 0.5353181942408031], [-0.4530441991251497, 0.7221461253633391, 0.5881929761231978], [0.14231547749954201, -1.092514667259412, -0.4736372611784801], [-0.6072898773665817, -0.24474990043730913, 0.6355795796019922], [-0.30374781057532946, 0.908175096465164, -0.5583339585677088], [-0.8435432527901645, -0.6326441734924393, -0.19189720153731812], [0.6966114417394823, -0.41678093069063143, 0.5290558629479323], [-0.578251749458885, -0.9683881186337603, -0.3162549340688789], [-0.016630139065925885, 1.2985577823004724, 0.2328482393056389], [0.5541031469969971, 0.975689146771055, 0.3374263686797452], [-0.3273193091064813, 0.2408612384078312, 0.7667137644723685], [-0.7029326236356022, 0.9343953623059575, -0.11116793314902801], [-0.3078877344819129, 1.2469683799890465, 0.19266904202411997]]\nfacets = \"hull\"\n"
                                        "[motion]\nstep_size = 0.05\ncontract_edge = [5, 9]\ntarget_length = 1.346\n",
                                        "hull.toml"),
            3, "contracted_hull");
  roundTrip(test::example("bodyhinge_squares", {"motion.steps=20"}), 20, "bodyhinge_squares");
  roundTrip(test::example("octahedral_volumes", {"motion.steps=20"}), 20, "octahedral_volumes");
  // A catalog system and a mesh read by `from`: the scene the file holds needs neither.
  const fs::path dir = scratch("mesh");
  fs::create_directories(dir);
  writeText(dir / "box.off", "OFF\n8 6 0\n0 0 0\n2 0 0\n2 1 0\n0 1 0\n0 0 1\n2 0 1\n2 1 1\n0 1 1\n"
                             "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n");
  writeText(dir / "box.toml", "title = \"a box\"\n[system]\nfrom = \"box.off\"\n[motion]\nsteps = 10\n");
  const scenes::Scene box = scenes::loadScene((dir / "box.toml").string());
  const pipeline::Motion m = pipeline::track(box, 10);
  present::writePath(box, m.path, (dir / "box_path.json").string());
  fs::remove(dir / "box.off");
  const scenes::Scene back = scenes::loadScene((dir / "box_path.json").string());
  CHECK(back.type == "polytope");
  CHECK(pipeline::track(back, 10).path.samples.size() == m.path.samples.size());
  writeText(dir / "k24.toml", "[system]\ntype = \"catalog\"\nname = \"k24\"\n[motion]\nsteps = 10\n");
  roundTrip(scenes::loadScene((dir / "k24.toml").string()), 10, "k24");
}

TEST_CASE("path file: a file that is not a path of its scene is refused at the array and index", "[pipeline][path]") {
  const scenes::Scene scene = test::example("double_watt", {"motion.steps=10"});
  const json good = present::pathJson(scene, pipeline::track(scene, 10).path);
  const auto refused = [&](const std::function<void(json&)>& edit, const std::string& where, const std::string& what) {
    json j = good;
    edit(j);
    const fs::path f = scratch("bad.json");
    writeText(f, j.dump(1));
    INFO(where);
    try {
      scenes::loadScene(f.string());
      FAIL("accepted");
    } catch (const scenes::SceneError& e) {
      CHECK_THAT(e.message, Catch::StartsWith(where) && Catch::Contains(what));
    }
  };
  refused([](json& j) { j["samples"][3].erase(0); }, "samples[3]", "not a list of 11 points");
  refused([](json& j) { j["samples"][4][2] = json::array({1.0}); }, "samples[4][2]", "not a point of 2 coordinates");
  refused([](json& j) { j["samples"][5][1][0] = 3.5; }, "samples[5]", "edge 1-2");  // a bar stretched
  refused([](json& j) { j["samples"][6][5][0] = 9.0; }, "samples[6][5]", "vertex 6 is pinned");
  refused([](json& j) { j["samples"][2][2][1] = "x"; }, "samples[2][2][1]", "not a finite number");
  refused([](json& j) { j["samples"] = json::array(); }, "samples", "empty");
  refused([](json& j) { j["events"] = json::array({{{"sample", 99}, {"kind", "singularity"}}}); }, "events[0].sample",
          "0..10");
  refused([](json& j) { j["events"] = json::array({{{"sample", 1}, {"kind", "bump"}}}); }, "events[0].kind", "'bump'");
  refused([](json& j) { j["scene"] = 3; }, "scene", "not a string");
  // Found by the import fuzzer: these threw the JSON library's type_error, not a SceneError.
  refused([](json& j) { j["status"] = json::array({1}); }, "status", "a string");
  refused([](json& j) { j["events"] = json::array({{{"sample", 1}, {"kind", 7}}}); }, "events[0].kind", "a string");
  // A broken embedded scene points into it.
  json j = good;
  j["scene"] = "title = 1\n";
  writeText(scratch("bad_scene.json"), j.dump());
  try {
    scenes::loadScene(scratch("bad_scene.json").string());
    FAIL("accepted");
  } catch (const scenes::SceneError& e) {
    CHECK_THAT(e.file, Catch::Contains("(its \"scene\")"));
    CHECK(e.line == 1);
  }
  // JSON syntax: line and column.
  writeText(scratch("syntax.json"), "{\"samples\": [], \"scene\": \n  [1,,2]}");
  try {
    scenes::loadScene(scratch("syntax.json").string());
    FAIL("accepted");
  } catch (const scenes::SceneError& e) {
    CHECK(e.line == 2);
    CHECK(e.column == 6);  // the second comma
  }
}
