#include "sweep/where.h"

#include <catch2/catch.hpp>

namespace {

using flexure::sweep::Json;
using flexure::sweep::Where;
using flexure::sweep::WhereError;

const std::vector<std::string> kFields = {"rigid", "inf_rigid", "nontrivial_inf_flexes", "stress_dim", "status",
                                          "second_order", "second_order.stress_margin", "title", "error"};

bool holds(const std::string& text, const Json& item) { return Where(text, kFields)(item); }

size_t errorAt(const std::string& text) {
  try {
    Where(text, kFields);
  } catch (const WhereError& e) {
    return e.offset;
  }
  FAIL("no error for " << text);
  return 0;
}

}  // namespace

TEST_CASE("where: comparisons, connectives and precedence") {
  const Json flexible = {{"rigid", "flexible"}, {"inf_rigid", false}, {"nontrivial_inf_flexes", 2}, {"stress_dim", 1},
                         {"second_order", {{"stress_margin", 0.25}}}, {"status", "ok"}, {"error", nullptr}};
  const Json rigid = {{"rigid", "rigid"}, {"inf_rigid", true}, {"nontrivial_inf_flexes", 0}, {"stress_dim", 0},
                      {"second_order", {{"stress_margin", nullptr}}}, {"status", "ok"}, {"error", nullptr}};
  CHECK(holds("nontrivial_inf_flexes > 0 and stress_dim > 0", flexible));
  CHECK_FALSE(holds("nontrivial_inf_flexes > 0 and stress_dim > 0", rigid));
  CHECK(holds("rigid == 'flexible'", flexible));
  CHECK(holds("rigid == \"rigid\"", rigid));
  CHECK(holds("rigid != 'flexible'", rigid));
  CHECK(holds("inf_rigid", rigid));
  CHECK(holds("not inf_rigid", flexible));
  CHECK(holds("!inf_rigid && stress_dim >= 1", flexible));
  CHECK(holds("inf_rigid == true", rigid));
  CHECK(holds("inf_rigid == false or stress_dim == 0", rigid));
  // and binds tighter than or; parentheses regroup.
  CHECK(holds("stress_dim == 0 or stress_dim == 1 and nontrivial_inf_flexes == 5", rigid));
  CHECK_FALSE(holds("(stress_dim == 0 or stress_dim == 1) and nontrivial_inf_flexes == 5", rigid));
  // Arithmetic, unary minus, nested fields.
  CHECK(holds("nontrivial_inf_flexes - stress_dim == 1", flexible));
  CHECK(holds("2 * stress_dim + 1 == 3 and -stress_dim < 0", flexible));
  CHECK(holds("second_order.stress_margin < 0.5", flexible));
  CHECK(holds("1e-3 < second_order.stress_margin", flexible));
  // Null and mismatched types: equality only, comparisons false.
  CHECK(holds("second_order.stress_margin == null", rigid));
  CHECK_FALSE(holds("second_order.stress_margin < 1", rigid));
  CHECK_FALSE(holds("second_order.stress_margin >= 1", rigid));
  CHECK_FALSE(holds("rigid == 1", rigid));
  CHECK(holds("rigid != 1", rigid));
  CHECK(holds("error == null", rigid));
  // A field the item does not have (a failed item) is null.
  const Json failed = {{"status", "error"}, {"error", "bad.g6:3:1: ..."}};
  CHECK_FALSE(holds("stress_dim > 0", failed));
  CHECK(holds("status == 'error'", failed));
  CHECK_FALSE(holds("rigid == 'flexible'", failed));
}

TEST_CASE("where: malformed expressions are errors at their place") {
  CHECK(errorAt("rigd == 'flexible'") == 0);
  try {
    Where("rigd == 'x'", kFields);
  } catch (const WhereError& e) {
    CHECK(std::string(e.what()).find("did you mean 'rigid'") != std::string::npos);
  }
  CHECK(errorAt("rigid = 'flexible'") == 6);
  CHECK(errorAt("stress_dim > ") == 13);
  CHECK(errorAt("(stress_dim > 0") == 15);
  CHECK(errorAt("rigid == 'flexible") == 9);
  CHECK(errorAt("stress_dim > 0 stress_dim") == 15);
  CHECK(errorAt("") == 0);
  CHECK(errorAt("stress_dim > 0 and") == 18);
  CHECK(errorAt("stress_dim # 1") == 11);
}

TEST_CASE("where: field paths of a JSON object, nested ones dotted") {
  const Json j = {{"a", 1}, {"b", {{"c", 2}, {"d", {1, 2}}}}};
  CHECK(flexure::sweep::fieldPaths(j) == std::vector<std::string>{"a", "b", "b.c", "b.d"});
}

TEST_CASE("where: nesting is bounded, long flat expressions are fine") {
  CHECK(errorAt(std::string(200, '(') + "stress_dim" + std::string(200, ')')) == 100);
  std::string nots;
  for (int i = 0; i < 5000; ++i) nots += "not ";
  CHECK_NOTHROW(errorAt(nots + "inf_rigid") > 0);
  std::string chain = "stress_dim == 0";
  for (int i = 0; i < 2000; ++i) chain += " or stress_dim == " + std::to_string(i);
  const Json item = {{"stress_dim", 1999}};
  CHECK(holds(chain, item));
  // A chain of operators deepens the tree by one each, and the evaluation recurses: bounded
  // (the fuzzer's 37 KB chain of minus signs overflowed the stack).
  std::string minus = "stress_dim";
  for (int i = 0; i < 3000; ++i) minus += "-1";
  CHECK(errorAt(minus + " < 0") > 0);
}
