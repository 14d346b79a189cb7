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

struct MotionSettings;

// Every `type` a [system] table takes, in the order messages list them: the system types (those
// of scenes/systems/, then any ExtraSystemType alive), then the meta-type "catalog"
// (scenes/scene_catalog.cpp).
std::vector<std::string> systemTypeNames();

namespace detail {

class Reader;

struct SystemType {
  std::string name;             // [system] type = "name"
  std::vector<int> dimensions;  // the coordinates a vertex may have (2, 3)
  // The model of the [system] table `sys`, whose keys have been checked against
  // keysOf("system", name) and whose vertices are `p` (in one of `dimensions`). Vertex numbers
  // count from `base`. Problems fail at their node.
  std::unique_ptr<engine::Model> (*build)(const Reader& r, const toml::table& sys, int base, engine::Matrix p);
  std::string doc;          // one line: the constraints it keeps (paper, appendix B)
  std::string keys_doc;     // its keys beyond `vertices` and `pinned`, as documented
  std::string trivial_doc;  // its trivial motions (the symmetry group)
  // [system] keys of this type that the key table (scenes/keys.cpp) does not list: those of a
  // type defined outside the scene library (an ExtraSystemType); its build reads them.
  std::vector<std::string> own_keys = {};
  // Its fold drive ([motion] fold_crease with fold_angle, or fold_percent), where it folds
  // (origami): checks them against `model` (built by this type) and fills `m`; the loader has
  // checked what does not depend on the type (one drive, no flex). nullptr: no fold drive.
  void (*read_fold_drive)(const Reader& r, const toml::table& motion, const engine::Model& model, int base,
                          MotionSettings& m) = nullptr;
};

// The system types, in the order of systemTypeNames().
const std::vector<SystemType>& systemTypes();

// The type called `name`, or nullptr (also for "catalog", which builds no model of its own).
const SystemType* findSystemType(const std::string& name);

// A system type defined outside scenes/systems/ (a test's toy type, a front end's own), a
// [system] type for as long as this value lives: one line adds it, no file of the library
// changes. It takes the key table's keys for every type ("vertices", "pinned", ...) and its
// own_keys. Not thread-safe: make it before loading scenes on other threads.
class ExtraSystemType {
 public:
  explicit ExtraSystemType(SystemType type);
  ~ExtraSystemType();
  ExtraSystemType(const ExtraSystemType&) = delete;
  ExtraSystemType& operator=(const ExtraSystemType&) = delete;

 private:
  std::string name_;
};

}  // namespace detail

}  // namespace flexure::scenes
