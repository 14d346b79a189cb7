// A tracked deformation path as JSON or CSV (SPEC section 3).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "engine/deformation_path.h"
#include "present/output_file.h"
#include "scenes/scene.h"

namespace flexure::present {

using scenes::Scene;

// With the path's flex (coefficients in the start's canonical nontrivial-flex basis) and how it
// was chosen.
// Without samples: every field but "samples" (the Python module hands them over as an array).
nlohmann::ordered_json pathJson(const Scene& scene, const engine::DeformationPath& path, bool with_samples = true);
// One row per sample: sample,x1,y1,(z1,)x2,... with every vertex, pinned ones included.
std::string pathCsv(const Scene& scene, const engine::DeformationPath& path);
// Origami: the path as a FOLD file, frame 0 the start and one frame per further sample
// (frame_inherit: vertices_coords and edges_foldAngle), readable by other origami software.
// Throws OutputError for other system types. Defined in origami's room, present/systems/origami.cpp.
std::string foldPath(const Scene& scene, const engine::DeformationPath& path);
// Whether foldPath writes this scene's paths (an origami scene).
bool writesFold(const Scene& scene);
// The path as JSON, CSV or FOLD (by the extension), written atomically.
Written writePath(const Scene& scene, const engine::DeformationPath& path, const std::string& file);

}  // namespace flexure::present
