// libFuzzer target: any bytes as a graph6/sparse6 file, an edge list, node-link JSON, or an OFF,
// OBJ or STL mesh (the first byte picks the format; 0xFF: a path JSON with its scene; 0xFE: a
// FOLD file; 0xFD: a FOLD file's frame, the second byte's value mod 8; 0xFC: NumPy's .npz or .npy).
// A SceneError is the expected answer to bad input; any other
// exception, crash, hang or sanitizer report is a bug.
#include <cstddef>
#include <cstdint>
#include <string>

#include "scenes/fold_file.h"
#include "scenes/importers.h"
#include "scenes/npz_file.h"
#include "scenes/path_file.h"
#include "scenes/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
  using namespace flexure::scenes;
  try {
    if (data[0] == 0xFF) {
      const Scene scene = loadPathJson("fuzz.json", text);
      if (!scene.given || scene.given->path.samples.empty()) __builtin_trap();
      return 0;
    }
    if (data[0] == 0xFC) {
      for (const auto& a : detail::readNumpyBytes(text, "fuzz.npz")) {
        size_t count = 1;
        for (size_t n : a.shape) count *= n;
        if (a.values.size() != count) __builtin_trap();
      }
      return 0;
    }
    if (data[0] == 0xFE || (data[0] == 0xFD && size > 1)) {
      const bool framed = data[0] == 0xFD;
      const FoldSheet f = framed ? readFold(text.substr(1), "fuzz.fold", data[1] % 8) : readFold(text, "fuzz.fold");
      const int n = static_cast<int>(f.vertices.size());
      for (const auto& face : f.faces)
        for (int v : face)
          if (v < 0 || v >= n || face.size() < 3) __builtin_trap();
      for (const auto& e : f.edges)
        if (e[0] < 0 || e[1] < 0 || e[0] >= n || e[1] >= n || e[0] == e[1]) __builtin_trap();
      if (f.assignments.size() != f.edges.size()) __builtin_trap();
      return 0;
    }
    const auto check = [](const ImportedGraph& g) {
      for (const auto& e : g.edges)
        if (e[0] < 0 || e[1] >= g.vertices || e[0] >= e[1]) __builtin_trap();
      if (!g.positions.empty() && static_cast<int>(g.positions.size()) != g.vertices) __builtin_trap();
    };
    switch (data[0] % 6) {
      case 0: {
        for (const ImportedGraph& g : readGraph6(text, "fuzz.g6")) check(g);
        break;
      }
      case 4: check(readEdgeList(text, "fuzz.edges")); break;
      case 5: check(readNodeLink(text, "fuzz.json")); break;
      default: {
        const ImportedMesh m = data[0] % 4 == 1 ? readOff(text, "fuzz.off")
                               : data[0] % 4 == 2 ? readObj(text, "fuzz.obj")
                                                  : readStl(text, "fuzz.stl");
        for (const auto& f : m.faces)
          for (int v : f)
            if (v < 0 || v >= static_cast<int>(m.vertices.size())) __builtin_trap();
      }
    }
  } catch (const SceneError&) {
  }
  return 0;
}
