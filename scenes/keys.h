// Every key of the scene language, described once: its table, type, range, default and one line
// of documentation. The loader reads the simple keys (numbers, integers, flags, colours, seeds)
// through this table, takes the list of allowed keys of every table from it (unknown keys and
// their suggestions), and reports ranges from it; `flexure keys` prints it as the key reference
// of docs/scene-format.md, which a test keeps equal to it. The system types themselves (names,
// dimensions, builders) are listed in scenes/system_types.cpp; `types` below names them.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "render/color.h"

namespace flexure::scenes {

struct Scene;

enum class KeyKind {
  Integer,        // an integer in [lo, hi]
  Number,         // a number (or expression) in [lo, hi], ends open where said
  Flag,           // true or false
  Color,          // "#RRGGBB", "#RRGGBBAA" or a palette name
  OptionalColor,  // the same; unset means a default that depends on the system
  Seed,           // a nonnegative integer
  OptionalSeed,   // the same; unset means another seed (said in the doc)
  Custom,         // read by its own code in the loader (lists, vertex numbers, tables, text)
};

struct KeySpec {
  std::string table;  // "" (top level), "system", "motion", "analysis", "render", "projection", "output"
  std::string key;
  KeyKind kind = KeyKind::Custom;
  std::string type;         // as documented: "integer", "number", "[[i, j], ...]", ...
  std::string default_doc;  // Custom keys: the default as documented (simple keys: from the code)
  std::string doc;          // one line
  // [system] keys: the system types that take the key ("" for every type but catalog).
  std::string types;
  // The value holds vertex numbers (counted from index_base): what Python rebases to 0.
  bool vertex_indices = false;
  // Integer and Number: the range, with open ends where the value must differ from the bound,
  // and the error when it is outside (default: "KEY must be between LO and HI").
  double lo = 0, hi = 0;
  bool open_lo = false, open_hi = false;
  std::string range_message;
  std::string range_doc;  // Custom keys: the range as documented
  // Integer and Number: a length is taken too ("8cm", "80mm", "3in", "9pt", "800px"), converted
  // by readRender (the figure's size, and sizes in points).
  bool lengths = false;
  // Where a simple key's value goes.
  std::variant<std::monostate, int& (*)(Scene&), double& (*)(Scene&), bool& (*)(Scene&),
               render::Color& (*)(Scene&), std::optional<render::Color>& (*)(Scene&),
               std::uint64_t& (*)(Scene&), std::optional<std::uint64_t>& (*)(Scene&)>
      field;
};

// Every key, in the order of the reference (and of the "known: ..." lists in messages).
const std::vector<KeySpec>& sceneKeys();

// The keys allowed in `table`; for "system", those of the system type `type`.
std::vector<std::string> keysOf(const std::string& table, const std::string& type = "");

// The keys of `table` that hold vertex numbers; for "system" with a type, those of that type.
std::vector<std::string> indexKeysOf(const std::string& table, const std::string& type = "");

// The range of a simple key as text ("16 to 8192", "> 0", "(0, 1)"; "" when it has none).
std::string rangeText(const KeySpec& k);
// A simple key's default, read from a default Scene ("1000", "steelblue" as #4682B4FF, ...).
std::string defaultText(const KeySpec& k);

// The key reference: one Markdown table per scene table.
std::string keyReferenceMarkdown();
// The table of system types (docs/scene-format.md), from the registry (scenes/system_types.cpp).
std::string systemTypesMarkdown();

// The Levenshtein distance of two words: what "did you mean" suggestions are chosen by.
int editDistance(const std::string& a, const std::string& b);

}  // namespace flexure::scenes
