// FFmpeg's side of the animations, loaded only when an MP4 is written or a video decoded:
// libavcodec and libavformat bring about 100 shared libraries whose loading cost more than a
// whole 100-frame GIF of K_{2,4} (which needs none of them). Built as libflexure-av.so.
#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/imgutils.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
}

#include "render/libav.h"

namespace flexure::render {

namespace {

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
using FramePtr = std::unique_ptr<AVFrame, FrameDeleter>;
using PacketPtr = std::unique_ptr<AVPacket, PacketDeleter>;
using CodecPtr = std::unique_ptr<AVCodecContext, CodecDeleter>;

FramePtr newFrame() {
  FramePtr f(av_frame_alloc());
  if (!f) throw std::bad_alloc();
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
  // call: some of FFmpeg's muxers (the GIF muxer, when it wrote the GIFs) free what they hold
  // back only there. The file is discarded anyway.
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


class Mp4Writer : public libav::Mp4Sink {
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

  void consume(const Image& image, int index) override {
    // swscale reads whole SIMD blocks: the rows go into a padded frame first.
    for (int y = 0; y < image.height; ++y)
      std::memcpy(rgba_->data[0] + static_cast<ptrdiff_t>(y) * rgba_->linesize[0], image.pixel(0, y),
                  static_cast<size_t>(image.width) * 4);
    check(av_frame_make_writable(yuv_.get()), "cannot reuse a frame");
    sws_scale(sws_.get(), rgba_->data, rgba_->linesize, 0, image.height, yuv_->data, yuv_->linesize);
    yuv_->pts = index;
    mux_->encode(yuv_.get(), 1);  // one frame of 1/fps each: the duration comes out exact
  }
  void finish() override {
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

VideoInfo probe(const std::string& path) {
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

std::unique_ptr<libav::Mp4Sink> openMp4(const std::string& path, const VideoOptions& options) {
  quietLibav();
  return std::make_unique<Mp4Writer>(path, options);
}

const libav::Api kApi{libav::kApiVersion, openMp4, probe};

}  // namespace

}  // namespace flexure::render

extern "C" const flexure::render::libav::Api* flexure_libav_api() { return &flexure::render::kApi; }
