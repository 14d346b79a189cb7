#include "scenes/toml_text.h"

#include <algorithm>

#include <cctype>
#include <vector>

#include "scenes/scene.h"

namespace flexure::scenes {

namespace {

// A scanner that knows just enough TOML to tell keys from values: strings (four kinds),
// comments, table headers, and the brackets of arrays and inline tables. Iterative: its own
// stack of brackets, never recursion.
class KeyDepthScanner {
 public:
  KeyDepthScanner(std::string_view s, int max_depth) : s_(s), max_(max_depth) {}

  TextPosition run() {
    bool line_start = true;
    while (i_ < s_.size()) {
      const char c = s_[i_];
      if (c == '\n') {
        newline();
        line_start = true;
        continue;
      }
      if (c == ' ' || c == '\t' || c == '\r') {
        ++i_;
        continue;
      }
      if (c == '#') {
        skipComment();
        continue;
      }
      if (line_start && stack_.empty()) {
        line_start = false;
        if (c == '[') {
          header();
        } else {
          base_ = header_depth_;
          key('=');
        }
        if (found_) return where_;
        continue;
      }
      line_start = false;
      if (c == '"' || c == '\'') {
        skipString();
      } else if (c == '[') {
        stack_.push_back({'[', valueDepth()});
        ++i_;
      } else if (c == '{') {
        stack_.push_back({'{', valueDepth()});
        ++i_;
        base_ = stack_.back().depth;
        key('=');
      } else if (c == ']' || c == '}') {
        if (!stack_.empty()) stack_.pop_back();
        ++i_;
      } else if (c == ',' && !stack_.empty() && stack_.back().kind == '{') {
        ++i_;
        base_ = stack_.back().depth;
        key('=');
      } else {
        ++i_;
      }
      if (found_) return where_;
    }
    return {};
  }

 private:
  struct Open {
    char kind;
    int depth;  // the key depth inside this bracket
  };

  // The depth of a value that opens here: below the last key, or inside the array around it.
  int valueDepth() const {
    return stack_.empty() || stack_.back().kind == '{' ? base_ + key_depth_ : stack_.back().depth + 1;
  }
  void newline() {
    ++i_;
    ++line_;
    line_at_ = i_;
  }
  void skipComment() {
    while (i_ < s_.size() && s_[i_] != '\n') ++i_;
  }
  // A string of any of the four kinds, starting at its quote.
  void skipString() {
    const char q = s_[i_];
    const bool multi = s_.substr(i_, 3) == std::string(3, q);
    i_ += multi ? 3 : 1;
    while (i_ < s_.size()) {
      const char c = s_[i_];
      if (c == '\\' && q == '"') {
        i_ += 2;
        continue;
      }
      if (c == '\n') {
        if (!multi) return;  // toml++ reports the unterminated string
        newline();
        continue;
      }
      if (c == q && (!multi || s_.substr(i_, 3) == std::string(3, q))) {
        i_ += multi ? 3 : 1;
        return;
      }
      ++i_;
    }
  }
  // A key up to `end` ('=' or ']'), counting its dotted parts; stops at the end of the line.
  void key(char end) {
    key_depth_ = 1;
    const size_t start = i_;
    const auto tooDeep = [&] {
      if (key_depth_ + base_ <= max_) return false;
      found_ = true;
      where_ = {line_, static_cast<int>(start - line_at_) + 1};
      return true;
    };
    if (tooDeep()) return;
    while (i_ < s_.size() && s_[i_] != end && s_[i_] != '\n') {
      const char c = s_[i_];
      if (c == '"' || c == '\'') {
        skipString();
        continue;
      }
      if (c == '.' && (++key_depth_, tooDeep())) return;
      if (c == '#') return;
      ++i_;
    }
    if (i_ < s_.size() && s_[i_] == end) ++i_;
  }
  // [a.b.c] or [[a.b.c]]: its parts are the depth of the keys below it.
  void header() {
    ++i_;
    if (i_ < s_.size() && s_[i_] == '[') ++i_;
    base_ = 0;
    key(']');
    header_depth_ = key_depth_;
    key_depth_ = 0;
    base_ = header_depth_;
  }

