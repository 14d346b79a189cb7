// Text for the raster renderer: UTF-8 shaped by HarfBuzz, fonts found by fontconfig (a
// character the main font lacks comes from the font fontconfig finds for it), glyphs rasterized
// by FreeType at an exact pixel size into one 8-bit atlas that grows as glyphs are needed.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace flexure::render {

struct Glyph {
  int x = 0, y = 0, w = 0, h = 0;  // rectangle in the atlas (rows top to bottom)
  int left = 0, top = 0;           // bearing: bitmap origin relative to the pen, px (top: above baseline)
};

// A glyph placed on a line: its pen position relative to the line's start on the baseline
// (px; x to the right, y up).
struct PlacedGlyph {
  const Glyph* glyph = nullptr;
  double x = 0, y = 0;
};

class GlyphAtlas {
 public:
  // `font`: a font file, or a fontconfig pattern ("DejaVu Sans", "Noto Serif:italic"); the
  // weight is bold or regular. Throws std::runtime_error when no font can be loaded.
  GlyphAtlas(const std::string& font, bool bold, int pixel_size);
  ~GlyphAtlas();
  GlyphAtlas(const GlyphAtlas&) = delete;
  GlyphAtlas& operator=(const GlyphAtlas&) = delete;

  int pixelSize() const;
  int width() const;
  int height() const;
  const std::vector<std::uint8_t>& pixels() const;
  // Changes whenever glyphs are added: a texture made from pixels() before is stale.
  int generation() const;
  // The line of UTF-8 text (malformed bytes read as U+FFFD), shaped run by run (a run: the
  // characters one font draws), left to right. Glyph pointers stay valid for the atlas's life; the vector until the
  // next call.
  const std::vector<PlacedGlyph>& layout(const std::string& utf8);
  // The font file the atlas draws with first (tests, diagnostics).
  std::string mainFontFile() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The font flexure labels with: FLEXURE_FONT (a file or a fontconfig pattern) if set, else
// "DejaVu Sans" (fonts-dejavu-core).
std::string defaultFont();
// The family name of a font (file or pattern) for formats that name fonts (SVG, PDF).
std::string fontFamily(const std::string& font);
// The characters of UTF-8 text (bytes that do not continue a character), for width estimates.
size_t utf8Characters(const std::string& text);

}  // namespace flexure::render
