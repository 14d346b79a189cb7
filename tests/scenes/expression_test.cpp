#include <catch2/catch.hpp>
#include <cmath>

#include "scenes/expression.h"

using flexure::scenes::evaluateExpression;
using flexure::scenes::ExpressionError;
using flexure::scenes::CompiledExpression;

TEST_CASE("expression: numbers operators and precedence", "[scenes]") {
  CHECK(evaluateExpression("1") == 1.0);
  CHECK(evaluateExpression("  2.5e-1 ") == 0.25);
  CHECK(evaluateExpression("1+2*3") == 7.0);
  CHECK(evaluateExpression("(1+2)*3") == 9.0);
  CHECK(evaluateExpression("2^3^2") == 512.0);  // right-associative
  CHECK(evaluateExpression("-2^2") == -4.0);    // ^ binds tighter than unary minus
  CHECK(evaluateExpression("2^-1") == 0.5);
  CHECK(evaluateExpression("7/2-1") == 2.5);
  CHECK(evaluateExpression("--1") == 1.0);
}

TEST_CASE("expression: functions and constants of the SPEC", "[scenes]") {
  CHECK(evaluateExpression("sqrt(3)/2") == Approx(std::sqrt(3.0) / 2).epsilon(1e-15));
  CHECK(evaluateExpression("cos(2*pi/5)") == Approx(std::cos(2 * M_PI / 5)).epsilon(1e-15));
  CHECK(evaluateExpression("1+sqrt(2)") == Approx(1 + std::sqrt(2.0)).epsilon(1e-15));
  CHECK(evaluateExpression("sin(pi/2) + tan(0) + asin(1) - acos(0) + atan(0)") == Approx(1.0));
  CHECK(evaluateExpression("exp(1) - e") == 0.0);
  CHECK(evaluateExpression("log(e^2)") == Approx(2.0));
  CHECK(evaluateExpression("abs(-3)") == 3.0);
}

TEST_CASE("expression: errors say where", "[scenes]") {
  auto offset = [](const char* s) {
    try {
      evaluateExpression(s);
    } catch (const ExpressionError& e) {
      return e.offset;
    }
    return -1;
  };
  CHECK(offset("1 + foo(2)") == 4);
  CHECK(offset("sqrt(-1)") == 5);
  CHECK(offset("1/0") == 2);
  CHECK(offset("(1+2") == 4);
  CHECK(offset("1 2") == 2);
  CHECK(offset("") == 0);
  CHECK(offset("2 * ") == 4);
  CHECK(offset("log(0)") == 4);
  CHECK(offset("1..2") == 0);
  CHECK_THROWS_WITH(evaluateExpression("pie"), Catch::Contains("unknown name 'pie'"));
  CHECK_THROWS_AS(evaluateExpression("10^400"), ExpressionError);
  CHECK_THROWS_WITH(evaluateExpression(std::string(1000, '(') + "1" + std::string(1000, ')')),
                    Catch::Contains("nested too deeply"));
}

TEST_CASE("expression: a sum of 100,000 terms is evaluated without recursion", "[scenes]") {
  // Left-associated sums build a chain as deep as the sum is long; the evaluator walks it in
  // post-order instead of recursing (15,000 terms used to overflow the stack).
  std::string text = "0*(";
  for (int i = 0; i < 100000; ++i) text += i ? "+x" : "x";
  text += ") + y";
  for (int i = 0; i < 100000; ++i) text += "+x";
  const CompiledExpression e(text, {"x", "y"});
  const double vars[2] = {0.5, 2.0};
  double f = 0, g[2] = {0, 0}, h[4];
  e.evaluate(vars, &f, g, h);
  CHECK(f == Approx(2.0 + 100000 * 0.5));
  CHECK(g[0] == Approx(100000.0));
  CHECK(g[1] == 1.0);
  CHECK(e.value(vars) == f);
}

#include <chrono>

#include "scenes/exact_number.h"

TEST_CASE("rational expressions: sizes bounded before every operation (issue 62)", "[scenes]") {
  using flexure::scenes::detail::evaluateRational;
  using flexure::engine::Rational;
  CHECK(evaluateRational("3/5") == Rational(3, 5));
  CHECK(evaluateRational("1/3 + 2^-4") == Rational(19, 48));
  CHECK(evaluateRational("(-1)^100001") == -1);
  CHECK(evaluateRational("1^99999999999999999999") == 1);
  CHECK(evaluateRational("0^123456789012") == 0);
  CHECK(evaluateRational("2^100000") == Rational(mpz_class(1) << 100000));  // 100,001 bits: within the limit
  CHECK(evaluateRational("1e-000000022") == Rational(1, mpz_class("10000000000000000000000")));
  // Beyond the limit: refused at the operator, at once (GMP aborted on the first, the second took
  // a minute and 1.3 GB).
  const auto t0 = std::chrono::steady_clock::now();
  struct Case {
    const char* text;
    int offset;
  };
  for (const Case c : {Case{"(((1/10)^10000)^10000)^10000", 15}, Case{"((1/10)^10000)^10000", 14},
                       Case{"2^400000", 1}, Case{"3^-99999999999999999999", 1}, Case{"1 + 1e-200000", 4},
                       Case{"(7^90000) * (7^90000)", 10}, Case{"7^-80000 + 1/3", 9}, Case{"1e-99999/2.5e+00001001+999991/10", 22}}) {
    INFO(c.text);
    try {
      evaluateRational(c.text);
      FAIL("not refused");
    } catch (const ExpressionError& e) {
      CHECK(e.offset == c.offset);
      CHECK(std::string(e.what()).find("limit") != std::string::npos);
    }
  }
  // No single result too large, but together: bounded too.
  std::string many;
  for (int i = 0; i < 1000; ++i) many += "7^50000 + ";
  CHECK_THROWS_WITH(evaluateRational(many + "1"), Catch::Contains("in all"));
  CHECK(std::chrono::steady_clock::now() - t0 < std::chrono::seconds(3));
  CHECK_THROWS_AS(evaluateRational(std::string(100000, '(') + "1" + std::string(100000, ')')), ExpressionError);
  CHECK_THROWS_AS(evaluateRational(std::string(100000, '-') + "1"), ExpressionError);
  // The double evaluator neither hangs nor crashes on them.
  CHECK(evaluateExpression("(((1/10)^10000)^10000)^10000") == 0.0);
}
