#include <catch2/catch.hpp>

#include <string>

#include "scenes/scene.h"
#include "scenes/toml_text.h"

using flexure::scenes::parseToml;
using flexure::scenes::SceneError;
using flexure::scenes::tooDeepKey;

namespace {

std::string dots(int parts) {
  std::string k = "a";
  for (int i = 1; i < parts; ++i) k += ".a";
  return k;
}

void requireDeep(const std::string& text, int line, int column) {
  const auto p = tooDeepKey(text, 8);
  CHECK(p.line == line);
  CHECK(p.column == column);
}

}  // namespace

TEST_CASE("toml text: key depth counts headers, dotted parts and inline tables", "[scenes]") {
  requireDeep(dots(8) + " = 1\n", 0, 0);
  requireDeep(dots(9) + " = 1\n", 1, 1);
  requireDeep("[" + dots(4) + "]\n" + dots(4) + " = 1\n", 0, 0);
  requireDeep("[" + dots(4) + "]\n" + dots(5) + " = 1\n", 2, 1);
  requireDeep("[[" + dots(9) + "]]\n", 1, 3);
  requireDeep("x = {a = {b = {c = {d = {e = {f = {g = 1}}}}}}}\n", 0, 0);  // x.a.b.c.d.e.f.g: 8
  requireDeep("x = {a = {b = {c = {d = {e = {f = {g.h = 1}}}}}}}\n", 1, 36);
  requireDeep("x = [{a = [{b = 1}]}]\n", 0, 0);
  // Dots that are not in keys: strings, numbers, comments, quoted keys.
  requireDeep("x = \"" + dots(40) + "\"\n", 0, 0);
  requireDeep("x = [1.5, 2.5, 3.5, 4.5, 5.5, 6.5, 7.5, 8.5, 9.5, 1.5]\n", 0, 0);
  requireDeep("# " + dots(40) + "\nx = 1 # " + dots(40) + "\n", 0, 0);
  requireDeep("\"" + dots(40) + "\" = 1\n", 0, 0);
  requireDeep("x = '''\n" + dots(40) + " = 1\n'''\n", 0, 0);
  requireDeep("x = \"\"\"\n\\\"\"\" " + dots(40) + " = 1\n\"\"\"\n", 0, 0);
  // Multi-line arrays: their lines are values, not keys.
  requireDeep("x = [\n  1.0,\n  2.0,\n]\n" + dots(9) + " = 1\n", 5, 1);
}

TEST_CASE("toml text: parseToml names the position of a too deep key and of syntax errors", "[scenes]") {
  try {
    parseToml("title = \"x\"\n" + dots(100) + " = 1\n", "s.toml");
    FAIL("no error");
  } catch (const SceneError& e) {
    CHECK(std::string(e.what()) == "s.toml:2:1: this key is nested more than 64 levels deep (table header, inline "
                                   "tables and dotted parts together)");
  }
  CHECK_THROWS_WITH(parseToml("x = [1,\n", "s.toml"), Catch::StartsWith("s.toml:"));
  CHECK(parseToml("[a.b]\nc.d = 1\n", "s.toml")["a"]["b"]["c"]["d"].value<int>() == 1);
}

