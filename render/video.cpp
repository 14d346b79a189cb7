#include "render/video.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavfilter/avfilter.h>
#include <libavfilter/buffersink.h>
#include <libavfilter/buffersrc.h>
#include <libavformat/avformat.h>
#include <libavutil/imgutils.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
}

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <exception>
#include <fstream>
#include <iterator>
#include <memory>
#include <limits>
#include <mutex>
#include <thread>
#include <vector>

namespace flexure::render {

namespace {

using Clock = std::chrono::steady_clock;
double seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

std::string avError(int code) {
  char buf[AV_ERROR_MAX_STRING_SIZE] = {0};
  av_strerror(code, buf, sizeof buf);
  return buf;
}

void check(int code, const std::string& what) {
  if (code < 0) throw std::runtime_error(what + ": " + avError(code));
}

void quietLibav() {
  static std::once_flag once;
  std::call_once(once, [] { av_log_set_level(AV_LOG_ERROR); });
}

struct FrameDeleter {
  void operator()(AVFrame* f) const { av_frame_free(&f); }
};
struct PacketDeleter {
  void operator()(AVPacket* p) const { av_packet_free(&p); }
};
struct CodecDeleter {
  void operator()(AVCodecContext* c) const { avcodec_free_context(&c); }
};
struct GraphDeleter {
  void operator()(AVFilterGraph* g) const { avfilter_graph_free(&g); }
};
using FramePtr = std::unique_ptr<AVFrame, FrameDeleter>;
using PacketPtr = std::unique_ptr<AVPacket, PacketDeleter>;
using CodecPtr = std::unique_ptr<AVCodecContext, CodecDeleter>;
using GraphPtr = std::unique_ptr<AVFilterGraph, GraphDeleter>;

FramePtr newFrame() {
  FramePtr f(av_frame_alloc());
  if (!f) throw std::bad_alloc();
  return f;
}

// An RGBA frame (libav owns its buffer) holding `image`.
FramePtr rgbaFrame(const Image& image, int64_t pts) {
  FramePtr f = newFrame();
  f->format = AV_PIX_FMT_RGBA;
  f->width = image.width;
  f->height = image.height;
  check(av_frame_get_buffer(f.get(), 0), "cannot allocate a frame");
  for (int y = 0; y < image.height; ++y)
    std::memcpy(f->data[0] + static_cast<ptrdiff_t>(y) * f->linesize[0], image.pixel(0, y),
                static_cast<size_t>(image.width) * 4);
  f->pts = pts;
  return f;
}

// The image's pixels handed to an RGBA frame without a copy: the frame's buffer takes the
// vector (the image is left empty), and frees it when FFmpeg lets go of the last reference
// (paletteuse keeps the previous frame). A copy into a fresh frame cost a memcpy and, for large
// frames, page faults on every frame.
FramePtr adoptRgbaFrame(Image& image, int64_t pts) {
  auto* pixels = new std::vector<std::uint8_t>(std::move(image.rgba));
  AVBufferRef* buf = av_buffer_create(
      pixels->data(), pixels->size(), [](void* opaque, uint8_t*) { delete static_cast<std::vector<std::uint8_t>*>(opaque); },
      pixels, 0);
  if (!buf) {
    image.rgba = std::move(*pixels);
    delete pixels;
    throw std::runtime_error("cannot allocate a frame");
  }
  FramePtr f = newFrame();
  f->format = AV_PIX_FMT_RGBA;
  f->width = image.width;
  f->height = image.height;
  f->buf[0] = buf;
  f->data[0] = buf->data;
  f->linesize[0] = image.width * 4;
  f->pts = pts;
  image.rgba.clear();
  return f;
}

struct FormatDeleter {
  void operator()(AVFormatContext* f) const {
    if (f->pb) avio_closep(&f->pb);
    avformat_free_context(f);
  }
};
struct SwsDeleter {
  void operator()(SwsContext* s) const { sws_freeContext(s); }
};

// A container being written: format context, one video stream, its encoder.
class Muxer {
 public:
  Muxer(const std::string& path, const char* format, AVCodecContext* codec, AVDictionary** options) : codec_(codec) {
    AVFormatContext* f = nullptr;
    check(avformat_alloc_output_context2(&f, nullptr, format, path.c_str()), "cannot set up " + path);
    owner_.reset(f);
    fmt_ = f;
    stream_ = avformat_new_stream(fmt_, nullptr);
    if (!stream_) throw std::runtime_error("cannot add a video stream to " + path);
    check(avcodec_parameters_from_context(stream_->codecpar, codec), "cannot set up the stream");
    stream_->time_base = codec->time_base;
    stream_->avg_frame_rate = codec->framerate;
    check(avio_open(&fmt_->pb, path.c_str(), AVIO_FLAG_WRITE), "cannot write " + path);
    check(avformat_write_header(fmt_, options), "cannot write the header of " + path);
    header_written_ = true;
    packet_.reset(av_packet_alloc());
  }
  // A muxer that stopped half-way (a write failed, the user interrupted) still gets its trailer
  // call: FFmpeg's GIF muxer frees its held-back packet only there. The file is discarded anyway.
  ~Muxer() {
    if (header_written_ && !finished_) av_write_trailer(fmt_);
  }
  Muxer(const Muxer&) = delete;
  Muxer& operator=(const Muxer&) = delete;

