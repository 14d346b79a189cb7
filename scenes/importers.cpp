#include "scenes/importers.h"

#include "engine/resources.h"

#include "scenes/json_text.h"


#include <Eigen/Dense>
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <functional>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <optional>
#include <set>

#include <nlohmann/json.hpp>

#include "scenes/scene.h"

namespace flexure::scenes {

namespace {

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string extension(const std::string& file) {
  const size_t slash = file.find_last_of('/');
  const size_t dot = file.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  return lower(file.substr(dot + 1));
}

// The lines of a text with their numbers (1-based); a '\r' before '\n' is dropped.
std::vector<std::pair<int, std::string>> linesOf(const std::string& text) {
  std::vector<std::pair<int, std::string>> out;
  size_t at = 0;
  int n = 0;
  while (at <= text.size()) {
    size_t end = text.find('\n', at);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(at, end - at);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    out.emplace_back(++n, std::move(line));
    if (end == text.size()) break;
    at = end + 1;
  }
  return out;
}

// ---- graph6 / sparse6

struct Bytes6 {
  const std::string& s;
  size_t at;
  const std::string& file;
  int line;
  int value(size_t i) const {
    const int c = static_cast<unsigned char>(s[i]);
    if (c < 63 || c > 126)
      throw SceneError(file, line, static_cast<int>(i) + 1,
                       "byte " + std::to_string(c) + " is not graph6/sparse6 data (63..126)");
    return c - 63;
  }
  [[noreturn]] void fail(size_t i, const std::string& m) const {
    throw SceneError(file, line, static_cast<int>(i) + 1, m);
  }
  // N(n) at `at`: one byte, or 126 and 18 bits, or 126 126 and 36 bits.
  long long size() {
    auto need = [&](size_t k) {
      if (at + k > s.size()) fail(s.size(), "the line ends inside the vertex count");
    };
    need(1);
    if (value(at) != 63) return value(at++);
    need(2);
    const int words = value(at + 1) == 63 ? 6 : 3;
    at += words == 6 ? 2 : 1;
    need(static_cast<size_t>(words));
    long long n = 0;
    for (int k = 0; k < words; ++k) n = (n << 6) | value(at++);
    return n;
  }
};

ImportedGraph graph6Line(const std::string& s, const std::string& file, int line, size_t start) {
  Bytes6 b{s, start, file, line};
  const long long n = b.size();
  if (n > kMaxImportedVertices)
    b.fail(start, "the graph has " + std::to_string(n) + " vertices; at most " + std::to_string(kMaxImportedVertices));
  ImportedGraph g;
  g.vertices = static_cast<int>(n);
  const unsigned long long bits = static_cast<unsigned long long>(n) * (n - (n > 0 ? 1 : 0)) / 2;
  const size_t bytes = static_cast<size_t>((bits + 5) / 6);
  if (s.size() - b.at != bytes)
    b.fail(std::min(s.size(), b.at + bytes), "graph6 of " + std::to_string(n) + " vertices has " + std::to_string(bytes) +
                                                 " bytes of edges, this line " + std::to_string(s.size() - b.at));
  unsigned long long k = 0;
  for (long long j = 1; j < n; ++j)
    for (long long i = 0; i < j; ++i, ++k) {
      const int byte = b.value(b.at + k / 6);
      if (!(byte & (32 >> (k % 6)))) continue;
      if (static_cast<long long>(g.edges.size()) >= kMaxImportedEdges)
        b.fail(b.at + k / 6, "more than " + std::to_string(kMaxImportedEdges) + " edges");
      g.edges.push_back({static_cast<int>(i), static_cast<int>(j)});
    }
  return g;
}

ImportedGraph sparse6Line(const std::string& s, const std::string& file, int line, size_t start) {
  Bytes6 b{s, start + 1, file, line};  // after ':'
  const long long n = b.size();
  if (n > kMaxImportedVertices)
    b.fail(start, "the graph has " + std::to_string(n) + " vertices; at most " + std::to_string(kMaxImportedVertices));
  int k = 1;
  while ((1LL << k) < n) ++k;
  const size_t data = b.at;
  const unsigned long long total = 6ULL * (s.size() - data);
  unsigned long long pos = 0;
  auto bit = [&](unsigned long long p) { return (b.value(data + p / 6) >> (5 - p % 6)) & 1; };
  ImportedGraph g;
  g.vertices = static_cast<int>(n);
  std::set<std::pair<int, int>> seen;
  long long v = 0;
  while (pos + 1 + static_cast<unsigned long long>(k) <= total) {
    const size_t at = data + pos / 6;
    const int first = bit(pos++);
    long long x = 0;
    for (int i = 0; i < k; ++i) x = (x << 1) | bit(pos++);
    if (first) ++v;
    if (x >= n || v >= n) break;  // padding
    if (x > v) {
      v = x;
      continue;
    }
    if (x == v) b.fail(at, "a loop at vertex " + std::to_string(x) + " (a bar joins two vertices)");
    if (!seen.insert({static_cast<int>(x), static_cast<int>(v)}).second)
      b.fail(at, "the edge " + std::to_string(x) + "-" + std::to_string(v) + " is repeated (a multigraph)");
    if (static_cast<long long>(g.edges.size()) >= kMaxImportedEdges)
      b.fail(at, "more than " + std::to_string(kMaxImportedEdges) + " edges");
    g.edges.push_back({static_cast<int>(x), static_cast<int>(v)});
  }
  // sparse6 names the vertex count in its header, whatever the edges: ":~~?A?B..." asks for
  // 2 million vertices in 13 bytes (1.4 GB and 5 s of work for free points). A vertex on no
  // edge is a free point of the framework; more than kMaxIsolatedVertices of them are refused.
  std::vector<char> used(static_cast<size_t>(n), 0);
  for (const auto& e : g.edges) used[static_cast<size_t>(e[0])] = used[static_cast<size_t>(e[1])] = 1;
  const long long isolated = n - std::count(used.begin(), used.end(), 1);
  if (isolated > kMaxIsolatedVertices)
    b.fail(start, "the graph has " + std::to_string(n) + " vertices, " + std::to_string(isolated) +
                      " of them on no edge (free points); at most " + std::to_string(kMaxIsolatedVertices) +
                      " such vertices are read from a sparse6 line");
  return g;
}

// ---- meshes

struct Tokens {
  std::vector<std::string> words;
  std::vector<int> columns;
};

Tokens split(const std::string& line) {
  Tokens t;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    if (i >= line.size() || line[i] == '#') break;
    const size_t j = i;
    while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i])) && line[i] != '#') ++i;
    t.words.push_back(line.substr(j, i - j));
    t.columns.push_back(static_cast<int>(j) + 1);
  }
  return t;
}

