#include "present/path_output.h"

#include <stdexcept>

#include <chrono>
#include <cstdio>
#include <sstream>

#include "engine/systems/origami.h"

namespace flexure::present {

namespace {

constexpr double kDegrees = 180.0 / M_PI;

// Every edge's fold angle at each sample, degrees (origami only).
std::vector<std::vector<double>> foldAnglesDegrees(const engine::Origami& o, const engine::DeformationPath& r) {
  std::vector<std::vector<double>> out;
  for (const engine::Vector& x : r.samples) {
    std::vector<double> a = o.foldAngles(o.system().vertexPositions(x));
    for (double& v : a) v *= kDegrees;
    out.push_back(std::move(a));
  }
  return out;
}

}  // namespace

nlohmann::ordered_json pathJson(const Scene& scene, const engine::DeformationPath& r, bool with_samples) {
  const auto& sys = scene.model->system();
  nlohmann::ordered_json j;
  j["status"] = engine::toString(r.summary.status);
  if (r.summary.status != engine::TrackStatus::Success || !r.summary.reason.empty()) j["reason"] = r.summary.reason;
  j["steps_requested"] = r.summary.steps_requested;
  j["steps_done"] = r.summary.steps_done;
  j["seed"] = r.summary.seed;
  j["dimension"] = sys.dimension();
  j["max_residual"] = r.summary.max_residual;
  j["residual_scale"] = sys.residualScale();
  j["step_size"] = scene.motion.step_size;
  j["rejected_steps"] = r.summary.rejected_steps;
  j["flex"] = r.flex;
  j["flex_choice"] = r.flex_choice;
  j["title"] = scene.title;
  j["system"] = scene.type;
  nlohmann::ordered_json samples = nlohmann::ordered_json::array();
  for (const engine::Vector& x : with_samples ? r.samples : std::vector<engine::Vector>{}) {
    const engine::Matrix p = sys.vertexPositions(x);
    nlohmann::ordered_json conf = nlohmann::ordered_json::array();
    for (int v = 0; v < sys.numVertices(); ++v) {
      nlohmann::ordered_json pt = nlohmann::ordered_json::array();
      for (int k = 0; k < sys.dimension(); ++k) pt.push_back(p(k, v));
      conf.push_back(pt);
    }
    samples.push_back(conf);
  }
  if (with_samples) j["samples"] = samples;
  const auto* origami = dynamic_cast<const engine::Origami*>(scene.model.get());
  if (origami && with_samples) j["fold_angles"] = foldAnglesDegrees(*origami, r);  // per sample, per crease
  nlohmann::ordered_json events = nlohmann::ordered_json::array();
  for (const auto& e : r.events) {
    nlohmann::ordered_json ev = {{"sample", e.sample}, {"kind", engine::toString(e.kind)}};
    if (e.kind == engine::EventKind::Contact && e.vertices.size() == 2)
      ev["pair"] = {e.vertices[0] + scene.index_base, e.vertices[1] + scene.index_base};
    if (e.kind == engine::EventKind::Intersection && e.faces.size() == 2)
      ev["faces"] = {e.faces[0] + scene.index_base, e.faces[1] + scene.index_base};
    ev["detail"] = e.detail;
    events.push_back(ev);
  }
  j["events"] = events;
  // What the samples are made of, for a reader that draws them without flexure (vertex numbers
  // from index_base, as in the scene), and the scene itself, which loads the path back
  // (`flexure render PATH.json`).
  const engine::Geometry g = r.segments.empty() ? scene.model->geometry() : r.geometryAt(0);
  const int b = scene.index_base;
  const auto list = [b](const auto& items) {
    nlohmann::ordered_json out = nlohmann::ordered_json::array();
    for (const auto& item : items) {
      nlohmann::ordered_json one = nlohmann::ordered_json::array();
      for (int v : item) one.push_back(v + b);
      out.push_back(one);
    }
    return out;
  };
  nlohmann::ordered_json st;
  st["index_base"] = b;
  st["vertices"] = g.points;
  st["edges"] = list(g.bars.edges);
  nlohmann::ordered_json pinned = nlohmann::ordered_json::array();
  for (int v : g.pinned) pinned.push_back(v + b);
  st["pinned"] = pinned;
  if (!g.facets.empty()) st["facets"] = list(g.facets.polygons);
  if (!g.angles.empty()) st["angles"] = list(g.angles.triples);
  if (!g.simplices.empty()) st["simplices"] = list(g.simplices.list);
  if (!g.balls.empty()) st["radii"] = g.balls.radii;
  if (!g.caps.empty()) st["caps"] = true;
  if (!g.bars.kinds.empty()) st["assignments"] = std::string(g.bars.kinds.begin(), g.bars.kinds.end());
  j["structure"] = st;
  if (scene.document) j["scene"] = scene.document();
  return j;
}

std::string pathCsv(const Scene& scene, const engine::DeformationPath& r) {
  const auto& sys = scene.model->system();
  const char* axes = "xyz";
  std::ostringstream o;
  o << "sample";
  for (int v = 0; v < sys.numVertices(); ++v)
    for (int k = 0; k < sys.dimension(); ++k) o << ',' << axes[k] << v + scene.index_base;
  // Origami: then every crease's fold angle in degrees (fold1, ... in the FOLD file's edge order).
  const auto* origami = dynamic_cast<const engine::Origami*>(scene.model.get());
  const std::vector<std::vector<double>> folds = origami ? foldAnglesDegrees(*origami, r) : std::vector<std::vector<double>>{};
  if (origami)
    for (size_t e = 0; e < origami->edges().size(); ++e) o << ",fold" << e + static_cast<size_t>(scene.index_base);
  o << '\n';
  char buf[32];
  for (size_t i = 0; i < r.samples.size(); ++i) {
    const engine::Matrix p = sys.vertexPositions(r.samples[i]);
    o << i;
    for (int v = 0; v < sys.numVertices(); ++v)
      for (int k = 0; k < sys.dimension(); ++k) {
        std::snprintf(buf, sizeof buf, "%.17g", p(k, v));
        o << ',' << buf;
      }
    if (origami)
      for (double a : folds[i]) {
        std::snprintf(buf, sizeof buf, "%.17g", a);
        o << ',' << buf;
      }
    o << '\n';
  }
  return o.str();
}

std::string foldPath(const Scene& scene, const engine::DeformationPath& r) {
  const auto* origami = dynamic_cast<const engine::Origami*>(scene.model.get());
  if (!origami)
    throw OutputError("a path is written as FOLD (.fold) for origami scenes only; this is a " + scene.type +
                      " (write .json or .csv)");
  const auto& sys = origami->system();
  const auto coords = [&](const engine::Vector& x) {
    const engine::Matrix p = sys.vertexPositions(x);
    nlohmann::ordered_json out = nlohmann::ordered_json::array();
    for (int v = 0; v < p.cols(); ++v) out.push_back({p(0, v), p(1, v), p(2, v)});
    return out;
  };
  const std::vector<std::vector<double>> folds = foldAnglesDegrees(*origami, r);
  nlohmann::ordered_json j;
  j["file_spec"] = 1.2;
  j["file_creator"] = "flexure";
  j["file_classes"] = {"singleModel", "animation"};
  j["frame_title"] = scene.title;
  j["frame_classes"] = {"foldedForm"};
  j["frame_attributes"] = {"3D"};
  j["vertices_coords"] = coords(r.samples.front());
  nlohmann::ordered_json edges = nlohmann::ordered_json::array(), faces = nlohmann::ordered_json::array();
  std::string assignments;
  for (const engine::Crease& c : origami->edges()) {
    edges.push_back({c.a, c.b});
    assignments += c.assignment;
  }
  for (const auto& f : origami->faces()) faces.push_back(f);
  j["edges_vertices"] = edges;
  nlohmann::ordered_json letters = nlohmann::ordered_json::array();
  for (char c : assignments) letters.push_back(std::string(1, c));
  j["edges_assignment"] = letters;
  j["edges_foldAngle"] = folds.front();
  j["faces_vertices"] = faces;
  j["flexure:sample"] = 0;
  j["flexure:status"] = engine::toString(r.summary.status);
  j["flexure:seed"] = r.summary.seed;
  j["flexure:max_residual"] = r.summary.max_residual;
  nlohmann::ordered_json frames = nlohmann::ordered_json::array();
  for (size_t i = 1; i < r.samples.size(); ++i)
    frames.push_back({{"frame_classes", {"foldedForm"}},
                      {"frame_parent", 0},
                      {"frame_inherit", true},
                      {"vertices_coords", coords(r.samples[i])},
                      {"edges_foldAngle", folds[i]},
                      {"flexure:sample", i}});
  j["file_frames"] = frames;
  return j.dump(1) + "\n";
}

Written writePath(const Scene& scene, const engine::DeformationPath& path, const std::string& file) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::string ext = extensionOf(file);
  if (ext != "json" && ext != "csv" && ext != "fold")
    throw std::invalid_argument("a path is written as .json, .csv or .fold, not '" + file + "'");
  writeFileAtomically(file, ext == "csv"    ? pathCsv(scene, path)
                            : ext == "fold" ? foldPath(scene, path)
                                            : pathJson(scene, path).dump(1) + "\n");
  Written w;
  w.file = file;
  w.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  w.summary = std::to_string(path.samples.size()) + " samples";
  return w;
}

}  // namespace flexure::present