  static bool needsGlobalHeader(const char* format) {
    const AVOutputFormat* f = av_guess_format(format, nullptr, nullptr);
    return f && (f->flags & AVFMT_GLOBALHEADER);
  }
  // Sends `frame` (nullptr: flush) and writes every packet that comes out. `duration`: of each
  // packet, in the codec's time base (0: leave it).
  void encode(AVFrame* frame, int64_t duration) {
    check(avcodec_send_frame(codec_, frame), "encoding failed");
    for (;;) {
      const int r = avcodec_receive_packet(codec_, packet_.get());
      if (r == AVERROR(EAGAIN) || r == AVERROR_EOF) return;
      check(r, "encoding failed");
      if (duration > 0) packet_->duration = duration;
      av_packet_rescale_ts(packet_.get(), codec_->time_base, stream_->time_base);
      packet_->stream_index = stream_->index;
      check(av_interleaved_write_frame(fmt_, packet_.get()), "cannot write a frame");
    }
  }
  void finish() {
    finished_ = true;
    check(av_write_trailer(fmt_), "cannot finish the file");
    check(avio_closep(&fmt_->pb), "cannot close the file");
  }

 private:
  std::unique_ptr<AVFormatContext, FormatDeleter> owner_;  // frees it however the constructor ends
  AVFormatContext* fmt_ = nullptr;
  AVStream* stream_ = nullptr;
  AVCodecContext* codec_;
  PacketPtr packet_;
  bool header_written_ = false, finished_ = false;
};

// Consumes frames on its own thread.
class Consumer {
 public:
  virtual ~Consumer() = default;
  // The consumer may take the image's pixels (leaving it empty); the pipeline then fills a new one.
  virtual void consume(Image& image, int index) = 0;
};

class Mp4Writer : public Consumer {
 public:
  Mp4Writer(const std::string& path, const VideoOptions& o) : o_(o) {
    if (o.width % 2 || o.height % 2)
      throw std::invalid_argument("MP4 (yuv420p) needs an even width and height, not " + std::to_string(o.width) +
                                  "x" + std::to_string(o.height));
    const AVCodec* codec = avcodec_find_encoder_by_name("libx264");
    if (!codec) throw std::runtime_error("this FFmpeg has no libx264 encoder");
    codec_.reset(avcodec_alloc_context3(codec));
    AVCodecContext* c = codec_.get();
    c->width = o.width;
    c->height = o.height;
    c->time_base = AVRational{1, o.fps};
    c->framerate = AVRational{o.fps, 1};
    c->pix_fmt = AV_PIX_FMT_YUV420P;
    c->color_range = AVCOL_RANGE_MPEG;
    c->colorspace = AVCOL_SPC_BT709;
    c->color_primaries = AVCOL_PRI_BT709;
    c->color_trc = AVCOL_TRC_IEC61966_2_1;
    if (Muxer::needsGlobalHeader("mp4")) c->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
    AVDictionary* opts = nullptr;
    av_dict_set(&opts, "preset", o.preset.c_str(), 0);
    av_dict_set(&opts, "crf", std::to_string(o.crf).c_str(), 0);
    const int r = avcodec_open2(c, codec, &opts);
    av_dict_free(&opts);
    check(r, "cannot open the H.264 encoder");
    AVDictionary* mopts = nullptr;
    av_dict_set(&mopts, "movflags", "+faststart", 0);
    try {
      mux_ = std::make_unique<Muxer>(path, "mp4", c, &mopts);
    } catch (...) {
      av_dict_free(&mopts);
      throw;
    }
    av_dict_free(&mopts);
    sws_.reset(sws_getContext(o.width, o.height, AV_PIX_FMT_RGBA, o.width, o.height, AV_PIX_FMT_YUV420P,
                              SWS_BILINEAR | SWS_ACCURATE_RND, nullptr, nullptr, nullptr));
    if (!sws_) throw std::runtime_error("cannot set up the colour conversion");
    const int* bt709 = sws_getCoefficients(SWS_CS_ITU709);
    sws_setColorspaceDetails(sws_.get(), bt709, 1, bt709, 0, 0, 1 << 16, 1 << 16);
    yuv_ = newFrame();
    yuv_->format = AV_PIX_FMT_YUV420P;
    yuv_->width = o.width;
    yuv_->height = o.height;
    check(av_frame_get_buffer(yuv_.get(), 0), "cannot allocate a frame");
    rgba_ = newFrame();
    rgba_->format = AV_PIX_FMT_RGBA;
    rgba_->width = o.width;
    rgba_->height = o.height;
    check(av_frame_get_buffer(rgba_.get(), 0), "cannot allocate a frame");
  }

