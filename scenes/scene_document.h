// A scene from a parsed TOML document rather than from text: what a sweep does for each item
// of a `[sweep]` scene (the document, with the item's values set, is validated like a file).
#pragma once

#include <toml++/toml.h>

#include <string>
#include <vector>

#include "scenes/scene.h"

namespace flexure::scenes {

// `doc` as the scene file `source_name` (messages name that file and the nodes' lines).
Scene loadSceneFromDocument(toml::table doc, const std::string& source_name,
                            const std::vector<std::string>& overrides = {});

}  // namespace flexure::scenes
