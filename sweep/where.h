// The filter of `flexure sweep --where`: a boolean expression over an item's JSON fields, e.g.
//   nontrivial_inf_flexes > 0 and stress_dim > 0
//   rigid == 'flexible' or numerics.gap < 1e6
// Grammar (lowest precedence first): `or` (also ||), `and` (&&), `not` (!), comparisons
// == != < <= > >=, + -, * /, unary -, and primaries: numbers, 'strings' or "strings", true,
// false, null, field names (dotted for nested objects: second_order.stress_margin) and
// parentheses. A field an item does not have is null (an item that failed has no results).
// Comparisons: numbers by value, strings by text, booleans and null by equality only; a
// comparison of mismatched types is false (!= true). Truth: false, null, 0 and '' are false.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace flexure::sweep {

// A malformed expression: where (0-based byte offset) and what.
using Json = nlohmann::ordered_json;

class WhereError : public std::invalid_argument {
 public:
  WhereError(size_t offset, const std::string& message) : std::invalid_argument(message), offset(offset) {}
  size_t offset;
};

class Where {
 public:
  // Parses `text`; every field name must be one of `fields` (dotted paths), so that a typo is
  // an error rather than a filter that keeps nothing.
  Where(std::string text, const std::vector<std::string>& fields);
  ~Where();
  Where(Where&&) noexcept;
  Where& operator=(Where&&) noexcept;
  bool operator()(const nlohmann::ordered_json& item) const;
  const std::string& text() const { return text_; }
  // The fields the expression reads (dotted paths, as written).
  const std::vector<std::string>& fields() const { return used_; }

  struct Node;

 private:
  std::string text_;
  std::vector<std::string> used_;
  std::unique_ptr<Node> root_;
};

// The dotted paths of every field of `j` (objects nested; arrays are leaves).
std::vector<std::string> fieldPaths(const nlohmann::ordered_json& j);

}  // namespace flexure::sweep
