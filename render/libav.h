// The interface of libflexure-av.so, the part of the animations that needs FFmpeg's libraries
// (MP4 writing, decoding for the tests). It is loaded on first use, so that the commands that
// write no MP4 (PNG, GIF, the analysis) do not load libavcodec, libavformat and the ~100
// libraries behind them: about 35 ms of every process that draws (bench_startup).
#pragma once

#include <memory>
#include <string>

#include "render/image.h"
#include "render/video.h"

namespace flexure::render::libav {

// An MP4 being written: frames in order, then finish().
class Mp4Sink {
 public:
  virtual ~Mp4Sink() = default;
  virtual void consume(const Image& image, int index) = 0;
  virtual void finish() = 0;
};

constexpr int kApiVersion = 1;

struct Api {
  int version;
  // Throw std::invalid_argument (an odd size) or std::runtime_error (libav's message).
  std::unique_ptr<Mp4Sink> (*open_mp4)(const std::string& path, const VideoOptions& options);
  VideoInfo (*probe)(const std::string& path);
};

// The module's functions, loaded once, from the file FLEXURE_AV_MODULE names (an absolute path,
// the only place tried when it is set), else beside the real file of the executable
// (/proc/self/exe; and PREFIX/lib/flexure for one installed in PREFIX/bin) or of the shared
// object (the Python module) that holds this code: never from the working directory or the
// build tree. Throws std::invalid_argument for a relative FLEXURE_AV_MODULE, std::runtime_error
// naming every place tried when none loads.
const Api& api();

}  // namespace flexure::render::libav
