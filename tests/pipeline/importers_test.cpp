// The file formats users have: graph6/sparse6 graphs and OFF/OBJ/STL meshes, read directly and
// through [system] from = "FILE", with known counts and broken files.
#include <catch2/catch.hpp>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "pipeline/pipeline.h"
#include "scenes/importers.h"
#include "scenes/scene.h"
#include "../test_common.h"

using namespace flexure;
using scenes::SceneError;

namespace {

std::filesystem::path tempDir() {
  static const std::filesystem::path d = test::scratchFolder("flexure-import");
  return d;
}

std::string write(const std::string& name, const std::string& text) { return test::writeScratch(tempDir(), name, text); }

// The error a call throws, or an empty one.
template <typename F>
SceneError errorOf(F f) {
  try {
    f();
  } catch (const SceneError& e) {
    return e;
  }
  return SceneError("", 0, 0, "no error");
}

const char* kCubeOff = R"(OFF
# a unit cube
8 6 12
0 0 0
1 0 0
1 1 0
0 1 0
0 0 1
1 0 1
1 1 1
0 1 1
4 0 3 2 1
4 4 5 6 7
4 0 1 5 4
4 1 2 6 5
4 2 3 7 6
4 3 0 4 7
)";

// An ASCII STL of triangles given by corner points.
std::string stl(const std::vector<std::array<std::array<double, 3>, 3>>& tris) {
  std::string s = "solid test\n";
  for (const auto& t : tris) {
    s += "  facet normal 0 0 0\n    outer loop\n";
    for (const auto& p : t)
      s += "      vertex " + std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(p[2]) + "\n";
    s += "    endloop\n  endfacet\n";
  }
  return s + "endsolid test\n";
}

}  // namespace

TEST_CASE("importers: graph6 and sparse6 of K4, the Petersen graph and McKay's example", "[scenes]") {
  const auto k4 = scenes::readGraph6("C~\n", "k4.g6");
  REQUIRE(k4.size() == 1);
  CHECK(k4[0].vertices == 4);
  CHECK(k4[0].edges.size() == 6);
  const auto both = scenes::readGraph6(">>graph6<<IheA@GUAo\n:I`ES@obGkqegW~\n", "p.g6");
  REQUIRE(both.size() == 2);
  for (const auto& g : both) {
    CHECK(g.vertices == 10);
    CHECK(g.edges.size() == 15);
    std::vector<int> degree(10, 0);
    for (const auto& e : g.edges) ++degree[e[0]], ++degree[e[1]];
    for (int d : degree) CHECK(d == 3);  // cubic
  }
  CHECK(std::set<std::array<int, 2>>(both[0].edges.begin(), both[0].edges.end()) ==
        std::set<std::array<int, 2>>(both[1].edges.begin(), both[1].edges.end()));
  // The sparse6 example of "Description of graph6, sparse6 and digraph6 encodings".
  const auto ex = scenes::readGraph6(":Fa@x^", "x.s6");
  CHECK(ex[0].vertices == 7);
  CHECK(ex[0].edges == std::vector<std::array<int, 2>>{{0, 1}, {0, 2}, {1, 2}, {5, 6}});
}

TEST_CASE("importers: broken graph6 files name the line and column", "[scenes]") {
  SceneError e = errorOf([] { scenes::readGraph6("C~\nC~~\n", "b.g6"); });
  CHECK(e.file == "b.g6");
  CHECK(e.line == 2);
  CHECK(e.message.find("bytes of edges") != std::string::npos);
  e = errorOf([] { scenes::readGraph6("C~\nC \n", "b.g6"); });
  CHECK((e.line == 2 && e.column == 2));
  e = errorOf([] { scenes::readGraph6("", "b.g6"); });
  CHECK(e.message == "the file holds no graph");
  e = errorOf([] { scenes::readGraph6("&C~\n", "b.g6"); });
  CHECK(e.message.find("digraph6") != std::string::npos);
}

