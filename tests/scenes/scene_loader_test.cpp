#include <catch2/catch.hpp>

#include "engine/rigidity.h"
#include "scenes/catalog.h"
#include "scenes/json_text.h"
#include "scenes/scene.h"

using flexure::scenes::loadScene;
using flexure::scenes::loadSceneFromString;
using flexure::scenes::Scene;
using flexure::scenes::SceneError;

namespace {

const char* kSquare = R"(title = "square"
[system]
type = "framework"
vertices = [[0,0],[1,0],[1,1],[0,1]]
edges = [[1,2],[2,3],[3,4],[1,4]]
)";

struct Expected {
  int line;
  int column;
  std::string text;
};

void requireError(const std::string& toml, const Expected& e,
                  const std::vector<std::string>& overrides = {}) {
  INFO(toml);
  try {
    loadSceneFromString(toml, "test.toml", overrides);
    FAIL("no error for this scene");
  } catch (const SceneError& err) {
    INFO(err.what());
    CHECK(err.line == e.line);
    CHECK(err.column == e.column);
    CHECK_THAT(err.message, Catch::Contains(e.text));
    CHECK_THAT(std::string(err.what()), Catch::StartsWith("test.toml:" + std::to_string(e.line) + ":" +
                                                          std::to_string(e.column) + ": "));
  }
}

std::string framework(const std::string& body) { return "[system]\ntype = \"framework\"\n" + body; }

}  // namespace

TEST_CASE("scene loader: a framework scene with every table", "[scenes]") {
  const Scene s = loadSceneFromString(std::string(kSquare) + R"(
[motion]
steps = 50
step_size = "1/40"
flex = [1]
seed = 7
[analysis]
rank_tolerance = 1e-10
[render]
width = 640
height = 480
fps = 30
[[output]]
file = "a.mp4"
[[output]]
file = "p.png"
kind = "projection"
[[output]]
file = "path.json"
)", "sq.toml");
  CHECK(s.title == "square");
  CHECK(s.type == "framework");
  CHECK(s.model->system().numVertices() == 4);
  CHECK(s.motion.steps == 50);
  CHECK(s.motion.step_size == 0.025);
  REQUIRE(s.motion.flex);
  CHECK(*s.motion.flex == std::vector<double>{1.0});
  CHECK(s.motion.seed == 7);
  CHECK(s.analysis.rank_tolerance == 1e-10);
  CHECK(s.render.width == 640);
  CHECK(s.render.fps == 30);
  REQUIRE(s.outputs.size() == 3);
  CHECK(s.outputs[0].kind == flexure::scenes::parseOutputKind("animation"));
  CHECK(s.outputs[1].kind == flexure::scenes::parseOutputKind("projection"));
  CHECK(s.outputs[2].kind == flexure::scenes::parseOutputKind("path"));
  CHECK(toString(s.outputs[0].kind) == std::string("animation"));
  CHECK(flexure::scenes::outputKindOfExtension("mp4") == flexure::scenes::OutputKind::Animation);
  CHECK(!flexure::scenes::parseOutputKind("movie"));
  CHECK(!flexure::scenes::canWrite(flexure::scenes::OutputKind::Path, "png"));
}

TEST_CASE("scene loader: index_base = 0 and pins", "[scenes]") {
  const Scene s = loadSceneFromString(R"(index_base = 0
[system]
type = "framework"
vertices = [[0,0],[1,0],[1,1]]
edges = [[0,1],[1,2],[0,2]]
pinned = [0]
)", "t.toml");
  CHECK(s.model->system().isPinned(0));
  CHECK(s.model->system().numVariables() == 4);
  CHECK(s.render.style.label_base == 0);  // the picture numbers vertices as the file does
}

TEST_CASE("scene loader: --set overrides keys before validation", "[scenes]") {
  const Scene s = loadSceneFromString(kSquare, "t.toml",
                                      {"motion.steps=9", "system.pinned=[1,2]", "title=renamed", "motion.flex=auto"});
  CHECK(s.motion.steps == 9);
  CHECK(s.model->system().numPinned() == 2);
  CHECK(s.title == "renamed");
  CHECK_FALSE(s.motion.flex);
  CHECK_THROWS_WITH(loadSceneFromString(kSquare, "t.toml", {"motion.steps=-3"}),
                    Catch::Contains("--set motion.steps=-3:1:5: steps must be between"));
  CHECK_THROWS_WITH(loadSceneFromString(kSquare, "t.toml", {"nokey"}), Catch::Contains("expected KEY=VALUE"));
  CHECK_THROWS_WITH(loadSceneFromString(kSquare, "t.toml", {"title.x=1"}), Catch::Contains("not a table"));
}

