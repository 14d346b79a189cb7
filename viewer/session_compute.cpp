// The session's compute thread: a job's scene loaded, analysed and tracked, the tangent cones
// at the path's singular points, and the result (or the error) published.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>

#include "engine/active_set.h"
#include "engine/drag.h"
#include "engine/factorization.h"
#include "engine/flex_space.h"
#include "present/report.h"
#include "viewer/session.h"
#include "viewer/session_internal.h"

namespace flexure::viewer {

using session_detail::Clock;

namespace {

// The branch points of the path: its singularity events with their tangent cones
// (pipeline::addBranchDirections: at most 10, systems of at most 400 free coordinates, whose
// dense SVD takes tens of milliseconds: the page waits for them).
std::vector<Computed::BranchPoint> branchPoints(const engine::DeformationPath& path) {
  std::vector<Computed::BranchPoint> out;
  for (const engine::TrackEvent& e : path.events) {
    if (e.kind != engine::EventKind::Singularity || !e.branches) continue;
    if (engine::piecewise(path.modelAt(e.sample))) continue;
    out.push_back({e.sample, e.detail, *e.branches});
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

}  // namespace

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
      c->branches = branchPoints(c->motion.path);
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

}  // namespace flexure::viewer
