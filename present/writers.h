// Output files from a scene and its tracked path: a frame or filmstrip (PNG, SVG, PDF, TikZ), an animation (MP4, GIF), a
// projection plot or its animation, and the path itself (JSON, CSV). Each is written
// atomically (present/output_file.h).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "engine/deformation_path.h"
#include "present/output_file.h"
#include "present/path_output.h"
#include "present/projection.h"
#include "render/renderer.h"
#include "render/video.h"
#include "scenes/scene.h"

namespace flexure::present {

// Sample `sample` of `path` (the start when path is null; clamped to the path) as a drawing:
// what frame `sample` of the animation shows (one alignment and camera for the whole path),
// with flex arrows when `flex` (the view then holds them too). `note`: "" or why there are no
// arrows.
struct FrameDrawing {
  render::DrawList list;
  render::View view;
  int sample = 0;
  std::string note;
};
FrameDrawing frameDrawing(const Scene& scene, const engine::DeformationPath* path, int sample, bool flex);
// The same as an image.
struct FrameImage {
  render::Image image;
  int sample = 0;
  std::string note;
};
FrameImage frameImage(const Scene& scene, const engine::DeformationPath* path, int sample, bool flex,
                      render::Renderer& renderer);
// One picture of sample `sample` of `path` (the start when path is null), as PNG, SVG, PDF or
// TikZ (by extension).
Written writeFrame(const Scene& scene, const engine::DeformationPath* path, int sample, bool flex,
                   const std::string& file, render::Renderer& renderer);
// A filmstrip: several samples in one figure, side by side in the path's one view (or
// overlaid, earlier ones fading, with [render] filmstrip_overlay), as PNG, SVG, PDF or TikZ.
Written writeFilmstrip(const Scene& scene, const engine::DeformationPath* path, const std::vector<int>& samples,
                       bool flex, const std::string& file, render::Renderer& renderer);
// An MP4 or GIF (by extension) of the whole path.
Written writeAnimation(const Scene& scene, const engine::DeformationPath& path, const std::string& file,
                       render::Renderer& renderer,
                       const std::vector<ProjectionPath>* paths, std::uint64_t projection_seed,
                       const render::FrameProgress& progress = {});
// The projection plot as an image.
render::Image projectionImage(const Scene& scene, const Projection& projection, render::Renderer& renderer);
// The projection plot (PNG, SVG, PDF, TikZ), or its animation with a moving marker (GIF/MP4).
Written writeProjection(const Scene& scene, const std::vector<ProjectionPath>& paths, std::uint64_t seed,
                        const std::string& file, const std::string& data_file, render::Renderer& renderer,
                        const render::FrameProgress& progress = {});

}  // namespace flexure::present
