// Text: UTF-8 shaped by HarfBuzz, fonts and fallbacks found by fontconfig, glyphs in an atlas
// that grows; and labels drawn from it.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdlib>
#include <string>

#include "render/camera.h"
#include "render/image.h"
#include "render/renderer.h"
#include "render/reproducible.h"
#include "render/text.h"
#include "render/utf8.h"

using namespace flexure::render;

namespace {

GlyphAtlas& atlas() {
  static GlyphAtlas a(defaultFont(), true, 30);
  return a;
}

std::vector<const Glyph*> glyphsOf(const std::string& text) {
  std::vector<const Glyph*> out;
  for (const PlacedGlyph& p : atlas().layout(text)) out.push_back(p.glyph);
  return out;
}

}  // namespace

TEST_CASE("text: the default font is found by fontconfig, not by a path in the code", "[render][text]") {
  const std::string file = atlas().mainFontFile();
  CHECK(file.find("DejaVuSans-Bold") != std::string::npos);
  GlyphAtlas regular(defaultFont(), false, 30);
  CHECK(regular.mainFontFile().find("DejaVuSans.ttf") != std::string::npos);
  CHECK_THROWS_WITH(GlyphAtlas("/no/such/font.ttf", true, 20), Catch::Contains("cannot load the font"));
}

TEST_CASE("text: ASCII lays out left to right, with kerning", "[render][text]") {
  const auto& watt = atlas().layout("Watt");
  REQUIRE(watt.size() == 4);
  for (size_t i = 1; i < watt.size(); ++i) CHECK(watt[i].x > watt[i - 1].x);
  // HarfBuzz applies the font's kerning: V tucks under A.
  const double av = atlas().layout("AV")[1].x, aa = atlas().layout("AA")[1].x;
  CHECK(av < aa - 0.5);
}

TEST_CASE("text: non-ASCII characters are drawn with their own glyphs", "[render][text]") {
  const Glyph* notdef = glyphsOf("\uE000")[0];  // a private-use character no font has
  const Glyph* question = glyphsOf("?")[0];
  for (const char* s : {"θ", "∈", "π", "ö", "–", "Ж", "∑"}) {
    INFO(s);
    const auto g = glyphsOf(s);
    REQUIRE(g.size() == 1);
    CHECK(g[0] != notdef);
    CHECK(g[0] != question);
    CHECK(g[0]->w > 0);
  }
  // Arabic is joined: the same letter three times takes initial, medial and final forms, none
  // of them the isolated one.
  const auto beh = glyphsOf("ببب");
  REQUIRE(beh.size() == 3);
  const Glyph* isolated = glyphsOf("ب")[0];
  CHECK(beh[0] != beh[1]);
  CHECK(beh[1] != beh[2]);
  for (const Glyph* g : beh) CHECK(g != isolated);
  // A combining accent is composed with its base when the font has the composed character.
  CHECK(glyphsOf("e\u0301") == glyphsOf("é"));
  // Malformed UTF-8 reads as U+FFFD, byte by byte.
  CHECK(glyphsOf("\xff") == glyphsOf("\uFFFD"));
  CHECK(glyphsOf("a\xc3") == glyphsOf("a\uFFFD"));
  CHECK(glyphsOf("\xe2\x88") == glyphsOf("\uFFFD\uFFFD"));
  CHECK(glyphsOf("\xc0\xaf").size() == 2);  // an overlong '/' is two bad bytes
}

TEST_CASE("text: a character the main font lacks comes from a fallback font", "[render][text]") {
  // U+2342 (APL quad backslash): DejaVu Sans Bold lacks it, DejaVu Sans Mono (fonts-dejavu-core)
  // has it.
  GlyphAtlas a(defaultFont(), true, 24);
  const int before = a.generation();
  const auto& line = a.layout("x\u2342");
  REQUIRE(line.size() == 2);
  const Glyph* apl = line[1].glyph;
  const Glyph* notdef = a.layout("\uE000")[0].glyph;
  CHECK(apl != notdef);
  CHECK(apl->w > 0);
  CHECK(a.generation() > before);
}

