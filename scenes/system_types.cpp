// The registry of system types: every type defined in scenes/systems/, listed here once, in the
// order messages name them. A new type is its file in scenes/systems/ plus its line below.
#include "scenes/system_types.h"

namespace flexure::scenes {

namespace detail {

// X(function): the SystemType that systems::function() in scenes/systems/ returns.
#define FLEXURE_SYSTEM_TYPES(X) \
  X(framework)                  \
  X(frameworkOnSurface)         \
  X(angularFramework)           \
  X(polytope)                   \
  X(bodyHinge)                  \
  X(bodyBar)                    \
  X(volumeHypergraph)           \
  X(spherePacking)              \
  X(sphericalDiskPacking)       \
  X(origami)

namespace systems {
#define FLEXURE_DECLARE(f) SystemType f();
FLEXURE_SYSTEM_TYPES(FLEXURE_DECLARE)
#undef FLEXURE_DECLARE
}  // namespace systems

const std::vector<SystemType>& systemTypes() {
#define FLEXURE_LIST(f) systems::f(),
  static const std::vector<SystemType> types = {FLEXURE_SYSTEM_TYPES(FLEXURE_LIST)};
#undef FLEXURE_LIST
  return types;
}

const SystemType* findSystemType(const std::string& name) {
  for (const SystemType& t : systemTypes())
    if (t.name == name) return &t;
  return nullptr;
}

}  // namespace detail

const std::vector<std::string>& systemTypeNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const detail::SystemType& t : detail::systemTypes()) out.push_back(t.name);
    out.push_back("catalog");
    return out;
  }();
  return names;
}

}  // namespace flexure::scenes
