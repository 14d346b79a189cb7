// Scene numbers as exact rationals, for the exact mode ([analysis] exact = true, analyze
// --exact): integers, decimals (the numeral as written, an exact decimal fraction) and strings
// of rational arithmetic ("3/5", "1/3 + 2^-4"). Internal to the scene library.
#pragma once

#include <toml++/toml.h>

#include <string>
#include <string_view>

#include "engine/exact/rational.h"
#include "scenes/toml_reader.h"

namespace flexure::scenes::detail {

// The value of + - * / ^ (integer exponents), parentheses and decimal numerals; throws
// ExpressionError (scenes/expression.h) at the offending offset for anything else (a function,
// pi, a division by zero), with the reason.
engine::Rational evaluateRational(std::string_view text);

// The exact value of a number node as the scene file writes it (SceneError at the node when it
// is not rational). A float whose numeral cannot be found in the file's text (a --set value)
// is the shortest decimal that reads back as its double.
engine::Rational exactNumber(const Reader& r, const toml::node& n, const std::string& what);

}  // namespace flexure::scenes::detail
