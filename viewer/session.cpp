#include "viewer/session.h"

#include <sys/stat.h>
#include <ctime>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include <Eigen/LU>

#include "render/image.h"
#include "render/plot.h"
#include "render/renderer.h"
#include "engine/drag.h"
#include "engine/factorization.h"
#include "engine/flex_space.h"
#include "present/output_file.h"
#include "present/path_output.h"
#include "present/report.h"
#include "present/text.h"
#include "render/camera.h"
#include "scenes/scene_edit.h"

namespace flexure::viewer {

struct Computed {
  std::uint64_t generation = 0;
  std::string text;                    // the scene file's text
  std::vector<std::string> overrides;  // --set, then the controls
  scenes::Scene scene;
  pipeline::Motion motion;
  nlohmann::ordered_json report;
  std::string report_text;
  std::vector<present::ProjectionPath> paths;
  present::Projection projection;
  double seconds = 0;
  // The tangent cone at the path's singular points (engine::tangentCone; see branchPoints).
  struct BranchPoint {
    int sample = 0;
    std::string event;
    engine::TangentCone cone;
    std::vector<std::string> kinds;  // per direction: "path" (the path goes on so), "back", "other"
  };
  std::vector<BranchPoint> branches;
  // Nontrivial flexes at a regular point of the path (a drag finds singular points by more).
  int regular_flexes = -1;
  std::string branch_note;            // the path left a singular point along a chosen branch
  // Only the render thread touches these: the views at the last size asked for.
  // The animation (camera, aligned samples) at the last frame size: made by whichever thread
  // needs it first (render thread, drags, the state's screen positions), then only read.
  mutable std::mutex animation_mutex;
  mutable std::shared_ptr<const present::Animation> animation;
  mutable std::unique_ptr<render::PlotCanvas> canvas;
  mutable int canvas_width = 0, canvas_height = 0;
  mutable render::Image image;
};

struct Session::Dragged {
  std::uint64_t generation = 0;
  int sample = 0;  // the sample the drag started from: its model and display map
  present::DisplayMap map;
  engine::DragResult result;  // result.x: the dragged configuration
  int vertex = 0;  // 0-based
  double target_px[2] = {0, 0};
  double remaining_px = 0;  // from the vertex to the pointer, in the frame's pixels
  double milliseconds = 0;
};

// The configuration of the current frame and where its vertices are on screen.
struct Session::Shown {
  int sample = 0;
  bool dragged = false;
  engine::Matrix vertices;  // d x n, the model's coordinates
  engine::Matrix screen;    // 2 x n, pixels from the top left
  double residual = 0;
};

namespace {

using Clock = std::chrono::steady_clock;

// A vertex this close to the pointer is shown as following it: what holds it back is drawn
// only beyond (the pointer is rarely exactly on the vertex's curve).
constexpr double kHeldPixels = 1.5;

// The animation for frames of this size (any thread: its const methods only read).
std::shared_ptr<const present::Animation> animationFor(const Computed& c, int width, int height) {
  std::lock_guard<std::mutex> lock(c.animation_mutex);
  if (!c.animation || c.animation->width() != width || c.animation->height() != height)
    c.animation = std::make_shared<const present::Animation>(c.scene, c.motion.path, width, height);
  return c.animation;
}

// The tangent cones at the path's singular points (at most 10; systems of at most 400 free
// coordinates, whose dense SVD takes tens of milliseconds: the page waits for them).
std::vector<Computed::BranchPoint> branchPoints(const engine::DeformationPath& path, std::uint64_t seed) {
  std::vector<Computed::BranchPoint> out;
  const int last = static_cast<int>(path.samples.size()) - 1;
  for (const engine::TrackEvent& e : path.events) {
    if (e.kind != engine::EventKind::Singularity || out.size() >= 10) continue;
    if (!out.empty() && out.back().sample == e.sample) continue;
    const engine::Model& model = path.modelAt(e.sample);
    if (model.tracking() != engine::Model::Tracking::Smooth) continue;
    Computed::BranchPoint b;
    b.sample = e.sample;
    b.event = e.detail;
    engine::TangentConeOptions o;
    o.seed = seed;
    o.dense_limit = 400;
    const engine::Vector& x = path.samples[static_cast<size_t>(e.sample)];
    b.cone = engine::tangentCone(model, x, o);
    for (const engine::Vector& landing : b.cone.landings) {
      const engine::Vector d = (landing - x).normalized();
      const auto towards = [&](int k) {  // the cosine with the secant to sample k
        if (k < 0 || k > last || k == e.sample) return -1.0;
        const engine::Vector s = path.samples[static_cast<size_t>(k)] - x;
        return s.norm() > 0 ? d.dot(s) / s.norm() : -1.0;
      };
      const double next = towards(e.sample + 1), previous = towards(e.sample - 1);
      b.kinds.push_back(std::max(next, previous) < 0.9 ? "other" : next >= previous ? "path" : "back");
    }
    out.push_back(std::move(b));
  }
  return out;
}

// The nontrivial flexes at a sample of the path away from its singular points (the middle
// one's neighbourhood), small systems only; else the start's count.
int regularFlexes(const pipeline::Motion& m) {
  const engine::DeformationPath& path = m.path;
  const int n = static_cast<int>(path.samples.size());
  if (n < 3 || path.modelAt(0).system().numVariables() > 1200) return m.rep.nontrivial;
  std::vector<int> singular = path.singularSamples();
  for (int k = n / 2; k < n; ++k)
    if (std::none_of(singular.begin(), singular.end(), [&](int s) { return std::abs(s - k) <= 1; })) {
      // The kernel's dimension less the trivial flexes (not a whole analysis: no second order).
      const engine::Model& model = path.modelAt(k);
      const engine::Vector& x = path.samples[static_cast<size_t>(k)];
      const engine::JacobianFactorization F(model.system().jacobian(x), engine::FactorizationOptions{});
      return model.system().numVariables() - F.rank() - static_cast<int>(engine::trivialFlexes(model, x, 1e-8).cols());
    }
  return m.rep.nontrivial;
}

// The columns of a d x n matrix as rows of numbers (a scene's vertices).
std::vector<std::vector<double>> rows(const engine::Matrix& p) {
  std::vector<std::vector<double>> out(static_cast<size_t>(p.cols()));
  for (int i = 0; i < p.cols(); ++i) out[static_cast<size_t>(i)].assign(p.col(i).data(), p.col(i).data() + p.rows());
  return out;
}

// JSON rows of a d x n matrix, one array per column.
nlohmann::json columns(const engine::Matrix& m) {
  nlohmann::json a = nlohmann::json::array();
  for (int i = 0; i < m.cols(); ++i) {
    nlohmann::json c = nlohmann::json::array();
    for (int k = 0; k < m.rows(); ++k) c.push_back(m(k, i));
    a.push_back(std::move(c));
  }
  return a;
}

// The text of line `line` (1-based) of `text`, without its newline.
std::string lineOf(const std::string& text, int line) {
  size_t at = 0;
  for (int i = 1; i < line; ++i) {
    at = text.find('\n', at);
    if (at == std::string::npos) return "";
    ++at;
  }
  const size_t end = text.find('\n', at);
  std::string s = text.substr(at, end == std::string::npos ? std::string::npos : end - at);
  if (!s.empty() && s.back() == '\r') s.pop_back();
  if (s.size() > 400) {
    size_t cut = 400;  // not inside a UTF-8 character
    while (cut > 0 && (static_cast<unsigned char>(s[cut]) & 0xC0) == 0x80) --cut;
    s = s.substr(0, cut) + "...";
  }
  return s;
}

// A plain file name: letters, digits, '.', '_', '-'; not hidden; ends in .toml.
bool plainTomlName(const std::string& name) {
  if (name.size() < 6 || name.size() > 128 || name[0] == '.' || name[0] == '-') return false;
  if (name.compare(name.size() - 5, 5, ".toml") != 0 || name.find("..") != std::string::npos) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' || c == '_' ||
           c == '-';
  });
}