double parseNumber(const std::string& w, const std::string& file, int line, int col, const std::string& what) {
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(w.c_str(), &end);
  if (w.empty() || *end != '\0') throw SceneError(file, line, col, what + " '" + w + "' is not a number");
  if (!std::isfinite(v) || std::abs(v) > kMaxCoordinate)
    throw SceneError(file, line, col, what + " '" + w + "' is not a finite coordinate within +-1e50");
  return v;
}

long long parseInteger(const std::string& w, const std::string& file, int line, int col, const std::string& what) {
  char* end = nullptr;
  errno = 0;
  const long long v = std::strtoll(w.c_str(), &end, 10);
  if (w.empty() || *end != '\0' || errno == ERANGE)
    throw SceneError(file, line, col, what + " '" + w + "' is not an integer");
  return v;
}

void checkFace(const std::vector<int>& f, int line, int col, const std::string& file) {
  if (f.size() < 3) throw SceneError(file, line, col, "a face needs at least 3 vertices, this one has " + std::to_string(f.size()));
  std::set<int> s(f.begin(), f.end());
  if (s.size() != f.size()) throw SceneError(file, line, col, "a face lists a vertex twice");
}

}  // namespace

std::optional<ImportedGraph> readGraph6Line(const std::string& line, const std::string& file, int n) {
  size_t start = 0;
  bool sparse = false;
  for (const char* h : {">>graph6<<", ">>sparse6<<"})
    if (line.compare(0, std::strlen(h), h) == 0) start = std::strlen(h), sparse = h[2] == 's';
  if (start == line.size()) return std::nullopt;  // empty, or a header alone
  if (line[start] == ':') sparse = true;
  else if (sparse) throw SceneError(file, n, static_cast<int>(start) + 1, "a sparse6 line starts with ':'");
  if (line[start] == '&')
    throw SceneError(file, n, static_cast<int>(start) + 1, "digraph6 (directed graphs) is not read: bars have no direction");
  return sparse ? sparse6Line(line, file, n, start) : graph6Line(line, file, n, start);
}

