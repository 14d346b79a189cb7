// The system types a [system] table can name, internal to the scene library. Each type is one
// SystemType value defined in its own scenes/systems/<type>.cpp and listed once, explicitly, in
// scenes/system_types.cpp (no self-registration: the scene library is static, and the linker
// would drop a file nothing refers to). The loader's dispatch, the list of types its messages
// name, the keys each type takes (scenes/keys.cpp, by name) and the vertex-number keys that
// Python rebases (keys.h indexKeysOf) all go through this list.
#pragma once

#include <toml++/toml.h>

#include <memory>
#include <string>
#include <vector>

#include "engine/model.h"

namespace flexure::scenes {

// Every `type` a [system] table takes, in the order messages list them: the system types,
// then the meta-type "catalog" (scenes/scene_catalog.cpp).
const std::vector<std::string>& systemTypeNames();

namespace detail {

class Reader;

struct SystemType {
  std::string name;             // [system] type = "name"
  std::vector<int> dimensions;  // the coordinates a vertex may have (2, 3)
  // The model of the [system] table `sys`, whose keys have been checked against
  // keysOf("system", name) and whose vertices are `p` (in one of `dimensions`). Vertex numbers
  // count from `base`. Problems fail at their node.
  std::unique_ptr<engine::Model> (*build)(const Reader& r, const toml::table& sys, int base, engine::Matrix p);
  std::string doc;  // one line: the constraints it keeps
};

// The system types, in the order of systemTypeNames().
const std::vector<SystemType>& systemTypes();

// The type called `name`, or nullptr (also for "catalog", which builds no model of its own).
const SystemType* findSystemType(const std::string& name);

}  // namespace detail

}  // namespace flexure::scenes
