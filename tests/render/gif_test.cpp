// The GIF writer, checked by decoding its files with libavformat/libavcodec (an independent
// decoder): exact colours come back exactly, through LZW dictionary resets, changed
// rectangles and transparent unchanged pixels; a palette of many colours stays close.
#include <catch2/catch.hpp>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>

#include "render/gif.h"
#include "render/video.h"

using namespace flexure::render;
namespace fs = std::filesystem;

namespace {

std::string tempFile(const std::string& name) {
  return (fs::temp_directory_path() / ("flexure_gif_test_" + std::to_string(::getpid()) + "_" + name)).string();
}

// Writes `frames` with the palette made from all of them and decodes the file.
VideoInfo roundTrip(const std::vector<Image>& frames, std::vector<Rgb>* palette_out = nullptr) {
  const std::string f = tempFile("rt.gif");
  GifPaletteBuilder stats;
  for (const Image& im : frames) stats.add(im);
  std::vector<Rgb> palette = stats.palette();
  if (palette_out) *palette_out = palette;
  {
    GifEncoder gif(f, frames[0].width, frames[0].height, palette, 10);
    for (size_t i = 0; i < frames.size(); ++i) {
      Image copy = frames[i];
      gif.add(copy, static_cast<int>(i));
    }
    gif.finish();
  }
  VideoInfo v = probeVideo(f);
  fs::remove(f);
  return v;
}

int maxDifference(const Image& a, const Image& b) {
  REQUIRE(a.width == b.width);
  REQUIRE(a.height == b.height);
  int worst = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x)
      for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(a.pixel(x, y)[c] - b.pixel(x, y)[c]));
  return worst;
}

// A frame of `colours` colours spaced at least 8 apart (so that dithering never changes them),
// picked per pixel by `rng`.
Image noise(int w, int h, int colours, std::mt19937& rng) {
  Image im(w, h);
  std::uniform_int_distribution<int> pick(0, colours - 1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int k = pick(rng);
      std::uint8_t* p = &im.rgba[(static_cast<size_t>(y) * w + x) * 4];
      p[0] = static_cast<std::uint8_t>(8 * (k % 8)), p[1] = static_cast<std::uint8_t>(8 * (k / 8 % 8));
      p[2] = static_cast<std::uint8_t>(64 * (k / 64)), p[3] = 255;
    }
  return im;
}

}  // namespace

TEST_CASE("gif: exact colours decode exactly, through dictionary resets and changed rectangles", "[render][gif]") {
  std::mt19937 rng(11);
  SECTION("one pixel") {
    Image a(1, 1);
    a.rgba = {10, 200, 30, 255};
    const VideoInfo v = roundTrip({a});
    CHECK(v.frames == 1);
    CHECK(maxDifference(v.first, a) == 0);
  }
  SECTION("noise of 150 colours: 12-bit codes and many clear codes") {
    const Image a = noise(301, 203, 150, rng);
    Image b = a;
    // The second frame changes a block in the middle: only that rectangle is stored, with its
    // unchanged pixels transparent.
    for (int y = 50; y < 90; ++y)
      for (int x = 120; x < 200; ++x)
        if ((x + y) % 3) b.rgba[(static_cast<size_t>(y) * 301 + x) * 4 + 2] = 192;
    std::vector<Rgb> palette;
    const VideoInfo v = roundTrip({a, b}, &palette);
    CHECK(palette.size() <= 255);
    CHECK(v.frames == 2);
    CHECK(v.loop == 0);
    CHECK(v.duration == Approx(0.2).margin(1e-9));
    CHECK(maxDifference(v.first, a) == 0);
    CHECK(maxDifference(v.last, b) == 0);
  }
  SECTION("long runs (the codes grow to 12 bits on one colour) and frames that change nothing") {
    Image a(997, 600);
    for (size_t i = 0; i < a.rgba.size(); i += 4) a.rgba[i] = 40, a.rgba[i + 1] = 80, a.rgba[i + 2] = 120, a.rgba[i + 3] = 255;
    Image b = a;
    b.rgba[(static_cast<size_t>(599) * 997 + 996) * 4] = 250;  // the last pixel only
    const VideoInfo v = roundTrip({a, a, a, b});
    CHECK(v.frames == 4);
    CHECK(v.duration == Approx(0.4).margin(1e-9));
    CHECK(maxDifference(v.first, a) == 0);
    CHECK(maxDifference(v.last, b) == 0);
  }
}

