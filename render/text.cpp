#include "render/text.h"

#include <fontconfig/fontconfig.h>
#include <ft2build.h>
#include FT_FREETYPE_H
#include <hb-ft.h>
#include <hb.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <map>
#include <optional>
#include <stdexcept>
#include <unordered_map>

namespace flexure::render {

std::string defaultFont() {
  if (const char* env = std::getenv("FLEXURE_FONT"); env && *env) return env;
  return "DejaVu Sans";
}

size_t utf8Characters(const std::string& text) {
  return static_cast<size_t>(std::count_if(text.begin(), text.end(), [](char c) { return (c & 0xC0) != 0x80; }));
}

namespace {

struct FontFile {
  std::string path;
  int index = 0;
};

// A font named with a '/' is a file; anything else a fontconfig pattern.
bool isPath(const std::string& s) { return s.find('/') != std::string::npos; }

// fontconfig's best font for `pattern` at a weight; with `covering`, the best one that has that
// character (fontconfig ranks the family above coverage, so the sorted list is searched).
std::optional<FontFile> match(const std::string& pattern, bool bold, std::optional<char32_t> covering) {
  FcPattern* p = FcNameParse(reinterpret_cast<const FcChar8*>(pattern.c_str()));
  if (!p) return std::nullopt;
  FcPatternDel(p, FC_WEIGHT);
  FcPatternAddInteger(p, FC_WEIGHT, bold ? FC_WEIGHT_BOLD : FC_WEIGHT_REGULAR);
  FcConfigSubstitute(nullptr, p, FcMatchPattern);
  FcDefaultSubstitute(p);
  FcResult result;
  FcFontSet* set = FcFontSort(nullptr, p, FcFalse, nullptr, &result);
  FcPatternDestroy(p);
  if (!set) return std::nullopt;
  std::optional<FontFile> out;
  for (int i = 0; i < set->nfont && !out; ++i) {
    FcChar8* file = nullptr;
    FcCharSet* cs = nullptr;
    if (FcPatternGetString(set->fonts[i], FC_FILE, 0, &file) != FcResultMatch) continue;
    if (covering && !(FcPatternGetCharSet(set->fonts[i], FC_CHARSET, 0, &cs) == FcResultMatch &&
                      FcCharSetHasChar(cs, *covering)))
      continue;
    int index = 0;
    FcPatternGetInteger(set->fonts[i], FC_INDEX, 0, &index);
    out = FontFile{reinterpret_cast<const char*>(file), index};
  }
  FcFontSetDestroy(set);
  return out;
}

// The regular weight next to a bold font file (DejaVuSans-Bold.ttf -> DejaVuSans.ttf), or the
// file itself when there is none.
std::string regularFile(const std::string& bold_path) {
  const auto pos = bold_path.rfind("-Bold");
  if (pos == std::string::npos) return bold_path;
  const std::string regular = bold_path.substr(0, pos) + bold_path.substr(pos + 5);
  return std::ifstream(regular).good() ? regular : bold_path;
}

// UTF-8 to code points; a malformed or overlong sequence, a surrogate or a value beyond
// U+10FFFF reads as U+FFFD and the decoder resumes at the next byte.
std::vector<char32_t> decodeUtf8(const std::string& s) {
  std::vector<char32_t> out;
  const auto* b = reinterpret_cast<const unsigned char*>(s.data());
  const size_t n = s.size();
  for (size_t i = 0; i < n;) {
    const unsigned c = b[i];
    int len = c < 0x80 ? 1 : (c >> 5) == 6 ? 2 : (c >> 4) == 14 ? 3 : (c >> 3) == 30 ? 4 : 0;
    char32_t cp = len == 1 ? c : len == 2 ? (c & 0x1F) : len == 3 ? (c & 0x0F) : (c & 0x07);
    bool ok = len > 0 && i + len <= n;
    for (int k = 1; ok && k < len; ++k) {
      ok = (b[i + k] & 0xC0) == 0x80;
      cp = (cp << 6) | (b[i + k] & 0x3F);
    }
    static const char32_t smallest[5] = {0, 0, 0x80, 0x800, 0x10000};
    ok = ok && cp >= smallest[len] && cp <= 0x10FFFF && !(cp >= 0xD800 && cp <= 0xDFFF);
    out.push_back(ok ? cp : 0xFFFD);
    i += ok ? static_cast<size_t>(len) : 1;
  }
  return out;
}

}  // namespace

std::string fontFamily(const std::string& font) {
  std::string family = "DejaVu Sans";
  FcPattern* p = nullptr;
  if (isPath(font)) {
    int count = 0;
    p = FcFreeTypeQuery(reinterpret_cast<const FcChar8*>(font.c_str()), 0, nullptr, &count);
  } else {
    p = FcNameParse(reinterpret_cast<const FcChar8*>(font.c_str()));
  }
  FcChar8* name = nullptr;
  if (p && FcPatternGetString(p, FC_FAMILY, 0, &name) == FcResultMatch) family = reinterpret_cast<const char*>(name);
  if (p) FcPatternDestroy(p);
  return family;
}

struct GlyphAtlas::Impl {
  struct Face {
    FT_Face ft = nullptr;
    hb_font_t* hb = nullptr;
    std::string file;
  };
  std::string pattern;
  bool bold = true;
  int size = 0, width = 0, height = 0, generation = 0;
  std::vector<std::uint8_t> pixels;
  FT_Library lib = nullptr;
  std::vector<Face> faces;                         // [0]: the main font
  std::map<char32_t, int> face_of;                 // characters the main font lacks: their face (0: none has it)
  std::unordered_map<std::uint64_t, Glyph> glyphs;  // key: face << 32 | glyph index
  std::unordered_map<std::string, std::vector<PlacedGlyph>> lines;  // layouts made, by text
  int pen_x = 1, pen_y = 1, shelf = 0;             // shelf packing