TEST_CASE("importers: a graph6 graph as a framework, realized at random from the seed", "[scenes]") {
  const std::string k33 = write("k33.g6", "EFz_\n");
  // K_{3,3}: 2n - 3 = 9 bars, a Laman graph: generically rigid in the plane.
  const scenes::Scene s = scenes::loadScene(k33);
  CHECK(s.type == "framework");
  CHECK(s.title == "k33.g6");
  const engine::RigidityReport r = pipeline::analyze(s);
  CHECK(r.nontrivial == 0);
  CHECK(r.stresses == 0);
  // In 3D: 18 - 6 = 12 > 9: three nontrivial flexes.
  const scenes::Scene s3 = scenes::loadScene(k33, {"system.dimension=3"});
  CHECK(s3.model->system().dimension() == 3);
  CHECK(pipeline::analyze(s3).nontrivial == 3);
  // The same seed, the same realization; another seed, another.
  const auto start = [](const scenes::Scene& x) { return x.model->startCoordinates(); };
  CHECK(start(scenes::loadScene(k33)) == start(s));
  CHECK(start(scenes::loadScene(k33, {"system.seed=2"})) != start(s));
  // Petersen in the plane: 20 - 3 - 15 = 2 nontrivial flexes, no stress.
  const std::string pet = write("petersen.s6", ":I`ES@obGkqegW~\n");
  const engine::RigidityReport rp = pipeline::analyze(scenes::loadScene(pet));
  CHECK(rp.nontrivial == 2);
  CHECK(rp.stresses == 0);
  // From a scene, relative to its folder, with the second graph of a stream and pins.
  write("two.g6", "C~\nEFz_\n");
  const std::string scene = write("from.toml", "[system]\nfrom = \"two.g6\"\ngraph = 2\npinned = [1]\n");
  const scenes::Scene f = scenes::loadScene(scene);
  CHECK(f.model->system().numVertices() == 6);
  CHECK(f.model->system().isPinned(0));
  SceneError e = errorOf([&] { scenes::loadScene(write("g3.toml", "[system]\nfrom = \"two.g6\"\ngraph = 3\n")); });
  CHECK(e.message.find("holds 2 graph(s)") != std::string::npos);
  CHECK(e.line == 3);
  e = errorOf([&] { scenes::loadScene(write("gv.toml", "[system]\nfrom = \"two.g6\"\nvertices = [[0, 0]]\n")); });
  CHECK(e.message.find("unknown key 'vertices'") != std::string::npos);
  e = errorOf([&] { scenes::loadScene(write("gm.toml", "[system]\nfrom = \"missing.g6\"\n")); });
  CHECK((e.line == 2 && e.message.find("cannot read") != std::string::npos));
}

TEST_CASE("importers: an OFF cube is the cube of the catalog", "[scenes]") {
  const scenes::Scene off = scenes::loadScene(write("cube.off", kCubeOff));
  CHECK(off.type == "polytope");
  const scenes::Scene cat = scenes::loadScene("cube");
  const engine::RigidityReport a = pipeline::analyze(off), b = pipeline::analyze(cat);
  CHECK(a.rank == b.rank);
  CHECK(a.nontrivial == b.nontrivial);
  CHECK(a.stresses == b.stresses);
  // Broken: a face vertex out of range, a short file.
  std::string bad = kCubeOff;
  bad.replace(bad.find("4 4 5 6 7"), 9, "4 4 5 6 9");
  SceneError e = errorOf([&] { scenes::readOff(bad, "bad.off"); });
  CHECK((e.line == 13 && e.column == 9));
  CHECK(e.message.find("out of range 0..7") != std::string::npos);
  e = errorOf([] { scenes::readOff("OFF\n8 6 12\n0 0 0\n", "short.off"); });
  CHECK(e.message.find("ends after 1 vertices") != std::string::npos);
  e = errorOf([] { scenes::readOff("PLY\n", "x.off"); });
  CHECK((e.line == 1 && e.column == 1));
}