template <class T>
nlohmann::json optionalJson(const std::optional<T>& v) {
  return v ? nlohmann::json(*v) : nlohmann::json();
}

}  // namespace

std::vector<std::string> MotionControls::assignments() const {
  std::vector<std::string> a;
  if (flex) {
    if (flex->empty()) {
      a.push_back("motion.flex=\"auto\"");
    } else {
      std::string s = "motion.flex=[";
      for (size_t i = 0; i < flex->size(); ++i) s += (i ? ", " : "") + scenes::tomlNumber((*flex)[i]);
      a.push_back(s + "]");
    }
  }
  if (step_size) a.push_back("motion.step_size=" + scenes::tomlNumber(*step_size));
  if (steps) a.push_back("motion.steps=" + std::to_string(*steps));
  if (seed) a.push_back("motion.seed=" + std::to_string(*seed));
  if (vertices) {
    std::string v = "system.vertices=[";
    for (size_t i = 0; i < vertices->size(); ++i) {
      v += i ? ", [" : "[";
      for (size_t k = 0; k < (*vertices)[i].size(); ++k) v += (k ? ", " : "") + scenes::tomlNumber((*vertices)[i][k]);
      v += "]";
    }
    a.push_back(v + "]");
  }
  return a;
}

Session::Session(std::string scene_path, SessionOptions options)
    : path_(std::move(scene_path)), catalog_(scenes::catalogArgument(path_)), options_(std::move(options)) {
  if (!catalog_) (void)scenes::readSceneFile(path_);  // an unreadable file is an error at once
  compute_thread_ = std::thread([this] { computeLoop(); });
  render_thread_ = std::thread([this] { renderLoop(); });
  checkFile();
}

