// Rigid origami from FOLD files: the specification's examples read and written back, a
// degree-4 vertex and the Miura-ori against their closed forms, folding from the flat state on
// the branch the mountain/valley assignment picks, and broken files.
#include <catch2/catch.hpp>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "engine/origami.h"
#include "pipeline/pipeline.h"
#include "present/output_file.h"
#include "present/path_output.h"
#include "scenes/fold_file.h"
#include "scenes/scene.h"
#include "../test_common.h"

using namespace flexure;
using nlohmann::json;
using scenes::SceneError;

namespace {

const std::string kData = FLEXURE_SOURCE_DIR "/tests/data/fold/";

std::filesystem::path tempDir() {
  static const std::filesystem::path d = test::scratchFolder("flexure-origami");
  return d;
}

std::string write(const std::string& name, const std::string& text) { return test::writeScratch(tempDir(), name, text); }

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

const engine::Origami& origamiOf(const scenes::Scene& s) {
  const auto* o = dynamic_cast<const engine::Origami*>(s.model.get());
  REQUIRE(o);
  return *o;
}

// A single degree-4 vertex at the origin, creases along the rays at angles 0, g, pi, -g (the
// sector angles g, pi - g, pi - g, g: flat-foldable), flat, with the assignment `letters` for
// these four creases in that order.
std::string degree4(double g, const std::string& letters) {
  json j;
  j["file_spec"] = 1.2;
  j["vertices_coords"] = {{0, 0}, {1, 0}, {std::cos(g), std::sin(g)}, {-1, 0}, {std::cos(g), -std::sin(g)}};
  j["faces_vertices"] = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 1}};
  j["edges_vertices"] = {{0, 1}, {0, 2}, {0, 3}, {0, 4}, {1, 2}, {2, 3}, {3, 4}, {4, 1}};
  json a = json::array();
  for (char c : letters) a.push_back(std::string(1, c));
  for (int k = 0; k < 4; ++k) a.push_back("B");
  j["edges_assignment"] = a;
  return j.dump();
}

// The Miura-ori of Schenk and Guest (PNAS 110:3276, 2013): m x n parallelogram facets of sides
// a = b = 1 and angle g, at fold parameter theta; vertices p(i, j) = (iS, jL + V (i mod 2),
// H (j mod 2)) with H = a sin(theta) sin(g), S = b cos(theta) tan(g) / sqrt(1 + cos^2(theta)
// tan^2(g)), L = a sqrt(1 - sin^2(theta) sin^2(g)), V = b / sqrt(1 + cos^2(theta) tan^2(g)).
struct Miura {
  double H, S, L, V;
};
Miura miuraCell(double theta, double g) {
  const double c = std::cos(theta), t = std::tan(g), q = std::sqrt(1 + c * c * t * t);
  return {std::sin(theta) * std::sin(g), c * t / q, std::sqrt(1 - std::pow(std::sin(theta) * std::sin(g), 2)), 1 / q};
}
json miuraFold(int m, int n, double theta, double g) {
  const Miura cell = miuraCell(theta, g);
  const auto index = [n](int i, int j) { return i * (n + 1) + j; };
  json v = json::array(), faces = json::array();
  for (int i = 0; i <= m; ++i)
    for (int j = 0; j <= n; ++j) v.push_back({i * cell.S, j * cell.L + cell.V * (i % 2), cell.H * (j % 2)});
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < n; ++j) faces.push_back({index(i, j), index(i + 1, j), index(i + 1, j + 1), index(i, j + 1)});
  json j;
  j["vertices_coords"] = v;
  j["faces_vertices"] = faces;  // counterclockwise seen from +z
  return j;
}

}  // namespace