TEST_CASE("importers: OBJ faces in every index form", "[scenes]") {
  const std::string obj =
      "# cube\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nvn 0 0 1\n"
      "f 1 4 3 2\nf 5/1 6/1 7/1 8/1\nf 1//1 2//1 6//1 5//1\nf 2/1/1 3/1/1 7/1/1 6/1/1\nf -6 -5 -1 -2\nf 4 1 5 8\n";
  const scenes::ImportedMesh m = scenes::readObj(obj, "c.obj");
  CHECK(m.vertices.size() == 8);
  REQUIRE(m.faces.size() == 6);
  CHECK(m.faces[4] == std::vector<int>{2, 3, 7, 6});
  const scenes::Scene s = scenes::loadScene(write("cube.obj", obj));
  CHECK(pipeline::analyze(s).nontrivial == pipeline::analyze(scenes::loadScene("cube")).nontrivial);
  const SceneError e = errorOf([] { scenes::readObj("v 0 0 0\nf 1 2 3\n", "x.obj"); });
  CHECK((e.line == 2 && e.column == 5));
}

TEST_CASE("importers: STL triangles welded and merged into planar facets", "[scenes]") {
  // The icosahedron (0, +-1, +-phi): its 20 triangles stay 20 facets.
  const double phi = (1 + std::sqrt(5.0)) / 2;
  std::vector<std::array<double, 3>> v;
  for (double a : {-1.0, 1.0})
    for (double b : {-phi, phi}) v.push_back({0, a, b}), v.push_back({a, b, 0}), v.push_back({b, 0, a});
  std::vector<std::array<std::array<double, 3>, 3>> tris;
  auto dist = [](const std::array<double, 3>& p, const std::array<double, 3>& q) {
    return std::hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]);
  };
  for (size_t i = 0; i < v.size(); ++i)
    for (size_t j = i + 1; j < v.size(); ++j)
      for (size_t k = j + 1; k < v.size(); ++k)
        if (std::abs(dist(v[i], v[j]) - 2) < 1e-9 && std::abs(dist(v[j], v[k]) - 2) < 1e-9 &&
            std::abs(dist(v[i], v[k]) - 2) < 1e-9) {
          std::array<std::array<double, 3>, 3> t{v[i], v[j], v[k]};
          // outward: (b - a) x (c - a) along the centroid
          const double ux = t[1][0] - t[0][0], uy = t[1][1] - t[0][1], uz = t[1][2] - t[0][2];
          const double wx = t[2][0] - t[0][0], wy = t[2][1] - t[0][1], wz = t[2][2] - t[0][2];
          const double nx = uy * wz - uz * wy, ny = uz * wx - ux * wz, nz = ux * wy - uy * wx;
          if (nx * (t[0][0] + t[1][0] + t[2][0]) + ny * (t[0][1] + t[1][1] + t[2][1]) + nz * (t[0][2] + t[1][2] + t[2][2]) < 0)
            std::swap(t[1], t[2]);
          tris.push_back(t);
        }
  REQUIRE(tris.size() == 20);
  const scenes::ImportedMesh ico = scenes::readStl(stl(tris), "ico.stl");
  CHECK(ico.vertices.size() == 12);
  CHECK(ico.faces.size() == 20);
  const engine::RigidityReport r = pipeline::analyze(scenes::loadScene(write("ico.stl", stl(tris))));
  CHECK(r.nontrivial == 0);  // Cauchy-Dehn: a convex triangulated polyhedron is infinitesimally rigid

  // A cube of 12 triangles: merged into 6 squares, the catalog's cube.
  const std::array<double, 3> c[8] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  const int quads[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  std::vector<std::array<std::array<double, 3>, 3>> cube;
  for (const auto& q : quads) {
    cube.push_back({c[q[0]], c[q[1]], c[q[2]]});
    cube.push_back({c[q[0]], c[q[2]], c[q[3]]});
  }
  const std::string text = stl(cube);
  const scenes::ImportedMesh m = scenes::readStl(text, "cube.stl");
  CHECK(m.vertices.size() == 8);
  REQUIRE(m.faces.size() == 6);
  for (const auto& f : m.faces) CHECK(f.size() == 4);
  // Binary STL of the same triangles.
  std::string bin(80, ' ');
  const std::uint32_t n = static_cast<std::uint32_t>(cube.size());
  bin.append(reinterpret_cast<const char*>(&n), 4);
  for (const auto& t : cube) {
    bin.append(12, '\0');
    for (const auto& p : t)
      for (double x : p) {
        const float f = static_cast<float>(x);
        bin.append(reinterpret_cast<const char*>(&f), 4);
      }
    bin.append(2, '\0');
  }
  const scenes::ImportedMesh mb = scenes::readStl(bin, "cube.stl");
  CHECK(mb.faces.size() == 6);
  const scenes::Scene s = scenes::loadScene(write("cube.stl", bin));
  CHECK(pipeline::analyze(s).nontrivial == pipeline::analyze(scenes::loadScene("cube")).nontrivial);
  // Broken: a cube with a missing triangle is not closed.
  cube.pop_back();
  const SceneError e = errorOf([&] { scenes::readStl(stl(cube), "open.stl"); });
  CHECK(e.message.find("open boundary") != std::string::npos);
  CHECK(e.line > 1);
}

