// World to pixels: the 2D window with equal aspect, or the 3D box seen from azimuth and
// elevation (z up, as in the reference package), orthographic or perspective.
#pragma once

#include <array>

#include "render/draw_list.h"

namespace flexure::render {

class Projector {
 public:
  explicit Projector(const View& view);
  // Pixel x, pixel y (origin at the bottom left) and depth in [-1, 1] (smaller is nearer).
  std::array<double, 3> operator()(const Point3& p) const;
  // The world point that projects to pixel (px, py) (origin at the bottom left) in the plane
  // through `through` facing the viewer (2D: the plane of the picture).
  Point3 unproject(double px, double py, const Point3& through) const;
  // Pixels per world unit at the centre of the view (the local scale with perspective).
  double pixelsPerUnit() const { return scale_; }
  // Pixels per world unit (across the line of sight) at p: pixelsPerUnit() unless perspective.
  double pixelsPerUnitAt(const Point3& p) const;
  // Depth units per world unit along the line of sight.
  double depthPerUnit() const { return depth_scale_; }
  // The eye-space direction of a world vector (x right, y up, z towards the viewer).
  std::array<double, 3> toEye(const Point3& v) const;

 private:
  View view_;
  std::array<double, 3> centre_{}, right_{}, up_{}, toward_{};
  double scale_ = 1, depth_scale_ = 1, depth_mid_ = 0, offset_u_ = 0, offset_v_ = 0;
  double distance_ = 0, focal_ = 0;
};

}  // namespace flexure::render
