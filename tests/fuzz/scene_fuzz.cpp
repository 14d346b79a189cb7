// libFuzzer target: any bytes as a scene file. A scene error is the expected answer to bad
// input; any other exception, crash, hang or sanitizer report is a bug.
#include <cstddef>
#include <cstdint>
#include <string>

#include "scenes/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const flexure::scenes::Scene scene = flexure::scenes::loadSceneFromString(text, "fuzz.toml");
    // What the loader accepted must be a consistent system.
    const auto& sys = scene.model->system();
    if (sys.numVertices() < 1 || (sys.dimension() != 2 && sys.dimension() != 3)) __builtin_trap();
  } catch (const flexure::scenes::SceneError&) {
  }
  return 0;
}