std::vector<ImportedGraph> readGraph6(const std::string& text, const std::string& file) {
  std::vector<ImportedGraph> out;
  for (const auto& [n, line] : linesOf(text))
    if (auto g = readGraph6Line(line, file, n)) out.push_back(std::move(*g));
  if (out.empty()) throw SceneError(file, 1, 1, "the file holds no graph");
  return out;
}

ImportedGraph readGraph6(const std::string& text, const std::string& file, long long which, long long& count) {
  std::optional<ImportedGraph> chosen;
  count = 0;
  for (const auto& [n, line] : linesOf(text)) {
    if (line.empty() || line == ">>graph6<<" || line == ">>sparse6<<") continue;
    if (++count == which) chosen = readGraph6Line(line, file, n);
  }
  if (count == 0) throw SceneError(file, 1, 1, "the file holds no graph");
  return chosen ? *chosen : ImportedGraph{};
}

ImportedMesh readOff(const std::string& text, const std::string& file) {
  ImportedMesh m;
  long long nv = -1, nf = -1;
  bool header = false;
  int last = 1;
  for (const auto& [n, line] : linesOf(text)) {
    last = n;
    Tokens t = split(line);
    if (t.words.empty()) continue;
    size_t w = 0;
    if (!header) {
      if (t.words[0] != "OFF")
        throw SceneError(file, n, t.columns[0], "an OFF file starts with 'OFF', not '" + t.words[0] + "'");
      header = true;
      if (t.words.size() == 1) continue;
      w = 1;
    }
    if (nv < 0) {
      if (t.words.size() - w < 2) throw SceneError(file, n, t.columns[w], "the counts line needs vertices, faces (and edges)");
      nv = parseInteger(t.words[w], file, n, t.columns[w], "vertex count");
      nf = parseInteger(t.words[w + 1], file, n, t.columns[w + 1], "face count");
      if (nv < 1 || nv > kMaxImportedVertices) throw SceneError(file, n, t.columns[w], "the vertex count must be 1.." + std::to_string(kMaxImportedVertices));
      if (nf < 1 || nf > 10 * kMaxImportedVertices) throw SceneError(file, n, t.columns[w + 1], "the face count must be positive");
      continue;
    }
    if (static_cast<long long>(m.vertices.size()) < nv) {
      if (t.words.size() < 3) throw SceneError(file, n, t.columns[0], "vertex " + std::to_string(m.vertices.size()) + " needs x y z");
      std::array<double, 3> p{};
      for (int k = 0; k < 3; ++k) p[k] = parseNumber(t.words[k], file, n, t.columns[k], "coordinate");
      m.vertices.push_back(p);
      continue;
    }
    if (static_cast<long long>(m.faces.size()) < nf) {
      const long long k = parseInteger(t.words[0], file, n, t.columns[0], "face size");
      if (k < 3 || static_cast<long long>(t.words.size()) - 1 < k)
        throw SceneError(file, n, t.columns[0], "face " + std::to_string(m.faces.size()) + " says " + std::to_string(k) +
                                                    " vertices and lists " + std::to_string(t.words.size() - 1));
      std::vector<int> f;
      for (long long i = 1; i <= k; ++i) {
        const long long v = parseInteger(t.words[i], file, n, t.columns[i], "face vertex");
        if (v < 0 || v >= nv)
          throw SceneError(file, n, t.columns[i], "face vertex " + std::to_string(v) + " is out of range 0.." + std::to_string(nv - 1));
        f.push_back(static_cast<int>(v));
      }
      checkFace(f, n, t.columns[0], file);
      m.faces.push_back(std::move(f));  // colours after the indices are ignored
      continue;
    }
    throw SceneError(file, n, t.columns[0], "text after the last face");
  }
  if (!header) throw SceneError(file, 1, 1, "an OFF file starts with 'OFF'; this one is empty");
  if (static_cast<long long>(m.vertices.size()) < nv || static_cast<long long>(m.faces.size()) < nf || nv < 0)
    throw SceneError(file, last, 1, "the file ends after " + std::to_string(m.vertices.size()) + " vertices and " +
                                        std::to_string(m.faces.size()) + " faces of the counts given");
  return m;
}

