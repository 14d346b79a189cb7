// libFuzzer target: any bytes as a numeric expression. Either a finite number or an
// ExpressionError pointing inside the text (in doubles, and as the exact mode's rational); and as a function of x, y, z (a surface), either
// an ExpressionError inside the text or a value with its derivatives at a point.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "scenes/exact_number.h"
#include "scenes/expression.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto inside = [&](const flexure::scenes::ExpressionError& e) {
    if (e.offset < 0 || static_cast<std::size_t>(e.offset) > size) __builtin_trap();
  };
  try {
    const double v = flexure::scenes::evaluateExpression(text);
    if (!std::isfinite(v)) __builtin_trap();
  } catch (const flexure::scenes::ExpressionError& e) {
    inside(e);
  }
  // The exact mode's parser (issue 62): a rational within the size limit, or an ExpressionError
  // inside the text; never GMP's abort, never a result beyond the limit.
  try {
    const flexure::engine::Rational q = flexure::scenes::detail::evaluateRational(text);
    if (flexure::engine::rationalBits(q) > flexure::engine::kMaxRationalBits) __builtin_trap();
  } catch (const flexure::scenes::ExpressionError& e) {
    inside(e);
  }
  try {
    const flexure::scenes::CompiledExpression f(text, {"x", "y", "z"});
    const double at[3] = {0.3, -0.7, 1.1};
    double value = 0, gradient[3], hessian[9];
    f.evaluate(at, &value, gradient, hessian);
    if (f.value(at) != value && !std::isnan(value)) __builtin_trap();
  } catch (const flexure::scenes::ExpressionError& e) {
    inside(e);
  }
  return 0;
}
