// The frame pipeline and the GIF passes; MP4 and decoding through libflexure-av.so (libav.h).
#include "render/video.h"

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <exception>
#include <limits>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "render/gif.h"
#include "render/libav.h"

namespace flexure::render {

namespace {

using Clock = std::chrono::steady_clock;
double seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

// Consumes frames on its own thread.
class Consumer {
 public:
  virtual ~Consumer() = default;
  // The consumer may take the image's pixels (leaving it empty, or with a recycled buffer of
  // any content); the pipeline then fills it again.
  virtual void consume(Image& image, int index) = 0;
};

// MP4: H.264 by libx264, in libflexure-av.so.
class Mp4Writer : public Consumer {
 public:
  Mp4Writer(const std::string& path, const VideoOptions& o) : sink_(libav::api().open_mp4(path, o)) {}
  void consume(Image& image, int index) override { sink_->consume(image, index); }
  void finish() { sink_->finish(); }

 private:
  std::unique_ptr<libav::Mp4Sink> sink_;
};

// The frames whose colours make the palette: all of a short clip, else kGifPaletteFrames
// evenly spaced ones from the first to the last (a clip's colours recur from frame to frame:
// statistics over every frame of a 100-frame GIF were a quarter of its whole process).
constexpr int kGifPaletteFrames = 32;
std::vector<int> gifPaletteFrames(int frames) {
  std::vector<int> pick;
  const int n = std::min(frames, kGifPaletteFrames);
  for (int i = 0; i < n; ++i)
    pick.push_back(n == 1 ? 0 : static_cast<int>(std::lround(static_cast<double>(i) * (frames - 1) / (n - 1))));
  return pick;
}

// Pass 1: colour statistics over the palette frames. With a cache, the frames are kept for pass 2.
class GifPalette : public Consumer {
 public:
  explicit GifPalette(std::vector<Image>* cache) : cache_(cache) {}
  void consume(Image& image, int) override {
    stats_.add(image);
    if (cache_) cache_->push_back(std::move(image));
  }
  std::vector<Rgb> palette() const { return stats_.palette(); }

 private:
  std::vector<Image>* cache_;
  GifPaletteBuilder stats_;
};

// Pass 2: the frames mapped to the palette and written.
class GifWriter : public Consumer {
 public:
  GifWriter(const std::string& path, const VideoOptions& o, std::vector<Rgb> palette)
      : gif_(path, o.width, o.height, std::move(palette), o.fps) {}
  void consume(Image& image, int index) override { gif_.add(image, index); }
  void finish() { gif_.finish(); }

