// The outputs of a study: what draws (frames, animations, projection plots) and the path
// files. Kept apart from pipeline.cpp so that front ends that draw nothing (the `flexure`
// executable's analyze and track) link no renderer, video encoder or font library.
#include "pipeline/pipeline.h"

#include <stdexcept>

#include "present/animation.h"
#include "present/output_file.h"
#include "present/path_output.h"

namespace flexure::pipeline {

const present::Projection& Study::projection() {
  if (!projection_) projection_ = present::projectPaths(scene_, projectionPaths(), projection_seed_);
  return *projection_;
}

present::Written Study::write(const scenes::OutputSpec& spec, const std::string& file, const RendererSource& renderer,
                              const std::string& data) {
  const render::FrameProgress frames = [this](int done, int total) {
    return stepCallback(Stage::Frames)(done, total);
  };
  switch (spec.kind) {
    case scenes::OutputKind::Path:
      return present::writePath(scene_, motion().path, file);
    case scenes::OutputKind::Frame:
      if (!spec.samples.empty())
        return present::writeFilmstrip(scene_, steps_ > 0 ? &motion().path : nullptr, spec.samples, spec.flex, file,
                                       renderer());
      return present::writeFrame(scene_, steps_ > 0 ? &motion().path : nullptr, spec.sample, spec.flex, file,
                                 renderer());
    case scenes::OutputKind::Animation:
      return present::writeAnimation(scene_, motion().path, file, renderer(),
                                     scene_.render.animation.side_by_side ? &projectionPaths() : nullptr,
                                     projection_seed_, frames);
    case scenes::OutputKind::Projection:
      return present::writeProjection(scene_, projectionPaths(), projection_seed_, file, data, renderer(), frames);
  }
  throw std::logic_error("unknown output kind");
}

render::Image Study::image(const scenes::OutputSpec& spec, const RendererSource& renderer) {
  switch (spec.kind) {
    case scenes::OutputKind::Frame:
      return present::frameImage(scene_, steps_ > 0 ? &motion().path : nullptr, spec.sample, spec.flex, renderer())
          .image;
    case scenes::OutputKind::Projection:
      return present::projectionImage(scene_, projection(), renderer());
    default:
      throw std::invalid_argument(std::string("a ") + scenes::toString(spec.kind) + " is not one image");
  }
}

void Study::animationFrames(const RendererSource& renderer,
                            const std::function<void(int, const render::Image&)>& frame) {
  const bool side = scene_.render.animation.side_by_side;
  const std::optional<present::Projection> plot =
      side ? std::optional<present::Projection>(projection()) : std::nullopt;
  const present::Animation anim(scene_, motion().path, scene_.render.width * (side ? 2 : 1), scene_.render.height,
                                plot ? &*plot : nullptr);
  const engine::StepCallback progress = stepCallback(Stage::Frames);
  render::Image image;
  for (int i = 0; i < anim.frameCount(); ++i) {
    if (!progress(i, anim.frameCount())) return;
    anim.frame(i, renderer(), image);
    frame(i, image);
  }
}

Study::RunResult Study::run(const std::vector<scenes::OutputSpec>& outputs, const std::string& dir,
                            const RendererSource& renderer,
                            const std::function<void(const present::Written&)>& on_written) {
  RunResult result;
  for (const auto& o : outputs) present::makeDirectories(present::directoryOf(placeIn(dir, o.file)));
  motion();
  for (const auto& o : outputs) {
    const std::string file = placeIn(dir, o.file);
    if (cancelled_) {
      result.stopped_before = file;
      return result;
    }
    // The projection's paths are tracked before the renderer starts (as the outputs need them).
    const bool needs_paths = o.kind == scenes::OutputKind::Projection ||
                             (o.kind == scenes::OutputKind::Animation && scene_.render.animation.side_by_side);
    if (needs_paths) projectionPaths();
    if (cancelled_) {
      result.stopped_before = file;
      return result;
    }
    result.written.push_back(write(o, file, renderer));
    if (on_written) on_written(result.written.back());
  }
  return result;
}

}  // namespace flexure::pipeline
