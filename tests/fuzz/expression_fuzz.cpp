// libFuzzer target: any bytes as a numeric expression. Either a finite number or an
// ExpressionError pointing inside the text.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "scenes/expression.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const double v = flexure::scenes::evaluateExpression(text);
    if (!std::isfinite(v)) __builtin_trap();
  } catch (const flexure::scenes::ExpressionError& e) {
    if (e.offset < 0 || static_cast<std::size_t>(e.offset) > size) __builtin_trap();
  }
  return 0;
}
