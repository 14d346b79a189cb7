// TOML scene files to Scene. Every problem is a SceneError with the file, line and column of
// the offending node; nothing is guessed.
#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "engine/contraction.h"
#include "engine/systems/angular_framework.h"
#include "engine/systems/body_framework.h"
#include "engine/systems/framework.h"
#include "engine/systems/framework_on_surface.h"
#include "engine/systems/origami.h"
#include "engine/systems/polytope.h"
#include "engine/systems/sphere_packing.h"
#include "engine/systems/spherical_disk_packing.h"
#include "engine/systems/volume_hypergraph.h"
#include "engine/random.h"
#include "scenes/catalog.h"
#include "scenes/expression.h"
#include "scenes/fold_file.h"
#include "scenes/importers.h"
#include "scenes/json_text.h"
#include "scenes/path_file.h"
#include "scenes/keys.h"
#include "scenes/scene.h"
#include "scenes/scene_document.h"
#include "scenes/scene_edit.h"
#include "scenes/toml_text.h"

namespace flexure::scenes {

namespace {

using engine::Matrix;

std::string fmt(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}


std::string typeName(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::table: return "a table";
    case toml::node_type::array: return "an array";
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a number";
    case toml::node_type::boolean: return "a boolean";
    default: return "a date or time";
  }
}

// Reads one parsed document; knows the file name for messages.
class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const toml::source_region& src, const std::string& message,
                         int column_shift = 0) const {
    const std::string file = src.path ? std::string(*src.path) : file_;
    throw SceneError(file, std::max<int>(1, static_cast<int>(src.begin.line)),
                     std::max<int>(1, static_cast<int>(src.begin.column)) + column_shift, message);
  }
  [[noreturn]] void fail(const toml::node& n, const std::string& message) const {
    fail(n.source(), message);
  }

  // Rejects keys not in `allowed`, pointing at the key, with a suggestion when one is close.
  void checkKeys(const toml::table& t, const std::vector<std::string>& allowed,
                 const std::string& where) const {
    for (auto&& [key, node] : t) {
      const std::string k(key.str());
      if (std::find(allowed.begin(), allowed.end(), k) != allowed.end()) continue;
      std::string msg = "unknown key '" + k + "' in " + where;
      std::string best;
      int best_d = 3;
      for (const auto& a : allowed) {
        const int d = editDistance(k, a);
        if (d < best_d) best_d = d, best = a;
      }
      if (!best.empty()) msg += " (did you mean '" + best + "'?)";
      else {
        msg += " (known: ";
        for (size_t i = 0; i < allowed.size(); ++i) msg += (i ? ", " : "") + allowed[i];
        msg += ")";
      }
      fail(key.source().begin.line ? key.source() : node.source(), msg);
    }
  }

  double number(const toml::node& n, const std::string& what) const {
    double v = 0.0;
    if (auto i = n.as_integer()) {
      v = static_cast<double>(i->get());
    } else if (auto f = n.as_floating_point()) {
      v = f->get();
    } else if (auto s = n.as_string()) {
      try {
        v = evaluateExpression(s->get());
      } catch (const ExpressionError& e) {
        // +1 for the opening quote
        fail(n.source(), what + ": " + e.what() + " in \"" + s->get() + "\"", e.offset + 1);
      }
    } else {
      fail(n, what + " must be a number or an expression string, not " + typeName(n));
    }
    if (std::isnan(v)) fail(n, what + " is NaN");
    if (std::isinf(v)) fail(n, what + " is infinite");
    return v;
  }

  long long integer(const toml::node& n, const std::string& what) const {
    if (auto i = n.as_integer()) return i->get();
    fail(n, what + " must be an integer, not " + typeName(n));
  }

  const toml::array& array(const toml::node& n, const std::string& what) const {
    if (auto a = n.as_array()) return *a;
    fail(n, what + " must be an array, not " + typeName(n));
  }

  const toml::table& table(const toml::node& n, const std::string& what) const {
    if (auto t = n.as_table()) return *t;
    fail(n, what + " must be a table, not " + typeName(n));
  }

  std::string string(const toml::node& n, const std::string& what) const {
    if (auto s = n.as_string()) return s->get();
    fail(n, what + " must be a string, not " + typeName(n));
  }

  const toml::node& require(const toml::table& t, const std::string& key,
                            const std::string& where) const {
    if (const toml::node* n = t.get(key)) return *n;
    fail(t.source(), where + " needs the key '" + key + "'");
  }

  const std::string& file() const { return file_; }

 private:
  std::string file_;
};

// Vertex numbers as written in the file -> 0-based, with range checks.
struct VertexIndexer {
  const Reader& r;
  int base;
  int count;
  int operator()(const toml::node& n, const std::string& what) const {
    const long long v = r.integer(n, what);
    if (v < base || v >= base + count)
      r.fail(n, what + " " + std::to_string(v) + " is out of range: vertices are numbered " +
                    std::to_string(base) + ".." + std::to_string(base + count - 1));
    return static_cast<int>(v - base);
  }
};

Matrix readVertices(const Reader& r, const toml::table& sys, std::vector<int> allowed_dims) {
  const toml::array& verts = r.array(r.require(sys, "vertices", "[system]"), "vertices");
  if (verts.empty()) r.fail(verts, "vertices is empty");
  int d = -1;
  Matrix p;
  for (size_t i = 0; i < verts.size(); ++i) {
    const toml::array& v = r.array(verts[i], "vertex " + std::to_string(i + 1));
    if (d < 0) {
      d = static_cast<int>(v.size());
      if (std::find(allowed_dims.begin(), allowed_dims.end(), d) == allowed_dims.end()) {
        std::string dims;
        for (size_t k = 0; k < allowed_dims.size(); ++k)
          dims += (k ? " or " : "") + std::to_string(allowed_dims[k]);
        r.fail(v, "a vertex has " + std::to_string(d) + " coordinates; this system type needs " + dims);
      }
      p.resize(d, static_cast<Eigen::Index>(verts.size()));
    } else if (static_cast<int>(v.size()) != d) {
      r.fail(v, "vertex " + std::to_string(i + 1) + " has " + std::to_string(v.size()) +
                    " coordinates, but the first vertex has " + std::to_string(d));
    }
    for (int k = 0; k < d; ++k) {
      const double x = r.number(v[k], "coordinate");
      if (std::abs(x) > kMaxCoordinate)
        r.fail(v[k], "coordinate " + fmt(x) + " is beyond +-" + fmt(kMaxCoordinate) +
                         ": squared lengths must stay finite; rescale the configuration");
      p(k, static_cast<Eigen::Index>(i)) = x;
    }
  }
  // The size of the configuration (largest coordinate range), not its distance from 0: a
  // square of side 1e-200 has squared lengths that underflow.
  const double extent = p.cols() > 1 ? (p.rowwise().maxCoeff() - p.rowwise().minCoeff()).maxCoeff() : 0.0;
  if (extent > 0 && extent < kMinExtent)
    r.fail(verts, "the vertices span only " + fmt(extent) + "; configurations must span at least " +
                      fmt(kMinExtent) + " (squared lengths must not underflow): rescale them");
  return p;
}

