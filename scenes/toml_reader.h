// The TOML side of reading a scene, internal to the scene library: a Reader over one parsed
// document, whose failures are SceneErrors at a node's file, line and column, and the readers
// of single values (numbers or expressions, integers, arrays, tables, strings, flags, colours).
#pragma once

#include <toml++/toml.h>

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "render/color.h"
#include "scenes/bulk_arrays.h"

namespace flexure::engine {
struct RationalMatrix;  // engine/exact/rational.h
}

namespace flexure::scenes::detail {

// A number as messages write it (10 significant digits).
std::string fmt(double v);

// A node's type as messages name it: "a table", "an array", "a string", ...
std::string typeName(const toml::node& n);

// Reads one parsed document; knows the file name for messages.
class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const toml::source_region& src, const std::string& message,
                         int column_shift = 0) const;
  [[noreturn]] void fail(const toml::node& n, const std::string& message) const {
    fail(n.source(), message);
  }

  // Rejects keys not in `allowed`, pointing at the key, with a suggestion when one is close.
  void checkKeys(const toml::table& t, const std::vector<std::string>& allowed,
                 const std::string& where) const;

  // A number or an expression string; never NaN or infinite.
  double number(const toml::node& n, const std::string& what) const;
  long long integer(const toml::node& n, const std::string& what) const;
  const toml::array& array(const toml::node& n, const std::string& what) const;
  const toml::table& table(const toml::node& n, const std::string& what) const;
  std::string string(const toml::node& n, const std::string& what) const;
  // t[key]; without it, a failure at t: "WHERE needs the key 'KEY'".
  const toml::node& require(const toml::table& t, const std::string& key,
                            const std::string& where) const;

  const std::string& file() const { return file_; }

  // The exact mode: the vertices' coordinates are also read as rationals (scenes/exact_number.h)
  // into exactPoints(), with the file's text (when given) to find the numerals floats were
  // written as.
  void setExact(bool exact) { exact_ = exact; }
  bool exact() const { return exact_; }
  void setText(const std::string* text) { text_ = text; }
  // The line of the file's text that a node of this file starts on; empty when the node is not
  // from the text (a --set value) or there is no text.
  std::string_view lineOfText(const toml::source_region& src) const;
  std::shared_ptr<engine::RationalMatrix>& exactPoints() const { return exact_points_; }

  // The arrays read from the text (scenes/bulk_arrays.h), and the one a node stands for: an
  // empty array of this file at the place of one of them (null for any other node, an
  // override's included).
  void setBulk(std::shared_ptr<const std::vector<BulkArray>> bulk) { bulk_ = std::move(bulk); }
  const BulkArray* bulk(const toml::node& n) const;
  // A failure at value k of a row of a bulk array (k < 0: at the row).
  [[noreturn]] void fail(const BulkArray& a, size_t row, long k, const std::string& message) const;
  // The numeral of a bulk value as the text writes it.
  std::string_view numeral(const BulkArray& a, size_t row, size_t k) const {
    return a.given ? std::string_view() : a.numeral(*text_, row, k);
  }

 private:
  // 1-based line and column of a byte offset of the text.
  std::pair<int, int> position(size_t offset) const;
  std::shared_ptr<const std::vector<BulkArray>> bulk_;
  std::string file_;
  bool exact_ = false;
  const std::string* text_ = nullptr;
  mutable std::vector<size_t> line_starts_;
  mutable std::shared_ptr<engine::RationalMatrix> exact_points_;
};

// true or false.
bool readFlag(const Reader& r, const toml::node& n, const std::string& what);
// "#RRGGBB", "#RRGGBBAA" or a colour name.
render::Color readColor(const Reader& r, const toml::node& n, const std::string& what);

}  // namespace flexure::scenes::detail
