// The registry of system types: every type defined in scenes/systems/, listed here once, in the
// order messages name them. A new type is its file in scenes/systems/ plus its line below.
#include "scenes/system_types.h"

#include <list>
#include <stdexcept>

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

namespace {

// The ExtraSystemType values alive, oldest first (a list: their addresses stay put).
std::list<SystemType>& extras() {
  static std::list<SystemType> types;
  return types;
}

}  // namespace

const SystemType* findSystemType(const std::string& name) {
  for (const SystemType& t : systemTypes())
    if (t.name == name) return &t;
  for (const SystemType& t : extras())
    if (t.name == name) return &t;
  return nullptr;
}

ExtraSystemType::ExtraSystemType(SystemType type) : name_(type.name) {
  if (findSystemType(name_) || name_ == "catalog")
    throw std::invalid_argument("system type '" + name_ + "' exists already");
  extras().push_back(std::move(type));
}

ExtraSystemType::~ExtraSystemType() {
  extras().remove_if([&](const SystemType& t) { return t.name == name_; });
}

}  // namespace detail

std::string systemTypesMarkdown() {
  std::string out =
      "| `type` | keys beyond `vertices`, `pinned` | constraints (paper, appendix B) | trivial motions |\n"
      "|---|---|---|---|\n";
  for (const detail::SystemType& t : detail::systemTypes())
    out += "| `" + t.name + "` | " + t.keys_doc + " | " + t.doc + " | " + t.trivial_doc + " |\n";
  out += "| `catalog` | `name` (see `flexure catalog`) | as the named system; the entry's title, motion and look "
         "come with it | |\n";
  return out;
}

std::vector<std::string> systemTypeNames() {
  std::vector<std::string> out;
  for (const detail::SystemType& t : detail::systemTypes()) out.push_back(t.name);
  for (const detail::SystemType& t : detail::extras()) out.push_back(t.name);
  out.push_back("catalog");
  return out;
}

}  // namespace flexure::scenes