Session::~Session() {
  {
    // Both threads read stopping_ under their own mutex.
    std::lock_guard<std::mutex> lock(mutex_);
    std::lock_guard<std::mutex> render_lock(render_mutex_);
    stopping_ = true;
    cancel_below_ = ~std::uint64_t{0};
  }
  changed_.notify_all();
  render_cv_.notify_all();
  compute_thread_.join();
  render_thread_.join();
}

bool Session::checkFile() {
  if (catalog_) {  // the entry's text, once; save as writes an editable copy
    std::lock_guard<std::mutex> lock(mutex_);
    if (next_job_ > 1) return false;
    text_ = catalog_->text;
    submitLocked();
    return true;
  }
  struct stat st {};
  if (::stat(path_.c_str(), &st) != 0) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (read_error_.empty()) {
      read_error_ = "cannot read " + path_ + " (it was moved or deleted); waiting for it to come back";
      mtime_ns_ = size_ = -1;
      ++revision_;
      changed_.notify_all();
    }
    return false;
  }
  const long long mtime = static_cast<long long>(st.st_mtim.tv_sec) * 1000000000LL + st.st_mtim.tv_nsec;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (mtime == mtime_ns_ && static_cast<long long>(st.st_size) == size_) return false;
  }
  // A save that truncates the file and then writes it (Python's open(..., "w"), many editors)
  // shows an empty file for a moment: an empty file younger than half a second is waited for,
  // not reported as a scene without a [system] table.
  if (st.st_size == 0) {
    timespec now{};
    ::clock_gettime(CLOCK_REALTIME, &now);
    const long long now_ns = static_cast<long long>(now.tv_sec) * 1000000000LL + now.tv_nsec;
    if (now_ns - mtime < 500000000LL) return false;
  }
  std::string text, read_error;
  try {
    text = scenes::sceneTextOfFile(path_, scenes::readSceneFile(path_));  // a mesh, graph or path JSON too
  } catch (const std::exception& e) {  // SceneError; ResourceError for a file too large to parse
    read_error = e.what();
  }
  // Written to while it was read: the next check reads it again.
  struct stat after {};
  if (::stat(path_.c_str(), &after) == 0 &&
      (after.st_size != st.st_size || after.st_mtim.tv_sec != st.st_mtim.tv_sec ||
       after.st_mtim.tv_nsec != st.st_mtim.tv_nsec))
    return false;
  std::lock_guard<std::mutex> lock(mutex_);
  mtime_ns_ = mtime, size_ = static_cast<long long>(st.st_size);
  if (!read_error.empty()) {
    read_error_ = read_error;
    ++revision_;
    changed_.notify_all();
    return false;
  }
  if (!read_error_.empty()) {
    read_error_.clear();
    ++revision_;
    changed_.notify_all();
  }
  if (text == text_ && next_job_ > 1) return false;
  text_ = text;
  submitLocked();
  return true;
}

std::vector<std::string> Session::overrides() const {
  std::vector<std::string> o = options_.overrides;
  for (auto& a : controls_.assignments()) o.push_back(std::move(a));
  return o;
}

void Session::setControls(const MotionControls& c) {
  if (c.steps && (*c.steps < 0 || *c.steps > options_.max_steps))
    throw std::invalid_argument("steps must be between 0 and " + std::to_string(options_.max_steps));
  if (c.step_size && !(std::isfinite(*c.step_size) && *c.step_size > 0))
    throw std::invalid_argument("step size must be a positive number");
  if (c.flex)
    for (double x : *c.flex)
      if (!std::isfinite(x)) throw std::invalid_argument("flex coefficients must be finite numbers");
  std::lock_guard<std::mutex> lock(mutex_);
  if (c.flex && !c.flex->empty() && computed_ && computed_->motion.rep.nontrivial != static_cast<int>(c.flex->size()))
    throw std::invalid_argument("flex needs " + std::to_string(computed_->motion.rep.nontrivial) +
                                " coefficient(s), one per nontrivial infinitesimal flex");
  MotionControls old = controls_;
  controls_ = c;
  if (!controls_.vertices) controls_.vertices = old.vertices;  // the motion form keeps a dragged start
  const std::vector<std::string> o = overrides();
  try {
    (void)scenes::loadSceneFromString(jobText(), path_, o);  // the scene's own checks (fast: no tracking)
  } catch (const scenes::SceneError& e) {
    controls_ = old;
    throw std::invalid_argument(e.message);
  }
  submitLocked();
}

void Session::resetControls() {
  std::lock_guard<std::mutex> lock(mutex_);
  controls_ = {};
  submitLocked();
}

