// Session::state: everything the page shows except images, as JSON, with the current frame's
// configuration and where its vertices are on screen (Session::shown).
#include <algorithm>
#include <cmath>
#include <optional>

#include "render/camera.h"
#include "viewer/session.h"
#include "viewer/session_internal.h"

namespace flexure::viewer {

using session_detail::animationFor;

// The configuration of the current frame and where its vertices are on screen.
struct Session::Shown {
  int sample = 0;
  bool dragged = false;
  engine::Matrix vertices;  // d x n, the model's coordinates
  engine::Matrix screen;    // 2 x n, pixels from the top left
  double residual = 0;
};

namespace {

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

template <class T>
nlohmann::json optionalJson(const std::optional<T>& v) {
  return v ? nlohmann::json(*v) : nlohmann::json();
}

}  // namespace

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
  controls["certify"] = optionalJson(controls_.certify);
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
                 {"steps", s.motion.steps}, {"seed", s.motion.seed}, {"certify", s.motion.certify}};
  // motion.certify: what is certified, for the bar under the slider (a step: one smooth arc
  // between its samples; a sample: a radius holding one point of the curve).
  if (r.certificate) {
    nlohmann::ordered_json steps = nlohmann::json::array(), samples = nlohmann::json::array();
    for (char st : r.certificate->steps) steps.push_back(st != 0);
    for (double v : r.certificate->radii) samples.push_back(!std::isnan(v));
    l["certificate"] = {{"certified", r.certificate->certified()}, {"reason", r.certificate->reason},
                        {"steps", steps}, {"samples", samples}};
  } else {
    l["certificate"] = nullptr;
  }
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
    for (size_t i = 0; i < b.cone.directions.size(); ++i) dirs.push_back({{"index", i}, {"kind", b.cone.kinds[i]}});
    branches.push_back({{"sample", b.sample}, {"event", b.event}, {"flexes", b.cone.flexes},
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

}  // namespace flexure::viewer
