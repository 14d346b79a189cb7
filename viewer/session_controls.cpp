// The motion controls (as --set overrides on top of the scene file), and the scene text with
// them written into it, saved next to the scene file.
#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "present/output_file.h"
#include "scenes/scene_edit.h"
#include "viewer/session.h"
#include "viewer/session_internal.h"

namespace flexure::viewer {

using session_detail::rows;

namespace {

// A plain file name: letters, digits, '.', '_', '-'; not hidden; ends in .toml.
bool plainTomlName(const std::string& name) {
  if (name.size() < 6 || name.size() > 128 || name[0] == '.' || name[0] == '-') return false;
  if (name.compare(name.size() - 5, 5, ".toml") != 0 || name.find("..") != std::string::npos) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' || c == '_' ||
           c == '-';
  });
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
  if (certify) a.push_back(std::string("motion.certify=") + (*certify ? "true" : "false"));
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