void Session::computeLoop() {
  for (;;) {
    Job job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      changed_.wait(lock, [&] { return stopping_ || pending_; });
      if (stopping_) return;
      job = std::move(*pending_);
      pending_.reset();
      computing_ = true;
      ++revision_;
    }
    const auto t0 = Clock::now();
    const auto keep_going = [&](int, int) { return job.id >= cancel_below_.load(); };
    std::shared_ptr<Computed> c;
    std::optional<scenes::SceneError> error;
    std::string failure;
    try {
      c = std::make_shared<Computed>();
      c->generation = job.id;
      c->text = job.text;
      c->overrides = job.overrides;
      c->scene = scenes::loadSceneFromString(job.text, path_, job.overrides);
      const scenes::Scene& scene = c->scene;
      pipeline::StudyOptions so;
      so.progress = [&](pipeline::Stage, int d, int t) { return keep_going(d, t); };
      so.branch = job.branch;
      pipeline::Study study(scene, so);
      c->motion = study.motion();
      if (job.branch) c->branch_note = job.branch->note;
      c->branches = branchPoints(c->motion.path, scene.motion.seed);
      c->regular_flexes = regularFlexes(c->motion);
      c->report = present::analysisJson(scene, study.analysis());
      // The state goes to the page on every change and drag: bases of a large system (megabytes
      // for 1,000 vertices) stay out of it.
      for (auto& [key, value] : c->report.items())
        if (value.is_structured()) {
          const size_t bytes = value.dump().size();
          if (bytes > 16384)
            value = "omitted from the viewer's state (" + std::to_string(bytes / 1024) + " KB): flexure analyze --json";
        }
      c->report_text = present::analysisText(scene, study.analysis());
      c->paths = study.projectionPaths();
      c->projection = study.projection();
      c->seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    } catch (const scenes::SceneError& e) {
      error = e;
    } catch (const std::exception& e) {
      failure = e.what();
    }
    const std::string line =
        error              ? std::string(error->what())
        : !failure.empty() ? path_ + ": " + failure
                           : path_ + ": " + std::to_string(c->motion.path.samples.size()) + " samples; " +
                                 c->motion.path.summary.briefReport() + " (" +
                                 std::to_string(static_cast<int>(1e3 * c->seconds)) + " ms)";
    std::unique_lock<std::mutex> lock(mutex_);
    computing_ = false;
    ++revision_;
    if (job.id < cancel_below_.load()) {  // a newer job replaced this one
      changed_.notify_all();
      continue;
    }
    if (error) {
      error_ = error;
      error_line_ = error->file == path_ ? lineOf(job.text, error->line) : "";
      failure_.clear();
    } else if (!failure.empty()) {
      error_.reset();
      failure_ = failure;
    } else {
      error_.reset();
      failure_.clear();
      computed_ = std::move(c);
      dragged_.reset();
      view_.dragged = false;
    }
    changed_.notify_all();
    lock.unlock();
    if (options_.log) options_.log(line);  // not under the lock: stderr may block
  }
}

bool Session::waitIdle(double seconds) const {
  std::unique_lock<std::mutex> lock(mutex_);
  return changed_.wait_for(lock, std::chrono::duration<double>(seconds), [&] { return !pending_ && !computing_; });
}

std::uint64_t Session::revision() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return revision_;
}

std::shared_ptr<const Computed> Session::current() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return computed_;
}

Session::Shown Session::shown(const Computed& c, const FrameRequest& v, const std::optional<Dragged>& dragged) const {
  Shown out;
  {
    const auto animation = animationFor(c, v.width, v.height);
    const present::Animation& a = *animation;
    const engine::DeformationPath& path = c.motion.path;
    out.dragged = v.dragged && dragged;
    out.sample = out.dragged ? dragged->sample : std::clamp(v.sample, 0, static_cast<int>(path.samples.size()) - 1);
    const engine::Model& model = path.modelAt(out.sample);
    const engine::Vector& x = out.dragged ? dragged->result.x : path.samples[static_cast<size_t>(out.sample)];
    out.vertices = model.system().vertexPositions(x);
    const engine::Matrix drawn = out.dragged ? dragged->map.apply(out.vertices) : a.shownPositions(out.sample);
    const render::Projector projector(a.viewFor(v.options));
    out.screen.resize(2, drawn.cols());
    for (int i = 0; i < drawn.cols(); ++i) {
      render::Point3 p{drawn(0, i), drawn(1, i), drawn.rows() > 2 ? drawn(2, i) : 0.0};
      const auto q = projector(p);
      out.screen(0, i) = q[0];
      out.screen(1, i) = v.height - q[1];
    }
    out.residual = model.system().numEquations() > 0 ? model.system().residuals(x).lpNorm<Eigen::Infinity>() : 0.0;
  }
  return out;
}

