#include "scenes/outputs.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "engine/contraction.h"
#include "engine/packing.h"
#include "engine/random.h"
#include "scenes/output_file.h"
#include "scenes/path_output.h"

namespace flexure::scenes {

namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

std::string format(const char* f, double a) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, a);
  return buf;
}

render::Color hex(unsigned rgb) {
  return {((rgb >> 16) & 255) / 255.f, ((rgb >> 8) & 255) / 255.f, (rgb & 255) / 255.f, 1};
}

// The diagonal of the configuration's bounding box: tolerances on positions are relative to it.
double extent(const engine::Matrix& p) {
  return p.cols() ? (p.rowwise().maxCoeff() - p.rowwise().minCoeff()).norm() : 0.0;
}

std::string coefficientsText(const std::vector<double>& c) {
  std::string s = "(";
  for (size_t i = 0; i < c.size(); ++i) s += (i ? ", " : "") + format("%.3g", c[i]);
  return s + ")";
}

}  // namespace

std::string extensionOf(const std::string& path) {
  const auto slash = path.find_last_of('/');
  const auto dot = path.rfind('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot + 1);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

engine::RigidityOptions rigidityOptions(const Scene& scene) {
  engine::RigidityOptions opt;
  opt.rank_tolerance = scene.analysis.rank_tolerance;
  opt.seed = scene.analysis.seed;
  opt.max_homotopy_flexes = scene.analysis.max_homotopy_flexes;
  opt.motion_check_steps = scene.analysis.motion_check_steps;
  return opt;
}

engine::RigidityReport analyzeScene(const Scene& scene) {
  return engine::analyzeRigidity(*scene.model, scene.model->startCoordinates(), rigidityOptions(scene));
}

Motion trackScene(const Scene& scene, int steps, const engine::StepCallback& on_step,
                  const std::vector<double>* coefficients) {
  Motion m;
  m.rep = analyzeScene(scene);
  const int k = m.rep.nontrivial;
  const std::vector<double>* given = coefficients ? coefficients : scene.motion.flex ? &*scene.motion.flex : nullptr;
  if (given) {
    m.coefficients = *given;
    if (static_cast<int>(m.coefficients.size()) != k && k > 0)
      throw SceneError(scene.motion.flex_file, scene.motion.flex_line, scene.motion.flex_column,
                       "flex has " + std::to_string(m.coefficients.size()) +
                           " coefficient(s), but the start configuration has " + std::to_string(k) +
                           " nontrivial infinitesimal flex(es)");
    m.note = "given";
  } else {
    m.coefficients.assign(m.rep.auto_flex.data(), m.rep.auto_flex.data() + m.rep.auto_flex.size());
    m.note = "auto: " + m.rep.auto_flex_note;
  }
  if (scene.motion.contract_edge) {
    const auto [a, b] = *scene.motion.contract_edge;
    engine::ContractionOptions copt;
    copt.step = scene.motion.step_size;
    copt.max_steps = scene.motion.steps_given || steps != scene.motion.steps ? steps : -1;
    copt.corrector.factorization.rank_tolerance = scene.analysis.rank_tolerance;
    m.coefficients.clear();
    m.note = "edge contraction of [" + std::to_string(a + scene.index_base) + ", " +
             std::to_string(b + scene.index_base) + "] to length " + format("%g", scene.motion.target_length);
    m.result = engine::contractEdge(*scene.model, scene.model->startCoordinates(),
                                    engine::distanceEquation(scene.model->system(), a, b), scene.motion.target_length,
                                    copt, on_step);
    return m;
  }
  engine::TrackerOptions opt;
  opt.steps = steps;
  opt.step_size = scene.motion.step_size;
  opt.seed = scene.motion.seed;
  opt.factorization.rank_tolerance = scene.analysis.rank_tolerance;
  opt.corrector.factorization = opt.factorization;
  engine::Vector direction = engine::Vector::Zero(m.rep.variables);
  if (k > 0) direction = m.rep.flex_basis * Eigen::Map<const engine::Vector>(m.coefficients.data(), k);
  if (const auto* packing = dynamic_cast<const engine::SpherePacking*>(scene.model.get()); packing && k > 0)
    m.result = engine::trackStickyPacking(*packing, direction, opt, on_step);
  else
    m.result = engine::trackMotion(*scene.model, scene.model->startCoordinates(), direction, opt,
                                   k > 0 ? on_step : engine::StepCallback{});
  return m;
}

engine::Geometry geometryAt(engine::Geometry g, const std::vector<engine::TrackEvent>& events, int sample) {
  for (const auto& e : events)
    if (e.kind == "contact" && e.sample <= sample && e.vertices.size() == 2) g.bars.push_back({e.vertices[0], e.vertices[1]});
  return g;
}

std::vector<int> frameSamples(int sample_count, int step) {
  std::vector<int> out;
  step = std::max(1, step);
  for (int s = 0; s < sample_count; s += step) out.push_back(s);
  if (sample_count > 0 && out.back() != sample_count - 1) out.push_back(sample_count - 1);
  return out;
}

std::vector<int> fixedVertices(const Scene& scene) {
  if (scene.render.animation.fixed_vertices) return *scene.render.animation.fixed_vertices;
  const engine::Geometry g = scene.model->geometry();
  // Pins fix the picture; a surface or the unit sphere of caps is fixed in space, so moving the
  // configuration would take it off what is drawn with it.
  if (!g.pinned.empty() || g.points < 2 || g.surface || g.caps) return {};
  if (g.dimension == 2 || g.points < 3) return {0, 1};
  const engine::Matrix p = scene.model->system().vertexPositions(scene.model->startCoordinates());
  const Eigen::Vector3d a = p.col(0), b = p.col(1), c = p.col(2);
  const double scale = std::max({(b - a).norm(), (c - a).norm(), 1e-300});
  return (b - a).cross(c - a).norm() > 1e-6 * scale * scale ? std::vector<int>{0, 1, 2} : std::vector<int>{0, 1};
}

void alignConfigurations(std::vector<engine::Matrix>& frames, const std::vector<int>& fixed,
                         const std::vector<double>& direction) {
  if (fixed.size() < 2 || frames.empty()) return;
  const int d = static_cast<int>(frames[0].rows());
  if (d == 2) {
    const double target = direction.size() == 2 ? std::atan2(direction[1], direction[0]) : 0.0;
    double angle = 0;
    for (engine::Matrix& p : frames) {
      const Eigen::Vector2d a = p.col(fixed[0]), b = p.col(fixed[1]) - a;
      const double scale = extent(p);
      if (b.norm() > 1e-12 * scale) angle = target - std::atan2(b.y(), b.x());
      const Eigen::Matrix2d r = Eigen::Rotation2Dd(angle).toRotationMatrix();
      p = r * (p.colwise() - a);
    }
    return;
  }
  Eigen::Vector3d dir = Eigen::Vector3d::UnitX();
  if (direction.size() == 3) dir = Eigen::Vector3d(direction[0], direction[1], direction[2]).normalized();
  // The half-plane for the third vertex: e_y (or e_z when dir is along e_y) made orthogonal to dir.
  Eigen::Vector3d up = Eigen::Vector3d::UnitY() - dir.y() * dir;
  if (up.norm() < 1e-6) up = Eigen::Vector3d::UnitZ() - dir.z() * dir;
  up.normalize();
  Eigen::Matrix3d rot = Eigen::Matrix3d::Identity();
  for (engine::Matrix& p : frames) {
    const Eigen::Vector3d a = p.col(fixed[0]);
    const Eigen::Vector3d b = p.col(fixed[1]) - a;
    const double scale = extent(p);
    if (b.norm() > 1e-12 * scale) {
      Eigen::Matrix3d r = Eigen::Quaterniond::FromTwoVectors(b, dir).toRotationMatrix();
      if (fixed.size() >= 3) {
        const Eigen::Vector3d c = r * (p.col(fixed[2]) - a);
        const Eigen::Vector3d perp = c - c.dot(dir) * dir;
        if (perp.norm() > 1e-12 * scale) {
          const Eigen::Vector3d u = perp.normalized();
          const double angle = std::atan2(u.cross(up).dot(dir), u.dot(up));
          r = Eigen::AngleAxisd(angle, dir).toRotationMatrix() * r;
        } else {
          r = rot;  // collinear: keep the previous frame's rotation
        }
      }
      rot = r;
    }
    p = rot * (p.colwise() - a);
  }
}

std::vector<int> fixedSimplex(const Scene& scene) {
  const AnimationSettings& as = scene.render.animation;
  if (as.fixed_simplex) return *as.fixed_simplex;
  const engine::Geometry g = scene.model->geometry();
  if (g.simplices.empty() || !g.pinned.empty() || as.fixed_vertices) return {};
  return g.simplices.front();
}

void normalizeEquiAffine(std::vector<engine::Matrix>& frames, const std::vector<int>& simplex, double t,
                         double tip) {
  if (frames.empty() || static_cast<int>(simplex.size()) != frames[0].rows() + 1) return;
  const int d = static_cast<int>(frames[0].rows());
  for (engine::Matrix& p : frames) {
    engine::Matrix E(d, d);
    for (int k = 0; k < d; ++k) E.col(k) = p.col(simplex[static_cast<size_t>(k) + 1]) - p.col(simplex[0]);
    const double det = E.determinant();
    const double scale = std::pow(E.colwise().norm().prod(), 1.0 / d);
    if (!(std::abs(det) > 1e-12 * std::pow(scale, d))) continue;
    // The reference simplex: upper triangular, the given stretch and tips, det(R) = det(E).
    engine::Matrix R = engine::Matrix::Zero(d, d);
    for (int k = 0; k + 1 < d; ++k) R(k, k) = t;
    for (int i = 0; i < d; ++i)
      for (int j = i + 1; j < d; ++j) R(i, j) = tip;
    R(d - 1, d - 1) = det / std::pow(t, d - 1);
    const engine::Matrix M = R * E.inverse();  // det M = 1
    const engine::Vector a = p.col(simplex[0]);
    p = M * (p.colwise() - a);
  }
}

engine::Matrix randomProjection(int n, int k, std::uint64_t seed) {
  engine::Random rng(seed);
  engine::Matrix g(n, k);
  for (int j = 0; j < k; ++j)
    for (int i = 0; i < n; ++i) g(i, j) = rng.gaussian();
  Eigen::HouseholderQR<engine::Matrix> qr(g);
  engine::Matrix q = qr.householderQ() * engine::Matrix::Identity(n, k);
  // A sign convention so that Q does not depend on the QR implementation: R's diagonal > 0.
  const engine::Matrix r = qr.matrixQR().topRows(k).triangularView<Eigen::Upper>();
  for (int j = 0; j < k; ++j)
    if (r(j, j) < 0) q.col(j) = -q.col(j);
  return q;
}

std::vector<ProjectionPath> projectionPaths(const Scene& scene, const Motion& main, const engine::StepCallback& on_step) {
  const ProjectionSettings& ps = scene.projection;
  std::vector<std::vector<double>> flexes = ps.flexes;
  const bool use_main = flexes.empty();
  if (use_main) flexes.push_back(main.coefficients);
  std::vector<ProjectionPath> out;
  for (const auto& c : flexes) {
    Motion forward = use_main ? main : trackScene(scene, scene.motion.steps, on_step, &c);
    ProjectionPath path;
    path.label = "flex " + coefficientsText(forward.coefficients);
    const auto& fs = forward.result.samples;
    path.complete = forward.result.summary.status == engine::TrackStatus::Success;
    path.status = forward.result.summary.briefReport();
    if (forward.rep.nontrivial > 0)
      path.flex = (forward.rep.flex_basis *
                   Eigen::Map<const engine::Vector>(forward.coefficients.data(), forward.rep.nontrivial))
                      .normalized();
    if (ps.both_directions && forward.rep.nontrivial > 0) {
      std::vector<double> minus = forward.coefficients;
      for (double& x : minus) x = -x;
      const Motion backward = trackScene(scene, scene.motion.steps, on_step, &minus);
      const auto& bs = backward.result.samples;
      for (size_t i = bs.size(); i-- > 1;) {
        path.samples.push_back(bs[i]);
        path.sample_numbers.push_back(-static_cast<int>(i));
      }
      for (const auto& e : backward.result.events)
        if (e.kind == "singularity" && e.sample > 0) path.singular.push_back(static_cast<int>(bs.size()) - 1 - e.sample);
      path.complete = path.complete && backward.result.summary.status == engine::TrackStatus::Success;
      path.status += "; backwards: " + backward.result.summary.briefReport();
    }
    path.start = static_cast<int>(path.samples.size());
    for (size_t i = 0; i < fs.size(); ++i) {
      path.samples.push_back(fs[i]);
      path.sample_numbers.push_back(static_cast<int>(i));
    }
    for (const auto& e : forward.result.events)
      if (e.kind == "singularity") path.singular.push_back(path.start + e.sample);
    std::sort(path.singular.begin(), path.singular.end());
    path.singular.erase(std::unique(path.singular.begin(), path.singular.end()), path.singular.end());
    out.push_back(std::move(path));
  }
  return out;
}

Projection projectPaths(const Scene& scene, const std::vector<ProjectionPath>& paths, std::uint64_t seed) {
  Projection pr;
  pr.seed = seed;
  const int n = paths.empty() || paths[0].samples.empty() ? 0 : static_cast<int>(paths[0].samples[0].size());
  pr.q = randomProjection(std::max(n, 2), 2, seed).topRows(n);
  const ProjectionSettings& ps = scene.projection;
  static const std::vector<unsigned> palette = {0x4682B4, 0xCD0000, 0x00A000, 0xFF8C00, 0x800080,
                                                0x008080, 0x595959, 0xB8860B, 0xFF1493, 0x000080};
  for (size_t j = 0; j < paths.size(); ++j) {
    render::PlotSeries ser;
    for (const auto& x : paths[j].samples) {
      const engine::Vector y = pr.q.transpose() * x;
      ser.points.push_back({y[0], y[1]});
    }
    pr.curves.push_back(ser.points);
    pr.starts.push_back(paths[j].start);
    ser.color = !ps.colors.empty() ? ps.colors[j % ps.colors.size()]
                : paths.size() == 1 ? hex(0x595959)  // gray35, as in the reference
                                    : hex(palette[j % palette.size()]);
    ser.label = paths.size() > 1 ? paths[j].label : "";
    ser.marks = paths[j].singular;
    pr.plot.series.push_back(std::move(ser));
  }
  if (!pr.curves.empty() && !pr.curves[0].empty()) pr.plot.start = pr.curves[0][static_cast<size_t>(paths[0].start)];
  if (ps.flex_arrows && pr.plot.start) {
    double span = 0;
    for (const auto& c : pr.curves)
      for (const auto& p : c)
        span = std::max({span, std::abs(p[0] - (*pr.plot.start)[0]), std::abs(p[1] - (*pr.plot.start)[1])});
    if (!(span > 0)) span = 1;
    for (size_t j = 0; j < paths.size(); ++j) {
      if (paths[j].flex.size() != n) continue;
      const engine::Vector v = pr.q.transpose() * paths[j].flex;
      if (!(v.norm() > 1e-12)) continue;
      const engine::Vector tip = v / v.norm() * 0.35 * span;
      const render::Point2 from = pr.curves[j][static_cast<size_t>(paths[j].start)];
      pr.plot.arrows.push_back({from, {from[0] + tip[0], from[1] + tip[1]}, scene.render.style.flex_color});
    }
  }
  pr.plot.title = scene.title.empty() ? std::string("Deformation path") : scene.title;
  pr.plot.subtitle = "random orthonormal projection of the deformation path (seed " + std::to_string(seed) + ")";
  pr.plot.xlabel = "projection axis 1";
  pr.plot.ylabel = "projection axis 2";
  return pr;
}

std::string projectionCsv(const std::vector<ProjectionPath>& paths, const Projection& pr) {
  std::ostringstream o;
  o << "path,sample,p1,p2\n";
  char buf[96];
  for (size_t j = 0; j < paths.size(); ++j)
    for (size_t i = 0; i < pr.curves[j].size(); ++i) {
      std::snprintf(buf, sizeof buf, "%zu,%d,%.17g,%.17g\n", j + 1, paths[j].sample_numbers[i], pr.curves[j][i][0],
                    pr.curves[j][i][1]);
      o << buf;
    }
  return o.str();
}

render::PlotStyle projectionStyle(const Scene& scene, int width, int height) {
  render::PlotStyle st;
  st.width = width, st.height = height;
  st.background = scene.render.style.background;
  st.line_width = scene.projection.line_width;
  st.marker_size = scene.projection.marker_size;
  st.arrow_size = scene.render.style.arrow_size;
  return st;
}

// ---------------------------------------------------------------------------------------------

Animation::Animation(const Scene& scene, const Motion& motion, int width, int height, const Projection* projection)
    : scene_(scene), geometry_(scene.model->geometry()), width_(width), height_(height) {
  const auto& sys = scene.model->system();
  const AnimationSettings& as = scene.render.animation;
  const auto& samples = motion.result.samples;
  samples_ = frameSamples(static_cast<int>(samples.size()), as.frame_step);
  for (const auto& x : samples) positions_.push_back(sys.vertexPositions(x));
  if (const std::vector<int> simplex = fixedSimplex(scene); !simplex.empty())
    normalizeEquiAffine(positions_, simplex, as.target_stretch, as.tip_value);
  else
    alignConfigurations(positions_, fixedVertices(scene), as.fixed_direction);
  const bool side = as.side_by_side && projection;
  panel_width_ = side ? width / 2 : width;
  style_ = scene.render.style;
  style_.width = panel_width_;
  style_.height = height;
  if (style_.ghost >= 0 && style_.ghost < static_cast<int>(positions_.size())) ghost_ = positions_[style_.ghost];
  view_ = fitView(geometry_, positions_, style_);
  view_.turntable = as.rotate && view_.three_d;
  surface_ = surfaceMesh(geometry_, view_, style_);
  events_ = motion.result.events;
  if (side) {
    plot_.emplace(projection->plot, projectionStyle(scene, width - panel_width_, height));
    if (!projection->curves.empty())
      cursor_path_.assign(projection->curves[0].begin() + projection->starts[0], projection->curves[0].end());
  }
}

render::DrawList Animation::figureAt(int k, const FigureStyle& style, bool flex) const {
  const AnimationSettings& as = scene_.render.animation;
  const auto at = [&](int j) -> const engine::Matrix& { return positions_[static_cast<size_t>(j)]; };
  FigureExtras extras;
  if (style.trace)
    for (int j = 0; j <= k; ++j) extras.trace.push_back(at(j));
  extras.ghost = ghost_;
  extras.surface = &surface_;
  const int last = static_cast<int>(positions_.size()) - 1;
  if (flex && last > 0) {
    // The velocity of the picture: a central difference of the aligned positions (one-sided at
    // the ends); figure() scales the longest arrow to flex_scale of the extent.
    const int a = std::max(0, k - 1), b = std::min(last, k + 1);
    extras.flex = at(b) - at(a);
    if (extras.flex.norm() == 0) extras.flex.resize(0, 0);
  }
  render::DrawList list = figure(geometryAt(geometry_, events_, k), at(k), style, extras);
  if (as.mark_events) {
    // A caption for half a second after each singular point or new contact.
    const int hold = std::max(1, scene_.render.fps / 2) * std::max(1, as.frame_step);
    for (auto it = events_.rbegin(); it != events_.rend(); ++it)
      if (k >= it->sample && k < it->sample + hold) {
        render::Label l;
        const double px = std::min(panel_width_, height_) / 1000.0;
        l.screen = true;
        l.at = {30 * px, 45 * px, 0};
        l.align = -1;
        l.size = static_cast<float>(style.font_size * px);
        l.color = render::Color{0xCD / 255.f, 0, 0, 1};
        l.text = (it->kind == "contact" ? it->detail : "singular point") + " (sample " + std::to_string(it->sample) + ")";
        list.labels.push_back(l);
        break;
      }
  }
  return list;
}

void Animation::sample(int k, const FrameOptions& o, render::Renderer& renderer, render::Image& out) const {
  k = std::clamp(k, 0, static_cast<int>(positions_.size()) - 1);
  FigureStyle style = style_;
  if (o.labels) style.labels = *o.labels;
  if (o.trace) style.trace = *o.trace;
  render::View view = view_;
  view.turntable = false;
  if (o.azimuth) view.azimuth = *o.azimuth;
  if (o.elevation) view.elevation = *o.elevation;
  view.zoom = o.zoom;
  renderer.render(figureAt(k, style, o.flex), view, out);
}

void Animation::frame(int i, render::Renderer& renderer, render::Image& out) const {
  const AnimationSettings& as = scene_.render.animation;
  const int k = samples_[static_cast<size_t>(i)];
  render::DrawList list = figureAt(k, style_, false);
  render::View view = view_;
  if (as.rotate && view.three_d) view.azimuth = style_.azimuth + 2 * M_PI * i / as.rotation_frames;
  if (!plot_) {
    renderer.render(list, view, out);
    return;
  }
  renderer.render(list, view, left_);
  std::optional<render::Point2> cursor;
  if (static_cast<size_t>(k) < cursor_path_.size()) cursor = cursor_path_[static_cast<size_t>(k)];
  renderer.render(plot_->draw(cursor), plot_->view(), right_);
  out.width = width_, out.height = height_;
  out.rgba.resize(static_cast<size_t>(width_) * height_ * 4);
  for (int y = 0; y < height_; ++y) {
    std::copy_n(left_.pixel(0, y), static_cast<size_t>(left_.width) * 4, &out.rgba[static_cast<size_t>(y) * width_ * 4]);
    std::copy_n(right_.pixel(0, y), static_cast<size_t>(right_.width) * 4,
                &out.rgba[(static_cast<size_t>(y) * width_ + left_.width) * 4]);
  }
}

// ---------------------------------------------------------------------------------------------

namespace {

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

Written writeFrame(const Scene& scene, const Motion* motion, int sample, bool flex, const std::string& file,
                   render::Renderer& renderer) {
  const auto t0 = Clock::now();
  FigureStyle style = scene.render.style;
  style.width = scene.render.width;
  style.height = scene.render.height;
  const engine::Model& model = *scene.model;
  const engine::ConstraintSystem& sys = model.system();
  std::vector<engine::Vector> start{model.startCoordinates()};
  const std::vector<engine::Vector>& samples = motion ? motion->result.samples : start;
  const int shown = std::clamp(sample, 0, static_cast<int>(samples.size()) - 1);
  const engine::Matrix positions = sys.vertexPositions(samples[static_cast<size_t>(shown)]);
  FigureExtras extras;
  std::string note;
  if (flex) {
    // The selected flex at the configuration shown: the scene's coefficients in its
    // nontrivial-flex basis (or its auto flex when their number does not fit there).
    engine::RigidityOptions ro = rigidityOptions(scene);
    ro.motion_check_steps = 0;  // only the flexes are drawn
    // A sticky packing's flexes at a later sample respect the contacts made up to there.
    const engine::Model* analysed = &model;
    engine::Vector x = samples[static_cast<size_t>(shown)];
    std::unique_ptr<engine::SpherePacking> stuck;
    if (const auto* packing = dynamic_cast<const engine::SpherePacking*>(&model); packing && motion) {
      const engine::Geometry now = geometryAt(model.geometry(), motion->result.events, shown);
      stuck = std::make_unique<engine::SpherePacking>(sys.positions(x), packing->radii(), packing->pinned(),
                                                      packing->tolerance(), packing->indexBase(), now.bars);
      analysed = stuck.get();
      x = stuck->startCoordinates();
    }
    const engine::RigidityReport rep = engine::analyzeRigidity(*analysed, x, ro);
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
  const engine::Geometry geometry =
      motion ? geometryAt(model.geometry(), motion->result.events, shown) : model.geometry();
  std::vector<engine::Matrix> frames{positions};
  if (extras.ghost) frames.push_back(*extras.ghost);
  if (extras.flex.size() > 0) frames.push_back(flexTips(positions, extras.flex, style));
  for (const auto& t : extras.trace) frames.push_back(t);
  const render::View view = fitView(geometry, frames, style);
  const std::vector<render::Polygon> surface = surfaceMesh(geometry, view, style);
  extras.surface = &surface;
  const render::Image image = renderer.render(figure(geometry, positions, style, extras), view);
  writePng(file, image);
  Written w;
  w.file = file;
  w.seconds = secondsSince(t0);
  w.summary = std::to_string(image.width) + "x" + std::to_string(image.height) + ", sample " + std::to_string(shown) + note;
  return w;
}

Written writeAnimation(const Scene& scene, const Motion& motion, const std::string& file, render::Renderer& renderer,
                       const std::vector<ProjectionPath>* paths, std::uint64_t projection_seed,
                       const render::FrameProgress& progress) {
  const std::string ext = extensionOf(file);
  const bool gif = ext == "gif";
  const bool side = scene.render.animation.side_by_side && paths && !paths->empty();
  const auto [w, h] = videoSize(scene, gif, side);
  TemporaryOutput out(file);
  std::optional<Projection> projection;
  if (side) projection = projectPaths(scene, *paths, projection_seed);
  const Animation anim(scene, motion, w, h, projection ? &*projection : nullptr);
  const render::VideoOptions opt = videoOptions(scene, gif, w, h);
  Written wr;
  wr.file = file;
  wr.video = encodeVideo(out, file, opt, anim.frameCount(),
                         [&](int i, render::Image& image) { anim.frame(i, renderer, image); }, progress);
  wr.seconds = wr.video.wall_seconds;
  wr.summary = videoSummary(wr.video, w, h, opt.fps);
  return wr;
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
    const render::PlotCanvas canvas(pr.plot, projectionStyle(scene, scene.render.width, scene.render.height));
    writePng(file, renderer.render(canvas.draw(), canvas.view()));
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

Written writePath(const Scene& scene, const Motion& motion, const std::string& file) {
  const auto t0 = Clock::now();
  const bool csv = extensionOf(file) == "csv";
  writeFileAtomically(file, csv ? pathCsv(scene, motion.result)
                                : pathJson(scene, motion.result, motion.coefficients, motion.note).dump(1) + "\n");
  Written w;
  w.file = file;
  w.seconds = secondsSince(t0);
  w.summary = std::to_string(motion.result.samples.size()) + " samples";
  return w;
}

}  // namespace flexure::scenes
