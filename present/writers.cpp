#include "present/writers.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>

#include "engine/rigidity.h"
#include "present/animation.h"
#include "present/figure.h"
#include "present/frames.h"
#include "present/output_file.h"
#include "present/path_output.h"
#include "present/print_mesh.h"
#include "present/surface_mesh.h"
#include "render/vector.h"

namespace flexure::present {

namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

std::string format(const char* f, double a) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, a);
  return buf;
}

// `dpi`: the resolution the PNG states (0: none, a figure in pixels).
void writePng(const std::string& file, const render::Image& image, double dpi = 0) {
  const auto png = render::encodePng(image, 6, dpi);
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

namespace {

// The rigidity analysis at sample `shown` that a drawing needs (its flexes, its stresses): of the
// model in force there (a sticky packing's flexes respect the contacts made so far), without the
// motion check.
engine::RigidityReport analysisAt(const Scene& scene, const engine::DeformationPath& path, int shown) {
  engine::RigidityOptions ro = scenes::rigidityOptions(scene);
  ro.motion_check_steps = 0;
  return engine::analyzeRigidity(path.modelAt(shown), path.samples[static_cast<size_t>(shown)], ro);
}

// The velocity field of the selected flex (d x n, the path's coordinates; empty with the reason
// in `note`) from the analysis at the sample: the scene's coefficients in its nontrivial-flex
// basis (or its auto flex when their number does not fit there).
engine::Matrix flexField(const Scene& scene, const engine::RigidityReport& rep, std::string& note) {
  const engine::ConstraintSystem& sys = scene.model->system();
  if (rep.nontrivial == 0) {
    note = "; no nontrivial infinitesimal flex there, no arrows";
    return {};
  }
  engine::Vector c = rep.auto_flex;
  if (scene.motion.flex && static_cast<int>(scene.motion.flex->size()) == rep.nontrivial)
    c = Eigen::Map<const engine::Vector>(scene.motion.flex->data(), rep.nontrivial);
  return sys.velocityField(rep.flex_basis * c).leftCols(sys.numVertices());  // not the facet normals
}

std::string frameSummary(int width, int height, const std::string& what, const std::string& note) {
  return std::to_string(width) + "x" + std::to_string(height) + ", " + what + note;
}

// A figure of panels as PNG (rendered panel by panel and laid side by side) or a vector format.
void writeFigure(const std::string& file, const render::VectorFigure& fig, render::Renderer& renderer) {
  render::VectorFormat format;
  if (render::vectorFormatOf(extensionOf(file), format)) {
    std::string bytes;
    try {
      bytes = render::vectorDocument(fig, format);
    } catch (const std::runtime_error& e) {
      throw OutputError("cannot write " + file + ": " + e.what());
    }
    writeFileAtomically(file, bytes);
    return;
  }
  if (fig.panels.size() == 1) {
    writePng(file, renderer.render(*fig.panels[0].list, fig.panels[0].view), fig.dpi == 96 ? 0 : fig.dpi);
    return;
  }
  render::Image out, panel;
  out.width = fig.width, out.height = fig.height;
  out.rgba.resize(static_cast<size_t>(fig.width) * fig.height * 4);
  const auto byte = [](float c) { return static_cast<std::uint8_t>(std::lround(255.0 * std::clamp(c, 0.f, 1.f))); };
  for (size_t i = 0; i < out.rgba.size(); i += 4)  // the background where no panel reaches
    out.rgba[i] = byte(fig.background.r), out.rgba[i + 1] = byte(fig.background.g),
    out.rgba[i + 2] = byte(fig.background.b), out.rgba[i + 3] = byte(fig.background.a);
  for (const render::VectorPanel& p : fig.panels) {
    renderer.render(*p.list, p.view, panel);
    const int x0 = static_cast<int>(p.x), y0 = static_cast<int>(p.y);
    for (int y = 0; y < panel.height && y0 + y < out.height; ++y)
      std::copy_n(panel.pixel(0, y), static_cast<size_t>(std::min(panel.width, out.width - x0)) * 4,
                  &out.rgba[(static_cast<size_t>(y0 + y) * out.width + x0) * 4]);
  }
  writePng(file, out, fig.dpi == 96 ? 0 : fig.dpi);
}

// A figure of the scene's [render] resolution (a figure sized in lengths has its dpi).
render::VectorFigure sceneFigure(const Scene& scene) {
  render::VectorFigure fig;
  fig.title = scene.title;
  fig.background = scene.render.style.background;
  fig.width = scene.render.width, fig.height = scene.render.height;
  if (scene.render.physical) fig.dpi = scene.render.dpi;
  return fig;
}

render::VectorFigure scenePanel(const Scene& scene, const render::DrawList& list, const render::View& view) {
  render::VectorFigure fig = sceneFigure(scene);
  fig.width = view.width, fig.height = view.height;
  fig.background = view.background;
  fig.panels.push_back({&list, view, 0, 0});
  return fig;
}

}  // namespace

namespace {

// [render] stress: equilibrium stress `stress` of the basis at sample `shown` drawn on the bars
// of `style` (tension red, compression blue, widths by magnitude; bars without stress thin and
// grey). A stress's sign is the basis vector's (the analysis JSON's stress_basis): positive is
// tension for distance constraints |p_i - p_j|^2 = L^2. Throws std::invalid_argument (wrong
// input: exit 1, Python's ValueError) when there is none.
// `sys` and `rep`: the system in force at the sample and its analysis there.
void addStress(const engine::ConstraintSystem& sys, const engine::RigidityReport& rep, int shown, FigureStyle& style,
               std::string& note) {
  const int k = style.stress;
  if (!rep.stress_basis_computed || k >= rep.stress_basis.cols())
    throw std::invalid_argument("stress " + std::to_string(k) + " ([render] stress, render --stress)" +
                                ": the equilibrium stresses at sample " + std::to_string(shown) +
                      (rep.stress_basis_computed
                           ? " span " + std::to_string(rep.stress_basis.cols()) + " dimension" +
                                 (rep.stress_basis.cols() == 1 ? "" : "s") +
                                 (rep.stress_basis.cols() > 0 ? " (stresses 0.." + std::to_string(rep.stress_basis.cols() - 1) + ")" : "")
                           : " were not computed (too many equations for the stress basis)"));
  const engine::Vector w = rep.stress_basis.col(k);
  double top = 0;
  for (int r = 0; r < w.size(); ++r)
    if (sys.equationVertices(r).size() == 2) top = std::max(top, std::abs(w[r]));
  if (!(top > 0))
    throw std::invalid_argument("stress " + std::to_string(k) + " ([render] stress, render --stress): the stress is zero on every bar");
  const render::Color tension{0xCD / 255.f, 0, 0, 1}, compression{0x1F / 255.f, 0x77 / 255.f, 0xB4 / 255.f, 1};
  int tense = 0, compressed = 0;
  for (int r = 0; r < w.size(); ++r) {
    const std::vector<int> v = sys.equationVertices(r);
    if (v.size() != 2) continue;
    scenes::PartStyle look;
    const double m = std::abs(w[r]) / top;
    if (m < 1e-9) {
      look.color = render::Color{0.8f, 0.8f, 0.8f, 1}, look.width = 0.3 * style.line_width;
    } else {
      look.color = w[r] > 0 ? tension : compression, look.width = style.line_width * (0.3 + 1.4 * m);
      (w[r] > 0 ? tense : compressed) += 1;
    }
    style.edge_styles[{std::min(v[0], v[1]), std::max(v[0], v[1])}] = look;
  }
  note += "; stress " + std::to_string(k) + " of " + std::to_string(rep.stress_basis.cols()) + ": " +
          std::to_string(tense) + " bars in tension (red), " + std::to_string(compressed) + " in compression (blue)";
}

// Sample `sample` of a non-empty path, drawn by `anim` (the path's one alignment and camera).
FrameDrawing pathDrawing(const Scene& scene, const engine::DeformationPath& path, const Animation& anim, int sample,
                         bool flex) {
  const int shown = std::clamp(sample, 0, static_cast<int>(path.samples.size()) - 1);
  FrameDrawing d;
  d.sample = shown;
  engine::Matrix field;
  const bool stress = anim.style().stress >= 0;
  std::optional<engine::RigidityReport> rep;  // one analysis for the arrows and the stress
  if (flex || stress) rep = analysisAt(scene, path, shown);
  if (flex) field = flexField(scene, *rep, d.note);
  std::optional<FigureStyle> stressed;
  if (stress) {
    stressed = anim.style();
    addStress(path.modelAt(shown).system(), *rep, shown, *stressed, d.note);
  }
  Animation::Still still = anim.still(shown, field.size() > 0 ? &field : nullptr, stressed ? &*stressed : nullptr);
  d.list = std::move(still.list);
  d.view = still.view;
  return d;
}

// The start alone, as a path of one sample: a still of it is the still of sample 0 of any path
// from there (the same alignment and orientation, the same framing).
engine::DeformationPath startPath(const Scene& scene) {
  engine::DeformationPath p;
  p.samples.push_back(scene.model->startCoordinates());
  p.startOn(*scene.model);
  return p;
}

}  // namespace

FrameDrawing frameDrawing(const Scene& scene, const engine::DeformationPath* path, int sample, bool flex) {
  if (!path || path->samples.empty()) {
    const engine::DeformationPath start = startPath(scene);
    return frameDrawing(scene, &start, 0, flex);
  }
  const Animation anim(scene, *path, scene.render.width, scene.render.height);
  return pathDrawing(scene, *path, anim, sample, flex);
}

FrameImage frameImage(const Scene& scene, const engine::DeformationPath* path, int sample, bool flex,
                      render::Renderer& renderer) {
  const FrameDrawing d = frameDrawing(scene, path, sample, flex);
  return {renderer.render(d.list, d.view), d.sample, d.note};
}

Written writeFrame(const Scene& scene, const engine::DeformationPath* path, int sample, bool flex,
                   const std::string& file, render::Renderer& renderer) {
  const auto t0 = Clock::now();
  if (const std::string ext = extensionOf(file); scenes::isSolidExtension(ext)) {
    // The configuration in the scene's own coordinates (not moved for display), as a solid.
    const int last = path && !path->samples.empty() ? static_cast<int>(path->samples.size()) - 1 : 0;
    const int shown = std::clamp(sample, 0, last);
    const engine::Vector x = path && !path->samples.empty() ? path->samples[static_cast<size_t>(shown)]
                                                            : scene.model->startCoordinates();
    const engine::Geometry g = path && !path->samples.empty() ? path->geometryAt(shown) : scene.model->geometry();
    const PrintMesh mesh = printMesh(g, scene.model->system().vertexPositions(x), scene.render.print_tube,
                                     scene.render.print_joint, scene.index_base);
    writeFileAtomically(file, printMeshFile(mesh, ext, scene.title));
    Written w;
    w.file = file;
    w.seconds = secondsSince(t0);
    w.summary = std::to_string(mesh.parts.size()) + " parts, " + std::to_string(mesh.triangles.size()) +
                " triangles, sample " + std::to_string(shown);
    return w;
  }
  const FrameDrawing d = frameDrawing(scene, path, sample, flex);
  writeFigure(file, scenePanel(scene, d.list, d.view), renderer);
  Written w;
  w.file = file;
  w.seconds = secondsSince(t0);
  w.summary = frameSummary(d.view.width, d.view.height, "sample " + std::to_string(d.sample), d.note);
  return w;
}

namespace {

// A filmstrip panel's caption: [render] caption's pieces filled in for `sample`; {arc_length}
// is the polygonal length of the path up to the sample, in coordinate space.
std::string panelCaption(const std::vector<scenes::CaptionPiece>& pieces, const engine::DeformationPath& path,
                         int sample) {
  using Piece = scenes::CaptionPiece;
  std::string out;
  for (const Piece& p : pieces)
    switch (p.kind) {
      case Piece::Text: out += p.text; break;
      case Piece::Sample: out += std::to_string(sample); break;
      case Piece::ArcLength: {
        double arc = 0;
        for (int k = 1; k <= sample && k < static_cast<int>(path.samples.size()); ++k)
          arc += (path.samples[static_cast<size_t>(k)] - path.samples[static_cast<size_t>(k - 1)]).norm();
        out += format("%.3g", arc);
        break;
      }
      case Piece::Event:
        for (const engine::TrackEvent& e : path.events)
          if (e.sample == sample) {
            out += e.kind == engine::EventKind::Singularity ? "singular point" : e.detail;
            break;
          }
        break;
      case Piece::Distance: {  // a contraction's or a driven edge's length
        const engine::Matrix q = path.modelAt(sample).system().vertexPositions(path.samples[static_cast<size_t>(sample)]);
        out += format("%.4g", (q.col(p.a) - q.col(p.b)).norm());
        break;
      }
    }
  return out;
}

}  // namespace

Written writeFilmstrip(const Scene& scene, const engine::DeformationPath* path, const std::vector<int>& samples,
                       bool flex, const std::string& file, render::Renderer& renderer) {
  const auto t0 = Clock::now();
  const engine::DeformationPath start = path && !path->samples.empty() ? engine::DeformationPath{} : startPath(scene);
  const engine::DeformationPath& shown_path = path && !path->samples.empty() ? *path : start;
  const bool overlay = scene.render.filmstrip_overlay;
  const int n = static_cast<int>(samples.size());
  // The panels: a grid of `columns` (all in one row by default). A figure sized in lengths is
  // that size, the grid's; in pixels, each panel has the scene's width and height.
  const int columns = overlay || n == 0 ? 1 : std::clamp(scene.render.columns > 0 ? scene.render.columns : n, 1, n);
  const int rows = overlay || n == 0 ? 1 : (n + columns - 1) / columns;
  const int w = scene.render.width, h = scene.render.height;
  const bool whole = overlay || scene.render.physical;
  const int pw = whole ? std::max(16, w / columns) : w, ph = whole ? std::max(16, h / rows) : h;
  // One alignment and camera orientation for every panel, made once; each panel framed on its sample.
  const Animation anim(scene, shown_path, pw, ph);
  std::vector<FrameDrawing> drawings;
  std::string shown, note;
  for (int k : samples) {
    drawings.push_back(pathDrawing(scene, shown_path, anim, k, flex));
    shown += (shown.empty() ? "" : ",") + std::to_string(drawings.back().sample);
    if (note.empty()) note = drawings.back().note;
  }
  // One scale for all panels, each centred on its sample: every panel's box as large as the
  // largest (a bar has one length on screen from panel to panel).
  std::array<double, 3> half{0, 0, 0};
  for (const FrameDrawing& d : drawings)
    for (int k = 0; k < 3; ++k) half[k] = std::max(half[k], 0.5 * (d.view.hi[k] - d.view.lo[k]));
  for (FrameDrawing& d : drawings)
    for (int k = 0; k < 3; ++k) {
      const double c = 0.5 * (d.view.lo[k] + d.view.hi[k]);
      d.view.lo[k] = c - half[k], d.view.hi[k] = c + half[k];
    }
  render::VectorFigure fig = sceneFigure(scene);
  render::DrawList overlaid;
  if (overlay && !drawings.empty()) {
    // One picture: every sample in the path's one view (the last one's, which holds them all
    // unless flex arrows widen it), earlier samples fading; the labels of the last alone.
    const size_t count = drawings.size();
    render::View view = drawings.back().view;
    const engine::Geometry g = shown_path.geometryAt(drawings.back().sample);
    std::vector<engine::Matrix> frames;
    for (const FrameDrawing& d : drawings) frames.push_back(anim.shownPositions(d.sample));
    const render::View fitted = fitView(g, frames, anim.style());
    view.lo = fitted.lo, view.hi = fitted.hi;
    for (size_t i = 0; i < count; ++i) {
      const float fade = count == 1 ? 1.f : static_cast<float>(0.2 + 0.8 * static_cast<double>(i) / static_cast<double>(count - 1));
      render::DrawList& l = drawings[i].list;
      overlaid.dimension = l.dimension;
      for (render::Polygon p : l.polygons) {
        p.fill.a *= fade;
        overlaid.polygons.push_back(std::move(p));
      }
      for (render::Shape sh : l.shapes) {
        sh.fill.a *= fade, sh.stroke.a *= fade;
        overlaid.shapes.push_back(sh);
      }
      if (i + 1 == count) overlaid.labels = l.labels;
    }
    fig.panels.push_back({&overlaid, view, 0, 0});
  } else {
    fig.width = whole ? w : pw * columns, fig.height = whole ? h : ph * rows;
    // Captions at the scene's font size (not shrunk with a crowded figure's labels).
    const double font = scene.render.style.font_size * pixelScale(anim.style());
    for (size_t i = 0; i < drawings.size(); ++i) {
      // Each panel's caption, under its figure.
      const std::string text = panelCaption(scene.render.caption, shown_path, drawings[i].sample);
      if (!text.empty()) {
        // A band of two lines under the figure, which shrinks to leave it free.
        const double band = 2.2 * font;
        render::View& v = drawings[i].view;
        v.zoom = std::max(0.2, 1 - band / ph);
        v.pan_y = 0.5 * band;
        render::Label l;
        l.screen = true;
        l.at = {0.5 * pw, ph - 0.9 * font, 0};
        l.text = text;
        l.size = static_cast<float>(font);
        l.regular = true;
        l.color = render::Color{0.35f, 0.35f, 0.35f, 1};
        l.role = "caption";
        drawings[i].list.labels.push_back(l);
      }
      const int col = static_cast<int>(i) % columns, row = static_cast<int>(i) / columns;
      fig.panels.push_back({&drawings[i].list, drawings[i].view, static_cast<double>(pw * col), static_cast<double>(ph * row)});
    }
  }
  writeFigure(file, fig, renderer);
  Written wr;
  wr.file = file;
  wr.seconds = secondsSince(t0);
  wr.summary = frameSummary(fig.width, fig.height, std::string(overlay ? "overlaid " : "") + "samples " + shown, note);
  return wr;
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
  const Animation anim(scene, path, w, h, projection ? &*projection : nullptr,
                       static_cast<double>(h) / scene.render.height);
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
  if (scenes::isImageExtension(ext)) {
    const render::PlotCanvas canvas(pr.plot, projectionStyle(scene, scene.render.width, scene.render.height));
    const render::DrawList list = canvas.draw();
    writeFigure(file, scenePanel(scene, list, canvas.view()), renderer);
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
