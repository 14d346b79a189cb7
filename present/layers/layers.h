// Internal to present/: the drawing of each layer of an engine::Geometry, one file per layer
// (present/layers/<layer>.cpp). figure() (present/figure.cpp) calls them in a fixed order, the
// order of the primitives in the DrawList, which decides the picture: facets, angles,
// simplices, the sphere of caps, bars, caps, balls, then pins, vertices and labels. A layer
// that is empty draws nothing.
#pragma once

#include <vector>

#include "engine/constraint_system.h"
#include "engine/geometry.h"
#include "render/draw_list.h"
#include "scenes/style.h"

namespace flexure::present::layers {

using scenes::FigureStyle;
using scenes::PartStyle;

inline render::Point3 point(const engine::Matrix& p, int i) {
  return {p(0, i), p(1, i), p.rows() > 2 ? p(2, i) : 0.0};
}

// What every layer draws with: the style and the sizes derived from it in pixels.
struct Pen {
  const FigureStyle& s;
  double px;        // pixels per unit of the style's sizes
  float line;       // the bar width
  float vr;         // the vertex disc's radius
  bool three_d;
};

// facets.cpp: translucent polygons, under the bars.
void drawFacets(render::DrawList& out, const engine::Facets& facets, const engine::Matrix& p, const Pen& pen);
// angles.cpp: a sector at the middle vertex of each triple, under the bars.
void drawAngles(render::DrawList& out, const engine::Angles& angles, const engine::Matrix& p, const Pen& pen);
// simplices.cpp: translucent faces and dashed outlines, one colour each.
void drawSimplices(render::DrawList& out, const engine::Simplices& simplices, const engine::Matrix& p, const Pen& pen);
// caps.cpp: the unit sphere (under the bars), then each cap's circle (over them).
void drawSphere(render::DrawList& out, const engine::Caps& caps, const Pen& pen);
void drawCaps(render::DrawList& out, const engine::Caps& caps, int points, const engine::Matrix& p, const Pen& pen);
// bars.cpp: the segments, by their role.
void drawBars(render::DrawList& out, const engine::Bars& bars, const engine::Matrix& p, const Pen& pen);
// balls.cpp: a ball of its radius at every point, translucent over the contact graph.
void drawBalls(render::DrawList& out, const engine::Balls& balls, int points, const engine::Matrix& p, const Pen& pen);
// vertices.cpp: the pins, the vertex marks and the vertex numbers.
void drawPins(render::DrawList& out, const engine::Geometry& g, const engine::Matrix& p, const Pen& pen);
void drawVertices(render::DrawList& out, const engine::Geometry& g, const engine::Matrix& p, const Pen& pen);
void drawLabels(render::DrawList& out, const engine::Geometry& g, const engine::Matrix& p, const Pen& pen);

}  // namespace flexure::present::layers