std::vector<int> readPinned(const Reader& r, const toml::table& sys, const VertexIndexer& vi) {
  std::vector<int> pinned;
  const toml::node* n = sys.get("pinned");
  if (!n) return pinned;
  std::map<int, const toml::node*> seen;
  for (const toml::node& e : r.array(*n, "pinned")) {
    const int v = vi(e, "pinned vertex");
    if (seen.count(v)) r.fail(e, "vertex " + std::to_string(v + vi.base) + " is pinned twice");
    seen[v] = &e;
    pinned.push_back(v);
  }
  return pinned;
}

// Flex coefficients in the nontrivial-flex basis, e.g. [1, 0.5]; not all zero.
std::vector<double> readCoefficients(const Reader& r, const toml::node& n, const std::string& what) {
  const toml::array& a = r.array(n, what);
  if (a.empty()) r.fail(n, what + " needs at least one coefficient");
  std::vector<double> c;
  for (const toml::node& e : a) c.push_back(r.number(e, "flex coefficient"));
  if (std::all_of(c.begin(), c.end(), [](double v) { return v == 0.0; }))
    r.fail(n, what + " coefficients are all zero: that is no direction");
  return c;
}

render::Color readColor(const Reader& r, const toml::node& n, const std::string& what) {
  const std::string text = r.string(n, what);
  const auto c = parseColor(text);
  if (!c) r.fail(n, what + ": unknown colour '" + text + "' (use #RRGGBB, #RRGGBBAA or a name such as steelblue)");
  return *c;
}

bool readFlag(const Reader& r, const toml::node& n, const std::string& what) {
  if (auto b = n.as_boolean()) return b->get();
  r.fail(n, what + " must be true or false, not " + typeName(n));
}

// The keys of `table` (scenes/keys.h) that `t` holds and that the table reads itself (numbers,
// integers, flags, colours, seeds), checked against their ranges, into `scene`.
void readSimpleKeys(const Reader& r, const toml::table& t, const std::string& table, Scene& scene) {
  for (const KeySpec& k : sceneKeys()) {
    if (k.table != table || k.kind == KeyKind::Custom) continue;
    const toml::node* n = t.get(k.key);
    if (!n) continue;
    const std::string& key = k.key;
    auto outside = [&](const std::string& lo, const std::string& hi) {
      r.fail(*n, !k.range_message.empty() ? k.range_message : key + " must be between " + lo + " and " + hi);
    };
    switch (k.kind) {
      case KeyKind::Integer: {
        const long long v = r.integer(*n, key);
        if (v < k.lo || v > k.hi) outside(std::to_string(static_cast<long long>(k.lo)), std::to_string(static_cast<long long>(k.hi)));
        std::get<int& (*)(Scene&)>(k.field)(scene) = static_cast<int>(v);
        break;
      }
      case KeyKind::Number: {
        const double v = r.number(*n, key);
        const bool above = k.open_lo ? v > k.lo : v >= k.lo, below = k.open_hi ? v < k.hi : v <= k.hi;
        if (!(above && below)) outside(fmt(k.lo), fmt(k.hi));
        std::get<double& (*)(Scene&)>(k.field)(scene) = v;
        break;
      }
      case KeyKind::Flag: std::get<bool& (*)(Scene&)>(k.field)(scene) = readFlag(r, *n, key); break;
      case KeyKind::Color: std::get<render::Color& (*)(Scene&)>(k.field)(scene) = readColor(r, *n, key); break;
      case KeyKind::OptionalColor:
        std::get<std::optional<render::Color>& (*)(Scene&)>(k.field)(scene) = readColor(r, *n, key);
        break;
      case KeyKind::Seed:
      case KeyKind::OptionalSeed: {
        const long long v = r.integer(*n, key);
        if (v < 0) r.fail(*n, key + " must be a nonnegative integer");
        if (k.kind == KeyKind::Seed) std::get<std::uint64_t& (*)(Scene&)>(k.field)(scene) = static_cast<std::uint64_t>(v);
        else std::get<std::optional<std::uint64_t>& (*)(Scene&)>(k.field)(scene) = static_cast<std::uint64_t>(v);
        break;
      }
      case KeyKind::Custom: break;
    }
  }
}

std::vector<std::vector<int>> readVertexLists(const Reader& r, const toml::table& sys, const std::string& key,
                                              const VertexIndexer& vi, const std::string& what, size_t min_size,
                                              size_t max_size, bool required);
[[noreturn]] void failAt(const Reader& r, const toml::table& sys, const engine::ModelError& e);

