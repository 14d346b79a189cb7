// [system] type = "framework": bars whose lengths are kept, in 2D or 3D, with optional lengths the
// realization must satisfy and points attached to the frame of 2 or 3 vertices.
#include <algorithm>
#include <map>
#include <optional>

#include "engine/systems/common.h"
#include "engine/systems/framework.h"
#include "scenes/system_reader.h"
#include "scenes/system_types.h"

namespace flexure::scenes::detail::systems {

namespace {

using engine::Matrix;

std::unique_ptr<engine::Model> buildFramework(const Reader& r, const toml::table& sys, int base, Matrix p) {
  const int n = static_cast<int>(p.cols());
  const VertexIndexer vi{r, base, n};
  std::vector<engine::Framework::Edge> edges;
  std::map<std::pair<int, int>, size_t> seen;
  const toml::node& edges_node = r.require(sys, "edges", "[system]");
  const BulkArray* bulk = r.bulk(edges_node);
  // A failure at edge e (its node, or its row of an array read from the text).
  std::vector<const toml::node*> edge_nodes;
  const auto failAtEdge = [&](size_t e, const std::string& message) {
    if (bulk) r.fail(*bulk, e, -1, message);
    r.fail(*edge_nodes[e], message);
  };
  const auto name = [&](int a, int b) { return "[" + std::to_string(a + base) + ", " + std::to_string(b + base) + "]"; };
  const auto add = [&](int a, int b) {
    if (a == b) failAtEdge(edges.size(), "edge " + name(a, b) + " joins a vertex to itself");
    if (!bulk) {  // (an array read from the text is checked for repeated pairs below, sorted: 10^6 edges)
      const auto key = std::minmax(a, b);
      if (auto it = seen.find(key); it != seen.end())
        failAtEdge(edges.size(), "duplicate edge " + name(a, b) + " (the same pair as edge " + std::to_string(it->second + 1) + ")");
      seen[key] = edges.size();
    }
    edges.push_back({a, b});
  };
  if (bulk) {
    edges.reserve(bulk->rows());
    for (size_t i = 0; i < bulk->rows(); ++i) {
      if (bulk->width(i) != 2) r.fail(*bulk, i, -1, "an edge joins 2 vertices, this one lists " + std::to_string(bulk->width(i)));
      const int a = vi(*bulk, i, 0, "edge vertex");  // (in this order: the first wrong value is reported)
      add(a, vi(*bulk, i, 1, "edge vertex"));
    }
    // Duplicates: the first repeated pair in file order, as the map finds it.
    std::vector<std::pair<std::pair<int, int>, size_t>> pairs;
    pairs.reserve(edges.size());
    for (size_t e = 0; e < edges.size(); ++e) pairs.push_back({std::minmax(edges[e][0], edges[e][1]), e});
    std::sort(pairs.begin(), pairs.end());
    size_t first_repeat = edges.size(), original = 0;
    for (size_t k = 1; k < pairs.size(); ++k)
      if (pairs[k].first == pairs[k - 1].first && pairs[k].second < first_repeat) {
        // pairs[k - 1] is the first of this pair (stable by index within equal pairs).
        size_t j = k - 1;
        while (j > 0 && pairs[j - 1].first == pairs[k].first) --j;
        first_repeat = pairs[k].second;
        original = pairs[j].second;
      }
    if (first_repeat < edges.size())
      failAtEdge(first_repeat, "duplicate edge " + name(edges[first_repeat][0], edges[first_repeat][1]) +
                                   " (the same pair as edge " + std::to_string(original + 1) + ")");
  } else {
    for (const toml::node& en : r.array(edges_node, "edges")) {
      const toml::array& e = r.array(en, "an edge");
      edge_nodes.push_back(&en);
      if (e.size() != 2) r.fail(e, "an edge joins 2 vertices, this one lists " + std::to_string(e.size()));
      const int a = vi(e[0], "edge vertex");
      add(a, vi(e[1], "edge vertex"));
    }
  }
  std::vector<double> lengths;
  std::optional<FlatArray> la;
  if (const toml::node* ln = sys.get("lengths")) {
    la.emplace(r, *ln, "lengths");
    if (la->size() != edges.size())
      la->fail("lengths has " + std::to_string(la->size()) + " entries for " + std::to_string(edges.size()) + " edges");
    for (size_t e = 0; e < la->size(); ++e) {
      const double l = la->number(e, "edge length");
      if (!(l > 0)) la->fail(e, "edge lengths must be positive");
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
    if (const std::string why = engine::systems_detail::closeVertices(p, a, b, base, scale); !why.empty())
      failAtEdge(e, "edge " + name(a, b) + (l == 0 ? " has length 0: " : " is too short: ") + why);
    if (!lengths.empty()) {
      const double residual = l * l - lengths[e] * lengths[e];
      if (std::abs(residual) > 1e-9 * std::max(l * l, lengths[e] * lengths[e]))
        la->fail(e,
               "the realization does not satisfy edge " + name(a, b) + ": its length is " + fmt(l) +
                   ", lengths says " + fmt(lengths[e]) + " (residual " + fmt(residual) + ")");
    }
  }
  if (r.exact() && !lengths.empty()) {
    // The exact mode: each length as written, exactly, must be the bar's length at the rational
    // coordinates; the bars then keep the start's lengths, which are those exactly (a double
    // squared is not the rational's square: 0.3 * 0.3 != 9/100, and the exact analysis would
    // find a residual that the scene does not have).
    const engine::RationalMatrix q = exactStart(r, p);
    for (size_t e = 0; e < edges.size(); ++e) {
      const engine::Rational l = la->exact(e, "edge length");
      const engine::Rational s = squaredDistance(q, edges[e][0], edges[e][1]);
      if (s != l * l) {
        const auto text = [](const engine::Rational& x) {
          const std::string t = engine::toString(x);
          return t.size() > 60 ? t.substr(0, 57) + "..." : t;
        };
        la->fail(e, "edge " + name(edges[e][0], edges[e][1]) + " does not have this length exactly: its squared length at "
                        "the rational coordinates is " + text(s) + ", lengths says " + text(l) + " (squared " + text(l * l) +
                        "); the exact mode analyses exact solutions only");
      }
    }
    lengths.clear();
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

}  // namespace

SystemType framework() {
  return {"framework", {2, 3}, buildFramework, "edge lengths, attached points in their frames",
          "`edges` (2D or 3D), `lengths`, `attached` (points held in the frame of 2 or 3 vertices)",
          "Euclidean"};
}

}  // namespace flexure::scenes::detail::systems