  void consume(Image& image, int index) override {
    // swscale reads whole SIMD blocks: the rows go into a padded frame first.
    for (int y = 0; y < image.height; ++y)
      std::memcpy(rgba_->data[0] + static_cast<ptrdiff_t>(y) * rgba_->linesize[0], image.pixel(0, y),
                  static_cast<size_t>(image.width) * 4);
    check(av_frame_make_writable(yuv_.get()), "cannot reuse a frame");
    sws_scale(sws_.get(), rgba_->data, rgba_->linesize, 0, image.height, yuv_->data, yuv_->linesize);
    yuv_->pts = index;
    mux_->encode(yuv_.get(), 1);  // one frame of 1/fps each: the duration comes out exact
  }
  void finish() {
    mux_->encode(nullptr, 1);
    mux_->finish();
  }

 private:
  VideoOptions o_;
  CodecPtr codec_;
  std::unique_ptr<Muxer> mux_;
  std::unique_ptr<SwsContext, SwsDeleter> sws_;
  FramePtr yuv_, rgba_;
};

int64_t gifPts(int index, int fps) { return std::llround(index * 100.0 / fps); }

AVFilterContext* addFilter(AVFilterGraph* g, const char* filter, const char* name, const std::string& args) {
  AVFilterContext* ctx = nullptr;
  check(avfilter_graph_create_filter(&ctx, avfilter_get_by_name(filter), name, args.c_str(), nullptr, g),
        std::string("cannot create the ") + filter + " filter");
  return ctx;
}

std::string bufferArgs(int w, int h, AVPixelFormat fmt) {
  return "video_size=" + std::to_string(w) + "x" + std::to_string(h) + ":pix_fmt=" + std::to_string(fmt) +
         ":time_base=1/100:pixel_aspect=1/1";
}

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

// Pass 1: palettegen over the palette frames; its one output frame is the palette. With a
// cache, the frames are kept for pass 2.
class GifPalette : public Consumer {
 public:
  GifPalette(const VideoOptions& o, std::vector<Image>* cache) : o_(o), cache_(cache) {
    graph_.reset(avfilter_graph_alloc());
    src_ = addFilter(graph_.get(), "buffer", "in", bufferArgs(o.width, o.height, AV_PIX_FMT_RGBA));
    AVFilterContext* gen = addFilter(graph_.get(), "palettegen", "gen", "max_colors=256:stats_mode=full");
    sink_ = addFilter(graph_.get(), "buffersink", "out", "");
    check(avfilter_link(src_, 0, gen, 0), "cannot link the palette filters");
    check(avfilter_link(gen, 0, sink_, 0), "cannot link the palette filters");
    check(avfilter_graph_config(graph_.get(), nullptr), "cannot configure the palette filters");
  }
  void consume(Image& image, int index) override {
    FramePtr f = rgbaFrame(image, gifPts(index, o_.fps));
    // Pushed through palettegen at once: without the flag the buffer source queues every frame
    // until the palette is asked for (a 1,000-frame 1000x1000 GIF held 4 GB).
    check(av_buffersrc_add_frame_flags(src_, f.get(), AV_BUFFERSRC_FLAG_PUSH), "palette statistics failed");
    if (cache_) cache_->push_back(std::move(image));
  }
  FramePtr palette() {
    check(av_buffersrc_add_frame(src_, nullptr), "palette statistics failed");
    FramePtr p = newFrame();
    check(av_buffersink_get_frame(sink_, p.get()), "palettegen made no palette");
    return p;
  }