  ~Impl() {
    for (Face& f : faces) {
      if (f.hb) hb_font_destroy(f.hb);
      if (f.ft) FT_Done_Face(f.ft);
    }
    if (lib) FT_Done_FreeType(lib);
  }

  // Opens a font file at the atlas's size; -1 when FreeType cannot read it.
  int open(const FontFile& file) {
    for (size_t i = 0; i < faces.size(); ++i)
      if (faces[i].file == file.path) return static_cast<int>(i);
    FT_Face ft = nullptr;
    if (FT_New_Face(lib, file.path.c_str(), file.index, &ft)) return -1;
    if (FT_Set_Pixel_Sizes(ft, 0, static_cast<FT_UInt>(size))) {
      FT_Done_Face(ft);
      return -1;
    }
    faces.push_back({ft, hb_ft_font_create_referenced(ft), file.path});
    return static_cast<int>(faces.size()) - 1;
  }

  // The face to draw a character with: the main font when it has it, else the font fontconfig
  // finds for it, else the main font (its missing-glyph box).
  int faceFor(char32_t c) {
    if (c < 0x20 || FT_Get_Char_Index(faces[0].ft, c)) return 0;
    if (auto it = face_of.find(c); it != face_of.end()) return it->second;
    int face = 0;
    for (size_t i = 1; i < faces.size() && !face; ++i)
      if (FT_Get_Char_Index(faces[i].ft, c)) face = static_cast<int>(i);
    if (!face)
      if (auto file = match(pattern, bold, c)) face = std::max(0, open(*file));
    return face_of[c] = face;
  }

  const Glyph& glyph(int face, unsigned index) {
    const std::uint64_t key = (static_cast<std::uint64_t>(face) << 32) | index;
    if (auto it = glyphs.find(key); it != glyphs.end()) return it->second;
    Glyph g;
    FT_Face ft = faces[static_cast<size_t>(face)].ft;
    if (!FT_Load_Glyph(ft, index, FT_LOAD_RENDER | FT_LOAD_TARGET_NORMAL) && ft->glyph->bitmap.pixel_mode == FT_PIXEL_MODE_GRAY) {
      const FT_GlyphSlot s = ft->glyph;
      g.w = static_cast<int>(s->bitmap.width), g.h = static_cast<int>(s->bitmap.rows);
      g.left = s->bitmap_left, g.top = s->bitmap_top;
      if (g.w > 0 && g.h > 0) {
        place(g);
        for (int r = 0; r < g.h; ++r)
          std::copy_n(s->bitmap.buffer + static_cast<long>(r) * s->bitmap.pitch, g.w,
                      pixels.begin() + static_cast<long>(g.y + r) * width + g.x);
        ++generation;
      } else {
        g.w = g.h = 0;
      }
    }
    return glyphs[key] = g;
  }

  // A rectangle for the glyph on the shelves; the atlas grows downwards (rows are appended, so
  // what is placed stays where it is).
  void place(Glyph& g) {
    g.w = std::min(g.w, width - 2);
    if (pen_x + g.w + 1 > width) pen_x = 1, pen_y += shelf + 1, shelf = 0;
    g.x = pen_x, g.y = pen_y;
    pen_x += g.w + 1;
    shelf = std::max(shelf, g.h);
    if (pen_y + shelf + 1 > height) {
      height = std::max(2 * height, pen_y + shelf + 1);
      pixels.resize(static_cast<size_t>(width) * height, 0);
    }
  }

