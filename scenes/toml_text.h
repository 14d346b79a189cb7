// TOML text in, a table out, with the limits that keep a hostile file from crashing the
// process: toml++ builds and destroys tables recursively, so a key with 30,000 dotted parts
// (80 KB) would overflow the stack. Keys are checked for depth before toml++ sees the text.
#pragma once

#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <toml++/toml.h>

namespace flexure::scenes {

// The deepest a key may reach: its table header's parts, the inline tables around it and its
// own dotted parts, together. Scenes use 3 or 4.
constexpr int kMaxKeyDepth = 64;
// The largest scene file read (a million-vertex framework is 26 MB).
constexpr std::size_t kMaxSceneBytes = std::size_t{256} << 20;

// Parses `text`; throws SceneError at `source`:line:column for a syntax error or a key nested
// deeper than kMaxKeyDepth.
toml::table parseToml(std::string_view text, const std::string& source);

// Where a key first goes deeper than `max_depth` (1-based line and column), or {0, 0}. Does not
// validate the rest: toml++ does that.
struct TextPosition {
  int line = 0, column = 0;
};
TextPosition tooDeepKey(std::string_view text, int max_depth = kMaxKeyDepth);

// The first non-ASCII character where toml++ would ask whether it is white space, which its
// Unicode table answers with undefined behaviour for most of U+00A1..U+0499 and others: outside
// strings and comments (never valid TOML), after a backslash in a basic string (never a valid
// escape), and first after a line-ending backslash of a multi-line string. {{0, 0}} when none.
struct NonAsciiProblem {
  TextPosition where;
  const char* why = "";
};
NonAsciiProblem misplacedNonAscii(std::string_view text);

// The shorthand of a [sweep] table (flexure sweep): keys with array positions and the values
// linspace(...), logspace(...) and A..B written without quotes, as in
//   system.vertices[3][1] = linspace(0, 1, 50)
//   motion.seed = 1..100
// are their quoted TOML forms ("system.vertices[3][1]" = "linspace(0, 1, 50)"). `text` is the
// scene with those quoted (unchanged outside [sweep] and [sweep.*] tables, and when already
// quoted); `inserted` says where, so that positions in it can be told in the original.
struct SweepShorthand {
  std::string text;
  std::vector<std::pair<int, int>> inserted;  // (line, original column) before which a quote went in, in order
  bool changed() const { return !inserted.empty(); }
  // The original column of `column` on `line` of `text`.
  int originalColumn(int line, int column) const;
};
SweepShorthand quoteSweepShorthand(std::string_view text);

}  // namespace flexure::scenes