TEST_CASE("origami: the FOLD specification's examples are read, checked against their assignments and written back",
          "[origami]") {
  struct Expect {
    const char* file;
    int vertices, faces, edges;
  };
  for (const Expect& e : {Expect{"simple", 6, 4, 9}, Expect{"squaretwist", 16, 9, 24}, Expect{"diagonal-cp", 4, 2, 5},
                          Expect{"diagonal-folded", 4, 2, 5}, Expect{"box", 39, 42, 80}}) {
    INFO(e.file);
    const std::string path = kData + e.file + ".fold";
    const scenes::Scene s = scenes::loadScene(path);
    CHECK(s.type == "origami");
    const engine::Origami& o = origamiOf(s);
    CHECK(o.system().numVertices() == e.vertices);
    CHECK(static_cast<int>(o.faces().size()) == e.faces);
    CHECK(static_cast<int>(o.edges().size()) == e.edges);
    // The fold angles flexure computes have the signs the files assign (FOLD: + valley), for
    // the files whose faces run counterclockwise as the specification says; box.fold lists its
    // faces clockwise, and every one of its signs is the other way.
    const std::vector<double> folds = o.foldAngles(o.system().vertexPositions(o.startCoordinates()));
    const json original = json::parse(slurp(path));
    const double sign = std::string(e.file) == "box" ? -1 : 1;
    int checked = 0;
    for (size_t k = 0; k < o.edges().size(); ++k) {
      const char a = o.edges()[k].assignment;
      if (std::string(e.file) == "diagonal-folded")  // folded flat along its diagonal, as the file says
        CHECK(std::abs(folds[k]) * 180 / M_PI == Approx(std::abs(original["edges_foldAngle"][k].get<double>())));
      // Flat, or folded flat (the geometry cannot tell M from V there).
      if (std::abs(folds[k]) < 1e-9 || std::abs(folds[k]) > M_PI - 1e-9) continue;
      ++checked;
      if (a == 'M') CHECK(sign * folds[k] < 0);
      if (a == 'V') CHECK(sign * folds[k] > 0);
    }
    if (std::string(e.file) == "simple" || std::string(e.file) == "squaretwist" || std::string(e.file) == "box")
      CHECK(checked > 0);
    // Written back as FOLD (a path of one sample) and read again: the same sheet.
    const pipeline::Motion m = pipeline::track(s, 0);
    const std::string back = write(std::string(e.file) + "_back.fold", present::foldPath(s, m.path));
    const scenes::FoldSheet a = scenes::readFold(slurp(path), path), b = scenes::readFold(slurp(back), back);
    REQUIRE(a.vertices.size() == b.vertices.size());
    for (size_t i = 0; i < a.vertices.size(); ++i)
      for (int k = 0; k < 3; ++k) CHECK(b.vertices[i][static_cast<size_t>(k)] == a.vertices[i][static_cast<size_t>(k)]);
    CHECK(b.faces == a.faces);
    CHECK(b.edges == a.edges);
    CHECK(b.assignments == a.assignments);
  }
  // Hull's rigidly folded square twist: one degree of freedom (FOLD's example, "rigidly folded").
  const scenes::Scene twist = scenes::loadScene(kData + "squaretwist.fold");
  const engine::RigidityReport rep = pipeline::analyze(twist);
  CHECK(rep.nontrivial == 1);
  CHECK(rep.rigid == engine::Verdict::Flexible);
}

TEST_CASE("origami: a degree-4 vertex folds from flat on the branch its assignment picks (fold-angle multiplier)",
          "[origami]") {
  for (double deg : {45.0, 60.0, 75.0}) {
    const double g = deg * M_PI / 180;
    INFO(deg);
    // Mountains on three creases, a valley on the one at angle 0: the Miura branch, where the
    // creases at +-g fold alike and the straight pair (0, pi) opposite ways, with
    // tan(rho_g / 2) = tan(rho_0 / 2) / cos g (Lang and Howell's fold-angle multiplier). Then
    // all flipped; then F on the +-g creases: only the straight line folds.
    for (const std::string letters : {"VMMM", "MVVV", "MFMF"}) {
      INFO(letters);
      const std::string file = write("vertex.fold", degree4(g, letters));
      const scenes::Scene s = scenes::loadScene(file, {"motion.steps=60", "motion.step_size=0.02"});
      const pipeline::Motion m = pipeline::track(s, s.motion.steps);
      CHECK(m.path.summary.steps_done == 60);
      CHECK(m.path.flex_choice.find("mountain/valley") != std::string::npos);
      const engine::Origami& o = origamiOf(s);
      double worst = 0;
      for (size_t k = 1; k < m.path.samples.size(); ++k) {
        const std::vector<double> r = o.foldAngles(o.system().vertexPositions(m.path.samples[k]));
        for (size_t e = 0; e < 4; ++e) {
          if (letters[e] == 'M') CHECK(r[e] < 0);
          if (letters[e] == 'V') CHECK(r[e] > 0);
        }
        if (letters == "MFMF") {
          worst = std::max({worst, std::abs(r[1]), std::abs(r[3]), std::abs(r[0] - r[2])});
        } else {
          worst = std::max(worst, std::abs(std::tan(std::abs(r[1]) / 2) - std::tan(std::abs(r[0]) / 2) / std::cos(g)));
          worst = std::max({worst, std::abs(r[1] - r[3]), std::abs(r[0] + r[2])});
        }
      }
      CHECK(worst < 1e-9);
    }
  }
}