TEST_CASE("importers: edge lists (networkx's write_edgelist) and what they refuse", "[scenes]") {
  // K_{3,3} with integer labels, a weight column and comments: numbered by value.
  const auto g = scenes::readEdgeList("# K33\n0 3 {'weight': 1}\n0 4\n0,5\n1 3\n1 4\n1 5\n2 3\n2 4\n\n2 5  # last\n", "k.edges");
  CHECK(g.vertices == 6);
  REQUIRE(g.edges.size() == 9);
  CHECK(g.edges[0] == std::array<int, 2>{0, 3});
  CHECK(g.edges[2] == std::array<int, 2>{0, 5});
  // Labels that are not all integers: the order of first appearance.
  const auto w = scenes::readEdgeList("b a\na c\n10 b\n", "w.edgelist");
  CHECK(w.vertices == 4);
  CHECK(w.edges == std::vector<std::array<int, 2>>{{0, 1}, {1, 2}, {0, 3}});
  // Integer labels by value, not as text: 10 after 9.
  const auto n = scenes::readEdgeList("10 9\n9 1\n", "n.edges");
  CHECK(n.edges == std::vector<std::array<int, 2>>{{1, 2}, {0, 1}});
  SceneError e = errorOf([] { scenes::readEdgeList("1 2\n3\n", "b.edges"); });
  CHECK(e.line == 2);
  CHECK(e.message == "an edge needs two vertices, this line names one");
  e = errorOf([] { scenes::readEdgeList("1 2\n  2 1\n", "b.edges"); });
  CHECK((e.line == 2 && e.column == 3));
  CHECK(e.message == "edge 2-1 is given twice");
  e = errorOf([] { scenes::readEdgeList("1 1\n", "b.edges"); });
  CHECK(e.message == "edge 1-1 joins a vertex to itself");
  e = errorOf([] { scenes::readEdgeList("# nothing\n", "b.edges"); });
  CHECK_THAT(e.message, Catch::Contains("names no edge"));
  // Through [system] from, like any graph: K33 generically rigid in the plane.
  const std::string file = write("k33.edges", "0 3\n0 4\n0 5\n1 3\n1 4\n1 5\n2 3\n2 4\n2 5\n");
  const scenes::Scene s = scenes::loadScene(file);
  CHECK(s.model->system().numVertices() == 6);
  CHECK(pipeline::analyze(s).inf_rigid);
  const std::string scene = write("k33.toml", "[system]\nfrom = \"k33.edges\"\ngraph = 2\n");
  CHECK_THAT(errorOf([&] { scenes::loadScene(scene); }).message, Catch::Contains("unknown key 'graph'"));
}