std::unique_ptr<engine::Model> buildFramework(const Reader& r, const toml::table& sys, int base) {
  r.checkKeys(sys, keysOf("system", "framework"), "[system] (framework)");
  const Matrix p = readVertices(r, sys, {2, 3});
  const int n = static_cast<int>(p.cols());
  const VertexIndexer vi{r, base, n};
  std::vector<engine::Framework::Edge> edges;
  std::vector<const toml::node*> edge_nodes;
  std::map<std::pair<int, int>, size_t> seen;
  const toml::array& es = r.array(r.require(sys, "edges", "[system]"), "edges");
  for (const toml::node& en : es) {
    const toml::array& e = r.array(en, "an edge");
    if (e.size() != 2) r.fail(e, "an edge joins 2 vertices, this one lists " + std::to_string(e.size()));
    const int a = vi(e[0], "edge vertex"), b = vi(e[1], "edge vertex");
    const std::string name = "[" + std::to_string(a + base) + ", " + std::to_string(b + base) + "]";
    if (a == b) r.fail(e, "edge " + name + " joins a vertex to itself");
    const auto key = std::minmax(a, b);
    if (auto it = seen.find(key); it != seen.end())
      r.fail(e, "duplicate edge " + name + " (the same pair as edge " +
                    std::to_string(it->second + 1) + ")");
    seen[key] = edges.size();
    edges.push_back({a, b});
    edge_nodes.push_back(&en);
  }
  std::vector<double> lengths;
  if (const toml::node* ln = sys.get("lengths")) {
    const toml::array& la = r.array(*ln, "lengths");
    if (la.size() != edges.size())
      r.fail(la, "lengths has " + std::to_string(la.size()) + " entries for " +
                     std::to_string(edges.size()) + " edges");
    for (size_t e = 0; e < la.size(); ++e) {
      const double l = r.number(la[e], "edge length");
      if (!(l > 0)) r.fail(la[e], "edge lengths must be positive");
      lengths.push_back(l);
    }
  }
  // Degenerate edges, and realizations that do not satisfy their own constraints.
  // Relative to the size of the configuration (its bounding-box diagonal), so that a framework
  // drawn at 1e-12 or 1e12 is judged like the same one at 1.
  const double scale = (p.rowwise().maxCoeff() - p.rowwise().minCoeff()).norm();
  for (size_t e = 0; e < edges.size(); ++e) {
    const auto [a, b] = edges[e];
    const double l = (p.col(a) - p.col(b)).norm();
    const std::string name = "[" + std::to_string(a + base) + ", " + std::to_string(b + base) + "]";
    if (l <= 1e-12 * scale)
      r.fail(*edge_nodes[e], "edge " + name + " has length 0: vertices " + std::to_string(a + base) +
                                 " and " + std::to_string(b + base) + " coincide");
    if (!lengths.empty()) {
      const double residual = l * l - lengths[e] * lengths[e];
      if (std::abs(residual) > 1e-9 * std::max(l * l, lengths[e] * lengths[e]))
        r.fail(*sys.get("lengths")->as_array()->get(e),
               "the realization does not satisfy edge " + name + ": its length is " + fmt(l) +
                   ", lengths says " + fmt(lengths[e]) + " (residual " + fmt(residual) + ")");
    }
  }
  const std::vector<int> pinned = readPinned(r, sys, vi);
  // attached = [[v, a, b(, c)], ...]: vertex v held in the frame of a, b (and c).
  std::vector<engine::Attachment> attached;
  for (auto& l : readVertexLists(r, sys, "attached", vi, "an attachment", 3, 4, false))
    attached.push_back({l[0], std::vector<int>(l.begin() + 1, l.end())});
  try {
    return std::make_unique<engine::Framework>(p, std::move(edges), pinned, lengths, std::move(attached));
  } catch (const engine::ModelError& e) {
    failAt(r, sys, e);
  }
}

// Lists of vertex numbers: facets, bodies, simplices (min_size..max_size entries each), and
// pairs and triples (fixed size).
std::vector<std::vector<int>> readVertexLists(const Reader& r, const toml::table& sys, const std::string& key,
                                              const VertexIndexer& vi, const std::string& what, size_t min_size,
                                              size_t max_size, bool required = true) {
  std::vector<std::vector<int>> out;
  const toml::node* n = sys.get(key);
  if (!n) {
    if (required) r.require(sys, key, "[system]");
    return out;
  }
  const toml::array& a = r.array(*n, key);
  for (const toml::node& en : a) {
    const toml::array& e = r.array(en, what);
    if (e.size() < min_size || e.size() > max_size) {
      const std::string want = min_size == max_size ? std::to_string(min_size)
                               : max_size == static_cast<size_t>(-1) ? "at least " + std::to_string(min_size)
                               : std::to_string(min_size) + " to " + std::to_string(max_size);
      r.fail(e, what + " lists " + want + (want == "at least 1" ? " vertex" : " vertices") + ", this one " +
                    std::to_string(e.size()));
    }
    std::vector<int> list;
    for (const toml::node& v : e) list.push_back(vi(v, what + " vertex"));
    out.push_back(std::move(list));
  }
  return out;
}

template <size_t N>
std::vector<std::array<int, N>> toArrays(const std::vector<std::vector<int>>& lists) {
  std::vector<std::array<int, N>> out;
  for (const auto& l : lists) {
    std::array<int, N> a{};
    std::copy(l.begin(), l.end(), a.begin());
    out.push_back(a);
  }
  return out;
}

// A ModelError points at an item of a [system] key: fail there.
[[noreturn]] void failAt(const Reader& r, const toml::table& sys, const engine::ModelError& e) {
  if (const toml::node* n = sys.get(e.key)) {
    if (const toml::array* a = n->as_array(); a && e.item >= 0 && static_cast<size_t>(e.item) < a->size())
      r.fail(*a->get(static_cast<size_t>(e.item)), e.what());
    r.fail(*n, e.what());
  }
  r.fail(sys.source(), e.what());
}

// sys.get(key) as a boolean (default false).
bool optionalFlag(const Reader& r, const toml::table& sys, const char* key) {
  const toml::node* n = sys.get(key);
  return n ? readFlag(r, *n, key) : false;
}

// f(x, y, z) from a scene string, with exact derivatives.
class ExpressionField final : public engine::ScalarField {
 public:
  explicit ExpressionField(CompiledExpression e) : e_(std::move(e)) {}
  double value(const double* x) const override { return e_.value(x); }
  void evaluate(const double* x, double* f, double* g, double* h) const override { e_.evaluate(x, f, g, h); }
  std::string text() const override { return "\"" + e_.text() + "\""; }

 private:
  CompiledExpression e_;
};