ImportedMesh readObj(const std::string& text, const std::string& file) {
  ImportedMesh m;
  for (const auto& [n, line] : linesOf(text)) {
    Tokens t = split(line);
    if (t.words.empty()) continue;
    if (t.words[0] == "v") {
      if (t.words.size() < 4) throw SceneError(file, n, t.columns[0], "a vertex needs x y z");
      std::array<double, 3> p{};
      for (int k = 0; k < 3; ++k) p[k] = parseNumber(t.words[k + 1], file, n, t.columns[k + 1], "coordinate");
      if (static_cast<long long>(m.vertices.size()) >= kMaxImportedVertices)
        throw SceneError(file, n, 1, "more than " + std::to_string(kMaxImportedVertices) + " vertices");
      m.vertices.push_back(p);
    } else if (t.words[0] == "f") {
      std::vector<int> f;
      for (size_t i = 1; i < t.words.size(); ++i) {
        const std::string w = t.words[i].substr(0, t.words[i].find('/'));
        long long v = parseInteger(w, file, n, t.columns[i], "face vertex");
        const long long count = static_cast<long long>(m.vertices.size());
        // 1-based, or negative: counted back from the last vertex read so far.
        const long long index = v > 0 ? v - 1 : count + v;
        if (v == 0 || index < 0 || index >= count)
          throw SceneError(file, n, t.columns[i], "face vertex " + std::to_string(v) + " is not one of the " +
                                                      std::to_string(count) + " vertices read so far");
        f.push_back(static_cast<int>(index));
      }
      checkFace(f, n, t.columns[0], file);
      m.faces.push_back(std::move(f));
    }
    // vt, vn, g, o, s, usemtl, mtllib, l ...: not geometry a polytope needs
  }
  if (m.vertices.empty() || m.faces.empty()) throw SceneError(file, 1, 1, "the OBJ file has no vertices or no faces");
  return m;
}

