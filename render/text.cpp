#include "render/text.h"

#include <ft2build.h>
#include FT_FREETYPE_H

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <stdexcept>

namespace flexure::render {

std::string defaultFontPath() {
  if (const char* env = std::getenv("FLEXURE_FONT")) return env;
  for (const char* p : {"/usr/share/fonts/truetype/dejavu/DejaVuSans-Bold.ttf",
                        "/usr/share/fonts/TTF/DejaVuSans-Bold.ttf",
                        "/usr/share/fonts/dejavu/DejaVuSans-Bold.ttf"})
    if (std::ifstream(p).good()) return p;
  return "/usr/share/fonts/truetype/dejavu/DejaVuSans-Bold.ttf";
}

std::string regularFontPath(const std::string& bold_path) {
  const auto pos = bold_path.rfind("-Bold");
  if (pos == std::string::npos) return bold_path;
  const std::string regular = bold_path.substr(0, pos) + bold_path.substr(pos + 5);
  return std::ifstream(regular).good() ? regular : bold_path;
}

GlyphAtlas::GlyphAtlas(const std::string& font_path, int pixel_size) : size_(pixel_size) {
  FT_Library lib = nullptr;
  if (FT_Init_FreeType(&lib)) throw std::runtime_error("FreeType could not start");
  FT_Face face = nullptr;
  if (FT_New_Face(lib, font_path.c_str(), 0, &face)) {
    FT_Done_FreeType(lib);
    throw std::runtime_error("cannot load the font " + font_path + " (install fonts-dejavu-core or set FLEXURE_FONT)");
  }
  FT_Set_Pixel_Sizes(face, 0, static_cast<FT_UInt>(pixel_size));
  // Shelf packing into a fixed-width atlas.
  struct Bitmap {
    Glyph g;
    std::vector<std::uint8_t> px;
  };
  std::vector<std::pair<char, Bitmap>> all;
  for (int c = 32; c < 127; ++c) {
    if (FT_Load_Char(face, static_cast<FT_ULong>(c), FT_LOAD_RENDER)) continue;
    const FT_GlyphSlot s = face->glyph;
    Bitmap b;
    b.g.w = static_cast<int>(s->bitmap.width);
    b.g.h = static_cast<int>(s->bitmap.rows);
    b.g.left = s->bitmap_left;
    b.g.top = s->bitmap_top;
    b.g.advance = static_cast<float>(s->advance.x) / 64.0f;
    b.px.resize(static_cast<size_t>(b.g.w) * b.g.h);
    for (int y = 0; y < b.g.h; ++y)
      std::copy_n(s->bitmap.buffer + y * s->bitmap.pitch, b.g.w, b.px.begin() + static_cast<long>(y) * b.g.w);
    all.emplace_back(static_cast<char>(c), std::move(b));
  }
  FT_Done_Face(face);
  FT_Done_FreeType(lib);
  width_ = std::max(64, 16 * (pixel_size + 2));
  int x = 1, y = 1, shelf = 0;
  for (auto& [c, b] : all) {
    if (x + b.g.w + 1 > width_) x = 1, y += shelf + 1, shelf = 0;
    b.g.x = x, b.g.y = y;
    x += b.g.w + 1;
    shelf = std::max(shelf, b.g.h);
  }
  height_ = y + shelf + 1;
  pixels_.assign(static_cast<size_t>(width_) * height_, 0);
  for (auto& [c, b] : all) {
    for (int r = 0; r < b.g.h; ++r)
      std::copy_n(b.px.begin() + static_cast<long>(r) * b.g.w, b.g.w,
                  pixels_.begin() + static_cast<long>(b.g.y + r) * width_ + b.g.x);
    glyphs_[c] = b.g;
  }
  if (!glyphs_.count('?')) throw std::runtime_error("the font " + font_path + " has no ASCII glyphs");
}

const Glyph& GlyphAtlas::glyph(char c) const {
  auto it = glyphs_.find(c);
  return it != glyphs_.end() ? it->second : glyphs_.at('?');
}

}  // namespace flexure::render