std::unique_ptr<engine::Model> buildOtherType(const Reader& r, const toml::table& sys, int base,
                                              const std::string& type) {
  auto keys = [&]() { r.checkKeys(sys, keysOf("system", type), "[system] (" + type + ")"); };
  const size_t any = static_cast<size_t>(-1);
  try {
    if (type == "polytope") {
      keys();
      const Matrix p = readVertices(r, sys, {3});
      const VertexIndexer vi{r, base, static_cast<int>(p.cols())};
      // facets = "hull": the facets of the vertices' convex hull.
      const toml::node& fn = r.require(sys, "facets", "[system]");
      std::vector<std::vector<int>> facets;
      if (fn.is_string()) {
        if (r.string(fn, "facets") != "hull")
          r.fail(fn, "facets must be a list of vertex cycles or \"hull\" (the facets of the convex hull)");
        facets = engine::convexHullFacets(p, 1e-9, base);
      } else {
        facets = readVertexLists(r, sys, "facets", vi, "a facet", 3, any);
      }
      return std::make_unique<engine::Polytope>(p, std::move(facets), readPinned(r, sys, vi), 1e-8, base);
    }
    if (type == "body_hinge" || type == "body_bar") {
      keys();
      const Matrix p = readVertices(r, sys, {2, 3});
      const VertexIndexer vi{r, base, static_cast<int>(p.cols())};
      auto bodies = readVertexLists(r, sys, "bodies", vi, "a body", 1, any);
      auto bars = toArrays<2>(readVertexLists(r, sys, "bars", vi, "a bar", 2, 2, type == "body_bar"));
      return std::make_unique<engine::BodyFramework>(type, p, std::move(bodies), bars, readPinned(r, sys, vi), base);
    }
    if (type == "origami") {
      keys();
      Matrix p = readVertices(r, sys, {2, 3});
      if (p.rows() == 2) {  // a crease pattern in the plane z = 0
        p.conservativeResize(3, Eigen::NoChange);
        p.row(2).setZero();
      }
      const VertexIndexer vi{r, base, static_cast<int>(p.cols())};
      auto faces = readVertexLists(r, sys, "faces", vi, "a face", 3, any);
      auto creases = toArrays<2>(readVertexLists(r, sys, "creases", vi, "a crease", 2, 2));
      std::string assignments;
      if (const toml::node* an = sys.get("assignments")) {
        assignments = r.string(*an, "assignments");
        if (assignments.size() != creases.size())
          r.fail(*an, "assignments has " + std::to_string(assignments.size()) + " letters for " +
                          std::to_string(creases.size()) + " creases");
        for (char& c : assignments) {
          c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
          if (std::string("BMVFUJ").find(c) == std::string::npos)
            r.fail(*an, std::string("assignments: unknown letter '") + c + "' (B, M, V, F, U or J)");
        }
      } else {
        assignments.assign(creases.size(), 'U');
      }
      std::vector<engine::Crease> edges;
      for (size_t e = 0; e < creases.size(); ++e) {
        engine::Crease c;
        c.a = creases[e][0], c.b = creases[e][1], c.assignment = assignments[e];
        edges.push_back(c);
      }
      return std::make_unique<engine::Origami>(p, std::move(faces), std::move(edges), readPinned(r, sys, vi), base);
    }
    if (type == "angular_framework") {
      keys();
      const Matrix p = readVertices(r, sys, {2, 3});
      const VertexIndexer vi{r, base, static_cast<int>(p.cols())};
      auto angles = toArrays<3>(readVertexLists(r, sys, "angles", vi, "an angle", 3, 3));
      return std::make_unique<engine::AngularFramework>(p, std::move(angles), readPinned(r, sys, vi), base);
    }
    if (type == "volume_hypergraph") {
      keys();
      const Matrix p = readVertices(r, sys, {2, 3});
      const VertexIndexer vi{r, base, static_cast<int>(p.cols())};
      auto simplices = readVertexLists(r, sys, "simplices", vi, "a simplex", 3, 4);
      return std::make_unique<engine::VolumeHypergraph>(p, std::move(simplices), readPinned(r, sys, vi), base);
    }
    if (type == "spherical_disk_packing") {
      keys();
      const Matrix p = readVertices(r, sys, {3});
      const VertexIndexer vi{r, base, static_cast<int>(p.cols())};
      auto contacts = toArrays<2>(readVertexLists(r, sys, "contacts", vi, "a contact", 2, 2));
      return std::make_unique<engine::SphericalDiskPacking>(p, std::move(contacts), readPinned(r, sys, vi), base);
    }
    if (type == "sphere_packing") {
      keys();
      const Matrix p = readVertices(r, sys, {2, 3});
      const int n = static_cast<int>(p.cols());
      const VertexIndexer vi{r, base, n};
      const toml::node* rn = sys.get("radii");
      const toml::node* one = sys.get("radius");
      if (rn && one) r.fail(*one, "give either radii (one per vertex) or radius (the same for all), not both");
      if (!rn && !one) r.require(sys, "radii", "[system] (sphere_packing; or one 'radius' for all)");
      std::vector<double> radii;
      if (one) {
        const double v = r.number(*one, "radius");
        if (!(v > 0)) r.fail(*one, "radius must be positive");
        radii.assign(static_cast<size_t>(n), v);
      } else {
        const toml::array& ra = r.array(*rn, "radii");
        if (static_cast<int>(ra.size()) != n)
          r.fail(ra, "radii has " + std::to_string(ra.size()) + " entries for " + std::to_string(n) + " vertices");
        for (const toml::node& e : ra) radii.push_back(r.number(e, "a radius"));
      }
      double tolerance = 1e-6;
      if (const toml::node* tn = sys.get("tolerance")) tolerance = r.number(*tn, "tolerance");
      return std::make_unique<engine::SpherePacking>(p, std::move(radii), readPinned(r, sys, vi), tolerance, base);
    }
    if (type == "framework_on_surface") {
      keys();
      const Matrix p = readVertices(r, sys, {3});
      const VertexIndexer vi{r, base, static_cast<int>(p.cols())};
      auto edges = toArrays<2>(readVertexLists(r, sys, "edges", vi, "an edge", 2, 2));
      const toml::node& sn = r.require(sys, "surface", "[system]");
      const std::string text = r.string(sn, "surface");
      std::shared_ptr<const engine::ScalarField> field;
      try {
        CompiledExpression e(text, {"x", "y", "z"});
        if (!e.usesVariable(0) && !e.usesVariable(1) && !e.usesVariable(2))
          r.fail(sn, "surface \"" + text + "\" does not depend on x, y or z");
        field = std::make_shared<ExpressionField>(std::move(e));
      } catch (const ExpressionError& e) {
        r.fail(sn.source(), "surface: " + std::string(e.what()) + " in \"" + text + "\"", e.offset + 1);
      }
      return std::make_unique<engine::FrameworkOnSurface>(p, std::move(edges), readPinned(r, sys, vi), field,
                                                          optionalFlag(r, sys, "project_start"), base);
    }
  } catch (const engine::ModelError& e) {
    failAt(r, sys, e);
  }
  return nullptr;
}

const std::vector<std::string> kSystemTypes = {"framework",         "framework_on_surface", "angular_framework",
                                               "polytope",          "body_hinge",           "body_bar",
                                               "volume_hypergraph", "sphere_packing",       "spherical_disk_packing",
                                               "origami",           "catalog"};


std::unique_ptr<engine::Model> buildModel(const Reader& r, const toml::table& sys, int base,
                                          std::string& type_out, int depth, toml::table* resolved = nullptr);

std::unique_ptr<engine::Model> buildCatalog(const Reader& r, const toml::table& sys, int outer_base,
                                            std::string& type_out, int depth, toml::table* resolved) {
  r.checkKeys(sys, keysOf("system", "catalog"), "[system] (catalog)");
  const toml::node& nn = r.require(sys, "name", "[system]");
  const std::string name = r.string(nn, "name");
  const CatalogEntry* entry = findCatalogEntry(name);
  if (!entry) {
    std::string known;
    for (const auto& e : catalog()) known += (known.empty() ? "" : ", ") + e.name;
    r.fail(nn, "unknown catalog name '" + name + "' (see `flexure catalog`: " + known + ")");
  }
  if (depth > 4) r.fail(nn, "catalog entries refer to each other in a loop");
  const std::string src = "catalog:" + entry->name;
  toml::table doc;
  try {
    doc = toml::parse(entry->text, src);
  } catch (const toml::parse_error& e) {
    r.fail(e.source(), std::string(e.description()));
  }
  Reader inner(src);
  int base = 1;
  if (const toml::node* b = doc.get("index_base")) base = static_cast<int>(inner.integer(*b, "index_base"));
  const toml::table& entry_system = inner.table(inner.require(doc, "system", "the scene"), "[system]");
  // The scene's own text (a path JSON's scene, a viewer's moved start) holds the entry's system
  // where it numbers vertices as the scene does.
  if (resolved && base == outer_base && !entry_system.contains("from")) *resolved = entry_system;
  return buildModel(inner, entry_system, base, type_out, depth + 1);
}

