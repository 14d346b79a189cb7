// Writing changed keys back into a scene file's text, keeping everything else as it was
// (comments, order, layout): the viewer's "save as".
#pragma once

#include <toml++/toml.h>

#include <string>
#include <vector>

namespace flexure::scenes {

// `text` with every "KEY=VALUE" assignment (the --set syntax: a dotted key, a TOML value)
// applied: an existing value is replaced in place, a missing key is added under its table's
// header (or in a new table at the end). When the edited text does not read back with the
// same values (an inline table, dotted keys elsewhere...), the whole document is written
// out again by the TOML library instead (comments are then lost). Throws SceneError when an
// assignment is malformed or `text` is not TOML.
std::string withKeys(const std::string& text, const std::vector<std::string>& assignments);

// --set KEY=VALUE on a parsed document: VALUE is parsed as TOML (a bare word becomes a
// string); missing tables on the way are created. Throws SceneError ("--set") when malformed.
void applyOverride(toml::table& doc, const std::string& assignment);

// The TOML text of a number that reads back as exactly the same double.
std::string tomlNumber(double value);

}  // namespace flexure::scenes
