// Helpers shared by several system types' models (engine/systems/<type>.cpp): item lists as
// text, deduplicated bars and coincident vertices, each failing with a ModelError at a scene key.
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "engine/model.h"

namespace flexure::engine::systems_detail {

// A vertex list as text, "[a, b, c]", numbered from `base`.
std::string listText(const std::vector<int>& f, int base);

// Bars of a framework-like system, deduplicated: each pair once, else a ModelError at `key`.
void addEdge(std::map<std::pair<int, int>, std::string>& seen, int a, int b, const std::string& owner,
             const std::string& key, int item, int base);

// A ModelError at (key, item) when vertices a and b of p coincide (relative to the extent of p).
void requireDistinct(const Matrix& p, int a, int b, const std::string& key, int item, int base, const std::string& what);

}  // namespace flexure::engine::systems_detail
