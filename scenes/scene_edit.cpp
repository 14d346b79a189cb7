#include "scenes/scene_edit.h"
#include "scenes/toml_text.h"

#include <algorithm>
#include <charconv>
#include <sstream>

#include "scenes/scene.h"

namespace flexure::scenes {

namespace {

// One KEY=VALUE: the key's parts and the value, parsed and as TOML text.
struct Assignment {
  std::vector<std::string> path;
  toml::table holder;  // {"v": value}
  std::string text;    // the value as written in a TOML file
};

Assignment parseAssignment(const std::string& assignment) {
  const std::string where = "--set " + assignment;
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw SceneError("--set", 1, 1, "expected KEY=VALUE, got '" + assignment + "'");
  const std::string key = assignment.substr(0, eq), value = assignment.substr(eq + 1);
  Assignment a;
  if (tooDeepKey("v = " + value).line > 0)
    throw SceneError(where, 1, 1, "the value nests keys more than " + std::to_string(kMaxKeyDepth) + " levels deep");
  try {
    a.holder = toml::parse("v = " + value, where);
    a.text = value;
  } catch (const toml::parse_error&) {
    // Not a TOML value: take the text as a string (so --set system.type=framework works).
    std::string quoted = "\"";
    for (char c : value) {
      if (c == '"' || c == '\\') quoted += '\\';
      quoted += c;
    }
    quoted += '"';
    try {
      a.holder = toml::parse("v = " + quoted, where);
      a.text = quoted;
    } catch (const toml::parse_error& e) {
      throw SceneError(where, 1, 1, "cannot read the value: " + std::string(e.description()));
    }
  }
  // The value text stops before a comment or trailing blanks ("v = 3 # x" parses too).
  const toml::source_region r = a.holder.get("v")->source();
  if (r.begin.line == 1 && r.end.line == 1 && r.end.column > r.begin.column)
    a.text = ("v = " + a.text).substr(r.begin.column - 1, r.end.column - r.begin.column);
  size_t start = 0;
  for (;;) {
    const auto dot = key.find('.', start);
    a.path.push_back(key.substr(start, dot == std::string::npos ? std::string::npos : dot - start));
    if (a.path.back().empty()) throw SceneError("--set", 1, 1, "malformed key '" + key + "'");
    if (dot == std::string::npos) break;
    start = dot + 1;
  }
  return a;
}

std::string format(const toml::table& t) {
  std::ostringstream os;
  os << toml::toml_formatter(t);
  return os.str();
}

// A key as TOML writes it: bare when it can be, quoted otherwise.
std::string keyText(const std::string& k) {
  const bool bare = std::all_of(k.begin(), k.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
  });
  if (bare) return k;
  std::string q = "\"";
  for (char c : k) {
    if (c == '"' || c == '\\') q += '\\';
    q += c;
  }
  return q + "\"";
}

// Byte offsets of (line, column) positions: columns count code points, from 1.
class Offsets {
 public:
  explicit Offsets(const std::string& text) : text_(text) {
    starts_.push_back(0);
    for (size_t i = 0; i < text.size(); ++i)
      if (text[i] == '\n') starts_.push_back(i + 1);
  }
  size_t at(toml::source_index line, toml::source_index column) const {
    if (line < 1 || line > starts_.size()) return text_.size();
    size_t i = starts_[line - 1];
    for (toml::source_index c = 1; c < column && i < text_.size() && text_[i] != '\n'; ++c) {
      ++i;
      while (i < text_.size() && (static_cast<unsigned char>(text_[i]) & 0xC0) == 0x80) ++i;
    }
    return i;
  }
  // Just after the end of `line` (its newline included).
  size_t afterLine(toml::source_index line) const {
    return line < starts_.size() ? starts_[line] : text_.size();
  }

 private:
  const std::string& text_;
  std::vector<size_t> starts_;
};

struct Edit {
  size_t begin, end;  // bytes replaced (begin == end: an insertion)
  std::string text;
  size_t order;       // insertions at one place keep the assignments' order
};

}  // namespace

