#include "render/image.h"

#include <png.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "render/provenance.h"

namespace flexure::render {

namespace {

void appendBytes(png_structp png, png_bytep data, png_size_t n) {
  auto* out = static_cast<std::vector<std::uint8_t>*>(png_get_io_ptr(png));
  out->insert(out->end(), data, data + n);
}

struct ReadCursor {
  const std::vector<std::uint8_t>* bytes;
  size_t at;
};

void readBytes(png_structp png, png_bytep data, png_size_t n) {
  auto* c = static_cast<ReadCursor*>(png_get_io_ptr(png));
  if (c->at + n > c->bytes->size()) png_error(png, "truncated PNG");
  std::memcpy(data, c->bytes->data() + c->at, n);
  c->at += n;
}

[[noreturn]] void onError(png_structp, png_const_charp message) { throw std::runtime_error(message); }
void onWarning(png_structp, png_const_charp) {}

}  // namespace

std::vector<std::uint8_t> encodePng(const Image& im, int level, double dpi) {
  bool opaque = true;
  for (size_t i = 3; i < im.rgba.size() && opaque; i += 4) opaque = im.rgba[i] == 255;
  std::vector<std::uint8_t> out;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, onError, onWarning);
  png_infop info = png_create_info_struct(png);
  try {
    png_set_write_fn(png, &out, appendBytes, nullptr);
    png_set_IHDR(png, info, im.width, im.height, 8, opaque ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_RGBA,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_compression_level(png, std::clamp(level, 0, 9));
    if (level <= 1) {
      // Interactive frames: one cheap filter and run-length matching instead of trying all
      // five filters on every row (half the time of a viewer frame with 1,000 vertices).
      png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
      png_set_compression_strategy(png, Z_RLE);
    }
    // Which flexure made it (render/provenance.h): a tEXt chunk, as `identify -verbose` shows.
    const std::string software = creatorText();
    png_text text{};
    text.compression = PNG_TEXT_COMPRESSION_NONE;
    text.key = const_cast<char*>("Software");
    text.text = const_cast<char*>(software.c_str());
    text.text_length = software.size();
    png_set_text(png, info, &text, 1);
    if (dpi > 0) {
      const auto per_metre = static_cast<png_uint_32>(std::lround(dpi / 0.0254));
      png_set_pHYs(png, info, per_metre, per_metre, PNG_RESOLUTION_METER);
    }
    png_write_info(png, info);
    std::vector<std::uint8_t> row(static_cast<size_t>(im.width) * 4);
    for (int y = 0; y < im.height; ++y) {
      const std::uint8_t* src = im.pixel(0, y);
      if (opaque) {
        for (int x = 0; x < im.width; ++x) std::memcpy(&row[3 * x], src + 4 * x, 3);
      } else {
        std::memcpy(row.data(), src, row.size());
      }
      png_write_row(png, row.data());
    }
    png_write_end(png, nullptr);
  } catch (...) {
    png_destroy_write_struct(&png, &info);
    throw;
  }
  png_destroy_write_struct(&png, &info);
  return out;
}

Image decodePng(const std::vector<std::uint8_t>& bytes) {
  if (bytes.size() < 8 || png_sig_cmp(bytes.data(), 0, 8) != 0) throw std::runtime_error("not a PNG file");
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, onError, onWarning);
  png_infop info = png_create_info_struct(png);
  Image im;
  ReadCursor cursor{&bytes, 0};
  try {
    png_set_read_fn(png, &cursor, readBytes);
    png_read_info(png, info);
    png_set_expand(png);
    png_set_strip_16(png);
    png_set_gray_to_rgb(png);
    png_set_add_alpha(png, 0xff, PNG_FILLER_AFTER);
    png_read_update_info(png, info);
    im = Image(static_cast<int>(png_get_image_width(png, info)), static_cast<int>(png_get_image_height(png, info)));
    std::vector<png_bytep> rows(im.height);
    for (int y = 0; y < im.height; ++y) rows[y] = &im.rgba[static_cast<size_t>(y) * im.width * 4];
    png_read_image(png, rows.data());
  } catch (...) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw;
  }
  png_destroy_read_struct(&png, &info, nullptr);
  return im;
}

}  // namespace flexure::render
