// Large arrays of a scene read straight from its text (internal to the scene library): the
// [system] `vertices`, `edges` (faces, bodies, facets, ... and the flat pinned, lengths and
// radii) of a scene with 10^5 or 10^6 vertices are millions of numbers,
// and toml++ builds a node with its source position for each (about 1 us apiece, and a deep
// copy for the scene's document). A plain array of arrays of numbers (with comments, blank
// lines and trailing commas, as TOML allows) is read here into flat vectors instead, and
// blanked in the text that toml++ parses (to `[]` with the same lines and the same column for
// what follows), so that every other error keeps its place. Anything else in it (a string, an
// expression, an underscore, a table, deeper nesting, a number out of range) leaves the array
// to toml++, which reports it as before.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace flexure::scenes::detail {

struct BulkArray {
  std::string key;              // "vertices", "edges", "faces", ..., "pinned", "lengths", "radii"
  bool flat = false;            // [a, b, ...] (pinned, lengths, radii): a row of one value each
  bool given = false;           // given as numbers (SceneArray, an .npz), not read from the text:
                                // no row_open, failures at line/column with the item
  std::string origin;           // given: the file it came from ("grid.npz"), named in messages
  const void* node = nullptr;   // given: the placeholder node (`KEY = []`, or one the loader
                                // put in for an .npz's array) that it stands for
  size_t open = 0, close = 0;   // byte offsets of its '[' and its ']' in the scene's text
  int line = 0, column = 0;     // of the '[' (1-based): where toml++ sees the blanked array
  std::vector<size_t> row_open;   // byte offset of each row's '[' (flat: of its value)
  std::vector<size_t> row_first;  // index in `values` of each row's first value (rows() + 1 entries)
  std::vector<double> values;
  std::vector<unsigned char> integer;  // per value: written as an integer (else a float)

  size_t rows() const { return row_first.empty() ? 0 : row_first.size() - 1; }
  size_t width(size_t row) const { return row_first[row + 1] - row_first[row]; }
  double value(size_t row, size_t k) const { return values[row_first[row] + k]; }
  bool isInteger(size_t row, size_t k) const { return integer[row_first[row] + k] != 0; }
  // The numeral of value k of a row as the text writes it, and its byte offset.
  std::string_view numeral(std::string_view text, size_t row, size_t k, size_t* offset = nullptr) const;
};

// The [system] keys that have bulk readers: arrays of rows (vertices, edges, faces, ...) and,
// with *flat set, flat arrays (pinned, lengths, radii).
bool bulkKey(std::string_view key, bool* flat = nullptr);

// Arrays shorter than this stay with toml++ (hand-written scenes keep exactly their old path).
inline constexpr size_t kBulkBytes = 16 * 1024;

struct BulkText {
  std::string text;               // the scene's text with the arrays blanked (empty: no array taken)
  std::vector<BulkArray> arrays;
};

// The [system] arrays of `text` (vertices, edges, ...: arrays of arrays of numbers; pinned,
// lengths, radii: arrays of numbers) at least kBulkBytes long, read, and the text with them
// blanked.
BulkText extractBulkArrays(std::string_view text);

}  // namespace flexure::scenes::detail
