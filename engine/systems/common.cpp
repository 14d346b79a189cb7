// The helpers shared by several system types' models (engine/systems/common.h).
#include "engine/systems/common.h"

#include <algorithm>

namespace flexure::engine::systems_detail {

std::string listText(const std::vector<int>& f, int base) {
  std::string s = "[";
  for (size_t i = 0; i < f.size(); ++i) s += (i ? ", " : "") + std::to_string(f[i] + base);
  return s + "]";
}

// Bars of a framework-like system, deduplicated: each pair once, else a ModelError at `key`.
void addEdge(std::map<std::pair<int, int>, std::string>& seen, int a, int b, const std::string& owner,
             const std::string& key, int item, int base) {
  const auto e = std::minmax(a, b);
  if (a == b) throw ModelError(key, item, owner + " joins vertex " + std::to_string(a + base) + " to itself");
  auto it = seen.find(e);
  if (it != seen.end())
    throw ModelError(key, item, owner + " repeats the pair [" + std::to_string(e.first + base) + ", " +
                                    std::to_string(e.second + base) + "] of " + it->second);
  seen[e] = owner;
}

std::string closeVertices(const Matrix& p, int a, int b, int base, double extent) {
  const std::string names = "vertices " + std::to_string(a + base) + " and " + std::to_string(b + base);
  if (p.col(a) == p.col(b)) return names + " coincide";
  const double d = (p.col(a) - p.col(b)).norm();
  if (d > kDistinctTolerance * extent) return "";
  return names + " are " + shortNumber(d) + " apart, less than " + shortNumber(kDistinctTolerance) +
         " of the configuration's extent " + shortNumber(extent) +
         " (the tolerance that tells vertices apart at that scale): too close to analyse";
}

void requireDistinct(const Matrix& p, int a, int b, const std::string& key, int item, int base, const std::string& what) {
  const std::string why = closeVertices(p, a, b, base, extentOf(p));
  if (!why.empty()) throw ModelError(key, item, what + ": " + why);
}

}  // namespace flexure::engine::systems_detail
