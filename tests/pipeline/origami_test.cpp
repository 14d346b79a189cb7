// Rigid origami from FOLD files: the specification's examples read and written back, a
// degree-4 vertex and the Miura-ori against their closed forms, folding from the flat state on
// the branch the mountain/valley assignment picks, and broken files.
#include <catch2/catch.hpp>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <nlohmann/json.hpp>
#include <string>

#include "engine/systems/origami.h"
#include "pipeline/pipeline.h"
#include "present/output_file.h"
#include "present/path_output.h"
#include "scenes/fold_file.h"
#include "scenes/scene.h"
#include "../scenes/scene_test_common.h"
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

// The flat m x n Miura-ori with the mountain/valley assignment of its Miura fold: the signs of
// the fold angles of the sheet folded part way (theta = 45 degrees).
json miuraFlat(int m, int n, double g) {
  const scenes::Scene fs = scenes::loadScene(write("miura45.fold", miuraFold(m, n, M_PI / 4, g).dump()));
  const engine::Origami& fo = origamiOf(fs);
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
  return flat;
}

// How far the Miura-ori sheet at p (n cells along j) is from Schenk and Guest's cell at the fold
// parameter theta its length L gives (set here): rigid-motion invariants, |p(0,0) p(0,2)| = 2L,
// |p(0,0) p(2,0)| = 2S, |p(0,0) p(1,0)|^2 = S^2 + V^2, |p(2,1) p(2,3)| = 2L.
double miuraDeviation(const engine::Matrix& p, int n, double g, double& theta) {
  const auto index = [n](int i, int j) { return i * (n + 1) + j; };
  const auto dist = [&](int a, int b) { return (p.col(a) - p.col(b)).norm(); };
  const double L = dist(index(0, 0), index(0, 2)) / 2;
  theta = std::asin(std::min(1.0, std::sqrt(std::max(0.0, 1 - L * L)) / std::sin(g)));
  const Miura cell = miuraCell(theta, g);
  return std::max({std::abs(dist(index(0, 0), index(2, 0)) / 2 - cell.S),
                   std::abs(dist(index(0, 0), index(1, 0)) - std::hypot(cell.S, cell.V)),
                   std::abs(dist(index(2, 1), index(2, 3)) / 2 - cell.L)});
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
  const int n = 4;
  // The assignment: the signs of the fold angles of the sheet folded part way (theta = 45 deg).
  const scenes::Scene fs = scenes::loadScene(write("miura45.fold", miuraFold(4, n, M_PI / 4, g).dump()));
  CHECK(pipeline::analyze(fs).nontrivial == 1);  // rigid origami Miura: one degree of freedom
  const scenes::Scene s = scenes::loadScene(write("miura_flat.fold", miuraFlat(4, n, g).dump()),
                                            {"motion.steps=400", "motion.step_size=0.05"});
  const pipeline::Motion path = pipeline::track(s, s.motion.steps);
  const engine::Origami& o = origamiOf(s);
  // It ends fully folded, before 400 steps, as a success that says why.
  CHECK(path.path.summary.status == engine::TrackStatus::Success);
  CHECK_THAT(path.path.summary.reason, Catch::Contains("fully folded"));
  CHECK(path.path.summary.steps_done < 400);
  double worst = 0, theta = 0;
  for (size_t k = 0; k < path.path.samples.size(); ++k) {
    const engine::Matrix p = o.system().vertexPositions(path.path.samples[k]);
    worst = std::max(worst, miuraDeviation(p, n, g, theta));
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

TEST_CASE("origami: the fold angle's gradient matches finite differences", "[origami]") {
  // The Miura-ori at theta = 45 degrees, moved off its constraints at random (seeded): the
  // gradient holds for any four points, not only rigid panels.
  const scenes::Scene s = scenes::loadScene(write("miura45g.fold", miuraFold(3, 3, M_PI / 4, M_PI / 3).dump()));
  const engine::Origami& o = origamiOf(s);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0, 0.05);
  engine::Vector x = o.startCoordinates();
  for (Eigen::Index i = 0; i < x.size(); ++i) x[i] += noise(rng);
  int checked = 0;
  for (size_t e = 0; e < o.edges().size(); ++e) {
    if (o.edges()[e].left < 0 || o.edges()[e].right < 0) continue;
    const int c = static_cast<int>(e);
    const engine::Vector g = o.foldAngleGradient(x, c);
    const double h = 1e-6;
    double worst = 0;
    for (Eigen::Index i = 0; i < x.size(); ++i) {
      engine::Vector xp = x, xm = x;
      xp[i] += h, xm[i] -= h;
      worst = std::max(worst, std::abs((o.foldAngle(xp, c) - o.foldAngle(xm, c)) / (2 * h) - g[i]));
    }
    CHECK(worst < 1e-7 * std::max(1.0, g.cwiseAbs().maxCoeff()));
    ++checked;
  }
  CHECK(checked == 12);
  // On the constraints, the four-point angle is the panels' fold angle.
  const std::vector<double> r = o.foldAngles(o.system().vertexPositions(o.startCoordinates()));
  for (size_t e = 0; e < o.edges().size(); ++e)
    if (o.edges()[e].left >= 0 && o.edges()[e].right >= 0) CHECK(o.foldAngle(o.startCoordinates(), static_cast<int>(e)) == Approx(r[e]).margin(1e-12));
}

TEST_CASE("origami: driving one crease, or the fold percentage, folds the Miura-ori as the closed form says",
          "[origami]") {
  const double g = M_PI / 3;
  const int n = 4;
  const std::string file = write("miura_drive.fold", miuraFlat(4, n, g).dump());
  const scenes::Scene flat = scenes::loadScene(file);
  const engine::Origami& fo = origamiOf(flat);
  // A mountain crease between two faces (FOLD counts from 0, as the scene does).
  int crease = -1;
  for (size_t e = 0; e < fo.edges().size() && crease < 0; ++e)
    if (fo.edges()[e].assignment == 'M') crease = static_cast<int>(e);
  REQUIRE(crease >= 0);
  const engine::Crease& c = fo.edges()[static_cast<size_t>(crease)];
  const std::string pair = "[" + std::to_string(c.a) + ", " + std::to_string(c.b) + "]";
  struct Drive {
    std::vector<std::string> keys;
    double target;  // the driven quantity's end: degrees of the crease, or the percentage
  };
  for (const Drive& d : {Drive{{"motion.fold_crease=" + pair, "motion.fold_angle=-150"}, -150},
                         Drive{{"motion.fold_percent=80"}, 80}}) {
    INFO(d.keys[0]);
    std::vector<std::string> keys = d.keys;
    keys.push_back("motion.steps=50");
    const scenes::Scene s = scenes::loadScene(file, keys);
    const pipeline::Motion m = pipeline::track(s, s.motion.steps);
    const engine::Origami& o = origamiOf(s);
    CHECK(m.path.summary.status == engine::TrackStatus::Success);
    CHECK_THAT(m.path.summary.reason, Catch::Contains("reached its target"));
    REQUIRE(m.path.samples.size() == 51);
    CHECK(m.path.summary.max_residual < 1e-10);
    double worst_drive = 0, worst_form = 0, theta = 0;
    for (size_t k = 0; k < m.path.samples.size(); ++k) {
      const engine::Matrix p = o.system().vertexPositions(m.path.samples[k]);
      const std::vector<double> r = o.foldAngles(p);
      // The driven quantity at its scheduled value: equal steps from 0.
      double value = r[static_cast<size_t>(crease)] * 180 / M_PI;
      if (d.keys.size() == 1) {
        double sum = 0, count = 0;
        for (size_t e = 0; e < o.edges().size(); ++e) {
          const char a = o.edges()[e].assignment;
          if (a == 'M' || a == 'V') sum += (a == 'V' ? 1 : -1) * r[e], ++count;
        }
        value = 100 * sum / (M_PI * count);
      }
      worst_drive = std::max(worst_drive, std::abs(value - d.target * static_cast<double>(k) / 50));
      worst_form = std::max(worst_form, miuraDeviation(p, n, g, theta));
      for (size_t e = 0; e < o.edges().size(); ++e) {
        if (k > 0 && o.edges()[e].assignment == 'M') CHECK(r[e] < 0);
        if (k > 0 && o.edges()[e].assignment == 'V') CHECK(r[e] > 0);
      }
    }
    CHECK(worst_drive < 1e-9);
    CHECK(worst_form < 1e-9);
    CHECK(theta > 0.3);  // folded well away from flat
  }
  // Bad driving is refused at its key.
  const auto error = [&](const std::vector<std::string>& keys) -> std::string {
    try {
      scenes::loadScene(file, keys);
    } catch (const SceneError& e) {
      return e.what();
    }
    return "no error";
  };
  CHECK_THAT(error({"motion.fold_crease=[0, 1]", "motion.fold_angle=90"}), Catch::Contains("[0, 1] is on the sheet's boundary"));
  CHECK_THAT(error({"motion.fold_crease=[0, 7]", "motion.fold_angle=90"}), Catch::Contains("[0, 7] is not an edge of the sheet"));
  CHECK_THAT(error({"motion.fold_crease=" + pair}), Catch::Contains("fold_crease needs fold_angle"));
  CHECK_THAT(error({"motion.fold_crease=" + pair, "motion.fold_angle=200"}), Catch::Contains("fold_angle is degrees in [-180, 180]"));
  CHECK_THAT(error({"motion.fold_percent=120"}), Catch::Contains("fold_percent is a percentage of the full fold, in [0, 100]"));
  CHECK_THAT(error({"motion.fold_percent=50", "motion.fold_angle=20"}), Catch::Contains("not both"));
  CHECK_THAT(error({"motion.fold_percent=50", "motion.flex=[1]"}), Catch::Contains("flex does not apply to a driven fold"));
  try {
    scenes::loadScene("square", {"motion.fold_percent=50"});
    FAIL("no error");
  } catch (const SceneError& e) {
    CHECK_THAT(e.what(), Catch::Contains("fold driving applies to origami; this system is a framework"));
  }
}

TEST_CASE("origami: a square creased along its diagonals and midlines folds with 5 degrees of freedom, "
          "symmetrically as its closed form says", "[origami]") {
  // A degree-8 vertex (sector angles 45 degrees), midlines mountain, diagonals valley. Driven
  // toward a fold percentage from flat, it folds in its symmetric mode: the diagonals alike
  // (rho_d), the midlines alike (rho_m), the creases on a cone of alternating heights. With the
  // spherical law of cosines at each crease, |rho_d| = 2 beta and |rho_m| = 2 alpha for the
  // elevations alpha (diagonals) and beta (midlines), and the 45 degree sector between a midline
  // and a diagonal gives cos(alpha) cos(beta) + sqrt(2) sin(alpha) sin(beta) = 1.
  const std::string file = write("square_base.toml",
      "[system]\ntype = \"origami\"\n"
      "vertices = [[0, 0], [1, 0], [1, 1], [0, 1], [-1, 1], [-1, 0], [-1, -1], [0, -1], [1, -1]]\n"
      "faces = [[1, 2, 3], [1, 3, 4], [1, 4, 5], [1, 5, 6], [1, 6, 7], [1, 7, 8], [1, 8, 9], [1, 9, 2]]\n"
      "creases = [[1, 2], [1, 3], [1, 4], [1, 5], [1, 6], [1, 7], [1, 8], [1, 9], [2, 3], [3, 4], [4, 5], [5, 6], "
      "[6, 7], [7, 8], [8, 9], [9, 2]]\n"
      "assignments = \"MVMVMVMVBBBBBBBB\"\n\n[motion]\nsteps = 60\nfold_percent = 60\n");
  const scenes::Scene s = scenes::loadScene(file);
  const pipeline::Motion m = pipeline::track(s, s.motion.steps);
  const engine::Origami& o = origamiOf(s);
  REQUIRE(m.path.samples.size() == 61);
  double worst_symmetry = 0, worst_form = 0;
  for (size_t k = 1; k < m.path.samples.size(); ++k) {
    const std::vector<double> r = o.foldAngles(o.system().vertexPositions(m.path.samples[k]));
    for (size_t e = 2; e < 8; ++e) worst_symmetry = std::max(worst_symmetry, std::abs(r[e] - r[e - 2]));
    CHECK(r[0] < 0);
    CHECK(r[1] > 0);
    const double alpha = std::abs(r[0]) / 2, beta = std::abs(r[1]) / 2;
    worst_form = std::max(worst_form, std::abs(std::cos(alpha) * std::cos(beta) + std::sqrt(2.0) * std::sin(alpha) * std::sin(beta) - 1));
  }
  CHECK(worst_symmetry < 1e-9);
  CHECK(worst_form < 1e-9);
  // Folded, the vertex has 8 - 3 = 5 degrees of freedom (more than the Miura-ori's one).
  const engine::RigidityReport folded = engine::analyzeRigidity(*s.model, m.path.samples[30], scenes::rigidityOptions(s));
  CHECK(folded.nontrivial == 5);
}

TEST_CASE("origami: an event names the faces that pass through each other, and one crease folds alone where it can",
          "[origami]") {
  // A strip of three unit squares with two valley creases, folded alike (the fold percentage):
  // the outer squares' free sides meet when both creases reach 120 degrees, and they pass
  // through each other after.
  const std::string file = write("strip.toml",
      "[system]\ntype = \"origami\"\n"
      "vertices = [[0, 0], [1, 0], [2, 0], [3, 0], [0, 1], [1, 1], [2, 1], [3, 1]]\n"
      "faces = [[1, 2, 6, 5], [2, 3, 7, 6], [3, 4, 8, 7]]\n"
      "creases = [[1, 2], [2, 3], [3, 4], [5, 6], [6, 7], [7, 8], [1, 5], [4, 8], [2, 6], [3, 7]]\n"
      "assignments = \"BBBBBBBBVV\"\n");
  const scenes::Scene s = scenes::loadScene(file, {"motion.steps=90", "motion.fold_percent=90"});
  const pipeline::Motion m = pipeline::track(s, s.motion.steps);
  const engine::Origami& o = origamiOf(s);
  int first = -1;
  for (size_t k = 0; k < m.path.samples.size() && first < 0; ++k)
    if (o.foldAngles(o.system().vertexPositions(m.path.samples[k]))[8] > 2 * M_PI / 3 + 1e-9) first = static_cast<int>(k);
  REQUIRE(first > 0);
  REQUIRE(m.path.events.size() == 1);
  const engine::TrackEvent& e = m.path.events[0];
  CHECK(e.kind == engine::EventKind::Intersection);
  CHECK(e.sample == first);
  CHECK(e.faces == std::vector<int>{0, 2});
  CHECK(e.detail == "faces 1 and 3 pass through each other");
  // Layers on each other do not count: the sheet folded flat (both creases at 180 degrees)
  // crosses nothing.
  engine::Matrix folded(3, 8);
  folded << 1, 1, 2, 2, 1, 1, 2, 2,  //
      0, 0, 0, 0, 1, 1, 1, 1,        //
      0, 0, 0, 0, 0, 0, 0, 0;
  CHECK(o.crossingFaces(folded).empty());
  // Folding one crease: the other needs not move, and stays flat exactly (two degrees of
  // freedom); the first square turns to the angle asked, in equal steps.
  const scenes::Scene one = scenes::loadScene(file, {"motion.steps=9", "motion.fold_crease=[2, 6]", "motion.fold_angle=90"});
  const pipeline::Motion folded_one = pipeline::track(one, one.motion.steps);
  REQUIRE(folded_one.path.samples.size() == 10);
  for (size_t k = 0; k < 10; ++k) {
    const std::vector<double> r = o.foldAngles(o.system().vertexPositions(folded_one.path.samples[k]));
    CHECK(r[8] * 180 / M_PI == Approx(10.0 * static_cast<double>(k)).margin(1e-9));
    CHECK(std::abs(r[9]) < 1e-12);
  }
  // The path JSON names the faces, and reads back with its event.
  const auto j = present::pathJson(s, m.path);
  bool named = false;
  for (const auto& ev : j["events"]) named = named || (ev["kind"] == "intersection" && ev["faces"] == nlohmann::ordered_json({1, 3}));
  CHECK(named);
  const std::string saved = write("strip_path.json", j.dump());
  const scenes::Scene again = scenes::loadScene(saved);
  REQUIRE(again.given);
  REQUIRE(again.given->path.events.size() == 1);
  CHECK(again.given->path.events[0].faces == std::vector<int>{0, 2});
}

TEST_CASE("origami: a frame of a multi-frame FOLD file is read, with what it inherits", "[origami]") {
  // The Miura-ori's path written as FOLD, read at frame 12: the 12th sample's sheet.
  const scenes::Scene s = scenes::loadScene(write("miura_frames.fold", miuraFlat(2, 2, M_PI / 3).dump()),
                                            {"motion.steps=20", "motion.step_size=0.05"});
  const pipeline::Motion m = pipeline::track(s, s.motion.steps);
  const std::string path = write("miura_path.fold", present::foldPath(s, m.path));
  const scenes::Scene at12 = scenes::loadScene(path, {"system.frame=12"});
  const engine::Origami& o = origamiOf(at12);
  CHECK(o.faces().size() == 4);  // faces and edges inherited from frame 0
  CHECK((o.system().vertexPositions(o.startCoordinates()) - origamiOf(s).system().vertexPositions(m.path.samples[12])).cwiseAbs().maxCoeff() < 1e-12);
  CHECK(pipeline::analyze(at12).nontrivial == 1);  // folded: the Miura-ori's one degree of freedom
  try {
    scenes::loadScene(path, {"system.frame=21"});
    FAIL("no error");
  } catch (const SceneError& e) {
    CHECK_THAT(e.what(), Catch::Contains("file_frames: frame 21 does not exist: the file has frames 0..20"));
  }
  // A frame that does not inherit stands alone: without vertices it is refused, named.
  const std::string bare = write("bare.fold", R"({"vertices_coords": [[0,0],[1,0],[0,1]], "faces_vertices": [[0,1,2]],
    "file_frames": [{"frame_inherit": false, "faces_vertices": [[0,1,2]]}]})");
  try {
    scenes::loadScene(bare, {"system.frame=1"});
    FAIL("no error");
  } catch (const SceneError& e) {
    CHECK_THAT(e.what(), Catch::Contains("frame 1: vertices_coords: missing"));
  }
}