 private:
  GifEncoder gif_;
};

// Frames from `source` (this thread) go through a short queue to `consumer` (a worker thread);
// consumed images come back to be filled again. `done_before` and `total` are for progress.
void pipeline(int frames, const FrameSource& source, Consumer& consumer, const FrameProgress& progress,
              int done_before, int total, VideoStats& stats) {
  std::mutex mu;
  std::condition_variable cv;
  std::deque<std::pair<int, Image>> queue;
  std::vector<Image> spare;
  bool closed = false;
  std::exception_ptr failure;
  double busy = 0;
  constexpr size_t kDepth = 3;
  std::thread worker([&] {
    for (;;) {
      std::pair<int, Image> item;
      {
        std::unique_lock<std::mutex> lock(mu);
        cv.wait(lock, [&] { return !queue.empty() || closed; });
        if (queue.empty()) return;
        item = std::move(queue.front());
        queue.pop_front();
      }
      cv.notify_all();
      const auto t0 = Clock::now();
      try {
        consumer.consume(item.second, item.first);
      } catch (...) {
        std::lock_guard<std::mutex> lock(mu);
        failure = std::current_exception();
        queue.clear();
        closed = true;
        cv.notify_all();
        return;
      }
      busy += seconds(t0, Clock::now());
      std::lock_guard<std::mutex> lock(mu);
      spare.push_back(std::move(item.second));
    }
  });
  auto stop = [&] {
    {
      std::lock_guard<std::mutex> lock(mu);
      closed = true;
    }
    cv.notify_all();
    worker.join();
  };
  try {
    for (int i = 0; i < frames; ++i) {
      Image image;
      {
        std::lock_guard<std::mutex> lock(mu);
        if (!spare.empty()) {
          image = std::move(spare.back());
          spare.pop_back();
        }
      }
      const auto t0 = Clock::now();
      source(i, image);
      stats.render_seconds += seconds(t0, Clock::now());
      {
        std::unique_lock<std::mutex> lock(mu);
        cv.wait(lock, [&] { return queue.size() < kDepth || failure; });
        if (failure) break;
        queue.emplace_back(i, std::move(image));
      }
      cv.notify_all();
      if (progress && !progress(done_before + i + 1, total)) {
        stop();
        throw VideoInterrupted("interrupted after " + std::to_string(i + 1) + " of " + std::to_string(frames) +
                               " frames");
      }
    }
  } catch (const VideoInterrupted&) {
    throw;
  } catch (...) {
    stop();
    throw;
  }
  stop();
  stats.encode_seconds += busy;
  if (failure) std::rethrow_exception(failure);
}

}  // namespace

VideoStats writeVideo(const std::string& path, const VideoOptions& o, int frames, const FrameSource& source,
                      const FrameProgress& progress) {
  if (frames < 1) throw std::invalid_argument("an animation needs at least one frame");
  if (o.width < 2 || o.height < 2 || o.fps < 1) throw std::invalid_argument("bad video size or frame rate");
  VideoStats stats;
  const auto t0 = Clock::now();
  const FrameSource checked = [&](int i, Image& image) {
    source(i, image);
    if (image.width != o.width || image.height != o.height ||
        image.rgba.size() != static_cast<size_t>(o.width) * o.height * 4)
      throw std::invalid_argument("frame " + std::to_string(i) + " is " + std::to_string(image.width) + "x" +
                                  std::to_string(image.height) + ", not " + std::to_string(o.width) + "x" +
                                  std::to_string(o.height));
  };
  if (o.format == VideoFormat::Mp4) {
    Mp4Writer writer(path, o);
    pipeline(frames, checked, writer, progress, 0, frames, stats);
    const auto t1 = Clock::now();
    writer.finish();
    stats.encode_seconds += seconds(t1, Clock::now());
  } else {
    if (o.fps > 50) throw std::invalid_argument("GIF frame delays are centiseconds: at most 50 frames/s");
    // Pass 1 renders only the palette frames and keeps them when that pays (see gif_keep);
    // pass 2 takes those and renders the others. Keeping every frame, as before, cost more
    // than rendering for cheap scenes: a 100-frame 480x480 GIF of K_{2,4} kept 92 MB (240 MB
    // peak, 0.29 s CPU, a third of it the kernel's page faults; now 157 MB and 0.25 s).
    const size_t frame_bytes = static_cast<size_t>(o.width) * o.height * 4;
    const std::vector<int> pick = gifPaletteFrames(frames);
    const int n = static_cast<int>(pick.size());
    // The first two palette frames rendered here, timed (the first also compiles shaders).
    std::vector<Image> first(static_cast<size_t>(std::min(n, 2)));
    double fastest = std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < first.size(); ++k) {
      const auto r0 = Clock::now();
      checked(pick[k], first[k]);
      const double s = seconds(r0, Clock::now());
      stats.render_seconds += s;
      fastest = std::min(fastest, s);
    }
    const bool fits = frame_bytes * pick.size() <= o.gif_cache_bytes;
    const bool keep = fits && (o.gif_keep == VideoOptions::GifKeep::Always ||
                               (o.gif_keep == VideoOptions::GifKeep::Auto &&
                                fastest >= 2e-3 * static_cast<double>(frame_bytes) / (1 << 20)));
    std::vector<Image> kept;
    if (keep) kept.reserve(pick.size());
    std::vector<Rgb> palette;
    {
      GifPalette stats_pass(keep ? &kept : nullptr);
      pipeline(
          n,
          [&](int i, Image& image) {
            if (static_cast<size_t>(i) < first.size()) image = std::move(first[static_cast<size_t>(i)]);
            else checked(pick[static_cast<size_t>(i)], image);
          },
          stats_pass, progress, 0, n + frames, stats);
      palette = stats_pass.palette();
    }
    std::vector<int> slot(static_cast<size_t>(frames), -1);
    for (int k = 0; keep && k < n; ++k) slot[static_cast<size_t>(pick[static_cast<size_t>(k)])] = k;
    stats.rendered_twice = !keep;
    GifWriter writer(path, o, std::move(palette));
    pipeline(
        frames,
        [&](int i, Image& image) {
          const int k = slot[static_cast<size_t>(i)];
          if (k >= 0) image = std::move(kept[static_cast<size_t>(k)]);
          else checked(i, image);
        },
        writer, progress, n, n + frames, stats);
    const auto t1 = Clock::now();
    writer.finish();
    stats.encode_seconds += seconds(t1, Clock::now());
  }
  stats.frames = frames;
  stats.wall_seconds = seconds(t0, Clock::now());
  return stats;
}

VideoInfo probeVideo(const std::string& path) { return libav::api().probe(path); }

}  // namespace flexure::render