TEST_CASE("importers: networkx's node-link JSON, with or without positions", "[scenes]") {
  // The 4-cycle with positions: a square, flexible; the positions are its realization.
  const std::string square = R"({"directed": false, "multigraph": false, "graph": {},
    "nodes": [{"id": "a", "pos": [0, 0]}, {"id": "b", "pos": [1, 0]}, {"id": "c", "pos": [1, 1]}, {"id": "d", "pos": [0, 1]}],
    "links": [{"source": "a", "target": "b"}, {"source": "b", "target": "c"}, {"source": "c", "target": "d"},
              {"source": "d", "target": "a"}]})";
  const auto g = scenes::readNodeLink(square, "sq.json");
  CHECK(g.vertices == 4);
  CHECK(g.edges.size() == 4);
  REQUIRE(g.positions.size() == 4);
  CHECK(g.positions[2] == std::vector<double>{1, 1});
  const scenes::Scene s = scenes::loadScene(write("sq.json", square));
  CHECK(s.model->system().dimension() == 2);
  const auto rep = pipeline::analyze(s);
  CHECK(rep.nontrivial == 1);
  CHECK(engine::toString(rep.rigid) == std::string("flexible"));
  // A position-less K4 (integer ids, networkx >= 3.4 writes "edges"): realized at random, in 3D
  // when asked; a seed for a file with positions is refused.
  const std::string k4 = R"({"nodes": [{"id": 0}, {"id": 1}, {"id": 2}, {"id": 3}],
    "edges": [{"source": 0, "target": 1}, {"source": 0, "target": 2}, {"source": 0, "target": 3},
              {"source": 1, "target": 2}, {"source": 1, "target": 3}, {"source": 2, "target": 3}]})";
  write("k4.json", k4);
  const scenes::Scene k = scenes::loadScene(write("k4.toml", "[system]\nfrom = \"k4.json\"\ndimension = 3\nseed = 5\n"));
  CHECK(k.model->system().dimension() == 3);
  CHECK(pipeline::analyze(k).inf_rigid);
  SceneError e = errorOf([] { scenes::loadScene(write("sqs.toml", "[system]\nfrom = \"sq.json\"\nseed = 2\n")); });
  CHECK((e.line == 3 && e.message == "the file gives the vertices' positions: seed is for a random realization"));
  // Broken files: the array and index, or the line and column of a syntax error.
  const std::pair<std::string, std::string> bad[] = {
      {R"({"nodes": [{"id": 0}, {"id": 1}], "links": [{"source": 0, "target": 7}]})", "links[0].target: node 7 is not in nodes"},
      {R"({"nodes": [{"id": 0}, {"id": 0}], "links": []})", "nodes[1]: node 0 is given twice"},
      {R"({"nodes": [{"id": 0, "pos": [0, 0]}, {"id": 1}], "links": [{"source": 0, "target": 1}]})", "some nodes have \"pos\""},
      {R"({"nodes": [{"id": 0, "pos": [0, 0]}, {"id": 1, "pos": [1, 0, 2]}], "links": []})", "nodes[1].pos: has 3 coordinates"},
      {R"({"nodes": [{"id": 0, "pos": [0, "x"]}], "links": []})", "nodes[0].pos[1]: not a number"},
      {R"({"directed": true, "nodes": [], "links": []})", "directed: a framework's bars have no direction"},
      {R"({"nodes": [{"id": 0}, {"id": 1}], "links": [{"source": 0, "target": 1}, {"source": 1, "target": 0}]})",
       "links[1]: edge 1-0 is given twice"},
      {R"([1, 2])", "node-link JSON is an object"},
      {R"({"directed": 5, "nodes": [], "links": []})", "directed: a framework's bars have no direction"},
      // A number beyond double: nlohmann's out_of_range, not its parse_error (found by the fuzzer).
      {"{\"nodes\": [{\"id\": 333333333333366e33333333333366}], \"links\": []}", "not JSON: number overflow"},
  };
  for (const auto& [text, message] : bad) {
    INFO(text);
    CHECK_THAT(errorOf([&] { scenes::readNodeLink(text, "b.json"); }).message, Catch::Contains(message));
  }
  e = errorOf([] { scenes::readNodeLink("{\"nodes\": [\n  {\"id\": 0,,}]}", "b.json"); });
  CHECK(e.line == 2);
  CHECK(e.column == 12);
  CHECK_THAT(e.message, Catch::StartsWith("not JSON: "));
}
