// The settings tables of a scene, read once its system is built: [motion] (a flex, an edge
// contraction or a driven fold), [analysis], [render] (with the animation's frame keys),
// [projection] and [[output]]. The simple keys come from the key table (scenes/keys.h).
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>

#include "engine/contraction.h"
#include "scenes/excerpt.h"
#include "scenes/keys.h"
#include "scenes/loader_parts.h"
#include "scenes/scene.h"
#include "scenes/system_reader.h"
#include "scenes/system_types.h"

namespace flexure::scenes::detail {

namespace {

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

// A flex direction given as coefficients (flex = "auto", e.g. `--set motion.flex=auto` over a
// catalog entry's flex, gives none).
bool explicitFlex(const toml::table& t) {
  const toml::node* n = t.get("flex");
  return n && !(n->is_string() && n->value_or(std::string()) == "auto");
}

// A length: a number and a unit, "8cm", "80 mm", "3.5in", "9pt" (1/72 in), or "800px".
struct Length {
  double value = 0;  // points, or pixels
  bool pixels = false;
};

// None when `text` is not a number and a unit (an expression, a word).
std::optional<Length> parseLength(const std::string& text) {
  size_t at = 0;
  double v = 0;
  try {
    v = std::stod(text, &at);
  } catch (const std::out_of_range&) {  // beyond the doubles ("1e400in"): a length, refused as too large
    char* end = nullptr;
    v = std::strtod(text.c_str(), &end);
    at = static_cast<size_t>(end - text.c_str());
  } catch (const std::exception&) {
    return std::nullopt;
  }
  std::string unit = text.substr(at);
  unit.erase(0, unit.find_first_not_of(' '));
  static const std::pair<const char*, double> kUnits[] = {{"pt", 1}, {"in", 72}, {"cm", 72 / 2.54}, {"mm", 72 / 25.4}};
  if (unit == "px") return Length{v, true};
  for (const auto& [name, points] : kUnits)
    if (unit == name) return Length{v * points, false};
  return std::nullopt;
}

// A key's length (it parses as one: parseLength), positive and finite.
Length readLength(const Reader& r, const toml::node& n, const std::string& key) {
  const std::string text = r.string(n, key);
  const std::optional<Length> l = parseLength(text);
  if (!l || !(l->value > 0) || !std::isfinite(l->value))  // "1e308in": finite as written, not in points
    r.fail(n, l && l->value > 0 ? key + " \"" + excerpt(text) + "\" is too large a length"
                                : key + " must be a positive length with its unit (\"8cm\", \"80mm\", \"3in\", \"9pt\", "
                                        "\"800px\"), not \"" + excerpt(text) + "\"");
  return *l;
}

bool isLength(const toml::node& n) { return n.is_string() && parseLength(n.value_or(std::string())).has_value(); }

// The keys of `table` (scenes/keys.h) that `t` holds and that the table reads itself (numbers,
// integers, flags, colours, seeds), checked against their ranges, into `scene`.
void readSimpleKeys(const Reader& r, const toml::table& t, const std::string& table, Scene& scene) {
  for (const KeySpec& k : sceneKeys()) {
    if (k.table != table || k.kind == KeyKind::Custom) continue;
    const toml::node* n = t.get(k.key);
    if (!n) continue;
    if (k.lengths && isLength(*n)) continue;  // readLengths converts it
    const std::string& key = k.key;
    auto outside = [&](const std::string& lo, const std::string& hi) {
      r.fail(*n, !k.range_message.empty() ? k.range_message : key + " must be between " + lo + " and " + hi);
    };
    switch (k.kind) {
      case KeyKind::Integer: {
        if (k.lengths && n->is_string())
          r.fail(*n, key + " must be an integer or a length with its unit (\"8cm\", \"80mm\", \"3in\", \"230pt\"), not \"" +
                         excerpt(n->value_or(std::string())) + "\"");
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
      for (auto s2 : geometry.simplices.list) {
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

}  // namespace

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
    if (const int k = model.rigidPartHolding(i, j); k >= 0)
      r.fail(*ce, "[" + std::to_string(i + base) + ", " + std::to_string(j + base) + "] lies in " +
                      model.rigidPartName(k) + ", which is rigid: its length cannot change (contract a bar between bodies)");
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
    if (explicitFlex(t)) r.fail(*t.get("flex"), "flex does not apply to an edge contraction (the edge length drives it)");
  }
  // Driving an origami fold: one crease to an angle, or every mountain and valley toward a
  // fold percentage.
  const toml::node* fc = t.get("fold_crease");
  const toml::node* fa = t.get("fold_angle");
  const toml::node* fp = t.get("fold_percent");
  if (fc || fa || fp) {
    const toml::node& at = fc ? *fc : fa ? *fa : *fp;
    const SystemType* type = findSystemType(model.typeName());
    if (!type || !type->read_fold_drive)
      r.fail(at, "fold driving applies to origami; this system is a " + model.typeName());
    if (ce) r.fail(at, "drive a fold or contract an edge, not both");
    if (explicitFlex(t)) r.fail(*t.get("flex"), "flex does not apply to a driven fold (the fold drives it)");
    if (fp && (fc || fa)) r.fail(*fp, "fold_percent drives every crease; fold_crease and fold_angle drive one: not both");
    type->read_fold_drive(r, t, model, base, m);
  }
  if (const toml::node* n = t.get("branch")) {
    const toml::array& a = r.array(*n, "branch");
    if (a.size() != 2)
      r.fail(*n, "branch is [k, j]: sample k of the path, direction j of the tangent cone there (both from 0)");
    const long long k = r.integer(*a.get(0), "branch sample"), j = r.integer(*a.get(1), "branch direction");
    if (k < 0 || k > m.steps)
      r.fail(*a.get(0), "branch: the sample must be between 0 and steps (" + std::to_string(m.steps) + ")");
    if (j < 0 || j > 1000) r.fail(*a.get(1), "branch: the direction must be between 0 and 1000 (it counts from 0)");
    if (m.contract_edge || m.fold_crease || m.fold_percent)
      r.fail(*n, "branch continues along a flex: not with an edge contraction or a driven fold");
    m.branch = std::array<int, 2>{static_cast<int>(k), static_cast<int>(j)};
    const auto& src = n->source();
    m.branch_file = src.path ? std::string(*src.path) : r.file();
    m.branch_line = static_cast<int>(src.begin.line);
    m.branch_column = static_cast<int>(src.begin.column);
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

// A size given as a length, in size units: points at the figure's resolution (96 per inch for a
// figure in pixels), over the pixels per size unit. After the figure's own size is read.
double sizeUnits(const Length& l, const RenderSettings& s) {
  const double dpi = s.physical ? s.dpi : 96.0, unit = s.physical ? s.style.unit_px : std::min(s.width, s.height) / 1000.0;
  return (l.pixels ? l.value : l.value * dpi / 72) / unit;
}

// The keys given as lengths (KeySpec::lengths): the figure's size in pixels at dpi (a figure
// sized in lengths draws its sizes in points), and sizes in points or pixels as size units.
void readLengths(const Reader& r, const toml::table& t, Scene& scene) {
  RenderSettings& s = scene.render;
  const toml::node* wn = t.get("width");
  const toml::node* hn = t.get("height");
  std::optional<Length> w, h;
  if (wn && isLength(*wn)) w = readLength(r, *wn, "width");
  if (hn && isLength(*hn)) h = readLength(r, *hn, "height");
  const auto pixels = [&](const toml::node& n, const std::string& key, double px, const std::string& how) {
    // The range is checked on the double, before it is rounded to an integer ("1e300in").
    if (!(px >= 15.5 && px < 8192.5))
      r.fail(n, key + " is " + fmt(px) + " px" + how + ": an image is 16 to 8192 px" +
                    (how.empty() ? "" : " (a lower dpi, or a smaller size)"));
    return static_cast<int>(std::lround(px));
  };
  if (w && w->pixels) s.width = pixels(*wn, "width", w->value, ""), w.reset();
  if (h && h->pixels) s.height = pixels(*hn, "height", h->value, ""), h.reset();
  if (w || h) {
    // The other one: left out, the same length; in pixels, those pixels at dpi (a catalog
    // entry's height under --set render.width=8cm).
    const std::string how = " at " + std::to_string(s.dpi) + " dpi";
    const double wpt = w ? w->value : wn ? s.width * 72.0 / s.dpi : h->value;
    const double hpt = h ? h->value : hn ? s.height * 72.0 / s.dpi : w->value;
    s.width = pixels(wn ? *wn : *hn, "width", wpt * s.dpi / 72, how);
    s.height = pixels(hn ? *hn : *wn, "height", hpt * s.dpi / 72, how);
    s.physical = true;
    s.style.unit_px = s.dpi / 72.0 * kPointsPerSizeUnit;
  }
  for (const KeySpec& k : sceneKeys()) {
    if (k.table != "render" || !k.lengths || k.kind != KeyKind::Number) continue;
    const toml::node* n = t.get(k.key);
    if (!n || !isLength(*n)) continue;
    const double v = sizeUnits(readLength(r, *n, k.key), s);
    if (v < k.lo || v > k.hi) r.fail(*n, k.key + " is " + fmt(v) + " size units here: it must be between " + fmt(k.lo) + " and " + fmt(k.hi));
    std::get<double& (*)(Scene&)>(k.field)(scene) = v;
  }
}

// A size of a part: a number (size units) or a length, converted as readLengths converts them.
double readSize(const Reader& r, const toml::node& n, const std::string& key, const RenderSettings& s) {
  double v = 0;
  if (isLength(n)) {
    v = sizeUnits(readLength(r, n, key), s);
  } else {
    v = r.number(n, key);
  }
  if (!(v >= 0 && v <= 1000)) r.fail(n, key + " is " + fmt(v) + " size units: it must be between 0 and 1000");
  return v;
}

// [render] edge_styles and vertex_styles: parts in their own look. Edges must be bars of the
// system (its plain bars: not creases, contacts or outlines).
void readPartStyles(const Reader& r, const toml::table& t, Scene& scene) {
  RenderSettings& s = scene.render;
  const engine::Geometry g = scene.model->geometry();
  const VertexIndexer vi{r, scene.index_base, scene.model->system().numVertices()};
  const auto part = [&](const toml::table& e, const std::string& what, const std::string& size_key) {
    PartStyle out;
    for (const auto& [k, v] : e) {
      const std::string key(k.str());
      if (key == "edges" || key == "vertices") continue;
      if (key == "color") out.color = readColor(r, v, what + " color");
      else if (key == size_key) out.width = readSize(r, v, what + " " + size_key, s);
      else if (key == "dash" && size_key == "width") out.dash = readFlag(r, v, what + " dash");
      else if (key == "label") out.label = r.string(v, what + " label");
      else
        r.fail(v, "unknown key '" + key + "' in " + what + "; known: " +
                      (size_key == "width" ? "edges, color, width, dash, label" : "vertices, color, size, label"));
    }
    return out;
  };
  if (const toml::node* n = t.get("edge_styles")) {
    for (const toml::node& e : r.array(*n, "edge_styles")) {
      const toml::table& tab = r.table(e, "an edge_styles entry");
      const PartStyle look = part(tab, "edge_styles", "width");
      for (const toml::node& en : r.array(r.require(tab, "edges", "an edge_styles entry"), "edges")) {
        const toml::array& pair = r.array(en, "an edge");
        if (pair.size() != 2) r.fail(en, "an edge is two vertices [i, j]");
        const int a = vi(pair[0], "edge vertex"), b = vi(pair[1], "edge vertex");
        const std::array<int, 2> key{std::min(a, b), std::max(a, b)};
        const bool bar = g.bars.role == engine::Bars::Role::Plain &&
                         std::any_of(g.bars.edges.begin(), g.bars.edges.end(), [&](const auto& x) {
                           return std::min(x[0], x[1]) == key[0] && std::max(x[0], x[1]) == key[1];
                         });
        if (!bar)
          r.fail(en, "[" + std::to_string(a + scene.index_base) + ", " + std::to_string(b + scene.index_base) +
                         "] is not a bar of this " + scene.model->typeName() + " (edge_styles styles its bars)");
        s.style.edge_styles[{key[0], key[1]}] = look;
      }
    }
  }
  if (const toml::node* n = t.get("vertex_styles")) {
    for (const toml::node& e : r.array(*n, "vertex_styles")) {
      const toml::table& tab = r.table(e, "a vertex_styles entry");
      const PartStyle look = part(tab, "vertex_styles", "size");
      for (const toml::node& v : r.array(r.require(tab, "vertices", "a vertex_styles entry"), "vertices"))
        s.style.vertex_styles[vi(v, "vertex")] = look;
    }
  }
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
  readLengths(r, t, scene);
  readPartStyles(r, t, scene);
  if (const toml::node* n = t.get("caption")) {
    try {  // Distance's vertices come back from 0
      s.caption = parseCaption(r.string(*n, "caption"), scene.index_base, scene.model->system().numVertices());
    } catch (const CaptionError& e) {  // at the place in the string (+1: its opening quote)
      r.fail(n->source(), "caption: " + std::string(e.what()), static_cast<int>(std::min<size_t>(e.offset, 1u << 30)) + 1);
    }
  }
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
      if (!kind) r.fail(*kn, "kind must be frame, animation, path or projection, not '" + excerpt(text) + "'");
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

}  // namespace flexure::scenes::detail