// Found by the valid-scene fuzzer (issue 41): driving the one hinge of a strip of two panels
// crashed (an SVD of the empty matrix of the other creases' fold rates).
TEST_CASE("origami: a strip of two panels is driven by its one crease", "[pipeline][origami]") {
  const scenes::Scene s = scenes::loadSceneFromString(
      "[system]\ntype = \"origami\"\nvertices = [[0,0],[1,0],[2,0],[0,1],[1,1],[2,1]]\n"
      "faces = [[1,2,5,4],[2,3,6,5]]\ncreases = [[1,2],[2,3],[1,4],[2,5],[3,6],[4,5],[5,6]]\n"
      "assignments = \"BBBVBBB\"\n[motion]\nsteps = 10\nfold_crease = [2, 5]\nfold_angle = 60\n",
      "strip.toml");
  const pipeline::Motion m = pipeline::track(s, 10);
  REQUIRE(m.path.summary.status == engine::TrackStatus::Success);
  const auto& o = dynamic_cast<const engine::Origami&>(*s.model);
  CHECK(o.foldAngle(m.path.samples.back(), 3) * 180 / M_PI == Approx(60).margin(1e-6));
  CHECK(m.path.summary.max_residual < 1e-12);
}

// Found by the valid-scene fuzzer (issue 41): contracting a crease or a panel's diagonal
// deformed the rigid panels, and every panel whose rigidity shares that distance (a strip of
// four panels shrank as a whole, at residual 1e-13). A panel's or a body's distance is refused
// at contract_edge; a bar between bodies contracts.
TEST_CASE("origami and bodies: contracting a distance inside a rigid panel or body is refused", "[pipeline][origami]") {
  const std::string sheet =
      "[system]\ntype = \"origami\"\nvertices = [[0,0],[1,0],[2,0],[0,1],[1,1],[2,1]]\n"
      "faces = [[1,2,5,4],[2,3,6,5]]\ncreases = [[1,2],[2,3],[1,4],[2,5],[3,6],[4,5],[5,6]]\n"
      "assignments = \"BBBVBBB\"\n[motion]\ntarget_length = 0.8\n";
  for (const char* edge : {"[2, 5]", "[1, 5]"}) {
    INFO(edge);
    test::requireSceneError(sheet + "contract_edge = " + edge + "\n", 9, 17, "lies in a panel, which is rigid");
  }
  const std::string bodies = "[system]\ntype = \"body_bar\"\nvertices = [[0,0],[1,0],[0,1],[3,0],[4,0],[3,1]]\n"
                             "bodies = [[1,2,3],[4,5,6]]\nbars = [[2,4],[3,6]]\n[motion]\ntarget_length = 1.5\n";
  test::requireSceneError(bodies + "contract_edge = [1, 2]\n", 8, 17, "lies in body 1, which is rigid");
  const scenes::Scene bar = scenes::loadSceneFromString(bodies + "contract_edge = [2, 4]\n", "b.toml");
  const pipeline::Motion m = pipeline::track(bar, 1000);
  CHECK(m.path.summary.status == engine::TrackStatus::Success);
  const auto& sys = bar.model->system();
  const engine::Matrix end = sys.vertexPositions(m.path.samples.back());
  CHECK((end.col(1) - end.col(3)).norm() == Approx(1.5).margin(1e-9));
  CHECK((end.col(0) - end.col(1)).norm() == Approx(1.0).margin(1e-9));  // the bodies stay rigid
  CHECK((end.col(3) - end.col(5)).norm() == Approx(1.0).margin(1e-9));
}

