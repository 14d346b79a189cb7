// The angles layer (angular frameworks): a sector at j for each angle (i, j, k), under the bars:
// the normalised lerp of the reference.
#include "present/layers/layers.h"

#include <algorithm>

#include <Eigen/Geometry>

namespace flexure::present::layers {

using render::Color;
using render::Point3;

void drawAngles(render::DrawList& out, const engine::Angles& angles, const engine::Matrix& p, const Pen& pen) {
  const FigureStyle& s = pen.s;
  const float line = pen.line;
  for (const auto& [i, j, k] : angles.triples) {
    const Eigen::Vector3d c(point(p, j).data()), u = Eigen::Vector3d(point(p, i).data()) - c,
                                                  w = Eigen::Vector3d(point(p, k).data()) - c;
    const double r = 0.3 * std::min(u.norm(), w.norm());
    if (!(r > 0)) continue;
    render::Polygon sector;
    sector.points.push_back({c[0], c[1], c[2]});
    std::vector<Point3> arc;
    for (int t = 0; t <= 20; ++t) {
      const double f = t / 20.0;
      Eigen::Vector3d q = (1 - f) * u.normalized() + f * w.normalized();
      if (q.norm() < 1e-9) continue;  // a straight angle: the lerp passes the centre
      q = c + r * q.normalized();
      arc.push_back({q[0], q[1], q[2]});
    }
    sector.points.insert(sector.points.end(), arc.begin(), arc.end());
    sector.fill = s.angle_color;
    sector.role = "angle";
    out.polygons.push_back(sector);
    Color stroke = s.angle_color;
    stroke.a = 1;
    for (size_t t = 0; t + 1 < arc.size(); ++t) {
      out.segment(arc[t], arc[t + 1], 0.5f * line, stroke);
      out.tag("angle");
    }
  }
}

}  // namespace flexure::present::layers
