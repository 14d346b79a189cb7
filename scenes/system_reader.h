// The readers that the [system] tables of several system types share, internal to the scene
// library: vertex numbers as written to 0-based ones, the start configuration, pins, lists of
// vertex numbers, optional flags, and a ModelError reported at the item it names.
#pragma once

#include <toml++/toml.h>

#include <algorithm>
#include <array>
#include <string>
#include <vector>

#include "engine/exact/rational.h"
#include "engine/model.h"
#include "scenes/toml_reader.h"

namespace flexure::scenes::detail {

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
  // The same for value k of a row of an array read from the text (scenes/bulk_arrays.h).
  int operator()(const BulkArray& a, size_t row, size_t k, const std::string& what) const {
    if (!a.isInteger(row, k)) r.fail(a, row, static_cast<long>(k), what + " must be an integer, not a number");
    const double v = a.value(row, k);
    if (v < base || v >= base + count)
      r.fail(a, row, static_cast<long>(k), what + " " + std::to_string(static_cast<long long>(v)) +
                                               " is out of range: vertices are numbered " + std::to_string(base) + ".." +
                                               std::to_string(base + count - 1));
    return static_cast<int>(v) - base;
  }
};

// The start configuration (one column per vertex), every vertex with the same number of
// coordinates, one of `allowed_dims`.
engine::Matrix readVertices(const Reader& r, const toml::table& sys, std::vector<int> allowed_dims);

// A flat array of a [system] key (pinned, lengths, radii) as toml++ reads it or as it was read
// from the text (scenes/bulk_arrays.h): its items, and failures at the array or at an item.
class FlatArray {
 public:
  FlatArray(const Reader& r, const toml::node& n, const std::string& key);
  size_t size() const { return bulk_ ? bulk_->rows() : array_->size(); }
  double number(size_t i, const std::string& what) const;
  // Item i read exactly (the exact mode: scenes/exact_number.h), refused at its place when it is
  // not rational or too large.
  engine::Rational exact(size_t i, const std::string& what) const;
  int vertex(const VertexIndexer& vi, size_t i, const std::string& what) const;
  [[noreturn]] void fail(const std::string& message) const { r_.fail(node_, message); }
  [[noreturn]] void fail(size_t i, const std::string& message) const;

 private:
  const Reader& r_;
  const toml::node& node_;
  const BulkArray* bulk_;
  const toml::array* array_ = nullptr;
};

// The exact mode's start as rationals (d x vertices): the coordinates as the file writes them
// (Reader::exactPoints), or, for vertices without a text (an import), the shortest decimals of
// the doubles `p`, as the exact analysis takes them (engine::exact::pointsFromDoubles).
engine::RationalMatrix exactStart(const Reader& r, const engine::Matrix& p);
// |q_a - q_b|^2 of columns a and b.
engine::Rational squaredDistance(const engine::RationalMatrix& q, int a, int b);

// pinned = [i, ...], each vertex once (none without the key).
std::vector<int> readPinned(const Reader& r, const toml::table& sys, const VertexIndexer& vi);

// Lists of vertex numbers: facets, bodies, simplices (min_size..max_size entries each), and
// pairs and triples (fixed size).
std::vector<std::vector<int>> readVertexLists(const Reader& r, const toml::table& sys, const std::string& key,
                                              const VertexIndexer& vi, const std::string& what, size_t min_size,
                                              size_t max_size, bool required = true);

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
[[noreturn]] void failAt(const Reader& r, const toml::table& sys, const engine::ModelError& e);

// sys.get(key) as a boolean (default false).
bool optionalFlag(const Reader& r, const toml::table& sys, const char* key);

// A key's [i, j]: two vertices, 0-based.
std::array<int, 2> vertexPair(const Reader& r, const toml::node& n, const std::string& key, int base, int vertices);

}  // namespace flexure::scenes::detail
