#include "engine/deformation_path.h"

#include <cmath>

#include <sstream>
#include <stdexcept>

namespace flexure::engine {

const char* toString(TrackStatus s) {
  switch (s) {
    case TrackStatus::Success: return "success";
    case TrackStatus::StoppedEarly:
    case TrackStatus::StoppedByCallback:
    case TrackStatus::LeftAdmissibleSet: return "stopped_early";
  }
  return "stopped_early";
}

const char* toString(EventKind k) {
  switch (k) {
    case EventKind::Singularity: return "singularity";
    case EventKind::Contact: return "contact";
    case EventKind::Intersection: return "intersection";
  }
  return "singularity";
}

std::string TrackSummary::briefReport() const {
  std::ostringstream o;
  o.precision(2);
  o << "tracked " << steps_done << "/" << steps_requested << " steps, " << rejected_steps
    << " rejected, max residual " << std::scientific << max_residual << ", seed " << seed << ": "
    << (status != TrackStatus::Success ? "stopped early: " + reason
        : reason.empty()              ? std::string("success")
                                      : "success: " + reason);
  return o.str();
}

void DeformationPath::startOn(const Model& model) {
  segments.clear();
  // Aliasing constructor with an empty owner: a non-owning pointer to the caller's model.
  segments.push_back({0, std::shared_ptr<const Model>(std::shared_ptr<const Model>(), &model)});
}

const Model& DeformationPath::modelAt(int k) const {
  if (segments.empty()) throw std::logic_error("DeformationPath::modelAt: the path has no model");
  const Segment* s = &segments.front();
  for (const Segment& t : segments)
    if (t.first_sample <= k) s = &t;
  return *s->model;
}

Geometry DeformationPath::geometryAt(int k) const {
  if (segments.empty()) throw std::logic_error("DeformationPath::geometryAt: the path has no model");
  Geometry g = segments.front().model->geometry();
  for (const TrackEvent& e : events)
    if (e.kind == EventKind::Contact && e.sample <= k && e.vertices.size() == 2)
      g.bars.edges.push_back({e.vertices[0], e.vertices[1]});
  return g;
}

std::vector<int> DeformationPath::singularSamples() const {
  std::vector<int> out;
  for (const TrackEvent& e : events)
    if (e.kind == EventKind::Singularity) out.push_back(e.sample);
  return out;
}

bool PathCertificate::certified() const {
  for (double r : radii)
    if (std::isnan(r)) return false;
  for (char s : steps)
    if (!s) return false;
  return !radii.empty();
}

}  // namespace flexure::engine