void Session::snapshot(std::shared_ptr<const Computed>& c, FrameRequest& view, std::optional<Dragged>& dragged,
                       bool shown_only) const {
  std::lock_guard<std::mutex> lock(mutex_);
  c = computed_;
  view = view_;
  if (dragged_ && (view.dragged || !shown_only)) dragged = *dragged_;
}

nlohmann::ordered_json Session::state() const {
  std::shared_ptr<const Computed> c0;
  FrameRequest v;
  std::optional<Dragged> dragged;
  snapshot(c0, v, dragged, false);
  std::optional<Shown> frame;
  if (c0) frame = shown(*c0, v, dragged);
  std::lock_guard<std::mutex> lock(mutex_);
  nlohmann::ordered_json j;
  j["revision"] = revision_;
  j["scene"] = path_;
  j["computing"] = computing_ || pending_.has_value();
  if (error_)
    j["error"] = {{"file", error_->file}, {"line", error_->line}, {"column", error_->column},
                  {"message", error_->message}, {"text", std::string(error_->what())}, {"line_text", error_line_}};
  else if (!failure_.empty())
    j["error"] = {{"file", path_}, {"line", 0}, {"column", 0}, {"message", failure_}, {"text", failure_},
                  {"line_text", ""}};
  else
    j["error"] = nullptr;
  j["read_error"] = read_error_.empty() ? nlohmann::json() : nlohmann::json(read_error_);
  nlohmann::ordered_json controls;
  if (controls_.flex) controls["flex"] = controls_.flex->empty() ? nlohmann::json("auto") : nlohmann::json(*controls_.flex);
  else controls["flex"] = nullptr;
  controls["step_size"] = optionalJson(controls_.step_size);
  controls["steps"] = optionalJson(controls_.steps);
  controls["seed"] = optionalJson(controls_.seed);
  j["controls"] = controls;
  j["max_steps"] = options_.max_steps;
  if (!computed_) {
    j["loaded"] = nullptr;
    return j;
  }
  const Computed& c = *computed_;
  const scenes::Scene& s = c.scene;
  const engine::DeformationPath& r = c.motion.path;
  nlohmann::ordered_json l;
  l["generation"] = c.generation;
  l["title"] = s.title;
  l["type"] = s.type;
  l["dimension"] = s.model->system().dimension();
  l["three_d"] = s.model->system().dimension() == 3;
  l["samples"] = r.samples.size();
  l["steps_requested"] = r.summary.steps_requested;
  l["complete"] = r.summary.status == engine::TrackStatus::Success;
  l["status"] = r.summary.briefReport();
  l["nontrivial"] = c.motion.rep.nontrivial;
  l["motion"] = {{"flex", r.flex}, {"flex_note", r.flex_choice}, {"step_size", s.motion.step_size},
                 {"steps", s.motion.steps}, {"seed", s.motion.seed}};
  nlohmann::ordered_json events = nlohmann::json::array();
  for (const auto& e : r.events) events.push_back({{"sample", e.sample}, {"kind", engine::toString(e.kind)}, {"detail", e.detail}});
  l["events"] = events;
  l["fps"] = s.render.fps;
  l["azimuth"] = s.render.style.azimuth;
  l["elevation"] = s.render.style.elevation;
  l["aspect"] = static_cast<double>(s.render.width) / s.render.height;
  l["projection_seed"] = c.projection.seed;
  l["seconds"] = c.seconds;
  l["report_text"] = c.report_text;
  l["report"] = c.report;
  l["index_base"] = s.index_base;
  l["labels"] = s.render.style.labels;
  l["pinned"] = nlohmann::json::array();
  for (int i = 0; i < s.model->system().numVertices(); ++i)
    if (s.model->system().isPinned(i)) l["pinned"].push_back(i + s.index_base);
  l["branch_note"] = c.branch_note;
  nlohmann::ordered_json branches = nlohmann::json::array();
  for (const auto& b : c.branches) {
    nlohmann::ordered_json dirs = nlohmann::json::array();
    for (size_t i = 0; i < b.cone.directions.size(); ++i) dirs.push_back({{"index", i}, {"kind", b.kinds[i]}});
    branches.push_back({{"sample", b.sample}, {"event", b.event}, {"flexes", b.cone.kernel_dimension},
                        {"stresses", b.cone.stresses}, {"computed", b.cone.computed}, {"note", b.cone.note},
                        {"directions", dirs}});
  }
  l["branches"] = branches;
  j["loaded"] = l;
  // The current frame, when the scene loaded and it is of the state shown.
  if (frame && c0 == computed_) {
    j["view"] = {{"sample", frame->sample}, {"dragged", frame->dragged}, {"width", v.width}, {"height", v.height}};
    j["vertices"] = columns(frame->vertices);
    j["screen"] = columns(frame->screen);
    j["residual"] = frame->residual;
  }
  if (dragged_ && dragged_->generation == c.generation) {
    const Dragged& d = *dragged_;
    nlohmann::ordered_json held = nlohmann::json::array();
    const engine::ConstraintSystem& sys = c.motion.path.modelAt(d.sample).system();
    for (const auto& h : d.result.held) {
      nlohmann::json vs = nlohmann::json::array();
      for (int i : h.vertices) vs.push_back(i + s.index_base);
      held.push_back({{"constraint", sys.equationLabel(h.equation, s.index_base)}, {"weight", h.weight}, {"vertices", vs}});
    }
    j["drag"] = {{"vertex", d.vertex + s.index_base}, {"to", {d.target_px[0], d.target_px[1]}},
                 {"reached", d.result.reached}, {"stop", d.result.stop}, {"moves", d.result.moves},
                 {"branch_choices", d.result.branch_choices}, {"remaining", d.result.remaining},
                 {"remaining_px", d.remaining_px},
                 {"residual", d.result.residual}, {"held", held}, {"milliseconds", d.milliseconds}};
  } else {
    j["drag"] = nullptr;
  }
  return j;
}

