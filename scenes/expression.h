// Numeric expressions in scene files: "sqrt(3)/2", "cos(2*pi/5)", "1+sqrt(2)", and functions of
// variables such as the surface "x^2 + y^2 - z^2 - 1".
// Grammar: + - * / ^ (right-associative, binds tighter than unary minus), parentheses,
// functions sqrt sin cos tan asin acos atan exp log abs, constants pi and e, decimal numbers,
// and the caller's variable names. Constant parts are folded (and checked) while parsing.
#pragma once

#include <algorithm>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "scenes/excerpt.h"

namespace flexure::scenes {

struct ExpressionError : std::runtime_error {
  ExpressionError(const std::string& message, int offset)
      : std::runtime_error(message), offset(offset) {}
  int offset;  // 0-based character offset in the expression where the problem is
};

// What every message about an error in the expression `text` says: the reason and a bounded
// excerpt of the text around the error ("REASON in \"...EXCERPT...\""), never the whole text.
inline std::string expressionMessage(const ExpressionError& e, std::string_view text) {
  return std::string(e.what()) + " in \"" + excerpt(text, static_cast<size_t>(std::max(0, e.offset))) + "\"";
}

// Evaluates `text`; throws ExpressionError on a syntax error, an unknown name, or a result that
// is not a finite number (e.g. sqrt(-1), 1/0).
double evaluateExpression(std::string_view text);

// A parsed function of up to 3 variables, evaluated with exact first and second derivatives
// (forward-mode automatic differentiation with second-order jets).
class CompiledExpression {
 public:
  // Throws ExpressionError for syntax errors, unknown names and non-finite constant parts.
  CompiledExpression(std::string_view text, std::vector<std::string> variables);

  double value(const double* vars) const;
  // f, its gradient (numVariables()) and, when hessian != nullptr, its Hessian (row-major).
  // Non-finite results are returned as they are (NaN, inf): the caller decides.
  void evaluate(const double* vars, double* f, double* gradient, double* hessian) const;
  int numVariables() const { return static_cast<int>(variables_.size()); }
  const std::string& text() const { return text_; }
  bool usesVariable(int i) const;

  enum class Op { Const, Var, Add, Sub, Mul, Div, Pow, Neg, Fn };
  struct Node {
    Op op = Op::Const;
    double value = 0;  // Const
    int index = 0;     // Var: variable; Fn: function
    int a = -1, b = -1;
  };

 private:
  friend class ExpressionParser;
  std::string text_;
  std::vector<std::string> variables_;
  std::vector<Node> nodes_;  // post-order: children before parents, the root last
};

}  // namespace flexure::scenes
