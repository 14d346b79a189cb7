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

// Two vertices closer than this times the configuration's extent (its bounding-box diagonal)
// cannot be told apart from coincident at that scale: a bar between them is a row of the
// rigidity matrix below its rank tolerance.
constexpr double kDistinctTolerance = 1e-12;

// Empty when vertices a and b of p are told apart at the scale `extent` (extentOf(p)); else why
// not, numbered from `base`: "vertices A and B coincide" only when they are the same point,
// else "vertices A and B are D apart, less than 1e-12 of the configuration's extent E (the
// tolerance that tells vertices apart at that scale)".
std::string closeVertices(const Matrix& p, int a, int b, int base, double extent);

// A ModelError at (key, item) when vertices a and b of p cannot be told apart (closeVertices).
void requireDistinct(const Matrix& p, int a, int b, const std::string& key, int item, int base, const std::string& what);

}  // namespace flexure::engine::systems_detail
