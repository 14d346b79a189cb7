// Numeric expressions in scene files: "sqrt(3)/2", "cos(2*pi/5)", "1+sqrt(2)".
// Grammar: + - * / ^ (right-associative, binds tighter than unary minus), parentheses,
// functions sqrt sin cos tan asin acos atan exp log abs, constants pi and e, decimal numbers.
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

namespace flexure::scenes {

struct ExpressionError : std::runtime_error {
  ExpressionError(const std::string& message, int offset)
      : std::runtime_error(message), offset(offset) {}
  int offset;  // 0-based character offset in the expression where the problem is
};

// Evaluates `text`; throws ExpressionError on a syntax error, an unknown name, or a result that
// is not a finite number (e.g. sqrt(-1), 1/0).
double evaluateExpression(std::string_view text);

}  // namespace flexure::scenes
