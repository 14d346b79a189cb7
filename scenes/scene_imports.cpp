// The systems read from other file formats: [system] from = FILE (graph6/sparse6, edge lists,
// node-link JSON, OFF/OBJ/STL meshes, FOLD files) as the [system] table it stands for, a
// graph's framework table at its seeded realization, and the scene such a file given as SCENE
// stands for.
#include <cctype>
#include <fstream>
#include <limits>

#include "engine/systems/origami.h"
#include "engine/random.h"
#include "scenes/fold_file.h"
#include "scenes/importers.h"
#include "scenes/loader_parts.h"
#include "scenes/scene.h"

namespace flexure::scenes::detail {

using engine::Matrix;

// A graph's framework table (type, vertices, edges) at its seeded random realization: uniform
// in the unit square or cube, vertex by vertex, from the seed (or at the positions the file
// gives). Vertex numbers from `base`.
std::string besideScene(const std::string& scene_file, const std::string& name) {
  const size_t slash = scene_file.find_last_of('/');
  return name.empty() || name[0] == '/' || slash == std::string::npos ? name : scene_file.substr(0, slash + 1) + name;
}

Matrix graphRealization(int vertices, int dimension, std::uint64_t seed) {
  engine::Random rng(seed);
  Matrix p(dimension, vertices);
  for (int v = 0; v < vertices; ++v)
    for (int k = 0; k < dimension; ++k) p(k, v) = rng.uniform();
  return p;
}

toml::table graphSystem(const ImportedGraph& g, int dimension, std::uint64_t seed, int base) {
  toml::array vertices, edges;
  if (!g.positions.empty()) {  // the file's own realization (node-link "pos"; the loader checks its rows)
    for (const auto& row : g.positions) {
      toml::array p;
      for (double x : row) p.push_back(x);
      vertices.push_back(std::move(p));
    }
  } else {
    const Matrix p = graphRealization(g.vertices, dimension, seed);
    for (int v = 0; v < g.vertices; ++v) {
      toml::array row;
      for (int k = 0; k < dimension; ++k) row.push_back(p(k, v));
      vertices.push_back(std::move(row));
    }
  }
  for (const auto& e : g.edges)
    edges.push_back(toml::array{static_cast<int64_t>(e[0]) + base, static_cast<int64_t>(e[1]) + base});
  toml::table t;
  t.insert("type", "framework");
  t.insert("vertices", std::move(vertices));
  t.insert("edges", std::move(edges));
  return t;
}

// [system] from = "FILE": the framework of a graph6/sparse6 file (a seeded random realization)
// or the polytope of an OFF/OBJ/STL mesh, as the [system] table it stands for. FILE is relative
// to the scene's folder.
std::unique_ptr<engine::Model> buildImported(const Reader& r, const toml::table& sys, const toml::node& from,
                                             int base, std::string& type_out, int depth, toml::table* resolved) {
  const std::string name = r.string(from, "from");
  const std::string path = besideScene(r.file(), name);
  if (!isImportable(path))
    r.fail(from, "from reads graph6/sparse6 (.g6, .s6), edge lists (.edges, .edgelist), node-link JSON (.json), "
                 "OFF, OBJ or STL meshes, or FOLD files (.fold), not '" + name + "'");
  std::string text;
  try {
    text = readSceneFile(path);
  } catch (const SceneError& e) {
    r.fail(from, "cannot read '" + path + "': " + e.message);
  }
  const bool graph6 = isGraphFile(path), graph = graph6 || isEdgeListFile(path) || isNodeLinkFile(path);
  const bool fold = isFoldFile(path);
  const std::string made = graph ? "framework" : fold ? "origami" : "polytope";
  if (const toml::node* t = sys.get("type"); t && r.string(*t, "type") != made)
    r.fail(*t, "a " + std::string(graph ? "graph file" : fold ? "FOLD file" : "mesh") + " is a" +
                   (fold ? "n " : " ") + made + "; leave type out or say \"" + made + "\"");
  toml::table out;
  out.insert("type", made);
  if (const toml::node* p = sys.get("pinned")) out.insert("pinned", *p);
  auto index = [&](int v) { return static_cast<int64_t>(v) + base; };
  if (graph) {
    if (graph6)
      r.checkKeys(sys, {"type", "from", "graph", "dimension", "seed", "pinned"}, "[system] (from a graph6/sparse6 file)");
    else
      r.checkKeys(sys, {"type", "from", "dimension", "seed", "pinned"}, "[system] (from an edge list or node-link JSON)");
    long long which = 1, dimension = 2;
    std::uint64_t seed = 1;
    if (const toml::node* n = sys.get("graph")) which = r.integer(*n, "graph");
    if (const toml::node* n = sys.get("dimension")) {
      dimension = r.integer(*n, "dimension");
      if (dimension != 2 && dimension != 3) r.fail(*n, "dimension must be 2 or 3");
    }
    if (const toml::node* n = sys.get("seed")) {
      const long long v = r.integer(*n, "seed");
      if (v < 0) r.fail(*n, "seed must be >= 0");
      seed = static_cast<std::uint64_t>(v);
    }
    ImportedGraph g;
    if (graph6) {
      long long count = 0;
      g = readGraph6(text, path, which, count);
      if (which < 1 || which > count)
        r.fail(sys.get("graph") ? sys.get("graph")->source() : from.source(),
               "graph " + std::to_string(which) + " is not in the file: it holds " + std::to_string(count) +
                   " graph(s), numbered from 1");
      if (g.edges.empty()) r.fail(from, "graph " + std::to_string(which) + " of '" + path + "' has no edge");
    } else {
      g = isEdgeListFile(path) ? readEdgeList(text, path) : readNodeLink(text, path);
      if (g.edges.empty()) r.fail(from, "the graph of '" + path + "' has no edge");
      if (!g.positions.empty()) {
        const long long d = static_cast<long long>(g.positions[0].size());
        if (const toml::node* n = sys.get("dimension"); n && dimension != d)
          r.fail(*n, "the file places its vertices in " + std::to_string(d) + "D");
        if (const toml::node* n = sys.get("seed"))
          r.fail(*n, "the file gives the vertices' positions: seed is for a random realization");
        dimension = d;
      }
    }
    const toml::table made_sys = graphSystem(g, static_cast<int>(dimension), seed, base);
    for (const auto& [k, v] : made_sys) out.insert_or_assign(k.str(), v);
  } else if (fold) {
    r.checkKeys(sys, {"type", "from", "pinned", "frame"}, "[system] (from a FOLD file)");
    long long frame = 0;
    if (const toml::node* n = sys.get("frame")) {
      frame = r.integer(*n, "frame");
      if (frame < 0 || frame > std::numeric_limits<int>::max()) r.fail(*n, "frame is 0 (the top level) or more");
    }
    const FoldSheet sheet = readFold(text, path, static_cast<int>(frame));
    // The sheet's own problems, told at the FOLD file's arrays.
    try {
      Matrix p(3, static_cast<Eigen::Index>(sheet.vertices.size()));
      for (size_t i = 0; i < sheet.vertices.size(); ++i)
        p.col(static_cast<Eigen::Index>(i)) << sheet.vertices[i][0], sheet.vertices[i][1], sheet.vertices[i][2];
      std::vector<engine::Crease> edges;
      for (size_t e = 0; e < sheet.edges.size(); ++e) {
        engine::Crease c;
        c.a = sheet.edges[e][0], c.b = sheet.edges[e][1], c.assignment = sheet.assignments[e];
        edges.push_back(c);
      }
      engine::Origami(p, sheet.faces, edges, {}, 0);
    } catch (const engine::ModelError& e) {
      const std::string array = e.key == "faces" ? "faces_vertices" : e.key == "creases" ? "edges_vertices" : "vertices_coords";
      throw SceneError(path, 1, 1, array + (e.item >= 0 ? "[" + std::to_string(e.item) + "]" : "") + ": " + e.what());
    }
    toml::array vertices, faces, creases;
    for (const auto& v : sheet.vertices) vertices.push_back(toml::array{v[0], v[1], v[2]});
    for (const auto& f : sheet.faces) {
      toml::array a;
      for (int v : f) a.push_back(index(v));
      faces.push_back(std::move(a));
    }
    for (const auto& e : sheet.edges) creases.push_back(toml::array{index(e[0]), index(e[1])});
    out.insert("vertices", std::move(vertices));
    out.insert("faces", std::move(faces));
    out.insert("creases", std::move(creases));
    out.insert("assignments", sheet.assignments);
  } else {
    r.checkKeys(sys, {"type", "from", "pinned"}, "[system] (from a mesh)");
    std::string ext = path.substr(path.find_last_of('.') + 1);
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    const ImportedMesh m = ext == "off" ? readOff(text, path) : ext == "obj" ? readObj(text, path) : readStl(text, path);
    toml::array vertices, facets;
    for (const auto& p : m.vertices) vertices.push_back(toml::array{p[0], p[1], p[2]});
    for (const auto& f : m.faces) {
      toml::array a;
      for (int v : f) a.push_back(index(v));
      facets.push_back(std::move(a));
    }
    out.insert("vertices", std::move(vertices));
    out.insert("facets", std::move(facets));
  }
  if (resolved) *resolved = out;
  return buildModel(r, out, base, type_out, depth + 1);
}

// A .json file that is not JSON (its first non-blank byte is not '{'): a scene file named so,
// read as TOML as it always was. Node-link JSON is an object.
bool tomlNamedJson(const std::string& path) {
  if (!isNodeLinkFile(path)) return false;
  std::ifstream in(path, std::ios::binary);
  char c = 0;
  while (in.get(c))
    if (!std::isspace(static_cast<unsigned char>(c))) return c != '{';
  return false;
}

// The scene a graph, mesh or FOLD file given as SCENE stands for: `[system] from = FILE`,
// titled with the file's name (FILE is found next to itself). A FOLD file counts its vertices
// and edges from 0, and so does its scene (messages, labels, the CSV's columns).
toml::table importedSceneDocument(const std::string& path) {
  const std::string name = path.substr(path.find_last_of('/') + 1);
  toml::table doc;
  doc.insert("title", name);
  if (isFoldFile(path)) doc.insert("index_base", 0);
  doc.insert("system", toml::table{{"from", name}});
  return doc;
}

}  // namespace flexure::scenes::detail