TEST_CASE("toml text: non-ASCII characters where toml++ cannot classify them are refused first", "[scenes]") {
  // toml++ 3.3's is_non_ascii_horizontal_whitespace reaches an unreachable point for most of
  // U+00A1..U+0499 (the fuzzer: "3" followed by U+0322 in an array, a UBSan report).
  const auto refused = [](const std::string& text, int line, int column, const std::string& why) {
    INFO(text);
    try {
      parseToml(text, "s.toml");
      FAIL("no error");
    } catch (const SceneError& e) {
      CHECK(e.line == line);
      CHECK(e.column == column);
      CHECK_THAT(e.message, Catch::Contains(why));
    }
  };
  refused("x = [[0,0],[3\xCC\xA2,1]]\n", 1, 14, "outside a string or a comment");
  refused("a = 1\nx = \xC3\xA9\n", 2, 5, "outside a string or a comment");
  refused("\xC3\xA9t\xC3\xA9 = 1\n", 1, 1, "outside a string or a comment");
  refused("t = \"a\\\xC3\xA9\"\n", 1, 8, "not an escape sequence");
  // A quote inside another token is not a string for toml++ (the fuzzer: [4a.a'a.a followed by
  // U+03DE), so what follows it is outside any string.
  refused("x = [4a.a'a.a\xCF\x9E]\n", 1, 14, "outside a string or a comment");
  refused("x = [4a.'\xCF\x9E']\n", 1, 10, "outside a string or a comment");
  refused("x = 0[[\"cos(\xCD\x8F\"\n", 1, 13, "outside a string or a comment");
  refused("x = 0=\"\xCD\x8F\"\n", 1, 8, "outside a string or a comment");
  refused("x = [1, 2a\"\xCD\x8F\"]\n", 1, 12, "outside a string or a comment");
  refused("t = \"\"\"a \\\n   \xCE\xB8\"\"\"\n", 2, 4, "line-ending backslash");
  // A backslash and blanks that do not end the line (the fuzzer, in CI: a UBSan report).
  refused("litlz = \"\"\"Te\\\\\\\t\t\t\t\xEF\xBB\xBD\t:t ", 1, 21, "a backslash and blanks");
  refused("t = \"a\\ \xC3\xA9\"\n", 1, 9, "a backslash and blanks");
  // Where TOML allows them, they are read as they are.
  const std::string ok = "\xEF\xBB\xBF# \xC3\xA9t\xC3\xA9, \xCE\xB8\n"
                         "title = \"Peaucellier\xE2\x80\x93Lipkin, \xCE\xB8 \xE2\x88\x88 [0, \xCF\x80], M\xC3\xB6" "bius\"\n"
                         "a = '\\\xC3\xA9'\n"
                         "b = \"\"\"one\n\xC3\xA9t\xC3\xA9 \\\n   two\"\"\"\n"
                         "c = \"\\u00e9\" # \xC3\xA9\n";
  const toml::table t = parseToml(ok, "s.toml");
  CHECK(t["title"].value<std::string>() == "Peaucellier\xE2\x80\x93Lipkin, \xCE\xB8 \xE2\x88\x88 [0, \xCF\x80], M\xC3\xB6" "bius");
  CHECK(t["a"].value<std::string>() == "\\\xC3\xA9");
  CHECK(t["b"].value<std::string>() == "one\n\xC3\xA9t\xC3\xA9 two");
  CHECK(t["c"].value<std::string>() == "\xC3\xA9");
}

TEST_CASE("toml text: the [sweep] shorthand is quoted, positions are told in the original") {
  using flexure::scenes::quoteSweepShorthand;
  const std::string text =
      "title = \"x..y\"\n"
      "[sweep]\n"
      "system.vertices[3][1] = linspace(0, 1, 50)  # fifty\n"
      "motion.seed = 1..100\n"
      "\"already[0]\" = \"2..3\"\n"
      "analysis.seed = [1, 2]\n"
      "[motion]\n"
      "steps = 1..2\n";
  const auto s = quoteSweepShorthand(text);
  REQUIRE(s.changed());
  CHECK(s.text ==
        "title = \"x..y\"\n"
        "[sweep]\n"
        "\"system.vertices[3][1]\" = \"linspace(0, 1, 50)\"  # fifty\n"
        "motion.seed = \"1..100\"\n"
        "\"already[0]\" = \"2..3\"\n"
        "analysis.seed = [1, 2]\n"
        "[motion]\n"
        "steps = 1..2\n");
  // Line 3: quotes before columns 1, 22, 25 and 43 of the original.
  CHECK(s.originalColumn(3, 1) == 1);   // the opening quote: the key's first character
  CHECK(s.originalColumn(3, 2) == 1);   // 's'
  CHECK(s.originalColumn(3, 25) == 23);  // "=", and the value's opening quote:
  CHECK(s.originalColumn(3, 27) == 25);
  CHECK(s.originalColumn(3, 28) == 25);  // 'l'
  CHECK(s.originalColumn(4, 15) == 15);
  CHECK(s.originalColumn(4, 16) == 15);
  CHECK(s.originalColumn(5, 3) == 3);
  CHECK_FALSE(quoteSweepShorthand("[motion]\nsteps = 1\n").changed());
  // A parse error after the shorthand points where it is in the file as written.
  try {
    flexure::scenes::parseToml("[sweep]\nsystem.vertices[3][1] = linspace(0, 1, 50) junk\n", "s.toml");
    FAIL("no error");
  } catch (const flexure::scenes::SceneError& e) {
    CHECK(e.line == 2);
    CHECK(e.column == 44);  // the "j" of junk
  }
}
