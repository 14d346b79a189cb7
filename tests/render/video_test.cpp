// MP4 and GIF writing, checked by decoding the files with libavformat (no ffprobe).
#include <catch2/catch.hpp>

#include <chrono>
#include <thread>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "render/video.h"

using namespace flexure::render;
namespace fs = std::filesystem;

namespace {

std::string tempFile(const std::string& name) {
  return (fs::temp_directory_path() / ("flexure_video_test_" + std::to_string(::getpid()) + "_" + name)).string();
}

std::string bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Frame i: a white image with a square moving right; frame 0 is red at the top-left corner.
void frameAt(int i, Image& im, int w = 64, int h = 48) {
  im = Image(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      std::uint8_t* p = &im.rgba[(static_cast<size_t>(y) * w + x) * 4];
      const bool square = x >= 2 * i && x < 2 * i + 12 && y >= 10 && y < 30;
      p[0] = 255, p[1] = square ? 0 : 255, p[2] = square ? 0 : 255, p[3] = 255;
    }
}

}  // namespace

TEST_CASE("video: MP4 has the exact frame count, size, codec and duration", "[render][video]") {
  const std::string f = tempFile("a.mp4");
  VideoOptions o;
  o.width = 64, o.height = 48, o.fps = 25;
  const VideoStats st = writeVideo(f, o, 30, [](int i, Image& im) { frameAt(i, im); });
  CHECK(st.frames == 30);
  const VideoInfo v = probeVideo(f);
  CHECK(v.codec == "h264");
  CHECK(v.pixel_format == "yuv420p");
  CHECK(v.width == 64);
  CHECK(v.height == 48);
  CHECK(v.frames == 30);
  CHECK(v.duration == Approx(30.0 / 25).margin(1e-9));
  CHECK(v.frame_rate == Approx(25));
  // Colours survive the YUV round trip: the square is red, the rest white.
  REQUIRE(v.first.width == 64);
  const std::uint8_t* red = v.first.pixel(6, 20);
  CHECK(red[0] > 200);
  CHECK(red[1] < 60);
  const std::uint8_t* white = v.first.pixel(50, 40);
  CHECK(white[0] > 230);
  CHECK(white[1] > 230);
  // The last frame shows the square moved right.
  CHECK(v.last.pixel(6, 20)[1] > 200);
  CHECK(v.last.pixel(60, 20)[1] < 60);
  // Deterministic: the same frames give the same bytes.
  const std::string g = tempFile("b.mp4");
  writeVideo(g, o, 30, [](int i, Image& im) { frameAt(i, im); });
  CHECK(bytes(f) == bytes(g));
  fs::remove(f);
  fs::remove(g);
}

TEST_CASE("video: GIF loops forever with a palette and keeps its timing", "[render][video]") {
  const std::string f = tempFile("a.gif");
  VideoOptions o;
  o.format = VideoFormat::Gif;
  o.width = 64, o.height = 48, o.fps = 20;
  o.gif_keep = VideoOptions::GifKeep::Always;
  int calls = 0;
  writeVideo(f, o, 24, [&](int i, Image& im) { ++calls, frameAt(i, im); });
  CHECK(calls == 24);  // kept in memory for the second pass
  const VideoInfo v = probeVideo(f);
  CHECK(v.codec == "gif");
  CHECK(v.width == 64);
  CHECK(v.height == 48);
  CHECK(v.frames == 24);
  CHECK(v.loop == 0);
  CHECK(v.duration == Approx(24 / 20.0).margin(0.011));
  CHECK(v.first.pixel(6, 20)[0] > 200);
  CHECK(v.first.pixel(6, 20)[1] < 60);
  CHECK(v.first.pixel(50, 40)[1] > 230);
  // Without room to keep the frames, they are rendered twice: the same file.
  const std::string g = tempFile("b.gif");
  o.gif_cache_bytes = 0;
  calls = 0;
  const VideoStats st = writeVideo(g, o, 24, [&](int i, Image& im) { ++calls, frameAt(i, im); });
  CHECK(st.rendered_twice);
  CHECK(calls == 48);
  CHECK(bytes(f) == bytes(g));
  // By default, slow frames (3 ms for 12 KB) are kept...
  o.gif_cache_bytes = VideoOptions{}.gif_cache_bytes;
  o.gif_keep = VideoOptions::GifKeep::Auto;
  calls = 0;
  CHECK(!writeVideo(g, o, 24, [&](int i, Image& im) {
           ++calls, frameAt(i, im);
           std::this_thread::sleep_for(std::chrono::milliseconds(3));
         }).rendered_twice);
  CHECK(calls == 24);
  CHECK(bytes(f) == bytes(g));
  // ... and cheap ones (1.2 MB frames handed over from memory filled beforehand: far under the
  // 2.3 ms it would take to keep one) are rendered twice. (Filled in the callback, the frames'
  // first-touch page faults alone took 2-3 ms on a loaded virtual machine.)
  VideoOptions big = o;
  big.width = 640, big.height = 480;
  calls = 0;
  std::vector<std::vector<uint8_t>> ready;
  for (int i = 0; i < 16; ++i) ready.emplace_back(640 * 480 * 4, uint8_t{0});
  const auto fill = [&](int i, Image& im) {
    ++calls;
    im.width = 640, im.height = 480;
    im.rgba.swap(ready.at(static_cast<size_t>(calls - 1)));
    std::memset(im.rgba.data(), 10 * i, im.rgba.size());
  };
  CHECK(writeVideo(g, big, 8, fill).rendered_twice);
  CHECK(calls == 16);
  fs::remove(f);
  fs::remove(g);
}