TEST_CASE("origami: the Miura-ori folds from flat as Schenk and Guest's closed form, and stops fully folded",
          "[origami]") {
  const double g = M_PI / 3;
  const int m = 4, n = 4;
  // The assignment: the signs of the fold angles of the sheet folded part way (theta = 45 deg).
  json folded = miuraFold(m, n, M_PI / 4, g);
  const scenes::Scene fs = scenes::loadScene(write("miura45.fold", folded.dump()));
  const engine::Origami& fo = origamiOf(fs);
  CHECK(pipeline::analyze(fs).nontrivial == 1);  // rigid origami Miura: one degree of freedom
  const std::vector<double> r45 = fo.foldAngles(fo.system().vertexPositions(fo.startCoordinates()));
  json flat = miuraFold(m, n, 0, g);
  json edges = json::array(), letters = json::array();
  for (size_t e = 0; e < fo.edges().size(); ++e) {
    const engine::Crease& c = fo.edges()[e];
    edges.push_back({c.a, c.b});
    letters.push_back(c.left < 0 || c.right < 0 ? "B" : r45[e] > 0 ? "V" : "M");
  }
  flat["edges_vertices"] = edges;
  flat["edges_assignment"] = letters;
  const scenes::Scene s = scenes::loadScene(write("miura_flat.fold", flat.dump()), {"motion.steps=400", "motion.step_size=0.05"});
  const pipeline::Motion path = pipeline::track(s, s.motion.steps);
  const engine::Origami& o = origamiOf(s);
  // It ends fully folded, before 400 steps, as a success that says why.
  CHECK(path.path.summary.status == engine::TrackStatus::Success);
  CHECK_THAT(path.path.summary.reason, Catch::Contains("fully folded"));
  CHECK(path.path.summary.steps_done < 400);
  const auto index = [n](int i, int j) { return i * (n + 1) + j; };
  double worst = 0, theta = 0;
  for (size_t k = 0; k < path.path.samples.size(); ++k) {
    const engine::Matrix p = o.system().vertexPositions(path.path.samples[k]);
    const auto dist = [&](int a, int b) { return (p.col(a) - p.col(b)).norm(); };
    // Rigid-motion invariants: |p(0,0) p(0,2)| = 2L, |p(0,0) p(2,0)| = 2S, |p(0,0) p(1,0)|^2 = S^2 + V^2.
    const double L = dist(index(0, 0), index(0, 2)) / 2;
    theta = std::asin(std::min(1.0, std::sqrt(std::max(0.0, 1 - L * L)) / std::sin(g)));
    const Miura cell = miuraCell(theta, g);
    worst = std::max(worst, std::abs(dist(index(0, 0), index(2, 0)) / 2 - cell.S));
    worst = std::max(worst, std::abs(dist(index(0, 0), index(1, 0)) - std::hypot(cell.S, cell.V)));
    worst = std::max(worst, std::abs(dist(index(2, 1), index(2, 3)) / 2 - cell.L));
    if (k > 0) {
      const std::vector<double> r = o.foldAngles(p);
      for (size_t e = 0; e < o.edges().size(); ++e) {
        if (o.edges()[e].assignment == 'M') CHECK(r[e] < 0);
        if (o.edges()[e].assignment == 'V') CHECK(r[e] > 0);
      }
    }
  }
  CHECK(worst < 1e-9);
  CHECK(theta * 180 / M_PI > 89);  // fully folded at the end
  // The samples are evenly spaced (the first one included).
  for (size_t k = 1; k < path.path.samples.size(); ++k)
    CHECK((path.path.samples[k] - path.path.samples[k - 1]).norm() == Approx(0.05).epsilon(0.25));
}

TEST_CASE("origami: outputs: fold angles per sample in JSON and CSV, the path as a multi-frame FOLD", "[origami]") {
  const std::string file = write("v60.fold", degree4(M_PI / 3, "VMMM"));
  const scenes::Scene s = scenes::loadScene(file, {"motion.steps=10", "motion.step_size=0.02"});
  const pipeline::Motion m = pipeline::track(s, s.motion.steps);
  const auto j = present::pathJson(s, m.path);
  REQUIRE(j["fold_angles"].size() == 11);
  CHECK(j["fold_angles"][10].size() == 8);
  CHECK(j["structure"]["assignments"] == "VMMMBBBB");
  CHECK(j["fold_angles"][10][0].get<double>() > 0);
  const std::string csv = present::pathCsv(s, m.path);
  // A FOLD file's scene counts from 0, as the file does.
  CHECK(s.index_base == 0);
  const std::string header = csv.substr(0, csv.find('\n'));
  CHECK(header.size() > 51);
  CHECK(header.substr(header.size() - 51) == ",z4,fold0,fold1,fold2,fold3,fold4,fold5,fold6,fold7");
  const json f = json::parse(present::foldPath(s, m.path));
  CHECK(f["file_frames"].size() == 10);
  CHECK(f["file_classes"] == json({"singleModel", "animation"}));
  CHECK(f["file_frames"][9]["frame_inherit"] == true);
  CHECK(f["file_frames"][9]["edges_foldAngle"][0].get<double>() == Approx(j["fold_angles"][10][0].get<double>()));
  // Frame 0 of the written file is the start: loading it gives the same sheet.
  const scenes::Scene again = scenes::loadScene(write("again.fold", f.dump()));
  CHECK(origamiOf(again).edges().size() == 8);
  // Other systems have no FOLD path.
  const scenes::Scene square = scenes::loadScene("square");
  CHECK_THROWS_AS(present::foldPath(square, pipeline::track(square, 2).path), present::OutputError);
}