nlohmann::ordered_json Session::drag(int vertex, double px, double py, std::uint64_t seq) {
  std::lock_guard<std::mutex> one_at_a_time(drag_mutex_);
  // Answered when this returns or throws: a frame waiting for it goes on.
  struct Answered {
    Session& s;
    std::uint64_t seq;
    ~Answered() {
      if (!seq) return;
      {
        std::lock_guard<std::mutex> lock(s.mutex_);
        s.drag_seq_ = std::max(s.drag_seq_, seq);
      }
      s.changed_.notify_all();
    }
  } answered{*this, seq};
  const auto t0 = Clock::now();
  std::shared_ptr<const Computed> c;
  FrameRequest v;
  std::optional<Dragged> from;
  snapshot(c, v, from, true);
  if (!c) throw std::invalid_argument("nothing to drag: the scene has not loaded");
  if (!std::isfinite(px) || !std::isfinite(py)) throw std::invalid_argument("the target must be finite pixels");
  Dragged next;
  {
    const auto animation = animationFor(*c, v.width, v.height);
    const present::Animation& a = *animation;
    const engine::DeformationPath& path = c->motion.path;
    const int k = from ? from->sample : std::clamp(v.sample, 0, static_cast<int>(path.samples.size()) - 1);
    const engine::Model& model = path.modelAt(k);
    const engine::ConstraintSystem& sys = model.system();
    const int base = c->scene.index_base, i = vertex - base;
    if (i < 0 || i >= sys.numVertices())
      throw std::invalid_argument("vertex " + std::to_string(vertex) + " does not exist (" + std::to_string(base) +
                                  ".." + std::to_string(sys.numVertices() - 1 + base) + ")");
    if (sys.isPinned(i)) throw std::invalid_argument("vertex " + std::to_string(vertex) + " is pinned");
    const engine::Vector& x = from ? from->result.x : path.samples[static_cast<size_t>(k)];
    const present::DisplayMap map = from ? from->map : a.displayMap(k);
    const engine::Matrix drawn = map.apply(sys.vertexPositions(x));
    const int d = sys.dimension();
    const render::Projector projector(a.viewFor(v.options));
    const render::Point3 through{drawn(0, i), drawn(1, i), d > 2 ? drawn(2, i) : 0.0};
    const render::Point3 w = projector.unproject(px, v.height - py, through);
    engine::Vector target(d);
    for (int r = 0; r < d; ++r) target[r] = w[static_cast<size_t>(r)] - map.b[r];
    target = map.A.fullPivLu().solve(target);
    engine::DragOptions o;
    // A quarter pixel, in the model's units.
    o.tolerance = 0.25 / projector.pixelsPerUnitAt(through) / std::max(map.A.norm() / std::sqrt(double(d)), 1e-300);
    o.regular_flexes = c->regular_flexes;
    // An answer in time for the next pointer move (the page asks again from where it stopped):
    // a move of a large system costs a sparse factorization or more.
    o.max_moves = sys.numVariables() <= 500 ? 12 : 3;
    o.factorization.rank_tolerance = c->scene.analysis.rank_tolerance;
    next.result = engine::dragVertex(model, x, i, target, o);
    {
      const engine::Vector p = sys.vertexPositions(next.result.x).col(i);
      const engine::Matrix shownp = map.apply(p);
      const render::Point3 at{shownp(0, 0), shownp(1, 0), d > 2 ? shownp(2, 0) : 0.0};
      const auto q = projector(at);
      next.remaining_px = std::hypot(q[0] - px, (v.height - q[1]) - py);
    }
    next.generation = c->generation;
    next.sample = k;
    next.map = map;
    next.vertex = i;
  }
  next.target_px[0] = px, next.target_px[1] = py;
  next.milliseconds = 1e3 * std::chrono::duration<double>(Clock::now() - t0).count();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (computed_ != c) throw std::invalid_argument("the scene changed during the drag; drag again");
    dragged_ = std::make_unique<Dragged>(std::move(next));
    view_.dragged = true;
    ++revision_;
  }
  return state();
}