  std::string_view s_;
  int max_;
  size_t i_ = 0, line_at_ = 0;
  int line_ = 1;
  int header_depth_ = 0, base_ = 0, key_depth_ = 0;
  std::vector<Open> stack_;
  bool found_ = false;
  TextPosition where_;
};

}  // namespace

TextPosition tooDeepKey(std::string_view text, int max_depth) { return KeyDepthScanner(text, max_depth).run(); }

NonAsciiProblem misplacedNonAscii(std::string_view s) {
  size_t i = 0, line_at = 0;
  int line = 1;
  auto at = [&](size_t k, const char* why) { return NonAsciiProblem{{line, static_cast<int>(k - line_at) + 1}, why}; };
  auto high = [&](size_t k) { return k < s.size() && static_cast<unsigned char>(s[k]) >= 0x80; };
  auto space = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; };
  const char* outside = "is outside a string or a comment: TOML allows characters beyond ASCII only there";
  if (s.substr(0, 3) == "\xEF\xBB\xBF") i = line_at = 3;  // a byte-order mark: toml++ skips it
  // Tokens as toml++ reads them. A bare value (a number, a date, true, or anything else that
  // does not start with a quote or a bracket) runs to the next white space, ',', ']', '}' or
  // '#': quotes, brackets and '=' inside it are its characters (4a.'b', 0[["c" and 0="c" are
  // one token each), and toml++ classifies every character of it. A bare key runs over
  // A-Z a-z 0-9 _ -. A quote where a key or a value starts opens a string.
  std::vector<char> open;  // the '[' and '{' of arrays and inline tables
  bool header = false;     // inside [table] or [[table]]
  char last = '\n';        // the last character that was not white space, a string or a token
  while (i < s.size()) {
    const char c = s[i];
    if (c == '\n') {
      line_at = ++i, ++line;
      last = '\n';
    } else if (space(c)) {
      ++i;
    } else if (c == '#') {
      while (i < s.size() && s[i] != '\n') ++i;  // comments may hold any text
    } else if (c == '"' || c == '\'') {
      const bool multi = s.substr(i, 3) == std::string(3, c);
      i += multi ? 3 : 1;
      last = c;
      while (i < s.size()) {
        const char d = s[i];
        if (d == c && (!multi || s.substr(i, 3) == std::string(3, c))) {
          i += multi ? 3 : 1;
          break;
        }
        if (d == '\n') {
          if (!multi) break;  // toml++ reports the unterminated string
          line_at = ++i, ++line;
          continue;
        }
        if (d == '\\' && c == '"') {
          if (high(i + 1)) return at(i + 1, "is not an escape sequence (\\b \\t \\n \\f \\r \\\" \\\\ \\uXXXX \\UXXXXXXXX)");
          // A line-ending backslash: toml++ skips the white space after it, and cannot classify a
          // non-ASCII character there (its Unicode table has a hole: undefined behaviour).
          size_t k = i + 1;
          while (k < s.size() && space(s[k])) ++k;
          // A backslash and blanks not followed by the line's end (never valid TOML): toml++ goes
          // on skipping white space and asks about the character after them (found by the fuzzer:
          // """Te\\\<tabs><U+FEFD>).
          if (k > i + 1 && high(k))
            return at(k, "cannot follow a backslash and blanks (a line-ending backslash must end its line)");
          if (multi && k < s.size() && s[k] == '\n') {
            while (k < s.size() && (space(s[k]) || s[k] == '\n')) {
              if (s[k] == '\n') line_at = k + 1, ++line;
              ++k;
            }
            if (high(k))
              return at(k, "cannot follow a line-ending backslash (the TOML reader cannot tell whether it is white "
                           "space): start the continued line with an ASCII character");
            i = k;
            continue;
          }
          i += 2;
          continue;
        }
        ++i;
      }
    } else if (c == '[' && open.empty() && last == '\n') {
      header = true;
      i += s.substr(i, 2) == "[[" ? 2 : 1;
      last = '[';
    } else if (c == '[' || c == '{') {
      open.push_back(c);
      last = c;
      ++i;
    } else if (c == ']' || c == '}') {
      if (header) {
        header = false;
      } else if (!open.empty()) {
        open.pop_back();
      }
      last = c;
      ++i;
    } else if (c == ',' || c == '=' || c == '.') {
      last = c;
      ++i;
    } else if (high(i)) {
      return at(i, outside);
    } else {
      const bool key = header || last == '.' || (open.empty() && last == '\n') ||
                       (!open.empty() && open.back() == '{' && (last == '{' || last == ','));
      size_t k = i;
      if (key) {
        while (k < s.size() && (std::isalnum(static_cast<unsigned char>(s[k])) || s[k] == '_' || s[k] == '-')) ++k;
        if (k == i) ++k;  // a character no key has: toml++ stops there with an error
      } else {
        while (k < s.size() && !space(s[k]) && s[k] != '\n' && s[k] != ',' && s[k] != ']' && s[k] != '}' &&
               s[k] != '#') {
          if (high(k)) return at(k, outside);
          ++k;
        }
      }
      last = 'a';
      i = k;
    }
  }
  return {};
}