  std::vector<PlacedGlyph> shape(const std::string& utf8) {
    const std::vector<char32_t> cps = decodeUtf8(utf8);
    std::vector<PlacedGlyph> out;
    double pen = 0;
    hb_buffer_t* buf = hb_buffer_create();
    hb_unicode_funcs_t* ucd = hb_unicode_funcs_get_default();
    // The direction a character's script writes in; none for spaces, digits, punctuation and
    // marks (common and inherited scripts), which go with the run they are in.
    const auto direction = [&](char32_t c) {
      const hb_script_t s = hb_unicode_script(ucd, c);
      return s == HB_SCRIPT_COMMON || s == HB_SCRIPT_INHERITED || s == HB_SCRIPT_UNKNOWN
                 ? HB_DIRECTION_INVALID
                 : hb_script_get_horizontal_direction(s);
    };
    for (size_t start = 0; start < cps.size();) {
      // A run: the characters one face draws in one direction (combining marks stay with their
      // base). Runs are placed in logical order: a right-to-left word in a left-to-right line
      // reads right, without the full bidirectional algorithm.
      const int face = faceFor(cps[start]);
      hb_direction_t dir = direction(cps[start]);
      size_t end = start + 1;
      while (end < cps.size()) {
        const bool mark = hb_unicode_general_category(ucd, cps[end]) == HB_UNICODE_GENERAL_CATEGORY_NON_SPACING_MARK &&
                          FT_Get_Char_Index(faces[static_cast<size_t>(face)].ft, cps[end]);
        const hb_direction_t d = direction(cps[end]);
        if (!mark && (faceFor(cps[end]) != face || (d != HB_DIRECTION_INVALID && dir != HB_DIRECTION_INVALID && d != dir)))
          break;
        if (dir == HB_DIRECTION_INVALID) dir = d;
        ++end;
      }
      // The spaces and punctuation after a right-to-left word before a left-to-right one belong
      // to the line, not to the word.
      if (dir == HB_DIRECTION_RTL && end < cps.size())
        while (end > start + 1 && direction(cps[end - 1]) == HB_DIRECTION_INVALID &&
               hb_unicode_general_category(ucd, cps[end - 1]) != HB_UNICODE_GENERAL_CATEGORY_NON_SPACING_MARK)
          --end;
      hb_buffer_clear_contents(buf);
      hb_buffer_add_utf32(buf, reinterpret_cast<const std::uint32_t*>(cps.data() + start),
                          static_cast<int>(end - start), 0, static_cast<int>(end - start));
      hb_buffer_guess_segment_properties(buf);
      hb_shape(faces[static_cast<size_t>(face)].hb, buf, nullptr, 0);
      unsigned count = 0;
      const hb_glyph_info_t* info = hb_buffer_get_glyph_infos(buf, &count);
      const hb_glyph_position_t* pos = hb_buffer_get_glyph_positions(buf, &count);
      for (unsigned i = 0; i < count; ++i) {
        const Glyph& g = glyph(face, info[i].codepoint);
        out.push_back({&g, pen + pos[i].x_offset / 64.0, pos[i].y_offset / 64.0});
        pen += pos[i].x_advance / 64.0;
      }
      start = end;
    }
    hb_buffer_destroy(buf);
    return out;
  }
};

GlyphAtlas::GlyphAtlas(const std::string& font, bool bold, int pixel_size) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.pattern = font.empty() ? defaultFont() : font;
  m.bold = bold;
  m.size = pixel_size;
  if (FT_Init_FreeType(&m.lib)) throw std::runtime_error("FreeType could not start");
  std::optional<FontFile> main;
  if (isPath(m.pattern)) {
    main = FontFile{bold ? m.pattern : regularFile(m.pattern), 0};
    m.pattern = "DejaVu Sans";  // fallbacks for the characters the file lacks
  } else {
    main = match(m.pattern, bold, std::nullopt);
  }
  if (!main || m.open(*main) != 0)
    throw std::runtime_error("cannot load the font \"" + font + "\"" + (main && main->path != font ? " (" + main->path + ")" : "") +
                             ": install fonts-dejavu-core, or set FLEXURE_FONT to a font file or a fontconfig name");
  m.width = std::max(64, 16 * (pixel_size + 2));
  m.height = std::max(16, 2 * pixel_size);
  m.pixels.assign(static_cast<size_t>(m.width) * m.height, 0);
  // Printable ASCII up front: most labels need nothing else.
  std::string ascii;
  for (char c = 32; c < 127; ++c) ascii += c;
  m.shape(ascii);
}

GlyphAtlas::~GlyphAtlas() = default;

int GlyphAtlas::pixelSize() const { return impl_->size; }
int GlyphAtlas::width() const { return impl_->width; }
int GlyphAtlas::height() const { return impl_->height; }
const std::vector<std::uint8_t>& GlyphAtlas::pixels() const { return impl_->pixels; }
int GlyphAtlas::generation() const { return impl_->generation; }
std::string GlyphAtlas::mainFontFile() const { return impl_->faces[0].file; }

const std::vector<PlacedGlyph>& GlyphAtlas::layout(const std::string& utf8) {
  Impl& m = *impl_;
  if (auto it = m.lines.find(utf8); it != m.lines.end()) return it->second;
  // Titles that change every frame ("t = 0.53") would grow the cache without end.
  if (m.lines.size() >= 4096) m.lines.clear();
  return m.lines[utf8] = m.shape(utf8);
}

}  // namespace flexure::render
