// A tracked deformation path as JSON or CSV (SPEC section 3).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "engine/motion_tracker.h"
#include "scenes/scene.h"

namespace flexure::scenes {

// `flex`: the coefficients used in the canonical nontrivial-flex basis; `flex_note` says how
// they were chosen.
nlohmann::ordered_json pathJson(const Scene& scene, const engine::TrackResult& result,
                                const std::vector<double>& flex, const std::string& flex_note);
// One row per sample: sample,x1,y1,(z1,)x2,... with every vertex, pinned ones included.
std::string pathCsv(const Scene& scene, const engine::TrackResult& result);

}  // namespace flexure::scenes