// A graph's framework table (type, vertices, edges) at its seeded random realization: uniform
// in the unit square or cube, vertex by vertex, from the seed (or at the positions the file
// gives). Vertex numbers from `base`.
toml::table graphSystem(const ImportedGraph& g, int dimension, std::uint64_t seed, int base) {
  engine::Random rng(seed);
  toml::array vertices, edges;
  for (int v = 0; v < g.vertices; ++v) {
    toml::array p;
    if (!g.positions.empty())  // the file's own realization (node-link "pos")
      for (double x : g.positions[static_cast<size_t>(v)]) p.push_back(x);
    else
      for (int k = 0; k < dimension; ++k) p.push_back(rng.uniform());
    vertices.push_back(std::move(p));
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
  const std::string& scene_file = r.file();
  const size_t slash = scene_file.find_last_of('/');
  const std::string path =
      name.empty() || name[0] == '/' || slash == std::string::npos ? name : scene_file.substr(0, slash + 1) + name;
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

std::unique_ptr<engine::Model> buildModel(const Reader& r, const toml::table& sys, int base,
                                          std::string& type_out, int depth, toml::table* resolved) {
  if (const toml::node* from = sys.get("from")) return buildImported(r, sys, *from, base, type_out, depth, resolved);
  const toml::node& tn = r.require(sys, "type", "[system]");
  const std::string type = r.string(tn, "type");
  try {
    if (type == "framework") {
      type_out = type;
      return buildFramework(r, sys, base);
    }
    if (type == "catalog") return buildCatalog(r, sys, base, type_out, depth, resolved);
    if (auto m = buildOtherType(r, sys, base, type)) {
      type_out = type;
      return m;
    }
  } catch (const std::invalid_argument& e) {
    r.fail(sys.source(), e.what());
  }
  std::string known;
  for (const auto& t : kSystemTypes) known += (known.empty() ? "" : ", ") + t;
  r.fail(tn, "unknown or unsupported system type '" + type + "' (this version supports: " + known + ")");
}

// A key's [i, j]: two vertices, 0-based.
std::array<int, 2> vertexPair(const Reader& r, const toml::node& n, const std::string& key, int base, int vertices) {
  const toml::array& a = r.array(n, key);
  if (a.size() != 2) r.fail(n, key + " names 2 vertices, not " + std::to_string(a.size()));
  const VertexIndexer vi{r, base, vertices};
  return {vi(a[0], key + " vertex"), vi(a[1], key + " vertex")};
}

void readMotion(const Reader& r, const toml::table& t, Scene& scene) {
  MotionSettings& m = scene.motion;
  const engine::Model& model = *scene.model;
  const int base = scene.index_base;
  r.checkKeys(t, keysOf("motion"), "[motion]");
  readSimpleKeys(r, t, "motion", scene);
  m.steps_given = t.get("steps") != nullptr;
  const toml::node* ce = t.get("contract_edge");
  const toml::node* tl = t.get("target_length");
  if (ce || tl) {
    if (!ce) r.fail(*tl, "target_length needs contract_edge = [i, j], the edge to contract");
    if (!tl) r.fail(*ce, "contract_edge needs target_length, the length to reach");
    const auto [i, j] = vertexPair(r, *ce, "contract_edge", base, model.system().numVertices());
    if (engine::distanceEquation(model.system(), i, j) < 0)
      r.fail(*ce, "[" + std::to_string(i + base) + ", " + std::to_string(j + base) +
                      "] is not an edge with a length constraint between free vertices of this system");
    // A rigid body's distance cannot change: contracting it deformed the body, and every body
    // whose rigidity shares that distance (a strip of panels shrank as a whole). Bars between
    // bodies contract.
    if (const auto* bodies = dynamic_cast<const engine::BodyFramework*>(&model))
      if (const int k = bodies->bodyHolding(i, j); k >= 0)
        r.fail(*ce, "[" + std::to_string(i + base) + ", " + std::to_string(j + base) + "] lies in " +
                        (scene.type == "origami" ? "a panel" : "body " + std::to_string(k + 1)) +
                        ", which is rigid: its length cannot change (contract a bar between bodies)");
    m.contract_edge = std::array<int, 2>{i, j};
    m.target_length = r.number(*tl, "target_length");
    if (!(m.target_length > 0)) r.fail(*tl, "target_length must be positive");
    // Without steps the contraction takes as many as it needs: bounded here, where the
    // numbers are.
    const engine::Matrix p = model.system().vertexPositions(model.startCoordinates());
    const double now = (p.col(i) - p.col(j)).norm();
    const double needed = std::ceil(std::abs(m.target_length - now) / m.step_size);
    const double most = std::min<double>(kMaxSteps, kMaxPathValues / model.system().numVariables() - 1);
    if (!m.steps_given && needed > most)
      r.fail(*tl, "going from length " + fmt(now) + " to " + fmt(m.target_length) + " in steps of " +
                      fmt(m.step_size) + " takes " + fmt(needed) + " steps; at most " +
                      std::to_string(static_cast<long long>(most)) + " here (a larger step_size, or steps = N to stop earlier)");
    if (t.get("flex")) r.fail(*t.get("flex"), "flex does not apply to an edge contraction (the edge length drives it)");
  }
  // Driving an origami fold: one crease to an angle, or every mountain and valley toward a
  // fold percentage.
  const toml::node* fc = t.get("fold_crease");
  const toml::node* fa = t.get("fold_angle");
  const toml::node* fp = t.get("fold_percent");
  if (fc || fa || fp) {
    const toml::node& at = fc ? *fc : fa ? *fa : *fp;
    const auto* origami = dynamic_cast<const engine::Origami*>(&model);
    if (!origami) r.fail(at, "fold driving applies to origami; this system is a " + model.typeName());
    if (ce) r.fail(at, "drive a fold or contract an edge, not both");
    if (t.get("flex")) r.fail(*t.get("flex"), "flex does not apply to a driven fold (the fold drives it)");
    if (fp && (fc || fa)) r.fail(*fp, "fold_percent drives every crease; fold_crease and fold_angle drive one: not both");
    if (fp) {
      const double v = r.number(*fp, "fold_percent");
      if (!(v >= 0 && v <= 100)) r.fail(*fp, "fold_percent is a percentage of the full fold, in [0, 100]");
      bool any = false;
      for (const engine::Crease& c : origami->edges())
        any = any || (c.left >= 0 && c.right >= 0 && (c.assignment == 'M' || c.assignment == 'V'));
      if (!any) r.fail(*fp, "fold_percent needs mountain (M) or valley (V) creases, and this sheet has none");
      m.fold_percent = v;
    } else {
      if (!fc) r.fail(*fa, "fold_angle needs fold_crease = [i, j], the crease to fold");
      if (!fa) r.fail(*fc, "fold_crease needs fold_angle, the angle to fold it to (degrees, + valley)");
      const auto [i, j] = vertexPair(r, *fc, "fold_crease", base, model.system().numVertices());
      const std::string name = "[" + std::to_string(i + base) + ", " + std::to_string(j + base) + "]";
      int found = -1;
      for (size_t e = 0; e < origami->edges().size(); ++e) {
        const engine::Crease& c = origami->edges()[e];
        if (std::minmax(c.a, c.b) == std::minmax(i, j)) found = static_cast<int>(e);
      }
      if (found < 0) r.fail(*fc, name + " is not an edge of the sheet");
      const engine::Crease& c = origami->edges()[static_cast<size_t>(found)];
      if (c.left < 0 || c.right < 0) r.fail(*fc, name + " is on the sheet's boundary: only a crease between two faces folds");
      if (origami->panelOfFace()[static_cast<size_t>(c.left)] == origami->panelOfFace()[static_cast<size_t>(c.right)])
        r.fail(*fc, name + " is a " + std::string(1, c.assignment) + " edge inside a rigid panel: it does not fold");
      const double deg = r.number(*fa, "fold_angle");
      if (!(deg >= -180 && deg <= 180)) r.fail(*fa, "fold_angle is degrees in [-180, 180] (+ valley, - mountain)");
      m.fold_crease = found;
      m.fold_angle = deg * M_PI / 180;
    }
  }
  if (const toml::node* n = t.get("flex")) {
    const auto& src = n->source();
    m.flex_file = src.path ? std::string(*src.path) : r.file();
    m.flex_line = static_cast<int>(src.begin.line);
    m.flex_column = static_cast<int>(src.begin.column);
    if (auto s = n->as_string()) {
      if (s->get() != "auto") r.fail(*n, "flex must be \"auto\" or an array of coefficients");
      m.flex.reset();
    } else {
      m.flex = readCoefficients(r, *n, "flex");
    }
  }
}

void readAnalysis(const Reader& r, const toml::table& t, Scene& scene) {
  r.checkKeys(t, keysOf("analysis"), "[analysis]");
  readSimpleKeys(r, t, "analysis", scene);
}

// The animation keys of [render] that are not simple (vertex numbers, a direction, a simplex).
void readAnimation(const Reader& r, const toml::table& t, AnimationSettings& a, int base, const engine::Model& model) {
  const int n = model.system().numVertices(), d = model.system().dimension();
  if (const toml::node* v = t.get("fixed_vertices")) {
    const toml::array& arr = r.array(*v, "fixed_vertices");
    if (!arr.empty() && (arr.size() < 2 || static_cast<int>(arr.size()) > d))
      r.fail(*v, "fixed_vertices lists 2" + std::string(d == 3 ? " or 3" : "") + " vertices (or none), not " +
                     std::to_string(arr.size()));
    const VertexIndexer vi{r, base, n};
    std::vector<int> fixed;
    for (const toml::node& e : arr) {
      const int k = vi(e, "fixed vertex");
      if (std::find(fixed.begin(), fixed.end(), k) != fixed.end()) r.fail(e, "a vertex is fixed twice");
      fixed.push_back(k);
    }
    a.fixed_vertices = fixed;
  }
  if (const toml::node* v = t.get("fixed_direction")) {
    const toml::array& arr = r.array(*v, "fixed_direction");
    if (static_cast<int>(arr.size()) != d)
      r.fail(*v, "fixed_direction needs " + std::to_string(d) + " coordinates (the dimension), not " +
                     std::to_string(arr.size()));
    a.fixed_direction.clear();
    double norm = 0;
    for (const toml::node& e : arr) {
      a.fixed_direction.push_back(r.number(e, "fixed_direction coordinate"));
      norm += a.fixed_direction.back() * a.fixed_direction.back();
    }
    if (!(norm > 0)) r.fail(*v, "fixed_direction is the zero vector");
  }
  // Volume hypergraphs are the models whose geometry has simplices.
  const engine::Geometry geometry = model.geometry();
  const bool hypergraph = !geometry.simplices.empty();
  if (const toml::node* v = t.get("fixed_simplex")) {
    if (!hypergraph) r.fail(*v, "fixed_simplex is for volume hypergraphs (use fixed_vertices)");
    if (t.get("fixed_vertices")) r.fail(*v, "give fixed_simplex or fixed_vertices, not both");
    const toml::array& arr = r.array(*v, "fixed_simplex");
    const VertexIndexer vi{r, base, n};
    std::vector<int> simplex;
    for (const toml::node& e : arr) simplex.push_back(vi(e, "fixed_simplex vertex"));
    if (!simplex.empty()) {
      std::vector<int> sorted = simplex;
      std::sort(sorted.begin(), sorted.end());
      bool found = false;
      for (auto s2 : geometry.simplices) {
        std::sort(s2.begin(), s2.end());
        found = found || s2 == sorted;
      }
      if (!found) r.fail(*v, "fixed_simplex must be one of the simplices (in any order)");
    }
    a.fixed_simplex = simplex;
  }
  for (const char* key : {"target_stretch", "tip_value"})
    if (const toml::node* v = t.get(key))
      if (!hypergraph) r.fail(*v, std::string(key) + " is for volume hypergraphs (with fixed_simplex)");
}

void readProjection(const Reader& r, const toml::table& t, Scene& scene) {
  ProjectionSettings& p = scene.projection;
  r.checkKeys(t, keysOf("projection"), "[projection]");
  readSimpleKeys(r, t, "projection", scene);
  if (const toml::node* n = t.get("flexes")) {
    const toml::array& a = r.array(*n, "flexes");
    if (a.empty()) r.fail(*n, "flexes needs at least one list of coefficients");
    if (a.size() > 64) r.fail(*n, "flexes lists more than 64 paths");
    for (const toml::node& e : a) p.flexes.push_back(readCoefficients(r, e, "a flexes entry"));
  }
  if (const toml::node* n = t.get("colors"))
    for (const toml::node& e : r.array(*n, "colors")) p.colors.push_back(readColor(r, e, "colors"));
}

void readRender(const Reader& r, const toml::table& t, Scene& scene) {
  r.checkKeys(t, keysOf("render"), "[render]");
  RenderSettings& s = scene.render;
  readAnimation(r, t, s.animation, scene.index_base, *scene.model);
  if (const toml::node* n = t.get("simplex_colors")) {
    const toml::array& a = r.array(*n, "simplex_colors");
    if (a.empty()) r.fail(*n, "simplex_colors needs at least one colour");
    s.style.simplex_colors.clear();
    for (const toml::node& c : a) s.style.simplex_colors.push_back(readColor(r, c, "simplex_colors"));
  }
  if (const toml::node* n = t.get("view")) {
    // [[x0, y0(, z0)], [x1, y1(, z1)]]: the lower and upper corners, in the scene's dimension.
    const int d = scene.model->system().dimension();
    const toml::array& a = r.array(*n, "view");
    if (a.size() != 2) r.fail(*n, "view is [[lower corner], [upper corner]]: two points");
    std::array<std::array<double, 3>, 2> box{};
    for (int c = 0; c < 2; ++c) {
      const toml::array& pt = r.array(a[static_cast<size_t>(c)], "a view corner");
      if (static_cast<int>(pt.size()) != d)
        r.fail(a[static_cast<size_t>(c)], "a view corner has " + std::to_string(d) + " coordinates in this " +
                                              std::to_string(d) + "D scene, not " + std::to_string(pt.size()));
      for (int k = 0; k < d; ++k) box[c][k] = r.number(pt[static_cast<size_t>(k)], "a view coordinate");
    }
    for (int k = 0; k < d; ++k)
      if (!(box[1][k] > box[0][k])) r.fail(a[1], "view: the upper corner must exceed the lower one on every axis");
    s.style.view_box = box;
  }
  if (const toml::node* n = t.get("title")) s.title = r.string(*n, "title");
  if (const toml::node* n = t.get("subtitle")) s.subtitle = r.string(*n, "subtitle");
  readSimpleKeys(r, t, "render", scene);
  // Sizes and labels given by hand are kept as given; the others follow the figure.
  s.style.auto_size = !t.contains("vertex_size") && !t.contains("line_width") && !t.contains("font_size");
  s.style.auto_labels = !t.contains("labels");
  s.style.auto_padding = !t.contains("padding");
}

void readOutputs(const Reader& r, const toml::node& n, std::vector<OutputSpec>& outs) {
  const toml::array& a = r.array(n, "[[output]]");
  for (const toml::node& e : a) {
    const toml::table& t = r.table(e, "an [[output]] entry");
    r.checkKeys(t, keysOf("output"), "[[output]]");
    OutputSpec o;
    const toml::node& fn = r.require(t, "file", "[[output]]");
    o.file = r.string(fn, "file");
    if (o.file.empty()) r.fail(fn, "file is empty");
    // A scene names files inside its own folder: a downloaded scene cannot write elsewhere.
    if (o.file[0] == '/') r.fail(fn, "file must be a path inside the scene's folder, not the absolute '" + o.file + "'");
    for (size_t at = 0; at <= o.file.size();) {
      const size_t end = std::min(o.file.find('/', at), o.file.size());
      const std::string part = o.file.substr(at, end - at);
      if (part == "..")
        r.fail(fn, "file must be a path inside the scene's folder; '..' leads out of it ('" + o.file + "')");
      if (part.empty() && end < o.file.size()) r.fail(fn, "file has an empty folder name ('" + o.file + "')");
      if (part.empty() || std::any_of(part.begin(), part.end(), [](char c) { return static_cast<unsigned char>(c) < 0x20; }))
        r.fail(fn, part.empty() ? "file names a folder, not a file ('" + o.file + "')"
                                : "file contains a control character");
      at = end + 1;
    }
    const auto dot = o.file.rfind('.');
    std::string ext = dot == std::string::npos ? "" : o.file.substr(dot + 1);
    std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
    std::optional<OutputKind> kind = outputKindOfExtension(ext);
    if (const toml::node* kn = t.get("kind")) {
      const std::string text = r.string(*kn, "kind");
      kind = parseOutputKind(text);
      if (!kind) r.fail(*kn, "kind must be frame, animation, path or projection, not '" + text + "'");
    }
    if (!kind)
      r.fail(fn, "cannot tell the output kind of '" + o.file +
                     "' from its extension (.png, .svg, .pdf, .tex, .obj, .stl, .gif, .mp4, .json, .csv, .fold); give kind = ...");
    o.kind = *kind;
    if (!canWrite(o.kind, ext))
      r.fail(fn, std::string("a ") + toString(o.kind) + " output cannot be written as '." + ext +
                     "' (frame: .png, .svg, .pdf, .tex, or .obj/.stl as a solid; animation: .gif, .mp4; path: .json, .csv, .fold; " +
                     "projection: .png, .svg, .pdf, .tex, or .gif/.mp4 for the animated projection)");
    if (const toml::node* sn = t.get("sample")) {
      const long long v = r.integer(*sn, "sample");
      if (v < 0 || v > 100000000) r.fail(*sn, "sample must be a sample number (0 is the start)");
      if (o.kind != OutputKind::Frame) r.fail(*sn, "sample applies to frame outputs only");
      o.sample = static_cast<int>(v);
    }
    if (const toml::node* sn = t.get("samples")) {
      const toml::array& a = r.array(*sn, "samples");
      if (a.empty() || a.size() > 64) r.fail(*sn, "samples lists 1 to 64 sample numbers");
      if (o.kind != OutputKind::Frame || isSolidExtension(ext))
        r.fail(*sn, "samples applies to picture frame outputs only (a filmstrip: .png, .svg, .pdf, .tex)");
      if (t.contains("sample")) r.fail(*sn, "give sample (one frame) or samples (a filmstrip), not both");
      for (const toml::node& e : a) {
        const long long v = r.integer(e, "a samples entry");
        if (v < 0 || v > 100000000) r.fail(e, "a samples entry must be a sample number (0 is the start)");
        o.samples.push_back(static_cast<int>(v));
      }
    }
    if (const toml::node* fl = t.get("flex")) {
      o.flex = readFlag(r, *fl, "flex");
      if (o.kind != OutputKind::Frame) r.fail(*fl, "flex applies to frame outputs only");
    }
    outs.push_back(o);
  }
}

// [system] type = "catalog": the entry's title and its [motion], [analysis], [render] and
// [projection] keys are the defaults of the scene's own (the scene's keys win, key by key; its
// [[output]] are its own). The settings that name vertices are read with the scene's
// index_base, so they are taken only when the entry counts vertices the same way.
void mergeCatalogEntry(toml::table& doc) {
  const toml::table* sys = doc["system"].as_table();
  if (!sys || (*sys)["type"].value_or(std::string()) != "catalog") return;
  const CatalogEntry* entry = findCatalogEntry((*sys)["name"].value_or(std::string()));
  if (!entry) return;  // buildCatalog reports it at the name
  toml::table e;
  try {
    e = toml::parse(entry->text, "catalog:" + entry->name);
  } catch (const toml::parse_error&) {
    return;  // buildCatalog reports it
  }
  if (!doc.contains("title") && e.contains("title")) doc.insert("title", *e.get("title"));
  if (doc["index_base"].value_or(int64_t{1}) != e["index_base"].value_or(int64_t{1})) return;
  for (const char* key : {"motion", "analysis", "render", "projection"}) {
    const toml::table* from = e[key].as_table();
    if (!from) continue;
    if (!doc.contains(key)) {
      doc.insert(key, *from);
      continue;
    }
    toml::table* to = doc[key].as_table();
    if (!to) continue;  // not a table: readScene reports it
    for (const auto& [k, v] : *from)
      if (!to->contains(k.str())) to->insert(k.str(), v);
  }
}

Scene readScene(toml::table& doc, const std::string& file, const std::vector<std::string>& overrides) {
  for (const auto& o : overrides) applyOverride(doc, o);
  mergeCatalogEntry(doc);
  Reader r(file);
  Scene scene;
  scene.motion.flex_file = file;
  r.checkKeys(doc, keysOf(""), "the scene");
  scene.path = file;
  if (const toml::node* n = doc.get("title")) scene.title = r.string(*n, "title");
  if (const toml::node* n = doc.get("index_base")) {
    const long long b = r.integer(*n, "index_base");
    if (b != 0 && b != 1) r.fail(*n, "index_base must be 0 or 1");
    scene.index_base = static_cast<int>(b);
  }
  const toml::node* sys = doc.get("system");
  if (!sys) throw SceneError(file, 1, 1, "the scene has no [system] table");
  toml::table resolved;
  scene.model = buildModel(r, r.table(*sys, "[system]"), scene.index_base, scene.type, 0, &resolved);
  if (const toml::node* n = doc.get("motion")) readMotion(r, r.table(*n, "[motion]"), scene);
  if (const toml::node* n = doc.get("analysis")) readAnalysis(r, r.table(*n, "[analysis]"), scene);
  if (const toml::node* n = doc.get("render")) readRender(r, r.table(*n, "[render]"), scene);
  if (const toml::node* n = doc.get("projection")) readProjection(r, r.table(*n, "[projection]"), scene);
  if (const toml::node* n = doc.get("output")) readOutputs(r, *n, scene.outputs);
  scene.render.style.label_base = scene.index_base;
  auto self = std::make_shared<toml::table>(doc);
  self->erase("output");
  self->erase("sweep");
  if (!resolved.empty()) self->insert_or_assign("system", std::move(resolved));
  scene.document = [self] {
    std::ostringstream text;
    text << toml::toml_formatter(*self);
    return text.str() + "\n";
  };
  return scene;
}

}  // namespace

Scene loadSceneFromString(const std::string& text, const std::string& source_name,
                          const std::vector<std::string>& overrides) {
  toml::table doc = parseToml(text, source_name);
  return readScene(doc, source_name, overrides);
}

std::string readSceneFile(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw SceneError(path, 1, 1, "is a directory, not a scene file");
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int err = errno;
    std::string m = std::string("cannot open the scene file: ") + std::strerror(err);
    if (err == ENOENT && path.find('/') == std::string::npos && path.find('.') == std::string::npos)
      m += " (nor is it a catalog name: `flexure catalog` lists them)";
    throw SceneError(path, 1, 1, m);
  }
  // Read in pieces up to the limit: /dev/zero or a FIFO has no size to ask for.
  std::string text;
  char buf[1 << 16];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    text.append(buf, static_cast<size_t>(in.gcount()));
    if (text.size() > kMaxSceneBytes)
      throw SceneError(path, 1, 1, "the scene file is larger than " + std::to_string(kMaxSceneBytes >> 20) + " MiB");
  }
  if (in.bad()) throw SceneError(path, 1, 1, "cannot read the scene file");
  return text;
}