toml::table parseToml(std::string_view text, const std::string& source) {
  if (const TextPosition p = tooDeepKey(text); p.line > 0)
    throw SceneError(source, p.line, p.column,
                     "this key is nested more than " + std::to_string(kMaxKeyDepth) +
                         " levels deep (table header, inline tables and dotted parts together)");
  // toml++ has undefined behaviour when it asks whether some non-ASCII characters are white
  // space (found by the fuzzer): they are refused first where TOML does not allow them anyway.
  if (const NonAsciiProblem p = misplacedNonAscii(text); p.where.line > 0)
    throw SceneError(source, p.where.line, p.where.column, std::string("a non-ASCII character here ") + p.why);
  const SweepShorthand sweep = quoteSweepShorthand(text);
  try {
    return toml::parse(sweep.changed() ? std::string_view(sweep.text) : text, source);
  } catch (const toml::parse_error& e) {
    const int line = static_cast<int>(e.source().begin.line);
    throw SceneError(source, line, sweep.originalColumn(line, static_cast<int>(e.source().begin.column)),
                     std::string(e.description()));
  }
}

namespace {

bool isDigits(std::string_view s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// "A..B" with integers A and B (optionally negative, blanks around the dots).
bool isIntegerRange(std::string_view v) {
  const size_t dots = v.find("..");
  if (dots == std::string_view::npos) return false;
  auto integer = [](std::string_view x) {
    while (!x.empty() && (x.front() == ' ' || x.front() == '\t')) x.remove_prefix(1);
    while (!x.empty() && (x.back() == ' ' || x.back() == '\t')) x.remove_suffix(1);
    if (!x.empty() && x.front() == '-') x.remove_prefix(1);
    return isDigits(x);
  };
  return integer(v.substr(0, dots)) && integer(v.substr(dots + 2));
}

}  // namespace

int SweepShorthand::originalColumn(int line, int column) const {
  int shift = 0;
  for (const auto& [l, original] : inserted) {
    if (l < line) continue;
    if (l > line) break;
    if (column > original + shift) ++shift;  // this quote stands before the column
  }
  return std::max(1, column - shift);
}

SweepShorthand quoteSweepShorthand(std::string_view text) {
  SweepShorthand out;
  if (text.find("sweep") == std::string_view::npos) return out;
  bool in_sweep = false;
  size_t at = 0;
  int line_no = 0;
  std::string result;
  while (at <= text.size()) {
    const size_t end = std::min(text.find('\n', at), text.size());
    std::string_view line = text.substr(at, end - at);
    ++line_no;
    std::string edited(line);
    const size_t first = line.find_first_not_of(" \t");
    if (first != std::string_view::npos && line[first] == '[') {
      // A table header: [sweep], [sweep.x] (not [[...]]).
      const size_t close = line.find(']', first);
      std::string name(close == std::string_view::npos ? line.substr(first + 1) : line.substr(first + 1, close - first - 1));
      name.erase(std::remove_if(name.begin(), name.end(), [](char c) { return c == ' ' || c == '\t'; }), name.end());
      in_sweep = line.compare(first, 2, "[[") != 0 && (name == "sweep" || name.rfind("sweep.", 0) == 0);
    } else if (in_sweep && first != std::string_view::npos && line[first] != '#' && line[first] != '"' &&
               line[first] != '\'') {
      const size_t eq = line.find('=', first);
      if (eq != std::string_view::npos) {
        std::vector<std::pair<size_t, size_t>> spans;  // [begin, end) to quote, in order
        size_t key_end = eq;
        while (key_end > first && (line[key_end - 1] == ' ' || line[key_end - 1] == '\t')) --key_end;
        const std::string_view key = line.substr(first, key_end - first);
        if (key.find('[') != std::string_view::npos && key.find('"') == std::string_view::npos) spans.push_back({first, key_end});
        size_t v = line.find_first_not_of(" \t", eq + 1);
        if (v != std::string_view::npos) {
          const std::string_view rest = line.substr(v);
          size_t v_end = std::string_view::npos;
          if (rest.rfind("linspace(", 0) == 0 || rest.rfind("logspace(", 0) == 0) {
            int depth = 0;
            for (size_t i = 0; i < rest.size(); ++i) {
              if (rest[i] == '(') ++depth;
              if (rest[i] == ')' && --depth == 0) {
                v_end = v + i + 1;
                break;
              }
            }
          } else {
            const size_t hash = rest.find('#');
            std::string_view value = rest.substr(0, hash);
            while (!value.empty() && (value.back() == ' ' || value.back() == '\t')) value.remove_suffix(1);
            if (isIntegerRange(value)) v_end = v + value.size();
          }
          if (v_end != std::string_view::npos) spans.push_back({v, v_end});
        }
        if (!spans.empty()) {
          edited.clear();
          size_t from = 0;
          for (const auto& [b, e] : spans) {
            edited += std::string(line.substr(from, b - from)) + "\"" + std::string(line.substr(b, e - b)) + "\"";
            out.inserted.push_back({line_no, static_cast<int>(b) + 1});
            out.inserted.push_back({line_no, static_cast<int>(e) + 1});
            from = e;
          }
          edited += std::string(line.substr(from));
        }
      }
    }
    result += edited;
    if (end < text.size()) result += '\n';
    at = end + 1;
  }
  if (!out.inserted.empty()) out.text = std::move(result);
  return out;
}

}  // namespace flexure::scenes
