// The Reader of scenes/toml_reader.h: failures at a node's position, unknown keys with a
// suggestion, and the typed readers of single values.
#include "scenes/toml_reader.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "scenes/exact_number.h"
#include "scenes/expression.h"
#include "scenes/keys.h"
#include "scenes/scene.h"
#include "scenes/style.h"

namespace flexure::scenes::detail {

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

void Reader::fail(const toml::source_region& src, const std::string& message, int column_shift) const {
  const std::string file = src.path ? std::string(*src.path) : file_;
  // Messages quote a bounded excerpt of what was written (scenes/excerpt.h); one that still
  // quotes more (a caller that quotes a value whole) is cut to its start and end.
  throw SceneError(file, std::max<int>(1, static_cast<int>(src.begin.line)),
                   std::max<int>(1, static_cast<int>(src.begin.column)) + column_shift, boundedMessage(message));
}

void Reader::checkKeys(const toml::table& t, const std::vector<std::string>& allowed,
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

double Reader::number(const toml::node& n, const std::string& what) const {
  double v = 0.0;
  if (auto i = n.as_integer()) {
    v = static_cast<double>(i->get());
  } else if (auto f = n.as_floating_point()) {
    v = f->get();
  } else if (auto s = n.as_string()) {
    try {
      v = evaluateExpression(s->get());
    } catch (const ExpressionError& e) {
      // Rational arithmetic whose double steps leave the double range although its value does
      // not ("p/q" of 1000-digit integers, as Python writes a Fraction): its exact value (sizes
      // bounded, scenes/exact_number.h), rounded once.
      bool rescued = false;
      ExpressionError why = e;
      try {
        const double x = engine::nearestDouble(evaluateRational(s->get()));
        if (std::isfinite(x)) v = x, rescued = true;
      } catch (const ExpressionError& exact) {
        // Rational arithmetic beyond the exact mode's sizes: that says more than "not finite".
        if (std::string(e.what()) == "the expression is not a finite number" &&
            std::string(exact.what()).find("limit") != std::string::npos)
          why = exact;
      }
      // +1 for the opening quote
      if (!rescued) fail(n.source(), what + ": " + expressionMessage(why, s->get()), why.offset + 1);
    }
  } else {
    fail(n, what + " must be a number or an expression string, not " + typeName(n));
  }
  if (std::isnan(v)) fail(n, what + " is NaN");
  if (std::isinf(v)) fail(n, what + " is infinite");
  return v;
}

const BulkArray* Reader::bulk(const toml::node& n) const {
  if (!bulk_) return nullptr;
  for (const BulkArray& b : *bulk_)
    if (b.node == &n) return &b;
  if (!text_) return nullptr;
  const toml::array* a = n.as_array();
  const toml::source_region& src = n.source();
  if (!a || !a->empty() || !src.path || *src.path != file_) return nullptr;
  for (const BulkArray& b : *bulk_)
    if (!b.node && static_cast<int>(src.begin.line) == b.line && static_cast<int>(src.begin.column) == b.column) return &b;
  return nullptr;
}

std::pair<int, int> Reader::position(size_t offset) const {
  if (line_starts_.empty()) {
    line_starts_.push_back(0);
    for (size_t i = 0; i < text_->size(); ++i)
      if ((*text_)[i] == '\n') line_starts_.push_back(i + 1);
  }
  const auto it = std::upper_bound(line_starts_.begin(), line_starts_.end(), offset);
  const size_t line = static_cast<size_t>(it - line_starts_.begin());
  return {static_cast<int>(line), static_cast<int>(offset - line_starts_[line - 1]) + 1};
}

void Reader::fail(const BulkArray& a, size_t row, long k, const std::string& message) const {
  if (a.given)
    throw SceneError(file_, a.line, a.column,
                     a.origin.empty() ? message
                                      : a.origin + ", " + a.key + "[" + std::to_string(row) + "]" +
                                            (k >= 0 && !a.flat ? "[" + std::to_string(k) + "]" : "") + ": " + message,
                     static_cast<long>(row));
  size_t offset = a.row_open[row];
  if (k >= 0) a.numeral(*text_, row, static_cast<size_t>(k), &offset);
  const auto [line, column] = position(offset);
  throw SceneError(file_, line, column, message);
}

std::string_view Reader::lineOfText(const toml::source_region& src) const {
  if (!text_ || !src.path || *src.path != file_ || src.begin.line < 1) return {};
  if (line_starts_.empty()) position(0);
  const size_t line = static_cast<size_t>(src.begin.line) - 1;
  if (line >= line_starts_.size()) return {};
  const size_t from = line_starts_[line];
  const size_t to = line + 1 < line_starts_.size() ? line_starts_[line + 1] : text_->size();
  return std::string_view(*text_).substr(from, to - from);
}

long long Reader::integer(const toml::node& n, const std::string& what) const {
  if (auto i = n.as_integer()) return i->get();
  fail(n, what + " must be an integer, not " + typeName(n));
}

const toml::array& Reader::array(const toml::node& n, const std::string& what) const {
  if (auto a = n.as_array()) return *a;
  fail(n, what + " must be an array, not " + typeName(n));
}

const toml::table& Reader::table(const toml::node& n, const std::string& what) const {
  if (auto t = n.as_table()) return *t;
  fail(n, what + " must be a table, not " + typeName(n));
}

std::string Reader::string(const toml::node& n, const std::string& what) const {
  if (auto s = n.as_string()) return s->get();
  fail(n, what + " must be a string, not " + typeName(n));
}

const toml::node& Reader::require(const toml::table& t, const std::string& key,
                                  const std::string& where) const {
  if (const toml::node* n = t.get(key)) return *n;
  fail(t.source(), where + " needs the key '" + key + "'");
}

render::Color readColor(const Reader& r, const toml::node& n, const std::string& what) {
  const std::string text = r.string(n, what);
  const auto c = parseColor(text);
  if (!c) r.fail(n, what + ": unknown colour '" + excerpt(text) + "' (use #RRGGBB, #RRGGBBAA or a name such as steelblue)");
  return *c;
}

bool readFlag(const Reader& r, const toml::node& n, const std::string& what) {
  if (auto b = n.as_boolean()) return b->get();
  r.fail(n, what + " must be true or false, not " + typeName(n));
}

}  // namespace flexure::scenes::detail