TEST_CASE("origami: a broken FOLD file is refused at its array and index", "[origami]") {
  const auto error = [](const std::string& text) -> std::string {
    const std::string file = write("bad.fold", text);
    try {
      scenes::loadScene(file);
    } catch (const SceneError& e) {
      return e.what();
    }
    return "no error";
  };
  const std::string square = R"("vertices_coords": [[0,0],[1,0],[1,1],[0,1]])";
  CHECK_THAT(error("{" + square + R"(, "faces_vertices": [[0,1,2,3]], "edges_vertices": [[0,1],[1,2],[2,3],[3,0]], "edges_assignment": ["B","B","X","B"]})"),
             Catch::Contains("bad.fold:1:1: edges_assignment[2]: unknown assignment \"X\""));
  CHECK_THAT(error("{" + square + R"(, "faces_vertices": [[0,1,2,3]], "edges_vertices": [[0,1],[1,2],[2,3],[3,0]], "edges_assignment": ["B","B","C","B"]})"),
             Catch::Contains("edges_assignment[2]: C (a cut) is not supported"));
  CHECK_THAT(error("{" + square + R"(, "faces_vertices": [[0,1,2,3]], "edges_vertices": [[0,1],[1,2],[2,3],[3,0]], "edges_assignment": ["B","B","B"]})"),
             Catch::Contains("edges_assignment: has 3 entries for 4 edges"));
  CHECK_THAT(error("{" + square + R"(, "faces_vertices": [[0,1,2,7]]})"), Catch::Contains("faces_vertices[0][3]: vertex 7 does not exist"));
  CHECK_THAT(error(R"({"vertices_coords": [[0,0,0],[1,0,0],[1,1,0.3],[0,1,0]], "faces_vertices": [[0,1,2,3]]})"),
             Catch::Contains("faces_vertices[0]: the face is not planar"));
  CHECK_THAT(error("{" + square + R"(, "faces_vertices": [[0,1,2,3]], "edges_vertices": [[0,1],[1,2],[2,3]]})"),
             Catch::Contains("faces_vertices[0]: the face's side [3, 0] is no crease"));  // FOLD counts from 0
  CHECK_THAT(error("{" + square + R"(, "faces_vertices": [[0,1,2],[0,2,3],[0,3,2]]})"),
             Catch::Contains("faces_vertices[2]"));
  CHECK_THAT(error(R"({"faces_vertices": [[0,1,2]]})"), Catch::Contains("vertices_coords: missing"));
  CHECK_THAT(error("{" + square + R"(, "faces_vertices": [[0,1,2,3]], "edges_vertices": [[0,1],[1,2],[2,3],[3,0]], "edges_foldAngle": [0,0,200,0]})"),
             Catch::Contains("edges_foldAngle[2]: a fold angle is degrees in [-180, 180]"));
  CHECK_THAT(error("{" + square + R"(, "faces_vertices": [[0,1,2],[0,2,3]], "edges_vertices": [[0,1],[1,2],[2,3],[3,0],[0,2]], "edges_assignment": ["B","B","B","B","B"]})"),
             Catch::Contains("edges_vertices[4]: the edge [0, 2] is a boundary (B), but faces 1 and 0 meet there"));
  CHECK_THAT(error("{\"vertices_coords\": [[0,0],\n [1,0]]\n, }"), Catch::Contains("bad.fold:3:"));
  // A crease pattern without faces_vertices: its faces are traced from its edges.
  const scenes::Scene traced = scenes::loadScene(write("traced.fold", "{" + square + R"(, "edges_vertices": [[0,1],[1,2],[2,3],[3,0],[0,2]], "edges_assignment": ["B","B","B","B","V"]})"));
  CHECK(origamiOf(traced).faces().size() == 2);
  // The scene language: type = "origami" inline, and its errors at the key.
  try {
    scenes::loadSceneFromString("[system]\ntype = \"origami\"\nvertices = [[0,0],[1,0],[1,1]]\nfaces = [[1,2,3]]\n"
                                "creases = [[1,2],[2,3],[3,1]]\nassignments = \"BB\"\n", "t.toml");
    FAIL("no error");
  } catch (const SceneError& e) {
    CHECK_THAT(e.what(), Catch::Contains("t.toml:6:15: assignments has 2 letters for 3 creases"));
  }
}
