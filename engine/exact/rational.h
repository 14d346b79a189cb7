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

// The exact value of a decimal numeral: [+-]digits[.digits][(e|E)[+-]digits], with TOML's
// underscores between digits; false (out untouched) for anything else, including inf and nan.
bool parseDecimal(std::string_view text, Rational& out);
// The shortest decimal numeral that reads back as v (finite), as an exact rational: what a
// decimal written with at most 15 significant digits was, when only its double is known.
Rational shortestDecimal(double v);
// "p/q", or "p" for an integer.
std::string toString(const Rational& q);

}  // namespace flexure::engine
