// A configuration as a solid for 3D printing or CAD: every bar a closed tube, every vertex a
// sphere (a packing's balls at their radii), each a closed triangle mesh of its own (slicers
// take the union of overlapping shells). Written as OBJ (one named object per part) or binary
// STL, in the scene's units; 2D scenes lie in the plane z = 0.
#pragma once

#include <string>

#include "engine/constraint_system.h"
#include "engine/geometry.h"
#include "scenes/style.h"

namespace flexure::present {

struct PrintMesh {
  std::vector<std::array<double, 3>> vertices;
  std::vector<std::array<int, 3>> triangles;  // counter-clockwise seen from outside
  struct Part {
    std::string name;    // "bar 1-2", "joint 3", "ball 4"
    int first_triangle;  // its triangles are [first_triangle, next part's)
  };
  std::vector<Part> parts;
};

// Tube radius tube * L and joint radius joint * L, with L the median bar length (the extent of
// the configuration when there are no bars). Vertex numbers in part names from `index_base`.
PrintMesh printMesh(const engine::Geometry& g, const engine::Matrix& positions, double tube, double joint,
                    int index_base);

// "obj" or "stl": the file's bytes.
std::string printMeshFile(const PrintMesh& mesh, const std::string& format, const std::string& title);

}  // namespace flexure::present
