// FOLD files (the origami community's JSON format, edemaine/fold doc/spec.md, version 1.2):
// what rigid origami needs of one frame (the file's top level, or one of its file_frames). Every problem is a SceneError
// naming the file, the array and the index (edges_assignment[5]), or the line and column of a
// JSON syntax error.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace flexure::scenes {

struct FoldSheet {
  std::vector<std::array<double, 3>> vertices;  // vertices_coords, missing trailing coordinates 0
  std::vector<std::vector<int>> faces;          // faces_vertices (or traced from a 2D crease pattern)
  std::vector<std::array<int, 2>> edges;        // edges_vertices (or the faces' sides)
  std::string assignments;                      // edges_assignment: one of B M V F U J per edge
  std::vector<double> fold_angles;              // edges_foldAngle (degrees), or empty
  bool traced_faces = false;                    // faces_vertices was missing: traced from the plane graph
};

// Reads frame `frame`: 0 is the file's top level, k >= 1 is file_frames[k - 1], with its
// parent's properties where it inherits them (frame_inherit, frame_parent). Without edges_vertices the edges are the faces' sides (B where one face has
// the side, U where two do); without edges_assignment every edge is U (B on the boundary);
// without faces_vertices a 2D crease pattern's faces are traced from its edges. Refused: non-
// planar faces, faces whose sides are no edges, unknown assignments (and C, cuts, which a sheet
// of shared vertices cannot hold), arrays of different lengths, indices out of range.
FoldSheet readFold(const std::string& text, const std::string& file, int frame = 0);

bool isFoldFile(const std::string& file);

}  // namespace flexure::scenes