const CatalogEntry* catalogArgument(const std::string& argument) {
  std::error_code ec;
  if (std::filesystem::exists(argument, ec)) return nullptr;  // a file of that name wins
  const std::string name = argument.rfind("catalog:", 0) == 0 ? argument.substr(8) : argument;
  return findCatalogEntry(name);
}

namespace {

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

}  // namespace

std::string sceneTextOfFile(const std::string& path, const std::string& text) {
  if (isNodeLinkFile(path) && looksLikePathJson(text)) {
    const nlohmann::json j = parseJsonText(text, path);
    if (isPathJson(j)) return j["scene"].is_string() ? j["scene"].get<std::string>() : text;
  }
  if (!isImportable(path) || tomlNamedJson(path)) return text;
  std::ostringstream o;
  o << toml::toml_formatter(importedSceneDocument(path)) << "\n";
  return o.str();
}

Scene loadScene(const std::string& path, const std::vector<std::string>& overrides) {
  if (const CatalogEntry* e = catalogArgument(path))
    return loadSceneFromString(e->text, "catalog:" + e->name, overrides);
  if (isNodeLinkFile(path)) {
    // A path JSON written by track: its scene and samples.
    std::error_code ec;
    if (std::filesystem::is_regular_file(path, ec)) {
      const std::string text = readSceneFile(path);
      if (looksLikePathJson(text)) {
        nlohmann::json j = parseJsonText(text, path);
        if (isPathJson(j)) return loadPathJson(path, j, overrides);
      }
    }
  }
  if (isImportable(path) && !tomlNamedJson(path)) {
    // A graph6/sparse6 file, a mesh or a FOLD file given directly.
    toml::table doc = importedSceneDocument(path);
    return readScene(doc, path, overrides);
  }
  return loadSceneFromString(readSceneFile(path), path, overrides);
}

Scene loadSceneFromDocument(toml::table doc, const std::string& source_name,
                            const std::vector<std::string>& overrides) {
  return readScene(doc, source_name, overrides);
}

Scene loadGraphScene(const ImportedGraph& g, int dimension, std::uint64_t seed, const std::string& source_name,
                     const std::string& title, const std::vector<std::string>& overrides) {
  if (dimension != 2 && dimension != 3) throw std::invalid_argument("a graph's realization has dimension 2 or 3");
  if (g.edges.empty()) throw SceneError(source_name, 1, 1, "the graph has no edge");
  toml::table doc;
  doc.insert("title", title);
  doc.insert("system", graphSystem(g, dimension, seed, 1));
  return readScene(doc, source_name, overrides);
}

}  // namespace flexure::scenes
