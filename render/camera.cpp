#include "render/camera.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace flexure::render {

namespace {
double dot(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
}  // namespace

Projector::Projector(const View& v) : view_(v) {
  for (int i = 0; i < 3; ++i) centre_[i] = 0.5 * (v.lo[i] + v.hi[i]);
  if (!v.three_d) {
    const double w = std::max(v.hi[0] - v.lo[0], 1e-300), h = std::max(v.hi[1] - v.lo[1], 1e-300);
    scale_ = std::min(v.width / w, v.height / h) * (v.zoom > 0 ? v.zoom : 1.0);
    depth_scale_ = 0;
    return;
  }
  const double ca = std::cos(v.azimuth), sa = std::sin(v.azimuth);
  const double ce = std::cos(v.elevation), se = std::sin(v.elevation);
  toward_ = {ce * ca, ce * sa, se};
  right_ = {-sa, ca, 0};
  up_ = {-se * ca, -se * sa, ce};
  double umin = std::numeric_limits<double>::infinity(), umax = -umin, vmin = umin, vmax = -umin;
  double wmin = umin, wmax = -umin, radius = 0;
  for (int c = 0; c < 8; ++c) {
    std::array<double, 3> d;
    for (int i = 0; i < 3; ++i) d[i] = ((c >> i) & 1 ? v.hi[i] : v.lo[i]) - centre_[i];
    const double u = dot(d, right_), vv = dot(d, up_), w = dot(d, toward_);
    umin = std::min(umin, u), umax = std::max(umax, u);
    vmin = std::min(vmin, vv), vmax = std::max(vmax, vv);
    wmin = std::min(wmin, w), wmax = std::max(wmax, w);
    radius = std::max(radius, std::sqrt(dot(d, d)));
  }
  radius = std::max(radius, 1e-300);
  if (v.perspective) {
    focal_ = 1.0 / std::tan(0.5 * v.field_of_view);
    distance_ = 1.1 * radius * focal_;
    // Fit the bounding sphere: at the near side it spans radius * focal / (distance - radius).
    scale_ = 0.5 * std::min(v.width, v.height) * (distance_ - radius) / radius;
    offset_u_ = offset_v_ = 0;
  } else if (v.turntable) {
    // Every azimuth: the horizontal extent is within the box's circle about the z axis.
    double rxy = 0, hz = 0.5 * (v.hi[2] - v.lo[2]);
    for (int c = 0; c < 4; ++c) {
      const double dx = ((c & 1) ? v.hi[0] : v.lo[0]) - centre_[0], dy = ((c & 2) ? v.hi[1] : v.lo[1]) - centre_[1];
      rxy = std::max(rxy, std::hypot(dx, dy));
    }
    const double vr = std::abs(se) * rxy + ce * hz;
    scale_ = std::min(v.width / std::max(2 * rxy, 1e-300), v.height / std::max(2 * vr, 1e-300));
    offset_u_ = offset_v_ = 0;
  } else {
    scale_ = std::min(v.width / std::max(umax - umin, 1e-300), v.height / std::max(vmax - vmin, 1e-300));
    offset_u_ = 0.5 * (umin + umax);
    offset_v_ = 0.5 * (vmin + vmax);
  }
  scale_ *= v.zoom > 0 ? v.zoom : 1.0;
  // Depth: the box's extent plus a margin (ball impostors reach out of it) mapped to [-0.8, 0.8].
  const double extent = std::max(wmax - wmin, 1e-300);
  depth_mid_ = 0.5 * (wmin + wmax);
  depth_scale_ = 1.6 / extent;
}

std::array<double, 3> Projector::toEye(const Point3& d) const {
  if (!view_.three_d) return {d[0], d[1], d[2]};
  std::array<double, 3> a{d[0], d[1], d[2]};
  return {dot(a, right_), dot(a, up_), dot(a, toward_)};
}

double Projector::pixelsPerUnitAt(const Point3& p) const {
  if (!view_.three_d || !view_.perspective) return scale_;
  std::array<double, 3> d;
  for (int i = 0; i < 3; ++i) d[i] = p[i] - centre_[i];
  return scale_ * distance_ / std::max(distance_ - dot(d, toward_), 1e-9 * distance_);
}

Point3 Projector::unproject(double px, double py, const Point3& through) const {
  if (!view_.three_d)
    return {centre_[0] + (px - 0.5 * view_.width - view_.pan_x) / scale_,
            centre_[1] + (py - 0.5 * view_.height - view_.pan_y) / scale_, through[2]};
  std::array<double, 3> d;
  for (int i = 0; i < 3; ++i) d[i] = through[i] - centre_[i];
  const double w = dot(d, toward_);
  double k = 1;
  if (view_.perspective) k = distance_ / std::max(distance_ - w, 1e-9 * distance_);
  const double u = (px - 0.5 * view_.width - view_.pan_x) / (scale_ * k) + offset_u_;
  const double v = (py - 0.5 * view_.height - view_.pan_y) / (scale_ * k) + offset_v_;
  Point3 out;
  for (int i = 0; i < 3; ++i) out[i] = centre_[i] + u * right_[i] + v * up_[i] + w * toward_[i];
  return out;
}

std::array<double, 3> Projector::operator()(const Point3& p) const {
  if (!view_.three_d)
    return {0.5 * view_.width + view_.pan_x + scale_ * (p[0] - centre_[0]),
            0.5 * view_.height + view_.pan_y + scale_ * (p[1] - centre_[1]), 0.0};
  std::array<double, 3> d;
  for (int i = 0; i < 3; ++i) d[i] = p[i] - centre_[i];
  double u = dot(d, right_) - offset_u_, v = dot(d, up_) - offset_v_;
  const double w = dot(d, toward_);
  if (view_.perspective) {
    const double k = distance_ / std::max(distance_ - w, 1e-9 * distance_);
    u *= k, v *= k;
  }
  const double depth = std::clamp(-(w - depth_mid_) * depth_scale_, -1.0, 1.0);
  return {0.5 * view_.width + view_.pan_x + scale_ * u, 0.5 * view_.height + view_.pan_y + scale_ * v, depth};
}

}  // namespace flexure::render
