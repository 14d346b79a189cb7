#include "viewer/session.h"

#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "render/image.h"
#include "render/plot.h"
#include "render/renderer.h"
#include "present/output_file.h"
#include "present/report.h"
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
  // Only the render thread touches these: the views at the last size asked for.
  mutable std::unique_ptr<present::Animation> animation;
  mutable std::unique_ptr<render::PlotCanvas> canvas;
  mutable int canvas_width = 0, canvas_height = 0;
  mutable render::Image image;
};

namespace {

using Clock = std::chrono::steady_clock;

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
    pending_ = Job{text_, overrides(), next_job_++};
    cancel_below_ = pending_->id;
    ++revision_;
    changed_.notify_all();
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
  std::string text, read_error;
  try {
    text = scenes::readSceneFile(path_);
  } catch (const scenes::SceneError& e) {
    read_error = e.what();
  }
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
  pending_ = Job{std::move(text), overrides(), next_job_++};
  cancel_below_ = pending_->id;
  ++revision_;
  changed_.notify_all();
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
  const std::vector<std::string> o = overrides();
  try {
    (void)scenes::loadSceneFromString(text_, path_, o);  // the scene's own checks (fast: no tracking)
  } catch (const scenes::SceneError& e) {
    controls_ = old;
    throw std::invalid_argument(e.message);
  }
  pending_ = Job{text_, o, next_job_++};
  cancel_below_ = pending_->id;
  ++revision_;
  changed_.notify_all();
}

void Session::resetControls() {
  std::lock_guard<std::mutex> lock(mutex_);
  controls_ = {};
  pending_ = Job{text_, overrides(), next_job_++};
  cancel_below_ = pending_->id;
  ++revision_;
  changed_.notify_all();
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
      pipeline::Study study(scene, so);
      c->motion = study.motion();
      c->report = present::analysisJson(scene, study.analysis());
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

nlohmann::ordered_json Session::state() const {
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
  j["loaded"] = l;
  return j;
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

std::future<void> Session::onRenderThread(std::function<void(render::Renderer&)> task) {
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

std::vector<std::uint8_t> Session::framePng(const FrameRequest& q) {
  const std::shared_ptr<const Computed> c = current();
  if (!c) return {};
  std::vector<std::uint8_t> png;
  onRenderThread([&](render::Renderer& r) {
    if (!c->animation || c->animation->width() != q.width || c->animation->height() != q.height)
      c->animation = std::make_unique<present::Animation>(c->scene, c->motion.path, q.width, q.height);
    c->animation->sample(q.sample, q.options, r, c->image);
    png = render::encodePng(c->image, options_.png_level);
  }).get();
  return png;
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
  // The controls as they are now, on the text shown (or on the file's text before any loaded).
  std::vector<std::string> o = overrides();
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