TEST_CASE("text: the atlas grows while a frame is laid out and earlier labels keep their glyphs", "[render][text]") {
  // Label "AB" alone, then "AB" with a long label of new glyphs laid out after it, which grows
  // the atlas: "AB" must be drawn the same both times.
  View view;
  view.width = 600, view.height = 200;
  view.lo = {0, 0, 0}, view.hi = {6, 2, 0};
  DrawList one;
  Label ab;
  ab.at = {1, 1.5, 0}, ab.text = "AB", ab.size = 17, ab.color = {0, 0, 0, 1};
  one.labels.push_back(ab);
  DrawList both = one;
  Label many = ab;
  many.at = {3, 0.5, 0};
  many.text = "ЖЗИЙКЛМНОПРСТУФХЦЧШЩЪЫЬЭЮЯ αβγδεζηθικλμνξοπρστυφχψω ∀∂∃∅∇∈∉∋∏∑−∕∙√∝∞∟∠∧∨∩∪∫";
  many.size = 11;
  both.labels.push_back(many);
  Renderer first, second;
  const Image alone = first.render(one, view);
  const Image together = second.render(both, view);
  long differing = 0, ink = 0;
  for (int y = 0; y < 100; ++y)
    for (int x = 0; x < 600; ++x) {
      ink += alone.pixel(x, y)[0] < 128;
      differing += std::abs(alone.pixel(x, y)[0] - together.pixel(x, y)[0]) > 2;
    }
  CHECK(ink > 100);
  CHECK(differing == 0);
  // The long label is drawn: ink below.
  long ink_below = 0;
  for (int y = 100; y < 200; ++y)
    for (int x = 0; x < 600; ++x) ink_below += together.pixel(x, y)[0] < 128;
  CHECK(ink_below > 500);
}

TEST_CASE("text: a right-to-left word in a left-to-right line keeps its place and its order", "[render][text]") {
  // "ab سلام cd": the Latin letters left to right at the ends, the Arabic word between them,
  // its letters right to left (the first letter, seen, at the right of the word).
  const auto& line = atlas().layout("ab \u0633\u0644\u0627\u0645 cd");
  REQUIRE(line.size() >= 8);
  const auto& a = atlas().layout("a");
  const auto& c = atlas().layout("c");
  const auto& sin = atlas().layout("\u0633\u0644\u0627\u0645");  // the word alone: its glyphs in visual order
  CHECK(line[0].glyph == a[0].glyph);
  CHECK(line[line.size() - 2].glyph == c[0].glyph);
  // The word's glyphs sit between "ab " and " cd", in the order it has alone.
  std::vector<const Glyph*> word, alone;
  for (size_t i = 3; i + 3 < line.size(); ++i) word.push_back(line[i].glyph);
  for (const PlacedGlyph& p : sin) alone.push_back(p.glyph);
  CHECK(word == alone);
  for (size_t i = 1; i < line.size(); ++i) CHECK(line[i].x > line[i - 1].x);
}

TEST_CASE("utf8: one strict cleaner for every writer: overlong forms, surrogates and noncharacters are replaced") {
  // Issue 42: overlong UTF-8, encoded surrogates and U+FFFE/U+FFFF passed the old cleaner into
  // SVG and TikZ (not well-formed) and PDF (refused, exit 3).
  const std::string bad = "a\xC0\x80" "b\xE0\x80\x80" "c\xED\xA0\x80" "d\xEF\xBF\xBE" "e\xEF\xBF\xBF" "f\xF4\x90\x80\x80" "g";
  const std::string clean = flexure::render::cleanText(bad);
  for (const char* seq : {"\xC0\x80", "\xED\xA0\x80", "\xEF\xBF\xBE", "\xEF\xBF\xBF", "\xF4\x90\x80\x80"})
    CHECK(clean.find(seq) == std::string::npos);
  CHECK(clean.rfind("a\xEF\xBF\xBD", 0) == 0);
  CHECK(clean.back() == 'g');
  CHECK(flexure::render::cleanText("tab\there\x7F\xC2\x85.") == "tab here  .");  // C0, DEL, C1: blanks
  CHECK(flexure::render::cleanText("\xE2\x88\x9A" "2 \xF0\x9F\x98\x80") == "\xE2\x88\x9A" "2 \xF0\x9F\x98\x80");  // valid: kept
  CHECK(flexure::render::isNoncharacter(0xFDD0));
  CHECK(flexure::render::isNoncharacter(0x10FFFF));
  CHECK_FALSE(flexure::render::isNoncharacter(0xFFFD));
}

TEST_CASE("reproducible: SOURCE_DATE_EPOCH is a number of seconds or refused") {
  const char* before = std::getenv("SOURCE_DATE_EPOCH");
  const std::string saved = before ? before : "";
  ::setenv("SOURCE_DATE_EPOCH", "1764000000", 1);
  CHECK(flexure::render::sourceDateEpoch() == 1764000000);
  for (const char* bad : {"abc", "-5", "1e9", "12abc", " 12", "99999999999999999999"}) {
    ::setenv("SOURCE_DATE_EPOCH", bad, 1);
    CHECK_THROWS_WITH(flexure::render::sourceDateEpoch(), Catch::Contains("SOURCE_DATE_EPOCH is '"));
  }
  ::unsetenv("SOURCE_DATE_EPOCH");
  CHECK(flexure::render::sourceDateEpoch() == -1);
  if (before) ::setenv("SOURCE_DATE_EPOCH", saved.c_str(), 1);  // as the run had it
}
