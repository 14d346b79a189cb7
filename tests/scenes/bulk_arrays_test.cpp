// Large [system] vertices and edges read straight from the text (scenes/bulk_arrays.h) against
// toml++'s reading of the same scene: each scene is loaded as written (the fast path) and with
// its first coordinate and first vertex number written in hexadecimal (0x0, 0x1: TOML, but not
// the fast path's plain decimals, so toml++ reads those arrays). Everything after the first row
// is at the same place in both texts, so models, documents and every error must agree exactly.
#include <catch2/catch.hpp>

#include <random>
#include <string>

#include "engine/exact/rational.h"
#include "engine/systems/framework.h"
#include "scenes/bulk_arrays.h"
#include "scenes/scene.h"

using flexure::scenes::loadSceneFromString;
using flexure::scenes::Scene;
using flexure::scenes::SceneError;

namespace {

// An n x n grid of unit squares braced every other row, as a scene; `coordinate(i, k)` writes
// coordinate k of vertex i (1-based vertex numbers), comments and blank lines here and there.
template <class Coordinate>
std::string gridScene(int n, Coordinate coordinate, const std::string& after = "") {
  std::string s = "title = \"grid\"\n[system]\ntype = \"framework\"\nvertices = [\n";
  for (int i = 0; i < n * n; ++i) {
    s += "[" + coordinate(i, 0) + ", " + coordinate(i, 1) + "],";
    s += i % 7 == 6 ? "  # seven\n" : i % 11 == 10 ? "\n\n" : " ";
  }
  s += "\n]\nedges = [";
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      const int i = r * n + c + 1;
      if (c + 1 < n) s += "[" + std::to_string(i) + ", " + std::to_string(i + 1) + "], ";
      if (r + 1 < n) s += "[" + std::to_string(i) + ",\n " + std::to_string(i + n) + "], ";
      if (c + 1 < n && r + 1 < n && r % 2 == 0) s += "[" + std::to_string(i) + ", " + std::to_string(i + n + 1) + "]\n, ";
    }
  s += "]\npinned = [1, 2]\n" + after;
  return s;
}

std::string plainCoordinate(int i, int k, int n) { return std::to_string(k == 0 ? i % n : i / n); }

// The same text with toml++ reading both arrays: the first coordinate and the first edge's first
// vertex in hexadecimal.
std::string slowText(std::string s) {
  const auto hex = [&](const std::string& head, const char* was, const char* is) {
    const size_t at = s.find(head);
    REQUIRE(at != std::string::npos);
    const size_t v = at + head.size();
    REQUIRE(s.compare(v, 4, was) == 0);
    s.replace(v, 4, is);                  // one character longer ...
    const size_t end = s.find("],", v);
    REQUIRE(s[end + 2] == ' ');
    s.erase(end + 2, 1);                  // ... and the blank after the row one shorter
  };
  hex("vertices = [\n", "[0, ", "[0x0,");
  hex("edges = [", "[1, ", "[0x1,");
  return s;
}

// A document of the slow text with its two hexadecimal numbers as the fast one writes them (toml++
// keeps an integer's base).
std::string decimal(std::string doc) {
  for (const auto& [from, to] : {std::pair<std::string, std::string>{"[ 0x1,", "[ 1,"}, {"[ 0x0,", "[ 0,"}}) {
    const size_t at = doc.find(from);
    REQUIRE(at != std::string::npos);
    doc.replace(at, from.size(), to);
  }
  return doc;
}