TEST_CASE("scene loader: expression strings anywhere a number goes", "[scenes]") {
  const Scene s = loadSceneFromString(framework(R"(vertices = [[0,0],[1,0],[0.5,"sqrt(3)/2"]]
edges = [[1,2],[2,3],[1,3]]
)"), "t.toml");
  CHECK(s.model->startPositions()(1, 2) == Approx(0.8660254037844386).epsilon(1e-15));
}

TEST_CASE("scene loader: a catalog system", "[scenes]") {
  const Scene s = loadSceneFromString("[system]\ntype = \"catalog\"\nname = \"double_watt\"\n", "t.toml");
  CHECK(s.type == "framework");
  CHECK(s.model->system().numVertices() == 11);
  CHECK(s.model->system().numPinned() == 3);
  requireError("[system]\ntype = \"catalog\"\nname = \"dodecahedronn\"\n", {3, 8, "unknown catalog name 'dodecahedronn'"});
  // The entry's title and settings, under the scene's own, key by key.
  CHECK(s.title == "Cuspidal double Watt mechanism");
  CHECK(s.motion.steps == 500);
  const Scene k = loadSceneFromString("title = \"mine\"\n[system]\ntype = \"catalog\"\nname = \"k24\"\n"
                                      "[motion]\nsteps = 9\n",
                                      "t.toml", {"render.width=321"});
  CHECK(k.title == "mine");
  CHECK(k.motion.steps == 9);
  CHECK(k.motion.step_size == 0.025);  // k24's
  CHECK(k.render.width == 321);
  // A scene that counts vertices from 0 takes only the title of an entry that counts from 1.
  const Scene plain = loadSceneFromString("[system]\ntype = \"framework\"\nvertices = [[0,0],[1,0]]\nedges = [[1,2]]\n",
                                          "p.toml");
  const Scene z = loadSceneFromString("index_base = 0\n[system]\ntype = \"catalog\"\nname = \"k24\"\n", "t.toml");
  CHECK(z.title == "Complete bipartite graph K_{2,4} in a flexible realization");
  CHECK(z.motion.steps == plain.motion.steps);
}

TEST_CASE("scene loader: every built-in catalog scene loads", "[scenes]") {
  REQUIRE(flexure::scenes::catalog().size() >= 10);
  for (const auto& e : flexure::scenes::catalog()) {
    INFO(e.name);
    CHECK_NOTHROW(loadSceneFromString(e.text, "catalog:" + e.name));
  }
}

TEST_CASE("scene loader: bad input is reported with file line and column", "[scenes]") {
  SECTION("TOML syntax") { requireError("[system\n", {1, 8, ""}); }
  SECTION("no [system]") { requireError("title = \"x\"\n", {1, 1, "no [system] table"}); }
  SECTION("unknown top-level key, with a suggestion") {
    requireError(std::string(kSquare) + "[moton]\nsteps = 3\n", {6, 2, "unknown key 'moton' in the scene (did you mean 'motion'?)"});
  }
  SECTION("unknown key in [system]") {
    requireError(framework("vertices = [[0,0],[1,0]]\nedges = [[1,2]]\npinned_vertices = [1]\n"),
                 {5, 1, "unknown key 'pinned_vertices'"});
  }
  SECTION("unknown system type") { requireError("[system]\ntype = \"frameworks\"\n", {2, 8, "unsupported system type 'frameworks'"}); }
  SECTION("wrong types") {
    requireError(framework("vertices = \"abc\"\nedges = []\n"), {3, 12, "vertices must be an array, not a string"});
    requireError(framework("vertices = [[0,0],[1,true]]\nedges = []\n"), {3, 22, "coordinate must be a number"});
    requireError(framework("vertices = [[0,0],[1,0]]\nedges = [[1,2.0]]\n"), {4, 13, "edge vertex must be an integer"});
    requireError(std::string(kSquare) + "[motion]\nsteps = 2.5\n", {7, 9, "steps must be an integer"});
    requireError("motion = 3\n" + std::string(kSquare), {1, 10, "[motion] must be a table"});
  }
  SECTION("vertex numbers out of range") {
    requireError(framework("vertices = [[0,0],[1,0],[0,1]]\nedges = [[1,2],[2,4]]\n"),
                 {4, 19, "edge vertex 4 is out of range: vertices are numbered 1..3"});
    requireError(framework("vertices = [[0,0],[1,0],[0,1]]\nedges = [[0,1]]\n"), {4, 11, "edge vertex 0 is out of range"});
    requireError(framework("vertices = [[0,0],[1,0],[0,1]]\nedges = [[1,2]]\npinned = [1, 9]\n"),
                 {5, 14, "pinned vertex 9 is out of range"});
    requireError(framework("vertices = [[0,0],[1,0],[0,1]]\nedges = [[1,2]]\npinned = [1, 1]\n"),
                 {5, 14, "vertex 1 is pinned twice"});
  }
  SECTION("duplicate, self and degenerate edges") {
    requireError(framework("vertices = [[0,0],[1,0],[0,1]]\nedges = [[1,2],[2,3],[2,1]]\n"),
                 {4, 22, "duplicate edge [2, 1] (the same pair as edge 1)"});
    requireError(framework("vertices = [[0,0],[1,0],[0,1]]\nedges = [[1,1]]\n"), {4, 10, "joins a vertex to itself"});
    requireError(framework("vertices = [[0,0],[1,0],[1,0]]\nedges = [[1,2],[2,3]]\n"),
                 {4, 16, "edge [2, 3] has length 0: vertices 2 and 3 coincide"});
    requireError(framework("vertices = [[0,0],[1,0]]\nedges = [[1,2,3]]\n"), {4, 10, "an edge joins 2 vertices"});
  }
  SECTION("NaN and infinite coordinates") {
    requireError(framework("vertices = [[0,0],[nan,0]]\nedges = [[1,2]]\n"), {3, 20, "coordinate is NaN"});
    requireError(framework("vertices = [[0,0],[1,-inf]]\nedges = [[1,2]]\n"), {3, 22, "coordinate is infinite"});
    requireError(framework("vertices = [[0,0],[1,\"sqrt(-1)\"]]\nedges = [[1,2]]\n"),
                 {3, 28, "sqrt(-1.000000) is not a finite number"});
    requireError(framework("vertices = [[0,0],[1,\"1/0\"]]\nedges = [[1,2]]\n"), {3, 25, "division by zero"});
  }
  SECTION("wrong dimensions") {
    requireError(framework("vertices = [[0,0,0,0],[1,0,0,0]]\nedges = [[1,2]]\n"),
                 {3, 13, "a vertex has 4 coordinates; this system type needs 2 or 3"});
    requireError(framework("vertices = [[0,0],[1,0,0]]\nedges = [[1,2]]\n"),
                 {3, 19, "vertex 2 has 3 coordinates, but the first vertex has 2"});
    requireError(framework("vertices = []\nedges = []\n"), {3, 12, "vertices is empty"});
  }
  SECTION("a realization that does not satisfy its constraints") {
    requireError(framework("vertices = [[0,0],[1,0],[0,1]]\nedges = [[1,2],[2,3]]\nlengths = [1, 1.5]\n"),
                 {5, 15, "does not satisfy edge [2, 3]: its length is 1.414213562, lengths says 1.5 (residual -0.25)"});
  }
  SECTION("motion, analysis, render and output values") {
    requireError(std::string(kSquare) + "[motion]\nstep_size = 0\n", {7, 13, "step_size must be positive"});
    requireError(std::string(kSquare) + "[motion]\nflex = [0, 0]\n", {7, 8, "flex coefficients are all zero"});
    requireError(std::string(kSquare) + "[motion]\nflex = \"random\"\n", {7, 8, "flex must be \"auto\""});
    requireError(std::string(kSquare) + "[motion]\nseed = -1\n", {7, 8, "seed must be a nonnegative integer"});
    requireError(std::string(kSquare) + "[analysis]\nrank_tolerance = 2\n", {7, 18, "rank_tolerance must be in (0, 1)"});
    requireError(std::string(kSquare) + "[analysis]\nseed = -3\n", {7, 8, "seed must be a nonnegative integer"});
    requireError(std::string(kSquare) + "[analysis]\nmax_homotopy_flexes = 12\n", {7, 23, "max_homotopy_flexes must be between 0 and 9"});
    requireError(std::string(kSquare) + "[analysis]\nmotion_check_steps = 2.5\n", {7, 22, "motion_check_steps"});
    requireError(std::string(kSquare) + "[render]\nwidth = 0\n", {7, 9, "width must be between 16 and 8192"});
    requireError(std::string(kSquare) + "[[output]]\nfile = \"x.avi\"\n", {7, 8, "cannot tell the output kind"});
    requireError(std::string(kSquare) + "[[output]]\nfile = \"x.png\"\nkind = \"movie\"\n", {8, 8, "kind must be frame"});
    requireError(std::string(kSquare) + "[[output]]\nfile = \"x.png\"\nsamples = []\n", {8, 11, "samples lists 1 to 64"});
    requireError(std::string(kSquare) + "[[output]]\nfile = \"x.gif\"\nsamples = [1, 2]\n", {8, 11, "samples applies to picture frame outputs only"});
    requireError(std::string(kSquare) + "[[output]]\nfile = \"x.stl\"\nsamples = [1, 2]\n", {8, 11, "samples applies to picture frame outputs only"});
    requireError(std::string(kSquare) + "[[output]]\nfile = \"x.pdf\"\nsample = 3\nsamples = [1, 2]\n", {9, 11, "not both"});
    requireError(std::string(kSquare) + "[[output]]\nfile = \"x.pdf\"\nsamples = [1, -2]\n", {8, 15, "a samples entry must be a sample number"});
    requireError(std::string(kSquare) + "[render]\ntitle = 3\n", {7, 9, "title must be a string"});
    requireError("index_base = 2\n" + std::string(kSquare), {1, 14, "index_base must be 0 or 1"});
  }
}

TEST_CASE("scene loader: unreadable file", "[scenes]") {
  CHECK_THROWS_WITH(loadScene("/nonexistent/dir/x.toml"),
                    "/nonexistent/dir/x.toml:1:1: cannot open the scene file: No such file or directory");
}

TEST_CASE("scene loader: JSON nested deeper than the limit is refused before it is parsed, at its line and column") {
  // Issue 42: a 200 KB JSON nested 100,000 deep crashed analyze, a sweep, the viewer and Python
  // (copies, comparisons and dumps of such a value recurse once per level).
  const std::string deep = "{\n  \"nodes\": " + std::string(100000, '[') + std::string(100000, ']') + ",\n \"links\": []}";
  try {
    flexure::scenes::checkJsonShape(deep, "deep.json");
    FAIL("accepted");
  } catch (const flexure::scenes::SceneError& e) {
    CHECK(e.file == "deep.json");
    CHECK(e.line == 2);
    CHECK(e.column == 12 + flexure::scenes::kMaxJsonDepth - 1);  // the object is the first level
    CHECK_THAT(e.message, Catch::Contains("nested deeper than 256 levels"));
  }
  // Brackets inside strings do not count; the limit itself is allowed.
  CHECK_NOTHROW(flexure::scenes::checkJsonShape("{\"a\": \"" + std::string(1000, '[') + "\\\"\"}", "s.json"));
  CHECK_NOTHROW(flexure::scenes::checkJsonShape(std::string(flexure::scenes::kMaxJsonDepth, '[') + std::string(flexure::scenes::kMaxJsonDepth, ']'), "x"));
  CHECK_THROWS(flexure::scenes::parseJsonText(std::string(flexure::scenes::kMaxJsonDepth + 1, '[') + std::string(flexure::scenes::kMaxJsonDepth + 1, ']'), "x"));
}

TEST_CASE("scene loader: a path JSON is told by its top-level keys, not by words in its text") {
  // Issue 42: a node-link file whose nodes are named "samples" and "scene" was read as a path.
  CHECK(flexure::scenes::isPathJson(nlohmann::json::parse(R"({"scene": "t", "samples": []})")));
  CHECK_FALSE(flexure::scenes::isPathJson(nlohmann::json::parse(
      R"({"directed": false, "nodes": [{"id": "samples"}, {"id": "scene"}], "links": [{"source": "samples", "target": "scene"}]})")));
  CHECK_FALSE(flexure::scenes::isPathJson(nlohmann::json::parse(R"([{"scene": "t", "samples": []}])")));
}
