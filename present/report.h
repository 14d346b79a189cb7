// The rigidity report of a scene, as JSON (SPEC section 3) and as text for people.
#pragma once

#include <nlohmann/json.hpp>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "engine/rigidity.h"
#include "scenes/scene.h"

namespace flexure::present {

using scenes::Scene;

nlohmann::ordered_json analysisJson(const Scene& scene, const engine::RigidityReport& report);
// Its first fields: the scene and the counts (title to inf_rigid), all a counts-only analysis has.
nlohmann::ordered_json countsJson(const Scene& scene, const engine::RigidityReport& report);
// "flexure": which flexure made an output and by which command (render/provenance.h): version,
// commit, build_type, command, and the seed the output's randomness flowed from (when it has
// one). Every JSON output carries it (SPEC section 5).
nlohmann::ordered_json provenanceJson(std::optional<std::uint64_t> seed = std::nullopt);
std::string analysisText(const Scene& scene, const engine::RigidityReport& report);

// "(c1, c2, ...)": flex coefficients in a label.
std::string coefficientsText(const std::vector<double>& c);

}  // namespace flexure::present