ImportedMesh readStl(const std::string& bytes, const std::string& file) {
  // Triangles first, then welding and merging.
  std::vector<std::array<std::array<double, 3>, 3>> tris;
  std::vector<std::pair<int, int>> where;  // line, column of each triangle (binary: 1, byte offset)
  bool binary = false;
  if (bytes.size() >= 84) {
    std::uint32_t count = 0;
    std::memcpy(&count, bytes.data() + 80, 4);
    binary = bytes.size() == 84 + 50ULL * count;
    if (binary) {
      for (std::uint32_t i = 0; i < count; ++i) {
        std::array<std::array<double, 3>, 3> t{};
        const size_t at = 84 + 50ULL * i;
        for (int v = 0; v < 3; ++v)
          for (int k = 0; k < 3; ++k) {
            float f = 0;
            std::memcpy(&f, bytes.data() + at + 12 + 12 * v + 4 * k, 4);
            if (!std::isfinite(f)) throw SceneError(file, 1, static_cast<int>(at + 12 + 12 * v + 4 * k) + 1, "a coordinate is not finite");
            t[v][k] = f;
          }
        tris.push_back(t);
        where.emplace_back(1, static_cast<int>(at) + 1);
      }
    }
  }
  if (!binary) {
    std::array<std::array<double, 3>, 3> t{};
    int nv = -1, facet_line = 1;
    bool solid = false;
    for (const auto& [n, line] : linesOf(bytes)) {
      Tokens tk = split(line);
      if (tk.words.empty()) continue;
      const std::string w = lower(tk.words[0]);
      if (!solid) {
        if (w != "solid") throw SceneError(file, n, tk.columns[0], "neither ASCII STL (it starts with 'solid') nor binary STL (its size is not 84 + 50 x its triangle count)");
        solid = true;
      } else if (w == "facet") {
        nv = 0, facet_line = n;
      } else if (w == "vertex") {
        if (nv < 0 || nv >= 3) throw SceneError(file, n, tk.columns[0], "a vertex outside a facet's loop of three");
        if (tk.words.size() < 4) throw SceneError(file, n, tk.columns[0], "a vertex needs x y z");
        for (int k = 0; k < 3; ++k) t[nv][k] = parseNumber(tk.words[k + 1], file, n, tk.columns[k + 1], "coordinate");
        ++nv;
      } else if (w == "endfacet") {
        if (nv != 3) throw SceneError(file, n, tk.columns[0], "a facet with " + std::to_string(std::max(nv, 0)) + " vertices, not 3");
        tris.push_back(t);
        where.emplace_back(facet_line, 1);
        nv = -1;
      }
    }
  }
  if (tris.empty()) throw SceneError(file, 1, 1, "the STL file has no triangles");
  if (static_cast<long long>(tris.size()) > kMaxImportedEdges)
    throw SceneError(file, 1, 1, "more than " + std::to_string(kMaxImportedEdges) + " triangles");
  // Weld: points equal within 1e-9 of the extent are one vertex.
  double lo = INFINITY, hi = -INFINITY;
  for (const auto& t : tris)
    for (const auto& p : t)
      for (double x : p) lo = std::min(lo, x), hi = std::max(hi, x);
  const double tol = std::max(hi - lo, 1e-300) * 1e-9;
  ImportedMesh m;
  std::map<std::array<long long, 3>, int> index;
  std::vector<std::array<int, 3>> faces;
  for (size_t i = 0; i < tris.size(); ++i) {
    std::array<int, 3> f{};
    for (int v = 0; v < 3; ++v) {
      std::array<long long, 3> key{};
      for (int k = 0; k < 3; ++k) key[k] = std::llround((tris[i][v][k] - lo) / tol);
      auto [it, added] = index.emplace(key, static_cast<int>(m.vertices.size()));
      if (added) m.vertices.push_back(tris[i][v]);
      f[v] = it->second;
    }
    if (f[0] == f[1] || f[1] == f[2] || f[0] == f[2])
      throw SceneError(file, where[i].first, where[i].second, "triangle " + std::to_string(i) + " is degenerate (two corners coincide)");
    faces.push_back(f);
  }
  // Merge edge-adjacent coplanar triangles (union-find over shared edges).
  auto normal = [&](const std::array<int, 3>& f) {
    Eigen::Vector3d a(m.vertices[f[0]].data()), b(m.vertices[f[1]].data()), c(m.vertices[f[2]].data());
    return Eigen::Vector3d((b - a).cross(c - a));
  };
  std::vector<int> parent(faces.size());
  for (size_t i = 0; i < parent.size(); ++i) parent[i] = static_cast<int>(i);
  std::function<int(int)> root = [&](int i) { return parent[i] == i ? i : parent[i] = root(parent[i]); };
  std::map<std::pair<int, int>, int> edge_face, edge_count;
  for (size_t i = 0; i < faces.size(); ++i)
    for (int e = 0; e < 3; ++e) ++edge_count[std::minmax(faces[i][e], faces[i][(e + 1) % 3])];
  // A polytope's surface is closed: every edge joins exactly two triangles.
  for (size_t i = 0; i < faces.size(); ++i)
    for (int e = 0; e < 3; ++e) {
      const int k = edge_count[std::minmax(faces[i][e], faces[i][(e + 1) % 3])];
      if (k != 2)
        throw SceneError(file, where[i].first, where[i].second,
                         "the mesh is not closed: an edge of triangle " + std::to_string(i) + " belongs to " +
                             std::to_string(k) + " triangle(s), not 2 (an open boundary)");
    }
  for (size_t i = 0; i < faces.size(); ++i)
    for (int e = 0; e < 3; ++e) {
      const int a = faces[i][e], b = faces[i][(e + 1) % 3];
      const auto key = std::minmax(a, b);
      auto [it, added] = edge_face.emplace(key, static_cast<int>(i));
      if (added) continue;
      const Eigen::Vector3d n1 = normal(faces[i]), n2 = normal(faces[it->second]);
      const double c = n1.dot(n2) / (n1.norm() * n2.norm());
      if (c > 1 - 1e-9) parent[root(static_cast<int>(i))] = root(it->second);
    }
  // Each group's boundary: its directed edges whose reverse is not in the group, one loop.
  std::map<int, std::vector<int>> groups;
  for (size_t i = 0; i < faces.size(); ++i) groups[root(static_cast<int>(i))].push_back(static_cast<int>(i));
  for (const auto& [r, members] : groups) {
    std::set<std::pair<int, int>> directed;
    for (int i : members)
      for (int e = 0; e < 3; ++e) directed.insert({faces[i][e], faces[i][(e + 1) % 3]});
    std::map<int, int> next;
    for (const auto& [a, b] : directed)
      if (!directed.count({b, a}) && !next.emplace(a, b).second)
        throw SceneError(file, where[members[0]].first, where[members[0]].second,
                         "the planar facet of triangle " + std::to_string(members[0]) + " touches itself at a vertex");
    if (next.empty())
      throw SceneError(file, where[members[0]].first, where[members[0]].second,
                       "triangle " + std::to_string(members[0]) + " and its coplanar neighbours enclose nothing");
    std::vector<int> loop{next.begin()->first};
    while (true) {
      auto it = next.find(loop.back());
      if (it == next.end())
        throw SceneError(file, where[members[0]].first, where[members[0]].second,
                         "the planar facet of triangle " + std::to_string(members[0]) + " has an open boundary (the mesh is not closed)");
      if (it->second == loop.front()) break;
      loop.push_back(it->second);
      if (loop.size() > next.size()) break;
    }
    if (loop.size() != next.size())
      throw SceneError(file, where[members[0]].first, where[members[0]].second,
                       "the planar facet of triangle " + std::to_string(members[0]) + " has a hole or several boundaries");
    m.faces.push_back(std::move(loop));
  }
  return m;
}

