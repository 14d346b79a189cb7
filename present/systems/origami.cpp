// Origami's room in present/: a path written as a FOLD file (the sheet's creases and faces, a
// frame per sample with its coordinates and fold angles), the format origami tools read.
#include <nlohmann/json.hpp>

#include "engine/systems/origami.h"
#include "present/path_output.h"
#include "present/text.h"

namespace flexure::present {

bool writesFold(const Scene& scene) { return dynamic_cast<const engine::Origami*>(scene.model.get()) != nullptr; }

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
  std::vector<std::vector<double>> folds;  // every crease's fold angle in degrees, per sample
  for (const engine::Vector& x : r.samples) folds.push_back(origami->sampleQuantityValues(sys.positions(x)));
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
  return jsonText(j, 1) + "\n";
}

}  // namespace flexure::present
