#include "present/writers.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>

#include "engine/rigidity.h"
#include "present/animation.h"
#include "present/figure.h"
#include "present/frames.h"
#include "present/output_file.h"
#include "present/path_output.h"
#include "present/surface_mesh.h"

namespace flexure::present {

namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

std::string format(const char* f, double a) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, a);
  return buf;
}

void writePng(const std::string& file, const render::Image& image) {
  const auto png = render::encodePng(image);
  writeFileAtomically(file, std::string(png.begin(), png.end()));
}

// The frame size of an animation: the scene's (twice as wide side by side), scaled down to
// gif_size for GIFs, rounded up to even for MP4.
std::pair<int, int> videoSize(const Scene& scene, bool gif, bool side) {
  int w = scene.render.width * (side ? 2 : 1), h = scene.render.height;
  if (gif) {
    const double s = std::min(1.0, scene.render.animation.gif_size / static_cast<double>(std::max(w, h)));
    w = std::max(16, static_cast<int>(std::lround(w * s)));
    h = std::max(16, static_cast<int>(std::lround(h * s)));
  } else {
    w += w % 2, h += h % 2;
  }
  return {w, h};
}

render::VideoOptions videoOptions(const Scene& scene, bool gif, int w, int h) {
  render::VideoOptions o;
  o.format = gif ? render::VideoFormat::Gif : render::VideoFormat::Mp4;
  o.width = w, o.height = h;
  o.fps = gif ? std::min(scene.render.fps, 50) : scene.render.fps;
  o.crf = scene.render.animation.crf;
  return o;
}

// writeVideo into `out`'s temporary file, then the final name; failures name the file.
render::VideoStats encodeVideo(TemporaryOutput& out, const std::string& file, const render::VideoOptions& opt,
                               int frames, const render::FrameSource& source, const render::FrameProgress& progress) {
  render::VideoStats stats;
  try {
    stats = render::writeVideo(out.temp(), opt, frames, source, progress);
  } catch (const render::VideoInterrupted&) {
    throw;
  } catch (const std::runtime_error& e) {
    throw OutputError("cannot write " + file + ": " + e.what());
  }
  out.commit();
  return stats;
}

std::string videoSummary(const render::VideoStats& s, int w, int h, int fps) {
  return std::to_string(s.frames) + " frames, " + std::to_string(w) + "x" + std::to_string(h) + ", " +
         std::to_string(fps) + " fps, " + format("%.2f s", static_cast<double>(s.frames) / fps) + "; rendering " +
         format("%.1f s", s.render_seconds) + ", encoding " + format("%.1f s", s.encode_seconds) + ", wall " +
         format("%.1f s", s.wall_seconds);
}

}  // namespace

FrameImage frameImage(const Scene& scene, const engine::DeformationPath* path, int sample, bool flex,
                      render::Renderer& renderer) {
  FigureStyle style = scene.render.style;
  style.width = scene.render.width;
  style.height = scene.render.height;
  const engine::Model& model = *scene.model;
  const engine::ConstraintSystem& sys = model.system();
  std::vector<engine::Vector> start{model.startCoordinates()};
  const std::vector<engine::Vector>& samples = path ? path->samples : start;
  const int shown = std::clamp(sample, 0, static_cast<int>(samples.size()) - 1);
  const engine::Matrix positions = sys.vertexPositions(samples[static_cast<size_t>(shown)]);
  FigureExtras extras;
  std::string note;
  if (flex) {
    // The selected flex at the configuration shown: the scene's coefficients in its
    // nontrivial-flex basis (or its auto flex when their number does not fit there).
    engine::RigidityOptions ro = scenes::rigidityOptions(scene);
    ro.motion_check_steps = 0;  // only the flexes are drawn
    // The model in force there: a sticky packing's flexes respect the contacts made so far.
    const engine::Model& analysed = path ? path->modelAt(shown) : model;
    const engine::Vector& x = samples[static_cast<size_t>(shown)];
    const engine::RigidityReport rep = engine::analyzeRigidity(analysed, x, ro);
    if (rep.nontrivial > 0) {
      engine::Vector c = rep.auto_flex;
      if (scene.motion.flex && static_cast<int>(scene.motion.flex->size()) == rep.nontrivial)
        c = Eigen::Map<const engine::Vector>(scene.motion.flex->data(), rep.nontrivial);
      extras.flex = sys.velocityField(rep.flex_basis * c).leftCols(sys.numVertices());  // not the facet normals
    } else {
      note = "; no nontrivial infinitesimal flex there, no arrows";
    }
  }
  if (style.trace)
    for (int k = 0; k <= shown; ++k) extras.trace.push_back(sys.vertexPositions(samples[static_cast<size_t>(k)]));
  if (style.ghost >= 0 && style.ghost < static_cast<int>(samples.size()))
    extras.ghost = sys.vertexPositions(samples[static_cast<size_t>(style.ghost)]);
  const engine::Geometry geometry = path ? path->geometryAt(shown) : model.geometry();
  std::vector<engine::Matrix> frames{positions};
  if (extras.ghost) frames.push_back(*extras.ghost);
  if (extras.flex.size() > 0) frames.push_back(flexTips(positions, extras.flex, style));
  for (const auto& t : extras.trace) frames.push_back(t);
  const render::View view = fitView(geometry, frames, style);
  const std::vector<render::Polygon> surface = surfaceMesh(geometry, view, style);
  extras.surface = &surface;
  return {renderer.render(figure(geometry, positions, style, extras), view), shown, note};
}