bool isGraphFile(const std::string& file) {
  const std::string e = extension(file);
  return e == "g6" || e == "s6" || e == "graph6" || e == "sparse6";
}

bool isEdgeListFile(const std::string& file) {
  const std::string e = extension(file);
  return e == "edges" || e == "edgelist";
}

bool isNodeLinkFile(const std::string& file) { return extension(file) == "json"; }

bool isImportable(const std::string& file) {
  const std::string e = extension(file);
  return isGraphFile(file) || isEdgeListFile(file) || isNodeLinkFile(file) || e == "off" || e == "obj" || e == "stl" ||
         e == "fold";
}

namespace {

// Edges between labelled vertices, numbered at the end (GraphBuilder::finish).
class LabelledGraph {
 public:
  // Adds edge (a, b); `where` names it in messages; returns false when it is a loop or repeat
  // (with `why`).
  bool add(const std::string& a, const std::string& b, std::string& why) {
    if (a == b) {
      why = "edge " + a + "-" + b + " joins a vertex to itself";
      return false;
    }
    const int i = vertex(a), j = vertex(b);
    if (!seen_.insert({std::min(i, j), std::max(i, j)}).second) {
      why = "edge " + a + "-" + b + " is given twice";
      return false;
    }
    if (static_cast<long long>(edges_.size()) >= kMaxImportedEdges) {
      why = "more than " + std::to_string(kMaxImportedEdges) + " edges";
      return false;
    }
    edges_.push_back({i, j});
    return true;
  }
  int vertex(const std::string& label) {
    const auto [it, added] = index_.emplace(label, static_cast<int>(labels_.size()));
    if (added) labels_.push_back(label);
    return it->second;
  }
  int count() const { return static_cast<int>(labels_.size()); }
  // Numbered by value when every label is an integer (`numeric`), else by first appearance.
  ImportedGraph finish(bool numeric) const {
    std::vector<int> order(labels_.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
    if (numeric)
      std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return std::stoll(labels_[a]) < std::stoll(labels_[b]); });
    std::vector<int> rank(labels_.size());
    for (size_t k = 0; k < order.size(); ++k) rank[static_cast<size_t>(order[k])] = static_cast<int>(k);
    ImportedGraph g;
    g.vertices = count();
    for (const auto& e : edges_) {
      const int a = rank[static_cast<size_t>(e[0])], b = rank[static_cast<size_t>(e[1])];
      g.edges.push_back({std::min(a, b), std::max(a, b)});
    }
    return g;
  }

