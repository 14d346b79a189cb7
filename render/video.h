// Animations encoded in-process: MP4 (H.264 by libx264 through FFmpeg's libraries, loaded on
// first use from libflexure-av.so: yuv420p, exact frame count and duration) and GIF (gif.h: one
// palette made over the clip, ordered dithering, changed rectangles, looping forever). Frames
// come from a callback on the calling thread (the one that owns the GL context); encoding runs
// on a second thread, so rendering and encoding overlap.
#pragma once

#include <functional>
#include <stdexcept>
#include <string>

#include "render/image.h"

namespace flexure::render {

enum class VideoFormat { Mp4, Gif };

struct VideoOptions {
  VideoFormat format = VideoFormat::Mp4;
  int width = 0, height = 0;   // every frame has this size; MP4 needs both even
  int fps = 25;                // MP4: exact; GIF: delays rounded to centiseconds, at most 50
  int crf = 20;                // MP4 quality (x264 constant rate factor, 0-51)
  std::string preset = "veryfast";
  // GIF: the palette frames (at most 32, rendered for the first pass) are kept in memory for
  // the second (palette-mapping) pass when they fit in this many bytes and rendering costs
  // more than holding them, and the second pass renders only the others; otherwise they are
  // rendered twice. The file is the same either way.
  size_t gif_cache_bytes = size_t{128} << 20;
  // Auto: kept when a frame takes at least 2 ms per MB of pixels to render (holding one cost
  // about 1.5 ms per MB here, its pages first touched: a 480x480 frame of K_{2,4} renders in
  // 0.4 ms, one of the coned cube in about 2).
  enum class GifKeep { Auto, Always, Never } gif_keep = GifKeep::Auto;
};

struct VideoStats {
  int frames = 0;
  double render_seconds = 0;  // in the frame callback
  double encode_seconds = 0;  // busy time of the encoder thread
  double wall_seconds = 0;
  bool rendered_twice = false;  // GIF only: the palette frames were rendered again for pass 2
};

// Thrown when the progress callback asks to stop; the partial file is left for the caller to
// remove (callers write to a temporary name).
struct VideoInterrupted : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Fills `frame` with frame `index`. The frames handed in are recycled: reuse their memory
// (Renderer::render(list, view, frame) does).
using FrameSource = std::function<void(int index, Image& frame)>;
// Called on the calling thread after each frame is queued: (done, total); false stops.
using FrameProgress = std::function<bool(int done, int total)>;

// Writes `frames` frames to `path`. Throws std::runtime_error (with libav's message) when the
// file cannot be written or encoding fails, VideoInterrupted when progress returns false.
VideoStats writeVideo(const std::string& path, const VideoOptions& options, int frames, const FrameSource& source,
                      const FrameProgress& progress = {});

// What a written file holds, found by decoding every frame (used by the tests).
struct VideoInfo {
  std::string format;       // container: "mov,mp4,m4a,3gp,3g2,mj2" or "gif"
  std::string codec;        // "h264", "gif"
  std::string pixel_format; // "yuv420p", "bgra", ...
  int width = 0, height = 0;
  int frames = 0;           // decoded
  double duration = 0;      // seconds: the last frame's time stamp plus its duration
  double frame_rate = 0;    // the stream's average frame rate
  int loop = -2;            // GIF: the NETSCAPE loop count (0: forever), -1: none; -2: not a GIF
  Image first, last;        // the first and last decoded frames, as RGBA
};
VideoInfo probeVideo(const std::string& path);

}  // namespace flexure::render
