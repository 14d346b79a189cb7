// The fast path of scenes/bulk_arrays.h: a scanner for plain arrays of arrays of numbers.
#include "scenes/bulk_arrays.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstring>
#include <cstdint>

namespace flexure::scenes::detail {

namespace {

bool isBlank(char c) { return c == ' ' || c == '\t'; }

// Reads one array of arrays of numbers starting at text[open] == '['; nullopt when it is
// anything else (toml++ then reads it and reports what is wrong).
class Scanner {
 public:
  Scanner(std::string_view text, size_t open) : s_(text), i_(open) {}

  bool scan(BulkArray& out) {
    ++i_;  // the outer '['
    out.row_first.push_back(0);
    const bool ok = items([&] {
      out.row_open.push_back(i_);
      if (out.flat) {
        if (!number(out)) return false;
      } else {
        if (peek() != '[') return false;
        ++i_;
        if (!items([&] { return number(out); })) return false;
        ++i_;  // the row's ']'
      }
      out.row_first.push_back(out.values.size());
      return true;
    });
    if (!ok) return false;
    out.close = i_;
    return true;
  }

  // The items of a list up to its ']' (i_ just past its '['), each read by `item`: blanks,
  // comments and commas between them, a trailing comma allowed; i_ then at the ']'.
  template <class Item>
  bool items(Item item) {
    for (;;) {
      if (!skip()) return false;
      if (peek() == ']') return true;
      if (!item()) return false;
      if (!skip()) return false;
      if (peek() == ',') {
        ++i_;
        continue;
      }
      if (peek() != ']') return false;
    }
  }

  // White space, line breaks and comments; false at the end of the text or at a character
  // that TOML does not allow there (a bare CR, a control character in a comment).
  bool skip() {
    while (i_ < s_.size()) {
      const char c = s_[i_];
      if (isBlank(c) || c == '\n') {
        ++i_;
      } else if (c == '\r') {
        if (i_ + 1 >= s_.size() || s_[i_ + 1] != '\n') return false;
        i_ += 2;
      } else if (c == '#') {
        while (i_ < s_.size() && s_[i_] != '\n') {
          const unsigned char u = static_cast<unsigned char>(s_[i_]);
          if ((u < 0x20 && u != '\t' && !(u == '\r' && i_ + 1 < s_.size() && s_[i_ + 1] == '\n')) || u == 0x7f)
            return false;
          ++i_;
        }
      } else {
        return true;
      }
    }
    return false;
  }

 private:
  char peek() const { return s_[i_]; }

  // A TOML integer or float in the plain decimal forms: [+-](0|[1-9][0-9]*)(.[0-9]+)?([eE][+-]?[0-9]+)?
  bool number(BulkArray& out) {
    size_t j = i_;
    const bool plus = s_[j] == '+';
    if (s_[j] == '+' || s_[j] == '-') ++j;
    const size_t digits = j;
    while (j < s_.size() && s_[j] >= '0' && s_[j] <= '9') ++j;
    if (j == digits || (s_[digits] == '0' && j - digits > 1)) return false;  // none, or a leading zero
    bool is_float = false;
    if (j < s_.size() && s_[j] == '.') {
      const size_t f = ++j;
      while (j < s_.size() && s_[j] >= '0' && s_[j] <= '9') ++j;
      if (j == f) return false;
      is_float = true;
    }
    if (j < s_.size() && (s_[j] == 'e' || s_[j] == 'E')) {
      ++j;
      if (j < s_.size() && (s_[j] == '+' || s_[j] == '-')) ++j;
      const size_t e = j;
      while (j < s_.size() && s_[j] >= '0' && s_[j] <= '9') ++j;
      if (j == e) return false;
      is_float = true;
    }
    // What follows a number: a separator (anything else, as "1_000" or "1.5x", is toml++'s).
    if (j < s_.size() && !(isBlank(s_[j]) || s_[j] == ',' || s_[j] == ']' || s_[j] == '\n' || s_[j] == '\r' || s_[j] == '#'))
      return false;
    const char* first = s_.data() + i_ + (plus ? 1 : 0);
    const char* last = s_.data() + j;
    double v = 0;
    if (is_float) {
      const auto r = std::from_chars(first, last, v);
      if (r.ec != std::errc() || r.ptr != last) return false;  // out of range: toml++ reads it
    } else {
      std::int64_t n = 0;
      const auto r = std::from_chars(first, last, n);
      if (r.ec != std::errc() || r.ptr != last) return false;
      if (n > (std::int64_t{1} << 53) || n < -(std::int64_t{1} << 53)) return false;  // not exact as a double
      v = static_cast<double>(n);
    }
    out.values.push_back(v);
    out.integer.push_back(is_float ? 0 : 1);
    i_ = j;
    return true;
  }