// Found by the valid-scene fuzzer (issue 41): a pinned strip of four panels whose drive leaves
// no freedom (the driven crease and the held ones fix every panel) crashed: an SVD of a matrix
// without rows.
TEST_CASE("origami: a drive that leaves no freedom folds its crease", "[pipeline][origami]") {
  const scenes::Scene s = scenes::loadSceneFromString(
      "[system]\ntype = \"origami\"\nvertices = [[0.0, 0.0], [0.539, 0.0], [1.688, 0.0], [2.24, 0.0], [3.021, 0.0], "
      "[0.0, 1.07], [0.539, 1.07], [1.688, 1.07], [2.24, 1.07], [3.021, 1.07]]\n"
      "faces = [[1, 2, 7, 6], [2, 3, 8, 7], [3, 4, 9, 8], [4, 5, 10, 9]]\n"
      "creases = [[1, 2], [1, 6], [2, 3], [2, 7], [3, 4], [3, 8], [4, 5], [4, 9], [5, 10], [6, 7], [7, 8], [8, 9], [9, 10]]\n"
      "assignments = \"BBBVBUBMBBBBB\"\npinned = [1, 2, 6]\n"
      "[motion]\nsteps = 30\nstep_size = 0.0222\nfold_crease = [2, 7]\nfold_angle = 60.7\n",
      "strip4.toml");
  const pipeline::Motion m = pipeline::track(s, 30);
  REQUIRE(m.path.summary.status == engine::TrackStatus::Success);
  const auto& o = dynamic_cast<const engine::Origami&>(*s.model);
  CHECK(o.foldAngle(m.path.samples.back(), 3) * 180 / M_PI == Approx(60.7).margin(1e-6));
  CHECK(m.path.summary.max_residual < 1e-12);
}