 private:
  std::map<std::string, int> index_;
  std::vector<std::string> labels_;
  std::set<std::pair<int, int>> seen_;
  std::vector<std::array<int, 2>> edges_;
};

bool isInteger(const std::string& s) {
  size_t i = s[0] == '-' || s[0] == '+' ? 1 : 0;
  return i < s.size() && s.size() <= 18 && std::all_of(s.begin() + static_cast<long>(i), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

}  // namespace

ImportedGraph readEdgeList(const std::string& text, const std::string& file) {
  LabelledGraph g;
  bool numeric = true;
  int line_no = 0;
  for (size_t at = 0; at < text.size();) {
    const size_t end = std::min(text.find('\n', at), text.size());
    std::string line = text.substr(at, end - at);
    at = end + 1;
    ++line_no;
    if (const size_t hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    std::vector<std::pair<std::string, int>> tokens;  // text, column
    for (size_t i = 0; i < line.size() && tokens.size() < 2;) {
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == ',' || line[i] == '\r')) ++i;
      if (i >= line.size()) break;
      const size_t b = i;
      while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != ',' && line[i] != '\r') ++i;
      tokens.push_back({line.substr(b, i - b), static_cast<int>(b) + 1});
    }
    if (tokens.empty()) continue;
    if (tokens.size() == 1)
      throw SceneError(file, line_no, tokens[0].second, "an edge needs two vertices, this line names one");
    for (const auto& [t, col] : tokens) {
      if (std::any_of(t.begin(), t.end(), [](char c) { return static_cast<unsigned char>(c) < 0x20; }))
        throw SceneError(file, line_no, col, "a control character in a vertex label");
      numeric = numeric && isInteger(t);
    }
    std::string why;
    if (!g.add(tokens[0].first, tokens[1].first, why)) throw SceneError(file, line_no, tokens[0].second, why);
    if (g.count() > kMaxImportedVertices)
      throw SceneError(file, line_no, tokens[0].second, "more than " + std::to_string(kMaxImportedVertices) + " vertices");
  }
  if (g.count() == 0) throw SceneError(file, 1, 1, "the edge list names no edge (one per line: two vertex labels)");
  return g.finish(numeric);
}

void checkJsonShape(std::string_view text, const std::string& file, int first_line) {
  int depth = 0, line = first_line;
  size_t line_start = 0;
  double values = 1;
  bool in_string = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') ++i;
      else if (c == '"') in_string = false;
      continue;
    }
    switch (c) {
      case '"': in_string = true; break;
      case '\n': ++line, line_start = i + 1; break;
      case ',': ++values; break;
      case '[':
      case '{':
        ++values;
        if (++depth > kMaxJsonDepth)
          throw SceneError(file, line, static_cast<int>(i - line_start) + 1,
                           "arrays and objects nested deeper than " + std::to_string(kMaxJsonDepth) +
                               " levels: not a file flexure reads");
        break;
      case ']':
      case '}': depth = std::max(0, depth - 1); break;
      default: break;
    }
  }
  engine::requireMemory("reading " + file + " (" + std::to_string(static_cast<long long>(values)) + " JSON values)",
                        32.0 * values + static_cast<double>(text.size()));
}

nlohmann::json parseJsonText(const std::string& text, const std::string& file) {
  checkJsonShape(text, file);
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    // The byte offset as line and column.
    const size_t at = std::min<size_t>(e.byte > 0 ? e.byte - 1 : 0, text.size());
    const int line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
    const size_t start = text.rfind('\n', at == 0 ? 0 : at - 1);
    const int column = static_cast<int>(at - (start == std::string::npos || at == 0 ? 0 : start + 1)) + 1;
    std::string what = e.what();
    if (const size_t colon = what.find(": "); colon != std::string::npos) what = what.substr(colon + 2);
    throw SceneError(file, line, column, "not JSON: " + what);
  } catch (const nlohmann::json::exception& e) {  // a number beyond double (out_of_range 406), found by the fuzzer
    std::string what = e.what();
    if (const size_t space = what.find("] "); space != std::string::npos) what = what.substr(space + 2);
    throw SceneError(file, 1, 1, "not JSON: " + what);
  }
}