  std::string_view s_;
  size_t i_;
};

// The name of a table header line ("[system]", "[ system ]" -> "system"); empty when the line
// is not a plain header.
std::string_view headerName(std::string_view line) {
  size_t i = 0;
  while (i < line.size() && isBlank(line[i])) ++i;
  if (i >= line.size() || line[i] != '[') return {};
  if (i + 1 < line.size() && line[i + 1] == '[') return "[[";  // an array of tables: not [system]
  const size_t close = line.find(']', i);
  if (close == std::string_view::npos) return {};
  // Only a table's name (bare or quoted keys, dots, blanks) and nothing but a comment after it:
  // not a row of an array ("[0, 1],").
  for (size_t k = i + 1; k < close; ++k)
    if (!(std::isalnum(static_cast<unsigned char>(line[k])) || std::strchr("_-.\"' \t", line[k]))) return {};
  for (size_t k = close + 1; k < line.size() && line[k] != '#'; ++k)
    if (!isBlank(line[k]) && line[k] != '\r') return {};
  std::string_view name = line.substr(i + 1, close - i - 1);
  while (!name.empty() && isBlank(name.front())) name.remove_prefix(1);
  while (!name.empty() && isBlank(name.back())) name.remove_suffix(1);
  return name;
}

// The key of a line `KEY = [` (bare key, blanks around '='), with the offset of its '['.
std::string_view arrayKey(std::string_view line, size_t& bracket) {
  size_t i = 0;
  while (i < line.size() && isBlank(line[i])) ++i;
  const size_t k = i;
  while (i < line.size() && (std::isalnum(static_cast<unsigned char>(line[i])) || line[i] == '_' || line[i] == '-')) ++i;
  const std::string_view key = line.substr(k, i - k);
  while (i < line.size() && isBlank(line[i])) ++i;
  if (i >= line.size() || line[i] != '=') return {};
  ++i;
  while (i < line.size() && isBlank(line[i])) ++i;
  if (i >= line.size() || line[i] != '[') return {};
  bracket = i;
  return key;
}

// The [system] keys read here: arrays of rows of numbers, and flat arrays of numbers. Each has a
// reader that knows both forms (scenes/system_reader.h); a key of the other form, or any other
// key, stays with toml++.
bool rowsKey(std::string_view key) {
  for (const char* k : {"vertices", "edges", "angles", "bodies", "bars", "attached", "faces", "creases", "facets",
                        "contacts", "simplices"})
    if (key == k) return true;
  return false;
}

bool flatKey(std::string_view key) { return key == "pinned" || key == "lengths" || key == "radii"; }

}  // namespace

bool bulkKey(std::string_view key, bool* flat) {
  if (flat) *flat = flatKey(key);
  return rowsKey(key) || flatKey(key);
}

std::string_view BulkArray::numeral(std::string_view text, size_t row, size_t k, size_t* offset) const {
  size_t i = row_open[row] + (flat ? 0 : 1);
  for (size_t n = 0;; ++n) {
    // Blanks, line breaks, comments and commas up to the next numeral.
    while (i < text.size()) {
      if (text[i] == '#') {
        while (i < text.size() && text[i] != '\n') ++i;
      } else if (isBlank(text[i]) || text[i] == '\n' || text[i] == '\r' || text[i] == ',') {
        ++i;
      } else {
        break;
      }
    }
    size_t j = i;
    while (j < text.size() && !(isBlank(text[j]) || text[j] == ',' || text[j] == ']' || text[j] == '\n' ||
                                text[j] == '\r' || text[j] == '#'))
      ++j;
    if (n == k || j >= text.size()) {
      if (offset) *offset = i;
      return text.substr(i, j - i);
    }
    i = j;
  }
}

BulkText extractBulkArrays(std::string_view text) {
  BulkText out;
  std::string_view table;  // the current table header's name ("" before the first)
  size_t line_start = 0;
  int line = 1;
  std::vector<BulkArray> arrays;
  while (line_start < text.size()) {
    size_t end = text.find('\n', line_start);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view l = text.substr(line_start, end - line_start);
    size_t next = end + 1;
    int next_line = line + 1;
    if (const std::string_view h = headerName(l); !h.empty()) {
      table = h;
    } else if (table == "system") {
      size_t bracket = 0;
      const std::string_view key = arrayKey(l, bracket);
      if ((rowsKey(key) || flatKey(key)) && (l.size() <= bracket + 1 || l[bracket + 1] != ']')) {
        BulkArray a;
        a.key = std::string(key);
        a.flat = flatKey(key);
        a.open = line_start + bracket;
        a.line = line;
        a.column = static_cast<int>(bracket) + 1;
        if (Scanner(text, a.open).scan(a) && a.close - a.open >= kBulkBytes) {
          // Go on after the array's last line (its lines are not headers or keys).
          const size_t after = text.find('\n', a.close);
          next_line = line + 1;
          for (size_t i = a.open; i < std::min(after, text.size()); ++i) next_line += text[i] == '\n' ? 1 : 0;
          next = after == std::string_view::npos ? text.size() : after + 1;
          arrays.push_back(std::move(a));
        }
      }
    }
    line_start = next;
    line = next_line;
  }
  if (arrays.empty()) return out;
  // The text with each array blanked: '[', its line breaks, blanks up to the column of its ']',
  // and the ']'.
  out.text.reserve(text.size() / 8);
  size_t from = 0;
  for (const BulkArray& a : arrays) {
    out.text.append(text.substr(from, a.open + 1 - from));
    size_t last_break = std::string_view::npos;
    for (size_t i = a.open; i < a.close; ++i)
      if (text[i] == '\n') {
        out.text.push_back('\n');
        last_break = i;
      }
    const size_t pad = last_break == std::string_view::npos ? a.close - a.open - 1 : a.close - last_break - 1;
    out.text.append(pad, ' ');
    out.text.push_back(']');
    from = a.close + 1;
  }
  out.text.append(text.substr(from));
  out.arrays = std::move(arrays);
  return out;
}

}  // namespace flexure::scenes::detail