TEST_CASE("origami: a certified track of the Miura vertex, and a Miura sheet refused with its reason",
          "[origami][certify]") {
  const double g = M_PI / 3;
  // One Miura vertex (2 x 2 parallelograms) folded part way (theta = 45 degrees): a regular
  // point, one degree of freedom; every sample and step of its fold certified (Krawczyk).
  const scenes::Scene folded = scenes::loadScene(write("miura_vertex45.fold", miuraFold(2, 2, M_PI / 4, g).dump()),
                                                 {"motion.steps=40", "motion.step_size=0.02", "motion.certify=true"});
  const pipeline::Motion m = pipeline::track(folded, folded.motion.steps);
  REQUIRE(m.path.certificate);
  INFO(m.path.certificate->reason);
  CHECK(m.path.summary.steps_done == 40);
  CHECK(m.path.certificate->certified());
  CHECK(m.path.certificate->flexible == true);
  // From the flat state: the start is singular (the sheet can fold either way there: a stress),
  // and says so; the fold beyond it is certified but for the steps next to the flat state.
  const scenes::Scene flat = scenes::loadScene(write("miura_vertex_flat.fold", miuraFlat(2, 2, g).dump()),
                                               {"motion.steps=60", "motion.step_size=0.05", "motion.certify=true"});
  const pipeline::Motion f = pipeline::track(flat, flat.motion.steps);
  REQUIRE(f.path.certificate);
  const engine::PathCertificate& c = *f.path.certificate;
  INFO(c.reason);
  CHECK(std::isnan(c.radii[0]));
  CHECK_THAT(c.reason, Catch::Contains("sample 0: 1 redundant constraint"));
  for (size_t k = 1; k < c.radii.size(); ++k) CHECK_FALSE(std::isnan(c.radii[k]));
  for (size_t k = 6; k < c.steps.size(); ++k) CHECK(c.steps[k]);
  // The 4 x 4 sheet: four constraints are redundant all along its fold (the stresses of a
  // Miura sheet), and the certificate says that their dependence is not proved.
  const scenes::Scene sheet = scenes::loadScene(write("miura_flat44.fold", miuraFlat(4, 4, g).dump()),
                                                {"motion.steps=5", "motion.step_size=0.05", "motion.certify=true"});
  const pipeline::Motion ms = pipeline::track(sheet, sheet.motion.steps);
  REQUIRE(ms.path.certificate);
  CHECK_FALSE(ms.path.certificate->certified());
  CHECK_THAT(ms.path.certificate->reason, Catch::Contains("redundant constraint(s) (stresses)"));
  CHECK_THAT(ms.path.certificate->reason, Catch::Contains("dependence is not proved"));
}