Written writeFrame(const Scene& scene, const engine::DeformationPath* path, int sample, bool flex,
                   const std::string& file, render::Renderer& renderer) {
  const auto t0 = Clock::now();
  const FrameImage f = frameImage(scene, path, sample, flex, renderer);
  writePng(file, f.image);
  Written w;
  w.file = file;
  w.seconds = secondsSince(t0);
  w.summary = std::to_string(f.image.width) + "x" + std::to_string(f.image.height) + ", sample " +
              std::to_string(f.sample) + f.note;
  return w;
}

Written writeAnimation(const Scene& scene, const engine::DeformationPath& path, const std::string& file,
                       render::Renderer& renderer,
                       const std::vector<ProjectionPath>* paths, std::uint64_t projection_seed,
                       const render::FrameProgress& progress) {
  const std::string ext = extensionOf(file);
  const bool gif = ext == "gif";
  const bool side = scene.render.animation.side_by_side && paths && !paths->empty();
  const auto [w, h] = videoSize(scene, gif, side);
  TemporaryOutput out(file);
  std::optional<Projection> projection;
  if (side) projection = projectPaths(scene, *paths, projection_seed);
  const Animation anim(scene, path, w, h, projection ? &*projection : nullptr);
  const render::VideoOptions opt = videoOptions(scene, gif, w, h);
  Written wr;
  wr.file = file;
  wr.video = encodeVideo(out, file, opt, anim.frameCount(),
                         [&](int i, render::Image& image) { anim.frame(i, renderer, image); }, progress);
  wr.seconds = wr.video.wall_seconds;
  wr.summary = videoSummary(wr.video, w, h, opt.fps);
  return wr;
}

render::Image projectionImage(const Scene& scene, const Projection& projection, render::Renderer& renderer) {
  const render::PlotCanvas canvas(projection.plot, projectionStyle(scene, scene.render.width, scene.render.height));
  return renderer.render(canvas.draw(), canvas.view());
}

Written writeProjection(const Scene& scene, const std::vector<ProjectionPath>& paths, std::uint64_t seed,
                        const std::string& file, const std::string& data_file, render::Renderer& renderer,
                        const render::FrameProgress& progress) {
  const auto t0 = Clock::now();
  const Projection pr = projectPaths(scene, paths, seed);
  const std::string ext = extensionOf(file);
  Written wr;
  wr.file = file;
  if (ext == "png") {
    writePng(file, projectionImage(scene, pr, renderer));
    wr.summary = std::to_string(scene.render.width) + "x" + std::to_string(scene.render.height) + ", " +
                 std::to_string(paths.size()) + " path(s), seed " + std::to_string(seed);
  } else {
    // The animated projection: a marker moving along the first curve.
    const bool gif = ext == "gif";
    const auto [w, h] = videoSize(scene, gif, false);
    TemporaryOutput out(file);
    const render::PlotCanvas canvas(pr.plot, projectionStyle(scene, w, h));
    const std::vector<int> frames =
        frameSamples(pr.curves.empty() ? 1 : static_cast<int>(pr.curves[0].size()), scene.render.animation.frame_step);
    const render::VideoOptions opt = videoOptions(scene, gif, w, h);
    wr.video = encodeVideo(
        out, file, opt, static_cast<int>(frames.size()),
        [&](int i, render::Image& image) {
          std::optional<render::Point2> cursor;
          if (!pr.curves.empty() && !pr.curves[0].empty())
            cursor = pr.curves[0][static_cast<size_t>(frames[static_cast<size_t>(i)])];
          renderer.render(canvas.draw(cursor), canvas.view(), image);
        },
        progress);
    wr.summary = videoSummary(wr.video, w, h, opt.fps) + ", seed " + std::to_string(seed);
  }
  if (!data_file.empty()) writeFileAtomically(data_file, projectionCsv(paths, pr));
  wr.seconds = secondsSince(t0);
  return wr;
}

}  // namespace flexure::present
