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
// is not rational). A float without a text (an import, a catalog entry) is the shortest decimal
// that reads back as its double.
// A float with a text (the file's, a --set value's) is that text read exactly, or refused at its
// place when its exact value is beyond engine::kMaxRationalBits: never a nearby number.
engine::Rational exactNumber(const Reader& r, const toml::node& n, const std::string& what);
// The same for value k of a row of an array read from the text (scenes/bulk_arrays.h); an array
// given as numbers (an .npz, Python's arrays) has no text: the shortest decimals of its doubles.
engine::Rational exactNumber(const Reader& r, const BulkArray& a, size_t row, size_t k, const std::string& what);

}  // namespace flexure::scenes::detail