void applyOverride(toml::table& doc, const std::string& assignment) {
  Assignment a = parseAssignment(assignment);
  toml::table* t = &doc;
  for (size_t i = 0; i + 1 < a.path.size(); ++i) {
    toml::node* next = t->get(a.path[i]);
    if (!next) next = &t->insert_or_assign(a.path[i], toml::table{}).first->second;
    if (!next->is_table()) {
      std::string prefix = a.path[0];
      for (size_t j = 1; j <= i; ++j) prefix += "." + a.path[j];
      throw SceneError("--set", 1, 1, "'" + prefix + "' is not a table");
    }
    t = next->as_table();
  }
  t->insert_or_assign(a.path.back(), std::move(*a.holder.get("v")));
}

std::string withKeys(const std::string& text, const std::vector<std::string>& assignments) {
  toml::table doc = parseToml(text, "scene");
  toml::table expected = doc;
  for (const auto& s : assignments) applyOverride(expected, s);

  const Offsets offsets(text);
  std::vector<Edit> edits;
  std::vector<std::pair<std::string, std::string>> new_tables;  // header, "key = value\n" lines
  for (size_t n = 0; n < assignments.size(); ++n) {
    const Assignment a = parseAssignment(assignments[n]);
    // A key given again later (the command line's, then the page's): only the last one counts.
    const std::string key = assignments[n].substr(0, assignments[n].find('='));
    bool later = false;
    for (size_t m = n + 1; m < assignments.size() && !later; ++m)
      later = assignments[m].substr(0, assignments[m].find('=')) == key;
    if (later) continue;
    const toml::table* parent = &doc;
    bool parent_exists = true;
    for (size_t i = 0; i + 1 < a.path.size() && parent_exists; ++i) {
      const toml::node* next = parent->get(a.path[i]);
      parent_exists = next && next->is_table();
      if (parent_exists) parent = next->as_table();
    }
    const std::string line = keyText(a.path.back()) + " = " + a.text + "\n";
    if (const toml::node* old = parent_exists ? parent->get(a.path.back()) : nullptr) {
      const toml::source_region r = old->source();
      edits.push_back({offsets.at(r.begin.line, r.begin.column), offsets.at(r.end.line, r.end.column), a.text, n});
    } else if (parent_exists && parent != &doc && parent->source().begin.line > 0) {
      edits.push_back({offsets.afterLine(parent->source().end.line), 0, line, n});
      edits.back().end = edits.back().begin;
    } else if (a.path.size() == 1) {
      // A top-level key: before the first table header.
      size_t at = 0;
      for (const auto& [k, v] : doc)
        if (v.is_table() && v.source().begin.line > 0) {
          at = offsets.at(v.source().begin.line, 1);
          break;
        }
      edits.push_back({at, at, line, n});
    } else {
      std::string header;
      for (size_t i = 0; i + 1 < a.path.size(); ++i) header += (i ? "." : "") + keyText(a.path[i]);
      auto it = std::find_if(new_tables.begin(), new_tables.end(), [&](const auto& p) { return p.first == header; });
      if (it == new_tables.end()) new_tables.emplace_back(header, line);
      else it->second += line;
    }
  }
  std::stable_sort(edits.begin(), edits.end(), [](const Edit& x, const Edit& y) {
    return x.begin != y.begin ? x.begin > y.begin : x.order > y.order;
  });
  std::string out = text;
  for (const Edit& e : edits) out.replace(e.begin, e.end - e.begin, e.text);
  for (const auto& [header, lines] : new_tables) {
    if (!out.empty() && out.back() != '\n') out += '\n';
    out += "\n[" + header + "]\n" + lines;
  }
  // Read back: the same document as the library's own edit, or the library's text instead.
  try {
    if (format(toml::parse(out, std::string("scene"))) == format(expected)) return out;
  } catch (const toml::parse_error&) {
  }
  return format(expected) + "\n";
}

std::string tomlNumber(double value) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, value);
  std::string s(buf, r.ptr);
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";  // stays a float in TOML
  return s;
}

}  // namespace flexure::scenes
