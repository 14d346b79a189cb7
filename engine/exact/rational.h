// Exact rational numbers and dense rational matrices: the arithmetic of the exact mode
// (engine/exact/exact_rigidity.h). Rationals are GMP's (mpq_class, canonical after every
// operation); the linear algebra that must scale (ranks, null spaces) runs in FLINT on integer
// matrices (engine/exact/exact_linear_algebra.h).
#pragma once

#include <gmpxx.h>

#include <string>
#include <string_view>
#include <vector>

namespace flexure::engine {

using Rational = mpq_class;

// A dense rows x cols matrix of rationals, row-major.
struct RationalMatrix {
  int rows = 0, cols = 0;
  std::vector<Rational> data;

  RationalMatrix() = default;
  RationalMatrix(int r, int c) : rows(r), cols(c), data(static_cast<size_t>(r) * static_cast<size_t>(c)) {}
  Rational& operator()(int i, int j) { return data[static_cast<size_t>(i) * static_cast<size_t>(cols) + static_cast<size_t>(j)]; }
  const Rational& operator()(int i, int j) const {
    return data[static_cast<size_t>(i) * static_cast<size_t>(cols) + static_cast<size_t>(j)];
  }
};

// The largest number the exact mode reads from its input: the bits of its numerator and of its
// denominator (lowest terms) together, at most this many (about 120,000 decimal digits in all).
// Every sensible scene number is far below it (a double's exact value has at most 2,200 bits,
// 1e-100000 has 332,193); above it, one product in the rigidity matrix costs milliseconds and an
// elimination hours, and GMP aborts (exit 134) on results near 2^37 bits. Numbers and the results
// of the operations in rational expressions are bounded by it before they are computed.
inline constexpr long kMaxRationalBits = 400000;
// The size of q as kMaxRationalBits counts it: bits of the numerator plus bits of the denominator.
long rationalBits(const Rational& q);

enum class DecimalRead {
  ok,            // out holds the exact value
  not_numeral,   // not a decimal numeral (out untouched)
  too_large,     // a numeral whose exact value is beyond kMaxRationalBits (out untouched)
};
// The exact value of a decimal numeral: [+-]digits[.digits][(e|E)[+-]digits], with TOML's
// underscores between digits, the exponent with any number of leading zeros (as TOML allows);
// not_numeral for anything else, including inf and nan.
DecimalRead readDecimal(std::string_view text, Rational& out);
// readDecimal(...) == DecimalRead::ok.
bool parseDecimal(std::string_view text, Rational& out);
// The shortest decimal numeral that reads back as v (finite), as an exact rational: what a
// decimal written with at most 15 significant digits was, when only its double is known.
Rational shortestDecimal(double v);
// The double nearest to q (+-inf beyond the double range; subnormal results may be off by one
// unit in the last place), however large q's numerator and denominator are.
double nearestDouble(const Rational& q);
// "p/q", or "p" for an integer.
std::string toString(const Rational& q);

}  // namespace flexure::engine
