// An RGBA8 image (top row first) and its PNG encoding (libpng).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace flexure::render {

struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba;  // width * height * 4, rows top to bottom

  Image() = default;
  Image(int w, int h) : width(w), height(h), rgba(static_cast<size_t>(w) * h * 4, 0) {}
  const std::uint8_t* pixel(int x, int y) const { return &rgba[(static_cast<size_t>(y) * width + x) * 4]; }
};

// PNG bytes (8-bit RGB when every pixel is opaque, RGBA otherwise). Deterministic: no time
// stamp, fixed compression settings; the one text chunk names the flexure that wrote it.
// `level`: zlib's 1 (fast, the viewer) to 9. `dpi` > 0: the resolution in a pHYs chunk, so that
// a figure sized in length units is placed at its size (LaTeX's \includegraphics, viewers).
std::vector<std::uint8_t> encodePng(const Image& image, int level = 6, double dpi = 0);
// Throws std::runtime_error on a file that is not a PNG.
Image decodePng(const std::vector<std::uint8_t>& bytes);

}  // namespace flexure::render