TEST_CASE("video: a long GIF's palette comes from 32 frames, the first and last among them", "[render][video]") {
  // 80 frames; the red square moves right by 2 px a frame and leaves the image at frame 32.
  // Frame 79 alone is green: the palette frames end with the last one, so its colour is kept.
  const auto frame = [](int i, Image& im) {
    frameAt(i % 40, im);
    if (i == 79)
      for (size_t p = 0; p < im.rgba.size(); p += 4) im.rgba[p] = 0, im.rgba[p + 1] = 200, im.rgba[p + 2] = 0;
  };
  const std::string f = tempFile("long.gif"), g = tempFile("long2.gif");
  VideoOptions o;
  o.format = VideoFormat::Gif;
  o.width = 64, o.height = 48, o.fps = 20;
  o.gif_keep = VideoOptions::GifKeep::Always;
  int calls = 0;
  writeVideo(f, o, 80, [&](int i, Image& im) { ++calls, frame(i, im); });
  CHECK(calls == 80);  // the 32 palette frames kept, the other 48 rendered in pass 2
  const VideoInfo v = probeVideo(f);
  CHECK(v.frames == 80);
  CHECK(v.first.pixel(6, 20)[0] > 200);
  CHECK(v.first.pixel(6, 20)[1] < 60);
  CHECK(v.last.pixel(30, 20)[0] < 40);
  CHECK(v.last.pixel(30, 20)[1] > 160);
  // Without the cache, pass 1 renders only the 32 palette frames: the same file.
  o.gif_cache_bytes = 0;
  calls = 0;
  const VideoStats st = writeVideo(g, o, 80, [&](int i, Image& im) { ++calls, frame(i, im); });
  CHECK(st.rendered_twice);
  CHECK(calls == 32 + 80);
  CHECK(bytes(f) == bytes(g));
  fs::remove(f);
  fs::remove(g);
}

TEST_CASE("video: bad sizes, wrong frames, interruption", "[render][video]") {
  const std::string f = tempFile("bad.mp4");
  VideoOptions o;
  o.width = 63, o.height = 48;
  CHECK_THROWS_AS(writeVideo(f, o, 3, [](int i, Image& im) { frameAt(i, im, 63, 48); }), std::invalid_argument);
  o.width = 64;
  // A frame of the wrong size is an error, not a crash.
  CHECK_THROWS_AS(writeVideo(f, o, 3, [](int i, Image& im) { frameAt(i, im, i == 1 ? 32 : 64, 48); }),
                  std::invalid_argument);
  // The progress callback can stop it.
  CHECK_THROWS_AS(writeVideo(f, o, 50, [](int i, Image& im) { frameAt(i % 20, im); },
                             [](int done, int) { return done < 5; }),
                  VideoInterrupted);
  CHECK_THROWS_AS(writeVideo(f, o, 0, [](int i, Image& im) { frameAt(i, im); }), std::invalid_argument);
  // An unwritable place.
  CHECK_THROWS_AS(writeVideo("/proc/flexure/x.mp4", o, 2, [](int i, Image& im) { frameAt(i, im); }),
                  std::runtime_error);
  o.format = VideoFormat::Gif;
  o.fps = 60;
  CHECK_THROWS_AS(writeVideo(f, o, 2, [](int i, Image& im) { frameAt(i, im); }), std::invalid_argument);
  fs::remove(f);
}