std::string errorOf(const std::string& text) {
  try {
    loadSceneFromString(text, "grid.toml");
  } catch (const SceneError& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace

TEST_CASE("bulk arrays: a large scene reads the same as through toml++", "[scenes]") {
  const int n = 40;  // 1,600 vertices, 3,900 bars: both arrays past kBulkBytes
  const std::string fast = gridScene(n, [&](int i, int k) { return plainCoordinate(i, k, n); });
  const std::string slow = slowText(fast);
  REQUIRE(fast.size() == slow.size());
  const flexure::scenes::detail::BulkText bulk = flexure::scenes::detail::extractBulkArrays(fast);
  REQUIRE(bulk.arrays.size() == 2);
  CHECK(flexure::scenes::detail::extractBulkArrays(slow).arrays.empty());
  CHECK(bulk.text.size() < fast.size() / 10);
  const Scene a = loadSceneFromString(fast, "grid.toml"), b = loadSceneFromString(slow, "grid.toml");
  const auto& fa = dynamic_cast<const flexure::engine::Framework&>(*a.model);
  const auto& fb = dynamic_cast<const flexure::engine::Framework&>(*b.model);
  CHECK(fa.edges() == fb.edges());
  CHECK(fa.system().positions(fa.startCoordinates()) == fb.system().positions(fb.startCoordinates()));
  CHECK(fa.system().numPinned() == 2);
  // The scene's document (what a path JSON carries) holds the arrays again, integers as integers.
  CHECK(a.document() == decimal(b.document()));
  const Scene again = loadSceneFromString(a.document(), "again.toml");
  CHECK(dynamic_cast<const flexure::engine::Framework&>(*again.model).edges() == fa.edges());
  // An override replaces an array read from the text.
  const Scene c = loadSceneFromString(fast, "grid.toml", {"system.edges=[[1,2]]"});
  CHECK(dynamic_cast<const flexure::engine::Framework&>(*c.model).edges().size() == 1);
  CHECK(c.document().find("[ 1, 2 ]") != std::string::npos);
  CHECK(c.document().size() < a.document().size() / 2);
}

TEST_CASE("bulk arrays: floats, signs, exponents and the exact mode", "[scenes]") {
  const int n = 30;
  std::mt19937 rng(45);
  std::vector<std::string> written;
  const std::string fast = gridScene(n, [&](int i, int k) {
    const double v = (k == 0 ? i % n : i / n) + (rng() % 1000) / 1e4;
    const int form = static_cast<int>(rng() % 4);
    char buf[64];
    if (i == 0 && k == 0) return std::string("0");
    if (form == 0) std::snprintf(buf, sizeof buf, "%.4f", v);
    else if (form == 1) std::snprintf(buf, sizeof buf, "+%.4f", v);
    else if (form == 2) std::snprintf(buf, sizeof buf, "%.3e", v);
    else std::snprintf(buf, sizeof buf, "%.4fE0", v);
    return std::string(buf);
  });
  const std::string slow = slowText(fast);
  const Scene a = loadSceneFromString(fast, "grid.toml", {"analysis.exact=true"});
  const Scene b = loadSceneFromString(slow, "grid.toml", {"analysis.exact=true"});
  CHECK(a.model->system().positions(a.model->startCoordinates()) ==
        b.model->system().positions(b.model->startCoordinates()));
  REQUIRE(a.exact_vertices);
  REQUIRE(b.exact_vertices);
  CHECK(a.exact_vertices->data == b.exact_vertices->data);
  // 1.2345e0 is exactly 12345/10^4 (the numeral, not the double).
  CHECK(a.document() == decimal(b.document()));
}

TEST_CASE("bulk arrays: every error at the same place with the same words as through toml++", "[scenes]") {
  const int n = 40;
  const auto plain = [&](int i, int k) { return plainCoordinate(i, k, n); };
  const auto check = [&](const std::string& fast) {
    const std::string slow = slowText(fast);
    const std::string a = errorOf(fast), b = errorOf(slow);
    INFO(a);
    CHECK(a != "no error");
    CHECK(a == b);
  };
  const std::string base = gridScene(n, plain);
  const auto replaced = [&](const std::string& from, const std::string& to, size_t after = 0) {
    std::string s = base;
    const size_t at = s.find(from, after);
    REQUIRE(at != std::string::npos);
    s.replace(at, from.size(), to);
    return s;
  };
  const size_t edges = base.find("edges = [");
  SECTION("a vertex number out of range") { check(replaced("[41, 42]", "[41, 4200]", edges)); }
  SECTION("a vertex number that is a float") { check(replaced("[41, 42]", "[41, 42.0]", edges)); }
  SECTION("an edge from a vertex to itself") { check(replaced("[41, 42]", "[41, 41]", edges)); }
  SECTION("a repeated edge") { check(replaced("[43, 44]", "[42, 41]", edges)); }
  SECTION("an edge with three vertices") { check(replaced("[41, 42]", "[41, 42, 43]", edges)); }
  SECTION("an edge of length 0") { check(replaced("[5, 0]", "[4, 0]")); }
  SECTION("a vertex with three coordinates") { check(replaced("[5, 0]", "[5, 0, 0]")); }
  SECTION("a coordinate out of range") { check(replaced("[5, 0]", "[5, 1e300]")); }
  SECTION("an error after the arrays keeps its place") {
    check(gridScene(n, plain, "unknown_key = 1\n"));
    check(gridScene(n, plain, "[motion]\nsteps = \"many\"\n"));
  }
  SECTION("a syntax error after an array") { check(replaced("]\npinned", "] x\npinned")); }
}

TEST_CASE("bulk arrays: what is not a plain array of numbers stays with toml++", "[scenes]") {
  const int n = 40;
  const std::string base = gridScene(n, [&](int i, int k) { return plainCoordinate(i, k, n); });
  using flexure::scenes::detail::extractBulkArrays;
  REQUIRE(extractBulkArrays(base).arrays.size() == 2);
  const auto taken = [&](const std::string& from, const std::string& to) {
    std::string s = base;
    const size_t at = s.find(from);
    REQUIRE(at != std::string::npos);
    s.replace(at, from.size(), to);
    return extractBulkArrays(s).arrays.size();
  };
  CHECK(taken("[5, 0]", "[\"1/3\", 0]") == 1);   // an expression string
  CHECK(taken("[5, 0]", "[5_0, 0]") == 1);       // an underscore
  CHECK(taken("[5, 0]", "[05, 0]") == 1);        // a leading zero (a TOML error)
  CHECK(taken("[5, 0]", "[5., 0]") == 1);        // a dot without digits (a TOML error)
  CHECK(taken("[5, 0]", "[inf, 0]") == 1);       // not finite
  CHECK(taken("[5, 0]", "[1e999, 0]") == 1);     // out of range
  CHECK(taken("[5, 0]", "[[5], 0]") == 1);       // deeper
  CHECK(taken("[5, 0]", "[5 0]") == 1);          // no comma
  CHECK(taken("[5, 0]", "[5, 0]\r") == 1);       // a bare CR
  CHECK(taken("[5, 0]", "[5, {x = 0}]") == 1);   // a table
  CHECK(taken("[5, 0]", "[9007199254740993, 0]") == 1);  // an integer a double cannot hold
  // Each still loads or fails as toml++ says (here: the expression string is a coordinate).
  std::string s = base;
  s.replace(s.find("[5, 0]"), 6, "[\"5\", 0]");
  CHECK_NOTHROW(loadSceneFromString(s, "grid.toml"));
  // A scene whose multi-line string looks like a [system] table with a large array: the
  // document shows that the array was not one, and toml++ reads the whole text.
  std::string fake = "title = \"\"\"\n[system]\nvertices = [\n";
  for (int i = 0; i < 3000; ++i) fake += "[" + std::to_string(i) + ", 0], ";
  fake += "\n]\n\"\"\"\n" + base.substr(base.find("[system]"));
  REQUIRE(extractBulkArrays(fake).arrays.size() == 3);
  const Scene f = loadSceneFromString(fake, "fake.toml");
  CHECK(f.model->system().numVertices() == n * n);
  CHECK(f.title.size() > 3000 * 6);
}

namespace {

// The n x n integer grid's vertices, as a [system] `vertices` array.
std::string gridVertices(int n) {
  std::string s = "vertices = [\n";
  for (int i = 0; i < n * n; ++i) s += "[" + std::to_string(i % n) + ", " + std::to_string(i / n) + "], ";
  return s + "\n]\n";
}

// The triangles of the n x n grid (two per square, 1-based), as the rows of `key`.
std::string gridTriangles(int n, const std::string& key) {
  std::string s = key + " = [\n";
  for (int r = 0; r + 1 < n; ++r)
    for (int c = 0; c + 1 < n; ++c) {
      const int i = r * n + c + 1;
      s += "[" + std::to_string(i) + ", " + std::to_string(i + 1) + ", " + std::to_string(i + n + 1) + "], [" +
           std::to_string(i) + ", " + std::to_string(i + n + 1) + ", " + std::to_string(i + n) + "],\n";
    }
  return s + "]\n";
}

// `text` with `key` quoted where it opens its array: toml++ then reads that array (the fast path
// takes bare keys only). The array's rows start on the next line, so every error inside them is
// at the same place in both texts.
std::string quotedKey(std::string text, const std::string& key) {
  const size_t at = text.find("\n" + key + " = [\n");
  REQUIRE(at != std::string::npos);
  text.replace(at + 1, key.size(), "\"" + key + "\"");
  return text;
}

}  // namespace

TEST_CASE("bulk arrays: every system type's large arrays read the same as through toml++", "[scenes]") {
  const int n = 70;  // 4,900 vertices, 9,522 triangles: every array past kBulkBytes
  std::string ones = "lengths = [\n", pins = "pinned = [\n", radii = "radii = [\n", angles = "angles = [\n";
  std::string edges = "edges = [\n";
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      const int i = r * n + c + 1;
      if (c + 1 < n) edges += "[" + std::to_string(i) + ", " + std::to_string(i + 1) + "], ", ones += "1, ";
      if (r + 1 < n) edges += "[" + std::to_string(i) + ", " + std::to_string(i + n) + "],\n", ones += "1.0,\n";
      if (r + 1 < n && c + 1 < n)  // the right angle at i between its neighbours right and up
        angles += "[" + std::to_string(i + 1) + ", " + std::to_string(i) + ", " + std::to_string(i + n) + "], ";
    }
  for (int i = 1; i <= n * n; ++i) {
    if (i % 3 != 0) pins += std::to_string(i) + ", ";
    radii += "0.5, ";
  }
  edges += "]\n", ones += "]\n", pins += "]\n", radii += "]\n", angles += "]\n";
  struct Case {
    const char* name;
    std::string text;
    std::vector<std::string> keys;
    size_t others = 1;  // the other arrays read from the text: the vertices (and the edges)
  };
  const std::string head = "title = \"t\"\n[system]\n";
  const std::vector<Case> cases = {
      {"framework: lengths and pinned", head + "type = \"framework\"\n" + gridVertices(n) + edges + ones + pins,
       {"lengths", "pinned"}, 2},
      {"body_hinge: bodies", head + "type = \"body_hinge\"\n" + gridVertices(n) + gridTriangles(n, "bodies"), {"bodies"}},
      {"volume_hypergraph: simplices", head + "type = \"volume_hypergraph\"\n" + gridVertices(n) + gridTriangles(n, "simplices"),
       {"simplices"}},
      {"sphere_packing: radii", head + "type = \"sphere_packing\"\n" + gridVertices(n) + radii, {"radii"}},
      {"angular_framework: angles", head + "type = \"angular_framework\"\n" + gridVertices(n) + angles, {"angles"}},
  };
  for (const Case& c : cases) {
    INFO(c.name);
    const auto bulk = flexure::scenes::detail::extractBulkArrays(c.text);
    CHECK(bulk.arrays.size() == c.keys.size() + c.others);
    std::string slow = c.text;
    for (const std::string& k : c.keys) slow = quotedKey(slow, k);
    CHECK(flexure::scenes::detail::extractBulkArrays(slow).arrays.size() == c.others);
    const Scene a = loadSceneFromString(c.text, "s.toml"), b = loadSceneFromString(slow, "s.toml");
    const auto& sa = a.model->system();
    const auto& sb = b.model->system();
    REQUIRE(sa.numVariables() == sb.numVariables());
    REQUIRE(sa.numEquations() == sb.numEquations());
    CHECK(sa.numPinned() == sb.numPinned());
    const flexure::engine::Vector xa = a.model->startCoordinates(), xb = b.model->startCoordinates();
    CHECK(xa == xb);
    const flexure::engine::SparseMatrix ja = sa.jacobian(xa), jb = sb.jacobian(xb);
    CHECK(ja.nonZeros() == jb.nonZeros());
    CHECK(flexure::engine::SparseMatrix(ja - jb).norm() == 0.0);
    CHECK(a.document() == b.document());
    // An error in a row, at the same place with the same words.
    for (const std::string& k : c.keys) {
      const size_t at = c.text.find("\n" + k + " = [\n");
      const size_t row = c.text.find(", ", c.text.find("\n", at + 1) + 200) + 2;  // an item past the first line
      const size_t end = c.text.find_first_of(",]", row);
      for (const std::string& bad : {std::string("99999"), std::string("-1"), std::string("\"x\"")}) {
        std::string f = c.text;
        f.replace(row, end - row, bad);
        std::string s = f;
        for (const std::string& q : c.keys) s = quotedKey(s, q);
        INFO(k << " <- " << bad);
        const std::string ea = errorOf(f), eb = errorOf(s);
        CHECK(ea != "no error");
        CHECK(ea == eb);
      }
    }
  }
}

TEST_CASE("bulk arrays: arrays given as numbers load as their text does, errors at their item", "[scenes]") {
  using flexure::scenes::SceneArray;
  const int n = 12;
  std::string text = "title = \"g\"\n[system]\ntype = \"framework\"\n" + gridVertices(n) + "edges = [\n";
  SceneArray v{"vertices", {}, static_cast<size_t>(n * n), 2, true}, e{"edges", {}, 0, 2, true};  // integers, as the text
  for (int i = 0; i < n * n; ++i) v.values.insert(v.values.end(), {static_cast<double>(i % n), static_cast<double>(i / n)});
  for (int i = 1; i <= n * n; ++i) {
    if (i % n != 0) text += "[" + std::to_string(i) + ", " + std::to_string(i + 1) + "],\n", e.values.insert(e.values.end(), {double(i), double(i + 1)});
    if (i + n <= n * n) text += "[" + std::to_string(i) + ", " + std::to_string(i + n) + "],\n", e.values.insert(e.values.end(), {double(i), double(i + n)});
  }
  text += "]\npinned = [1, 2]\n";
  e.rows = e.values.size() / 2;
  const std::string placeholders = "title = \"g\"\n[system]\ntype = \"framework\"\nvertices = []\nedges = []\npinned = [1, 2]\n";
  const Scene a = loadSceneFromString(text, "g.toml"), b = loadSceneFromString(placeholders, "g.toml", {v, e});
  CHECK(a.model->startCoordinates() == b.model->startCoordinates());
  CHECK(dynamic_cast<const flexure::engine::Framework&>(*a.model).edges() ==
        dynamic_cast<const flexure::engine::Framework&>(*b.model).edges());
  CHECK(a.document() == b.document());
  // An error in a row: at the placeholder, with the row as the item.
  const auto failure = [&](std::vector<SceneArray> arrays) {
    try {
      loadSceneFromString(placeholders, "g.toml", std::move(arrays));
    } catch (const SceneError& err) {
      return err;
    }
    FAIL("no error");
    return SceneError("", 0, 0, "");
  };
  SceneArray bad = e;
  bad.values[2 * 5 + 1] = 999;
  const SceneError range = failure({v, bad});
  CHECK(range.line == 5);
  CHECK(range.item == 5);
  CHECK(range.message.find("out of range") != std::string::npos);
  SceneArray nan = v;
  nan.values[7] = std::nan("");
  const SceneError not_a_number = failure({nan, e});
  CHECK(not_a_number.line == 4);
  CHECK(not_a_number.item == 3);
  CHECK_THROWS_AS(loadSceneFromString(text, "g.toml", {v}), std::invalid_argument);  // no placeholder
}