 private:
  VideoOptions o_;
  std::vector<Image>* cache_;
  GraphPtr graph_;
  AVFilterContext *src_ = nullptr, *sink_ = nullptr;
};

// Pass 2: paletteuse with the palette, the GIF encoder, the GIF muxer (loop forever).
class GifWriter : public Consumer {
 public:
  GifWriter(const std::string& path, const VideoOptions& o, AVFrame* palette) : o_(o) {
    graph_.reset(avfilter_graph_alloc());
    src_ = addFilter(graph_.get(), "buffer", "in", bufferArgs(o.width, o.height, AV_PIX_FMT_RGBA));
    pal_ = addFilter(graph_.get(), "buffer", "pal",
                     bufferArgs(palette->width, palette->height, static_cast<AVPixelFormat>(palette->format)));
    AVFilterContext* use = addFilter(graph_.get(), "paletteuse", "use", "dither=bayer:bayer_scale=4:diff_mode=rectangle");
    sink_ = addFilter(graph_.get(), "buffersink", "out", "");
    check(avfilter_link(src_, 0, use, 0), "cannot link the GIF filters");
    check(avfilter_link(pal_, 0, use, 1), "cannot link the GIF filters");
    check(avfilter_link(use, 0, sink_, 0), "cannot link the GIF filters");
    check(avfilter_graph_config(graph_.get(), nullptr), "cannot configure the GIF filters");
    palette->pts = 0;
    check(av_buffersrc_add_frame(pal_, palette), "cannot use the palette");
    check(av_buffersrc_add_frame(pal_, nullptr), "cannot use the palette");

    const AVCodec* codec = avcodec_find_encoder(AV_CODEC_ID_GIF);
    if (!codec) throw std::runtime_error("this FFmpeg has no GIF encoder");
    codec_.reset(avcodec_alloc_context3(codec));
    AVCodecContext* c = codec_.get();
    c->width = o.width;
    c->height = o.height;
    c->time_base = AVRational{1, 100};
    c->framerate = AVRational{o.fps, 1};
    c->pix_fmt = AV_PIX_FMT_PAL8;
    check(avcodec_open2(c, codec, nullptr), "cannot open the GIF encoder");
    AVDictionary* mopts = nullptr;
    av_dict_set(&mopts, "loop", "0", 0);
    try {
      mux_ = std::make_unique<Muxer>(path, "gif", c, &mopts);
    } catch (...) {
      av_dict_free(&mopts);
      throw;
    }
    av_dict_free(&mopts);
    out_ = newFrame();
  }
  void consume(Image& image, int index) override {
    FramePtr f = adoptRgbaFrame(image, gifPts(index, o_.fps));
    check(av_buffersrc_add_frame(src_, f.get()), "palette mapping failed");
    drain();
  }
  void finish() {
    check(av_buffersrc_add_frame(src_, nullptr), "palette mapping failed");
    drain();
    mux_->encode(nullptr, 0);
    mux_->finish();
  }