ImportedGraph readNodeLink(const std::string& text, const std::string& file) {
  nlohmann::json j = parseJsonText(text, file);
  auto fail = [&](const std::string& where, const std::string& m) { throw SceneError(file, 1, 1, where + ": " + m); };
  if (!j.is_object()) fail("the file", "node-link JSON is an object with \"nodes\" and \"links\"");
  if (!j.contains("nodes") || !j["nodes"].is_array()) fail("nodes", "missing, or not an array (networkx's node_link_data writes it)");
  const char* links_key = j.contains("links") ? "links" : "edges";
  if (!j.contains(links_key) || !j[links_key].is_array()) fail("links", "missing, or not an array");
  // (value() would throw for a "directed" that is not a boolean.)
  const auto flag = [&](const char* key) { return j.contains(key) && !(j[key].is_boolean() && !j[key].get<bool>()); };
  if (flag("directed")) fail("directed", "a framework's bars have no direction: give an undirected graph (\"directed\": false)");
  if (flag("multigraph")) fail("multigraph", "a bar joins two vertices once: give a simple graph (\"multigraph\": false)");
  const auto& nodes = j["nodes"];
  const auto& links = j[links_key];
  if (static_cast<long long>(nodes.size()) > kMaxImportedVertices)
    fail("nodes", "more than " + std::to_string(kMaxImportedVertices) + " vertices");
  if (static_cast<long long>(links.size()) > kMaxImportedEdges) fail(links_key, "more than " + std::to_string(kMaxImportedEdges) + " edges");
  LabelledGraph g;
  // A node's name as the messages and labels show it (ids are strings, numbers or, from
  // networkx's tuples, arrays of them; nesting is bounded by checkJsonShape).
  auto label = [](const nlohmann::json& id) { return id.is_string() ? "\"" + id.get<std::string>() + "\"" : id.dump(); };
  std::vector<std::vector<double>> positions;
  bool all_pos = true;
  size_t dim = 0;
  for (size_t i = 0; i < nodes.size(); ++i) {
    const std::string where = "nodes[" + std::to_string(i) + "]";
    const auto& n = nodes[i];
    if (!n.is_object() || !n.contains("id")) fail(where, "a node is an object with an \"id\"");
    const std::string id = label(n["id"]);
    if (g.vertex(id) != static_cast<int>(i)) fail(where, "node " + id + " is given twice");
    const auto pos = n.find("pos");
    if (pos == n.end()) {
      all_pos = false;
      continue;
    }
    if (!pos->is_array() || (pos->size() != 2 && pos->size() != 3))
      fail(where + ".pos", "a position is 2 or 3 numbers");
    if (dim == 0) dim = pos->size();
    if (pos->size() != dim) fail(where + ".pos", "has " + std::to_string(pos->size()) + " coordinates, the first node's " + std::to_string(dim));
    std::vector<double> p;
    for (size_t k = 0; k < pos->size(); ++k) {
      if (!(*pos)[k].is_number()) fail(where + ".pos[" + std::to_string(k) + "]", "not a number");
      const double x = (*pos)[k].get<double>();
      if (!std::isfinite(x)) fail(where + ".pos[" + std::to_string(k) + "]", "not a finite number");
      p.push_back(x);
    }
    positions.push_back(std::move(p));
  }
  if (nodes.empty()) fail("nodes", "the graph has no vertex");
  for (size_t i = 0; i < links.size(); ++i) {
    const std::string where = std::string(links_key) + "[" + std::to_string(i) + "]";
    const auto& l = links[i];
    if (!l.is_object() || !l.contains("source") || !l.contains("target"))
      fail(where, "a link is an object with \"source\" and \"target\"");
    const std::string a = label(l["source"]), b = label(l["target"]);
    for (const auto& [end, id] : {std::pair{"source", a}, std::pair{"target", b}}) {
      const int before = g.count();
      g.vertex(id);
      if (g.count() != before) fail(where + "." + end, "node " + id + " is not in nodes");
    }
    std::string why;
    if (!g.add(a, b, why)) fail(where, why);
  }
  ImportedGraph out = g.finish(false);
  if (all_pos) out.positions = std::move(positions);
  else if (!positions.empty()) fail("nodes", "some nodes have \"pos\" and some do not: give every node a position, or none");
  return out;
}

}  // namespace flexure::scenes
