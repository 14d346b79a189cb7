#include "present/path_output.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "present/report.h"
#include "present/text.h"

namespace flexure::present {

namespace {

// The model's quantities (Model::sampleQuantities: origami's fold angles) at every sample.
std::vector<std::vector<double>> sampleQuantities(const engine::Model& m, const engine::DeformationPath& r) {
  std::vector<std::vector<double>> out;
  for (const engine::Vector& x : r.samples) out.push_back(m.sampleQuantityValues(m.system().positions(x)));
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
  if (r.certificate) {
    // track --certify (SPEC section 5): a radius per sample (null: not certified), a flag per step.
    j["certified"] = r.certificate->certified();
    nlohmann::ordered_json radii = nlohmann::ordered_json::array(), steps = nlohmann::ordered_json::array();
    for (double v : r.certificate->radii) radii.push_back(std::isnan(v) ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(v));
    for (char s : r.certificate->steps) steps.push_back(s != 0);
    j["certificate"] = {{"radii", radii}, {"steps", steps}, {"reason", r.certificate->reason}};
    // Added to SPEC section 5's fields: true when a certified chain from the start proves the
    // motion nontrivial, else null.
    j["certificate"]["flexible"] =
        r.certificate->flexible ? nlohmann::ordered_json(*r.certificate->flexible) : nlohmann::ordered_json(nullptr);
  }
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
  const engine::Model::SampleQuantities quantities = scene.model->sampleQuantities();
  if (!quantities.json_key.empty() && with_samples)
    j[quantities.json_key] = sampleQuantities(*scene.model, r);  // per sample, per item (origami: per crease)
  nlohmann::ordered_json events = nlohmann::ordered_json::array();
  for (const auto& e : r.events) {
    nlohmann::ordered_json ev = {{"sample", e.sample}, {"kind", engine::toString(e.kind)}};
    if (e.kind == engine::EventKind::Contact && e.vertices.size() == 2)
      ev["pair"] = {e.vertices[0] + scene.index_base, e.vertices[1] + scene.index_base};
    if (e.kind == engine::EventKind::Intersection && e.faces.size() == 2)
      ev["faces"] = {e.faces[0] + scene.index_base, e.faces[1] + scene.index_base};
    ev["detail"] = e.detail;
    if (e.branches) {
      // The branches that meet there (SPEC section 5): each direction as per-vertex
      // displacements (unit in the free coordinates), what `track --branch SAMPLE:J` follows.
      const engine::BranchDirections& br = *e.branches;
      if (br.computed) {
        const engine::ConstraintSystem& sys = r.modelAt(e.sample).system();
        nlohmann::ordered_json dirs = nlohmann::ordered_json::array();
        for (const engine::Vector& d : br.directions) {
          const engine::Matrix f = sys.velocityField(d);
          nlohmann::ordered_json field = nlohmann::ordered_json::array();
          for (int v = 0; v < f.cols(); ++v) {
            nlohmann::ordered_json vec = nlohmann::ordered_json::array();
            for (int k = 0; k < f.rows(); ++k) vec.push_back(std::abs(f(k, v)) < 1e-15 ? 0.0 : f(k, v));  // no -0
            field.push_back(vec);
          }
          dirs.push_back(field);
        }
        ev["directions"] = dirs;
        ev["direction_kinds"] = br.kinds;
        ev["tangent_cone"] = {{"flexes", br.flexes}, {"stresses", br.stresses}, {"note", br.note}};
      } else {
        ev["directions"] = nullptr;
        ev["tangent_cone"] = {{"note", br.note}};
      }
    }
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
  j["flexure"] = provenanceJson(r.summary.seed);
  return j;
}

std::string pathCsv(const Scene& scene, const engine::DeformationPath& r) {
  const auto& sys = scene.model->system();
  const char* axes = "xyz";
  std::ostringstream o;
  o << "sample";
  for (int v = 0; v < sys.numVertices(); ++v)
    for (int k = 0; k < sys.dimension(); ++k) o << ',' << axes[k] << v + scene.index_base;
  // Then the model's quantities (origami: every crease's fold angle in degrees, fold1, ... in the
  // FOLD file's edge order).
  const engine::Model::SampleQuantities quantities = scene.model->sampleQuantities();
  const bool with_quantities = !quantities.json_key.empty();
  const std::vector<std::vector<double>> folds =
      with_quantities ? sampleQuantities(*scene.model, r) : std::vector<std::vector<double>>{};
  if (with_quantities) {
    const size_t items = scene.model->sampleQuantityValues(scene.model->startPositions()).size();
    for (size_t e = 0; e < items; ++e) o << ',' << quantities.csv_prefix << e + static_cast<size_t>(scene.index_base);
  }
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
    if (with_quantities)
      for (double a : folds[i]) {
        std::snprintf(buf, sizeof buf, "%.17g", a);
        o << ',' << buf;
      }
    o << '\n';
  }
  return o.str();
}

Written writePath(const Scene& scene, const engine::DeformationPath& path, const std::string& file) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::string ext = extensionOf(file);
  if (ext != "json" && ext != "csv" && ext != "fold")
    throw std::invalid_argument("a path is written as .json, .csv or .fold, not '" + file + "'");
  writeFileAtomically(file, ext == "csv"    ? pathCsv(scene, path)
                            : ext == "fold" ? foldPath(scene, path)
                                            : jsonText(pathJson(scene, path), 1) + "\n");  // file names need not be UTF-8
  Written w;
  w.file = file;
  w.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  w.summary = std::to_string(path.samples.size()) + " samples";
  return w;
}

}  // namespace flexure::present
