// The caps layer (spherical disk packings): the unit sphere, each cap's circle (centre a / |a|^2,
// radius sqrt(1 - 1/|a|^2), in the plane a . y = 1); the contact graph joining the cones'
// apices a is the bars layer (role Apex), drawn between the two.
#include "present/layers/layers.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace flexure::present::layers {

using render::Color;
using render::Point3;

void drawSphere(render::DrawList& out, const engine::Caps& caps, const Pen& pen) {
  if (caps.empty()) return;
  const FigureStyle& s = pen.s;
  out.disc({0, 0, 0}, 1, s.sphere_color);
  out.tag("sphere");
  out.shapes.back().world_radius = 0.99;  // just inside the circles on its front: no z-fighting
  out.shapes.back().shaded = true;
}

void drawCaps(render::DrawList& out, const engine::Caps& caps, int points, const engine::Matrix& p, const Pen& pen) {
  if (caps.empty()) return;
  const FigureStyle& s = pen.s;
  const float line = pen.line;
  for (int i = 0; i < points; ++i) {
    const Eigen::Vector3d a(point(p, i).data());
    const double n2 = a.squaredNorm();
    if (!(n2 > 1)) continue;
    const Eigen::Vector3d c = a / n2, e = a.normalized();
    const Eigen::Vector3d e1 = e.unitOrthogonal(), e2 = e.cross(e1);
    const double rho = std::sqrt(1 - 1 / n2);
    Point3 prev{};
    for (int t = 0; t <= 64; ++t) {
      const double phi = 2 * M_PI * t / 64;
      const Eigen::Vector3d q = c + rho * (std::cos(phi) * e1 + std::sin(phi) * e2);
      const Point3 cur{q[0], q[1], q[2]};
      // Drawn as (barely) translucent: sorted with the sphere and not writing depth, so the
      // anti-aliased fringe of one piece never hides the next one behind it.
      Color cap = s.cap_color;
      cap.a = std::min(cap.a, 0.99f);
      if (t > 0) {
        out.segment(prev, cur, 0.75f * line, cap);
        out.tag("cap");
      }
      prev = cur;
    }
  }
}

}  // namespace flexure::present::layers
