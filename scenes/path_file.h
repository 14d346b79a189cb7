// A path JSON written by `flexure track -o PATH.json` read back as a scene: the scene it embeds
// ("scene", its TOML text) and the path it holds ("samples", "events", ...). Every sample is
// checked against the scene's constraints (a file that is not a path of its scene is refused at
// the sample, with the equation that fails); pinned vertices must stay where they are pinned.
#pragma once

#include <string>
#include <vector>

#include "scenes/scene.h"

namespace flexure::scenes {

// Whether `text` may be a path JSON (an object naming "samples" and "scene"): a quick look,
// before the text is parsed; isPathJson() decides on the parsed value.
bool looksLikePathJson(const std::string& text);

// The scene with `given` set; SceneError naming the array and index of what is wrong.
Scene loadPathJson(const std::string& file, const std::string& text, const std::vector<std::string>& overrides = {});

}  // namespace flexure::scenes