void Session::startFromDragged() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!dragged_ || !computed_ || dragged_->generation != computed_->generation)
    throw std::invalid_argument("drag a vertex first: its configuration becomes the start");
  MotionControls next = controls_;
  next.vertices = rows(computed_->motion.path.modelAt(dragged_->sample).system().vertexPositions(dragged_->result.x));
  // A new start has its own flexes: the form's coefficients may not fit it.
  if (next.flex && !next.flex->empty()) next.flex = std::vector<double>{};
  std::vector<std::string> o = options_.overrides;
  for (auto& a : next.assignments()) o.push_back(std::move(a));
  const MotionControls old = controls_;
  controls_ = next;
  try {
    (void)scenes::loadSceneFromString(jobText(), path_, o);
  } catch (const scenes::SceneError& e) {
    controls_ = old;
    throw std::invalid_argument("this scene cannot start from the dragged configuration: " + e.message);
  }
  submitLocked();
}

void Session::followBranch(int sample, int direction) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!computed_) throw std::invalid_argument("nothing loaded");
  for (const auto& b : computed_->branches)
    if (b.sample == sample) {
      if (direction < 0 || direction >= static_cast<int>(b.cone.directions.size()))
        throw std::invalid_argument("sample " + std::to_string(sample) + " has " +
                                    std::to_string(b.cone.directions.size()) + " branch direction(s)");
      pipeline::StudyOptions::Branch br;
      br.sample = sample;
      br.direction = b.cone.directions[static_cast<size_t>(direction)];
      br.note = "branch direction " + std::to_string(direction) + " (" + b.kinds[static_cast<size_t>(direction)] + ")";
      pending_ = Job{computed_->text, computed_->overrides, next_job_++, br};
      cancel_below_ = pending_->id;
      ++revision_;
      changed_.notify_all();
      return;
    }
  throw std::invalid_argument("sample " + std::to_string(sample) + " is not a singular point of the path");
}

// The text a job loads: the scene's own, or, with a moved start, the scene as one text with
// its system spelled out (`[system] from = FILE` or a catalog entry take no vertices).
std::string Session::jobText() const {
  if (!controls_.vertices) return text_;
  try {
    (void)scenes::loadSceneFromString(text_, path_, overrides());
    return text_;  // the file itself takes the vertices (and keeps its comments when saved)
  } catch (const scenes::SceneError&) {
  }
  try {
    const scenes::Scene s = scenes::loadSceneFromString(text_, path_, options_.overrides);
    if (s.document) return s.document();
  } catch (const scenes::SceneError&) {
  }
  return text_;
}

void Session::submitLocked(std::optional<pipeline::StudyOptions::Branch> branch) {
  pending_ = Job{jobText(), overrides(), next_job_++, std::move(branch)};
  cancel_below_ = pending_->id;
  ++revision_;
  changed_.notify_all();
}

std::string Session::pathText(bool csv) const {
  const std::shared_ptr<const Computed> c = current();
  if (!c) return "";
  return csv ? present::pathCsv(c->scene, c->motion.path) : present::jsonText(present::pathJson(c->scene, c->motion.path));
}

void Session::renderLoop() {
  std::unique_ptr<render::Renderer> renderer;
  try {
    renderer = std::make_unique<render::Renderer>();
  } catch (const std::exception& e) {
    std::lock_guard<std::mutex> lock(render_mutex_);
    render_error_ = std::string("cannot render: ") + e.what();
  }
  for (;;) {
    std::vector<std::packaged_task<void(render::Renderer&)>> tasks;
    {
      std::unique_lock<std::mutex> lock(render_mutex_);
      render_cv_.wait(lock, [&] { return stopping_ || !render_queue_.empty(); });
      if (render_queue_.empty()) return;  // stopping
      tasks.swap(render_queue_);
    }
    for (auto& t : tasks) {
      if (renderer) t(*renderer);
      else t = {};  // the future reports a broken promise
    }
  }
}

std::future<void> Session::onRenderThread(std::function<void(render::Renderer&)> task) const {
  std::packaged_task<void(render::Renderer&)> t(std::move(task));
  std::future<void> f = t.get_future();
  {
    std::lock_guard<std::mutex> lock(render_mutex_);
    if (!render_error_.empty()) throw std::runtime_error(render_error_);
    render_queue_.push_back(std::move(t));
  }
  render_cv_.notify_one();
  return f;
}