 private:
  void drain() {
    for (;;) {
      const int r = av_buffersink_get_frame(sink_, out_.get());
      if (r == AVERROR(EAGAIN) || r == AVERROR_EOF) return;
      check(r, "palette mapping failed");
      mux_->encode(out_.get(), 0);
      av_frame_unref(out_.get());
    }
  }
  VideoOptions o_;
  GraphPtr graph_;
  AVFilterContext *src_ = nullptr, *pal_ = nullptr, *sink_ = nullptr;
  CodecPtr codec_;
  std::unique_ptr<Muxer> mux_;
  FramePtr out_;
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
  quietLibav();
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
    FramePtr palette;
    {
      GifPalette stats_pass(o, keep ? &kept : nullptr);
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
    GifWriter writer(path, o, palette.get());
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

namespace {

// The NETSCAPE2.0 application extension of a GIF: its loop count, or -1 without one.
int gifLoopCount(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto pos = bytes.find("NETSCAPE2.0");
  if (pos == std::string::npos || pos + 16 > bytes.size()) return -1;
  const auto* b = reinterpret_cast<const unsigned char*>(bytes.data()) + pos + 11;
  if (b[0] != 3 || b[1] != 1) return -1;
  return b[2] | (b[3] << 8);
}

}  // namespace

VideoInfo probeVideo(const std::string& path) {
  quietLibav();
  AVFormatContext* fmt = nullptr;
  check(avformat_open_input(&fmt, path.c_str(), nullptr, nullptr), "cannot open " + path);
  std::unique_ptr<AVFormatContext, void (*)(AVFormatContext*)> guard(fmt, [](AVFormatContext* f) {
    avformat_close_input(&f);
  });
  check(avformat_find_stream_info(fmt, nullptr), "cannot read " + path);
  const AVCodec* dec = nullptr;
  const int si = av_find_best_stream(fmt, AVMEDIA_TYPE_VIDEO, -1, -1, &dec, 0);
  check(si, "no video stream in " + path);
  AVStream* st = fmt->streams[si];
  CodecPtr ctx(avcodec_alloc_context3(dec));
  check(avcodec_parameters_to_context(ctx.get(), st->codecpar), "cannot decode " + path);
  check(avcodec_open2(ctx.get(), dec, nullptr), "cannot decode " + path);
  VideoInfo info;
  info.format = fmt->iformat->name;
  info.codec = dec->name;
  info.width = ctx->width;
  info.height = ctx->height;
  const char* pf = av_get_pix_fmt_name(ctx->pix_fmt);
  info.pixel_format = pf ? pf : "";
  info.frame_rate = st->avg_frame_rate.den ? av_q2d(st->avg_frame_rate) : 0;
  PacketPtr pkt(av_packet_alloc());
  FramePtr frame = newFrame();
  double end = 0;
  SwsContext* sws = nullptr;
  struct SwsGuard {
    SwsContext*& s;
    ~SwsGuard() { sws_freeContext(s); }
  } sws_guard{sws};
  auto toRgba = [&](Image& out) {
    sws = sws_getCachedContext(sws, frame->width, frame->height, static_cast<AVPixelFormat>(frame->format),
                               frame->width, frame->height, AV_PIX_FMT_RGBA, SWS_BILINEAR, nullptr, nullptr, nullptr);
    if (!sws) return;
    // swscale writes whole SIMD blocks: convert into a padded frame, then copy the rows.
    FramePtr rgba = newFrame();
    rgba->format = AV_PIX_FMT_RGBA;
    rgba->width = frame->width;
    rgba->height = frame->height;
    check(av_frame_get_buffer(rgba.get(), 0), "cannot allocate a frame");
    sws_scale(sws, frame->data, frame->linesize, 0, frame->height, rgba->data, rgba->linesize);
    out = Image(frame->width, frame->height);
    for (int y = 0; y < frame->height; ++y)
      std::memcpy(&out.rgba[static_cast<size_t>(y) * frame->width * 4], rgba->data[0] + static_cast<ptrdiff_t>(y) * rgba->linesize[0],
                  static_cast<size_t>(frame->width) * 4);
  };
  auto receive = [&] {
    while (avcodec_receive_frame(ctx.get(), frame.get()) == 0) {
      if (info.frames == 0) toRgba(info.first);
      toRgba(info.last);
      ++info.frames;
      const int64_t ts = frame->best_effort_timestamp != AV_NOPTS_VALUE ? frame->best_effort_timestamp : frame->pts;
      if (ts != AV_NOPTS_VALUE) end = std::max(end, (ts + frame->pkt_duration) * av_q2d(st->time_base));
      av_frame_unref(frame.get());
    }
  };
  while (av_read_frame(fmt, pkt.get()) >= 0) {
    if (pkt->stream_index == si) {
      check(avcodec_send_packet(ctx.get(), pkt.get()), "cannot decode " + path);
      receive();
    }
    av_packet_unref(pkt.get());
  }
  avcodec_send_packet(ctx.get(), nullptr);
  receive();
  const int64_t start = st->start_time != AV_NOPTS_VALUE ? st->start_time : 0;
  info.duration = end - start * av_q2d(st->time_base);
  info.loop = info.codec == "gif" ? gifLoopCount(path) : -2;
  if (info.pixel_format.empty()) info.pixel_format = "unknown";
  return info;
}

}  // namespace flexure::render