TEST_CASE("gif: random sizes, colours and changes round-trip exactly", "[render][gif]") {
  // Widths and heights from 1 to 160, 1 to 150 colours, a second frame changed in a random
  // rectangle (or not at all), a third frame equal to the second.
  std::mt19937 rng(2026);
  for (int trial = 0; trial < 40; ++trial) {
    const int w = std::uniform_int_distribution<int>(1, 160)(rng), h = std::uniform_int_distribution<int>(1, 160)(rng);
    const int colours = std::uniform_int_distribution<int>(1, 150)(rng);
    const Image a = noise(w, h, colours, rng);
    Image b = a;
    if (trial % 5) {
      const int x0 = std::uniform_int_distribution<int>(0, w - 1)(rng), y0 = std::uniform_int_distribution<int>(0, h - 1)(rng);
      const int x1 = std::uniform_int_distribution<int>(x0 + 1, w)(rng), y1 = std::uniform_int_distribution<int>(y0 + 1, h)(rng);
      const Image patch = noise(w, h, colours, rng);
      for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x)
          for (int c = 0; c < 4; ++c) b.rgba[(static_cast<size_t>(y) * w + x) * 4 + c] = patch.pixel(x, y)[c];
    }
    INFO("trial " << trial << ": " << w << "x" << h << ", " << colours << " colours");
    const VideoInfo v = roundTrip({a, b, b});
    CHECK(v.frames == 3);
    CHECK(maxDifference(v.first, a) == 0);
    CHECK(maxDifference(v.last, b) == 0);
  }
}

TEST_CASE("gif: more than 255 colours are cut to a close palette, and flat areas keep their colour", "[render][gif]") {
  // A white background with a smooth 128x128 patch of 16,384 colours.
  Image im(256, 256);
  for (int y = 0; y < 256; ++y)
    for (int x = 0; x < 256; ++x) {
      std::uint8_t* p = &im.rgba[(static_cast<size_t>(y) * 256 + x) * 4];
      const bool patch = x >= 64 && x < 192 && y >= 64 && y < 192;
      p[0] = patch ? static_cast<std::uint8_t>(2 * (x - 64)) : 255;
      p[1] = patch ? static_cast<std::uint8_t>(2 * (y - 64)) : 255;
      p[2] = patch ? static_cast<std::uint8_t>(x + y - 128) : 255;
      p[3] = 255;
    }
  std::vector<Rgb> palette;
  const VideoInfo v = roundTrip({im}, &palette);
  CHECK(palette.size() == 255);
  // The background holds most of its box: it is exact, dithering and all.
  CHECK(v.first.pixel(3, 3)[0] == 255);
  CHECK(v.first.pixel(250, 20)[1] == 255);
  CHECK(v.first.pixel(20, 250)[2] == 255);
  // The patch: 255 colours for 16,384 give a mean error of a few levels, none far off.
  double sum = 0;
  int worst = 0;
  for (int y = 64; y < 192; ++y)
    for (int x = 64; x < 192; ++x)
      for (int c = 0; c < 3; ++c) {
        const int d = std::abs(v.first.pixel(x, y)[c] - im.pixel(x, y)[c]);
        sum += d, worst = std::max(worst, d);
      }
  CHECK(sum / (128.0 * 128 * 3) < 6);
  CHECK(worst < 40);
  // The palette is a function of the colours: the same statistics give the same palette.
  GifPaletteBuilder again;
  again.add(im);
  CHECK(again.palette() == palette);
}

TEST_CASE("gif: bad sizes and unwritable places", "[render][gif]") {
  const std::vector<Rgb> palette{{0, 0, 0}};
  CHECK_THROWS_AS(GifEncoder(tempFile("x.gif"), 70000, 10, palette, 10), std::invalid_argument);
  CHECK_THROWS_AS(GifEncoder(tempFile("x.gif"), 10, 10, {}, 10), std::invalid_argument);
  CHECK_THROWS_AS(GifEncoder(tempFile("x.gif"), 10, 10, palette, 60), std::invalid_argument);
  CHECK_THROWS_AS(GifEncoder("/proc/flexure/x.gif", 10, 10, palette, 10), std::runtime_error);
  GifEncoder gif(tempFile("y.gif"), 10, 10, palette, 10);
  Image wrong(9, 10);
  CHECK_THROWS_AS(gif.add(wrong, 0), std::invalid_argument);
  fs::remove(tempFile("x.gif"));
  fs::remove(tempFile("y.gif"));
}