bool Session::takeFrameRequest(const std::shared_ptr<const Computed>& c, const FrameRequest& q,
                               std::optional<Dragged>& dragged) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (q.after > drag_seq_)
    changed_.wait_for(lock, std::chrono::seconds(1), [&] { return drag_seq_ >= q.after || stopping_; });
  if (c != computed_) return false;  // replaced meanwhile
  view_ = q;
  view_.dragged = q.dragged && dragged_;
  if (view_.dragged) dragged = *dragged_;
  return true;
}

// What frame.png draws for `q`: the sample, or the dragged configuration on screen.
present::Animation::Still Session::frameDrawing(const Computed& c, const FrameRequest& q,
                                                const std::optional<Dragged>& dragged) const {
  const auto animation = animationFor(c, q.width, q.height);
  const present::Animation& a = *animation;
  if (dragged) {
    const engine::Matrix p = c.motion.path.modelAt(dragged->sample).system().vertexPositions(dragged->result.x);
    std::vector<present::FigureExtras::Highlight> held;
    if (dragged->remaining_px >= kHeldPixels)
      for (const auto& h : dragged->result.held) held.push_back({h.vertices, std::abs(h.weight)});
    return a.configurationDrawing(dragged->sample, dragged->map.apply(p), q.options, held);
  }
  return a.sampleDrawing(q.sample, q.options);
}

std::vector<std::uint8_t> Session::framePng(const FrameRequest& q) {
  const std::shared_ptr<const Computed> c = current();
  std::optional<Dragged> dragged;
  if (!c || !takeFrameRequest(c, q, dragged)) return {};
  std::vector<std::uint8_t> png;
  onRenderThread([&](render::Renderer& r) {
    const present::Animation::Still d = frameDrawing(*c, q, dragged);
    r.render(d.list, d.view, c->image);
    png = render::encodePng(c->image, options_.png_level);
  }).get();
  return png;
}

std::string Session::frameVector(const FrameRequest& q, render::VectorFormat format) {
  const std::shared_ptr<const Computed> c = current();
  std::optional<Dragged> dragged;
  if (!c || !takeFrameRequest(c, q, dragged)) return {};
  std::string text;
  onRenderThread([&](render::Renderer&) {
    const present::Animation::Still d = frameDrawing(*c, q, dragged);
    text = render::vectorDocument(render::singlePanel(d.list, d.view, c->scene.title), format);
  }).get();
  return text;
}

std::vector<std::uint8_t> Session::projectionPng(int sample, int width, int height) {
  const std::shared_ptr<const Computed> c = current();
  if (!c) return {};
  std::vector<std::uint8_t> png;
  onRenderThread([&](render::Renderer& r) {
    if (!c->canvas || c->canvas_width != width || c->canvas_height != height) {
      c->canvas = std::make_unique<render::PlotCanvas>(c->projection.plot,
                                                       present::projectionStyle(c->scene, width, height));
      c->canvas_width = width, c->canvas_height = height;
    }
    std::optional<render::Point2> cursor;
    if (!c->projection.curves.empty()) {
      const auto& curve = c->projection.curves[0];
      const long at = static_cast<long>(c->projection.starts[0]) + std::max(sample, 0);
      if (!curve.empty()) cursor = curve[static_cast<size_t>(std::min<long>(at, static_cast<long>(curve.size()) - 1))];
    }
    r.render(c->canvas->draw(cursor), c->canvas->view(), c->image);
    png = render::encodePng(c->image, options_.png_level);
  }).get();
  return png;
}

std::string Session::sceneText() const {
  const std::shared_ptr<const Computed> c = current();
  std::lock_guard<std::mutex> lock(mutex_);
  // The controls as they are now, on the text shown (or on the file's text before any loaded);
  // a dragged configuration on screen is the start.
  MotionControls controls = controls_;
  if (c && view_.dragged && dragged_ && dragged_->generation == c->generation) {
    controls.vertices = rows(c->motion.path.modelAt(dragged_->sample).system().vertexPositions(dragged_->result.x));
  }
  std::vector<std::string> o = options_.overrides;
  for (auto& a : controls.assignments()) o.push_back(std::move(a));
  return scenes::withKeys(c ? c->text : text_, o);
}

std::string Session::saveAs(const std::string& name, bool overwrite) const {
  if (!plainTomlName(name))
    throw std::invalid_argument("a file name like my_scene.toml: letters, digits, '.', '_', '-', ending in .toml");
  const std::string dir = present::directoryOf(path_);
  const std::string target = dir == "/" ? "/" + name : dir + "/" + name;
  struct stat st {};
  if (!overwrite && ::stat(target.c_str(), &st) == 0) throw std::invalid_argument(target + " exists");
  const std::string text = sceneText();
  // What is written must load.
  try {
    (void)scenes::loadSceneFromString(text, target);
  } catch (const scenes::SceneError& e) {
    throw std::invalid_argument(std::string("the edited scene does not load: ") + e.what());
  }
  present::writeFileAtomically(target, text);
  return target;
}

}  // namespace flexure::viewer
