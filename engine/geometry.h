// What a configuration is made of, for whoever draws it (present/figure.cpp): indices into the
// columns of the positions matrix (system().positions(x)), no rendering types. The drawing is
// grouped into typed layers; each model type fills the layers it has (an empty layer is not
// drawn), and says through them how they look, so that whoever draws never asks for the type.
// present/layers/<layer>.cpp draws each one.
#pragma once

#include <array>
#include <vector>

namespace flexure::engine {

class ScalarField;

// The vertices themselves: how each point is marked, and whether it is numbered.
struct Vertices {
  enum class Look {
    Disc,  // a disc at every vertex (the joints of a framework)
    Dot,   // a small dot: the sheet is the picture, not its vertices (origami)
    None,  // no mark: another layer shows the points (balls, caps)
  };
  Look look = Look::Disc;
  bool numbered = true;  // auto_labels may number the vertices (origami: false, the sheet reads better without)
};

// Segments between two vertices, drawn by their role.
struct Bars {
  enum class Role {
    Plain,    // framework bars
    Contact,  // the contact graph of balls, under them
    Apex,     // the contact graph of caps, joining the cones' apices a
    Crease,   // origami creases, each drawn by its FOLD assignment (kinds)
    Outline,  // the edges of simplices, drawn as their dashed outlines (not again as bars)
  };
  std::vector<std::array<int, 2>> edges;
  Role role = Role::Plain;
  // Crease: per edge, its FOLD assignment (B boundary, M mountain, V valley, F flat, U
  // unassigned, J join); empty for every other role.
  std::vector<char> kinds;
  bool empty() const { return edges.empty(); }
};

// Planar polygons, cyclic vertex lists, translucent under the bars.
struct Facets {
  std::vector<std::vector<int>> polygons;
  bool panels = false;  // the panels of a paper sheet (origami): the panel colour
  bool empty() const { return polygons.empty(); }
};

// Angles (i, j, k): the angle at j, drawn as a sector.
struct Angles {
  std::vector<std::array<int, 3>> triples;
  bool empty() const { return triples.empty(); }
};

// Volume hypergraphs: d + 1 vertices each, translucent faces and dashed outlines.
struct Simplices {
  std::vector<std::vector<int>> list;
  bool empty() const { return list.empty(); }
};

// Sphere (disk) packings: a ball of its radius around every point.
struct Balls {
  std::vector<double> radii;  // one per point
  bool empty() const { return radii.empty(); }
};

// The points are caps of the unit sphere (a.y = 1): the sphere and each cap's circle.
struct Caps {
  bool on = false;
  bool empty() const { return !on; }
};

// The surface the points live on.
struct Surface {
  const ScalarField* field = nullptr;
  bool empty() const { return !field; }
};

struct Geometry {
  int dimension = 2;
  int points = 0;            // vertices (columns of the positions)
  std::vector<int> pinned;
  Vertices vertices;
  Bars bars;
  Facets facets;
  Angles angles;
  Simplices simplices;
  Balls balls;
  Caps caps;
  Surface surface;
};

}  // namespace flexure::engine
