// Glyphs rasterized with FreeType at an exact pixel size, packed into one 8-bit atlas.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace flexure::render {

struct Glyph {
  int x = 0, y = 0, w = 0, h = 0;  // rectangle in the atlas (rows top to bottom)
  int left = 0, top = 0;           // bearing: bitmap origin relative to the pen, px (top: above baseline)
  float advance = 0;               // px
};

class GlyphAtlas {
 public:
  // Throws std::runtime_error when the font cannot be loaded.
  GlyphAtlas(const std::string& font_path, int pixel_size);
  int pixelSize() const { return size_; }
  int width() const { return width_; }
  int height() const { return height_; }
  const std::vector<std::uint8_t>& pixels() const { return pixels_; }
  // Printable ASCII; anything else is drawn as '?'.
  const Glyph& glyph(char c) const;

 private:
  int size_ = 0, width_ = 0, height_ = 0;
  std::vector<std::uint8_t> pixels_;
  std::map<char, Glyph> glyphs_;
};

// The bold sans font flexure labels with (fonts-dejavu-core), or FLEXURE_FONT if set.
std::string defaultFontPath();
// The regular weight next to a bold font file (DejaVuSans-Bold.ttf -> DejaVuSans.ttf), or the
// bold one itself when there is none.
std::string regularFontPath(const std::string& bold_path);

}  // namespace flexure::render
