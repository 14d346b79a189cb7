// GIF89a written directly, without libav: one global palette of at most 255 colours made by
// median cut over chosen frames (index 255 is transparent), frames mapped with 8x8 ordered
// (Bayer) dithering of the colours not in (or within a level of) the palette, each frame
// stored as the rectangle that changed since the one before with its unchanged pixels
// transparent, LZW-compressed; loops forever. (FFmpeg's palettegen,
// paletteuse and GIF encoder did this before; they and the 166 libraries libavfilter loads
// were half the time of a small animation.)
#pragma once

#include <array>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "render/image.h"

namespace flexure::render {

using Rgb = std::array<std::uint8_t, 3>;

// Colour statistics over frames, and the palette they make.
class GifPaletteBuilder {
 public:
  GifPaletteBuilder();
  void add(const Image& image);
  // At most `colours` colours (1-255): all of them when there are that few, else median cut
  // (boxes split at the weighted median of their widest axis, the box with the largest squared
  // error first), each the rounded mean of its box, or the colour that holds more than half of
  // it. Deterministic.
  std::vector<Rgb> palette(int colours = 255) const;

 private:
  void count(std::uint32_t rgb, std::uint32_t n);
  std::vector<std::uint64_t> slots_;  // (rgb + 1) << 32 | count, open addressing
  size_t used_ = 0;
};

class GifEncoder {
 public:
  // Opens `path` (std::runtime_error when it cannot). Frame i is shown from round(100 i / fps)
  // to round(100 (i + 1) / fps) centiseconds.
  GifEncoder(const std::string& path, int width, int height, std::vector<Rgb> palette, int fps);
  ~GifEncoder();
  GifEncoder(const GifEncoder&) = delete;
  GifEncoder& operator=(const GifEncoder&) = delete;
  // Appends frame `index` (frames come in order). The encoder keeps the pixels as the previous
  // frame: `image` gets back a buffer of the same size and undefined content.
  void add(Image& image, int index);
  // Writes the trailer and closes the file; throws std::runtime_error on a write error.
  void finish();

 private:
  std::uint8_t nearest(std::uint32_t rgb);
  void mapRect(const Image& image, int x0, int y0, int x1, int y1, bool diff);
  void compress();
  void put(const void* data, size_t n);

  std::FILE* file_ = nullptr;
  std::string path_;
  int width_, height_, fps_;
  std::vector<Rgb> palette_;
  std::vector<std::uint8_t> previous_;  // the previous frame's RGBA (empty before the first)
  std::vector<std::uint8_t> indices_;   // the current rectangle's palette indices
  std::vector<std::uint64_t> cache_;    // (dithered colour + 1) << 8 | index, direct-mapped
  std::vector<std::uint32_t> dict_;     // LZW: (prefix << 8 | byte) << 12 | code, hashed
  std::vector<std::uint8_t> packed_;    // the current frame's LZW codes as bytes
  std::vector<std::uint8_t> out_;       // bytes waiting for the file
};

}  // namespace flexure::render
