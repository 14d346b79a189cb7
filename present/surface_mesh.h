// Triangles of an implicit surface f = 0 inside a box, for drawing (frameworks on surfaces):
// f is sampled on a regular grid and every grid cube is split into the 6 tetrahedra of its Kuhn
// triangulation (all sharing the cube's main diagonal, so neighbouring cubes match), each cut
// by the linear interpolant of f (marching tetrahedra: marching cubes without its ambiguous
// cases and without its 256-case table). The mesh is crack-free; it is clipped by the box.
#pragma once

#include <array>
#include <functional>
#include <vector>

namespace flexure::present {

using Triangle3 = std::array<std::array<double, 3>, 3>;

// `samples` cells per axis (>= 1). Non-finite values of f count as outside (f > 0).
std::vector<Triangle3> meshImplicitSurface(const std::function<double(const double*)>& f,
                                           const std::array<double, 3>& lo, const std::array<double, 3>& hi,
                                           int samples);

}  // namespace flexure::present
