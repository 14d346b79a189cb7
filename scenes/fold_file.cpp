#include "scenes/fold_file.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "scenes/importers.h"
#include "scenes/json_text.h"
#include "scenes/scene.h"

namespace flexure::scenes {

bool isFoldFile(const std::string& file) {
  const auto dot = file.find_last_of('.');
  if (dot == std::string::npos) return false;
  std::string ext = file.substr(dot + 1);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == "fold";
}

namespace {

using Json = nlohmann::json;

struct Reader {
  const std::string& file;
  std::string frame;  // "" for frame 0, else "frame K: "
  [[noreturn]] void fail(const std::string& where, const std::string& message) const {
    throw SceneError(file, 1, 1, frame + where + ": " + message);
  }
  static std::string at(const std::string& array, size_t i) { return array + "[" + std::to_string(i) + "]"; }
  static std::string at(const std::string& array, size_t i, size_t j) { return at(array, i) + "[" + std::to_string(j) + "]"; }
  const Json* array(const Json& j, const std::string& key) const {
    if (!j.contains(key)) return nullptr;
    if (!j[key].is_array()) fail(key, "must be an array");
    return &j[key];
  }
  int index(const Json& v, const std::string& where, size_t n) const {
    if (!v.is_number_integer() && !v.is_number_unsigned()) fail(where, "a vertex index is an integer");
    const long long i = v.get<long long>();
    if (i < 0 || i >= static_cast<long long>(n))
      fail(where, "vertex " + std::to_string(i) + " does not exist: vertices are numbered 0.." + std::to_string(n - 1));
    return static_cast<int>(i);
  }
};

// The bounded faces of a plane straight-line graph, counterclockwise: every directed edge
// u -> v continues at v along the edge that comes next clockwise after v -> u.
std::vector<std::vector<int>> traceFaces(const std::vector<std::array<double, 3>>& p,
                                         const std::vector<std::array<int, 2>>& edges) {
  const size_t n = p.size();
  std::vector<std::vector<int>> around(n);
  for (const auto& e : edges) around[static_cast<size_t>(e[0])].push_back(e[1]), around[static_cast<size_t>(e[1])].push_back(e[0]);
  const auto angle = [&](int from, int to) {
    return std::atan2(p[static_cast<size_t>(to)][1] - p[static_cast<size_t>(from)][1],
                      p[static_cast<size_t>(to)][0] - p[static_cast<size_t>(from)][0]);
  };
  for (size_t v = 0; v < n; ++v)
    std::sort(around[v].begin(), around[v].end(),
              [&](int a, int b) { return angle(static_cast<int>(v), a) < angle(static_cast<int>(v), b); });
  std::set<std::pair<int, int>> used;
  std::vector<std::vector<int>> faces;
  for (const auto& e : edges)
    for (const auto& [u0, v0] : {std::pair{e[0], e[1]}, std::pair{e[1], e[0]}}) {
      if (used.count({u0, v0})) continue;
      std::vector<int> face;
      int u = u0, v = v0;
      while (used.insert({u, v}).second && face.size() <= 2 * edges.size()) {
        face.push_back(u);
        const auto& nb = around[static_cast<size_t>(v)];
        const auto it = std::find(nb.begin(), nb.end(), u);
        // Counterclockwise order around v: the one before u is the next clockwise.
        const int w = it == nb.begin() ? nb.back() : *(it - 1);
        u = v, v = w;
      }
      double area = 0;
      for (size_t i = 0; i < face.size(); ++i) {
        const auto& a = p[static_cast<size_t>(face[i])];
        const auto& b = p[static_cast<size_t>(face[(i + 1) % face.size()])];
        area += a[0] * b[1] - a[1] * b[0];
      }
      if (area > 0 && face.size() >= 3) faces.push_back(std::move(face));
    }
  return faces;
}

// Frame k of the file as one object: the top level for 0 (without file_frames), else
// file_frames[k - 1], over its parent's properties when it inherits them (frame_inherit, from
// frame_parent, 0 when not given), and so on up the chain (followed without recursion: a file
// may hold many frames).
Json frameObject(const Json& top, int k, const Reader& r) {
  const Json* frames = r.array(top, "file_frames");
  const long long count = frames ? static_cast<long long>(frames->size()) : 0;
  if (k < 0 || k > count)
    r.fail("file_frames", "frame " + std::to_string(k) + " does not exist: the file has frames 0.." + std::to_string(count) +
                              " (0 is the top level, k is file_frames[k - 1])");
  // The chain k, its parent, ... up to a frame that does not inherit.
  std::vector<long long> chain;
  std::set<long long> seen;
  for (long long f = k;;) {
    chain.push_back(f);
    if (f == 0) break;
    const std::string at = Reader::at("file_frames", static_cast<size_t>(f - 1));
    const Json& frame = (*frames)[static_cast<size_t>(f - 1)];
    if (!frame.is_object()) r.fail(at, "a frame is a JSON object");
    const Json inherit = frame.value("frame_inherit", Json(false));
    if (!inherit.is_boolean()) r.fail(at + ".frame_inherit", "true or false");
    if (!inherit.get<bool>()) break;
    long long parent = 0;
    if (frame.contains("frame_parent")) {
      if (!frame["frame_parent"].is_number_integer() && !frame["frame_parent"].is_number_unsigned())
        r.fail(at + ".frame_parent", "a frame number");
      parent = frame["frame_parent"].get<long long>();
    }
    if (parent < 0 || parent > count) r.fail(at + ".frame_parent", "frame " + std::to_string(parent) + " does not exist");
    if (!seen.insert(f).second || seen.count(parent))
      r.fail(at + ".frame_parent", "the frames inherit from each other in a cycle");
    f = parent;
  }
  // Merged from the oldest ancestor down; a frame's own file_frames and frame_* keys are not
  // properties of the sheet.
  Json out = Json::object();
  for (size_t i = chain.size(); i-- > 0;) {
    const Json& f = chain[i] == 0 ? top : (*frames)[static_cast<size_t>(chain[i] - 1)];
    for (const auto& [key, value] : f.items())
      if (key != "file_frames" && key.rfind("frame_", 0) != 0) out[key] = value;
  }
  return out;
}

}  // namespace

FoldSheet readFold(const std::string& text, const std::string& file, int frame) {
  const Json top = parseJsonText(text, file);
  if (!top.is_object())
    Reader{file, ""}.fail("the file", "a FOLD file is a JSON object (\"vertices_coords\", \"faces_vertices\", ...)");
  const Json j = frameObject(top, frame, Reader{file, ""});
  const Reader r{file, frame == 0 ? "" : "frame " + std::to_string(frame) + ": "};
  FoldSheet s;
  // vertices_coords
  const Json* vc = r.array(j, "vertices_coords");
  if (!vc) r.fail("vertices_coords", "missing: a sheet needs its vertices' coordinates");
  if (vc->empty()) r.fail("vertices_coords", "is empty");
  if (static_cast<long long>(vc->size()) > kMaxImportedVertices)
    r.fail("vertices_coords", "more than " + std::to_string(kMaxImportedVertices) + " vertices");
  bool planar_pattern = true;
  for (size_t i = 0; i < vc->size(); ++i) {
    const Json& v = (*vc)[i];
    if (!v.is_array() || v.size() < 2 || v.size() > 3) r.fail(Reader::at("vertices_coords", i), "a vertex is 2 or 3 numbers");
    std::array<double, 3> x{0, 0, 0};
    for (size_t k = 0; k < v.size(); ++k) {
      if (!v[k].is_number()) r.fail(Reader::at("vertices_coords", i, k), "a coordinate is a number");
      x[k] = v[k].get<double>();
      if (!std::isfinite(x[k])) r.fail(Reader::at("vertices_coords", i, k), "a coordinate is finite");
    }
    planar_pattern = planar_pattern && x[2] == 0;
    s.vertices.push_back(x);
  }
  const size_t n = s.vertices.size();
  // faces_vertices
  if (const Json* fv = r.array(j, "faces_vertices")) {
    for (size_t f = 0; f < fv->size(); ++f) {
      const Json& face = (*fv)[f];
      if (!face.is_array()) r.fail(Reader::at("faces_vertices", f), "a face is an array of vertex indices");
      std::vector<int> vs;
      for (size_t k = 0; k < face.size(); ++k) vs.push_back(r.index(face[k], Reader::at("faces_vertices", f, k), n));
      if (vs.size() < 3) r.fail(Reader::at("faces_vertices", f), "a face has at least 3 vertices");
      if (std::set<int>(vs.begin(), vs.end()).size() != vs.size())
        r.fail(Reader::at("faces_vertices", f), "the face does not close once: it lists a vertex twice");
      s.faces.push_back(std::move(vs));
    }
  }
  // edges_vertices, edges_assignment, edges_foldAngle
  const Json* ev = r.array(j, "edges_vertices");
  if (ev) {
    for (size_t e = 0; e < ev->size(); ++e) {
      const Json& edge = (*ev)[e];
      if (!edge.is_array() || edge.size() != 2) r.fail(Reader::at("edges_vertices", e), "an edge is two vertex indices");
      const int a = r.index(edge[0], Reader::at("edges_vertices", e, 0), n);
      const int b = r.index(edge[1], Reader::at("edges_vertices", e, 1), n);
      if (a == b) r.fail(Reader::at("edges_vertices", e), "the edge joins vertex " + std::to_string(a) + " to itself");
      s.edges.push_back({a, b});
    }
  }
  if (const Json* ea = r.array(j, "edges_assignment")) {
    if (!ev) r.fail("edges_assignment", "given without edges_vertices");
    if (ea->size() != ev->size())
      r.fail("edges_assignment", "has " + std::to_string(ea->size()) + " entries for " + std::to_string(ev->size()) +
                                     " edges (edges_vertices)");
    for (size_t e = 0; e < ea->size(); ++e) {
      const Json& a = (*ea)[e];
      const std::string t = a.is_string() ? a.get<std::string>() : "";
      const char c = t.size() == 1 ? static_cast<char>(std::toupper(static_cast<unsigned char>(t[0]))) : '?';
      if (c == 'C')
        r.fail(Reader::at("edges_assignment", e),
               "C (a cut) is not supported: panels on either side of a cut share its vertices here; split the vertices");
      if (std::string("BMVFUJ").find(c) == std::string::npos)
        r.fail(Reader::at("edges_assignment", e), "unknown assignment " +
                                                              (a.is_string() ? a.dump().substr(0, 40) : "(" + std::string(a.type_name()) + ")") +
                                                              " (B, M, V, F, U, C or J)");
      s.assignments += c;
    }
  }
  const Json* fa = r.array(j, "edges_foldAngle");
  if (!fa) fa = r.array(j, "edges_foldAngles");  // FOLD 1.0's name
  if (fa) {
    if (!ev) r.fail("edges_foldAngle", "given without edges_vertices");
    if (fa->size() != ev->size())
      r.fail("edges_foldAngle", "has " + std::to_string(fa->size()) + " entries for " + std::to_string(ev->size()) + " edges");
    for (size_t e = 0; e < fa->size(); ++e) {
      const Json& a = (*fa)[e];
      if (!a.is_number() && !a.is_null()) r.fail(Reader::at("edges_foldAngle", e), "a fold angle is a number (degrees)");
      const double v = a.is_number() ? a.get<double>() : 0.0;
      if (!std::isfinite(v) || v < -180 || v > 180) r.fail(Reader::at("edges_foldAngle", e), "a fold angle is degrees in [-180, 180]");
      s.fold_angles.push_back(v);
    }
  }
  if (s.faces.empty()) {
    if (!ev || s.edges.empty()) r.fail("faces_vertices", "missing, and there are no edges_vertices to find the faces from");
    if (!planar_pattern)
      r.fail("faces_vertices", "missing: faces can be traced only from a 2D crease pattern (this one is folded in 3D)");
    s.faces = traceFaces(s.vertices, s.edges);
    s.traced_faces = true;
    if (s.faces.empty()) r.fail("faces_vertices", "missing, and the edges enclose no face");
  }
  // How many faces have each side: without edges_vertices the sides are the edges, and without
  // edges_assignment an edge of one face is the boundary (B), of two unassigned (U).
  std::map<std::pair<int, int>, int> faces_at;
  for (const auto& f : s.faces)
    for (size_t i = 0; i < f.size(); ++i) ++faces_at[std::minmax(f[i], f[(i + 1) % f.size()])];
  if (!ev)
    for (const auto& [e, c] : faces_at) s.edges.push_back({e.first, e.second});
  if (s.assignments.empty())
    for (const auto& e : s.edges) s.assignments += faces_at[std::minmax(e[0], e[1])] == 1 ? 'B' : 'U';
  // Planar faces: within 1e-6 of the sheet's size of the face's plane.
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (const auto& x : s.vertices)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], x[k]), hi[k] = std::max(hi[k], x[k]);
  const double size = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  for (size_t f = 0; f < s.faces.size(); ++f) {
    const auto& face = s.faces[f];
    double nrm[3] = {0, 0, 0}, c[3] = {0, 0, 0};
    for (size_t i = 0; i < face.size(); ++i) {
      const auto& a = s.vertices[static_cast<size_t>(face[i])];
      const auto& b = s.vertices[static_cast<size_t>(face[(i + 1) % face.size()])];
      nrm[0] += (a[1] - b[1]) * (a[2] + b[2]);
      nrm[1] += (a[2] - b[2]) * (a[0] + b[0]);
      nrm[2] += (a[0] - b[0]) * (a[1] + b[1]);
      for (int k = 0; k < 3; ++k) c[k] += a[k] / static_cast<double>(face.size());
    }
    const double len = std::sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
    if (!(len > 1e-12 * size * size))
      r.fail(Reader::at("faces_vertices", f), "the face has no area (its vertices are collinear)");
    for (size_t i = 0; i < face.size(); ++i) {
      const auto& a = s.vertices[static_cast<size_t>(face[i])];
      const double off = std::abs((a[0] - c[0]) * nrm[0] + (a[1] - c[1]) * nrm[1] + (a[2] - c[2]) * nrm[2]) / len;
      if (off > 1e-6 * size) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "%.3g", off);
        r.fail(Reader::at("faces_vertices", f), "the face is not planar: vertex " + std::to_string(face[i]) + " is " +
                                                    buf + " off its plane (a rigid panel is flat)");
      }
    }
  }
  return s;
}

}  // namespace flexure::scenes
