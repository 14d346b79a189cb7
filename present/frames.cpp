#include "present/frames.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace flexure::present {

namespace {

// The diagonal of the configuration's bounding box: tolerances on positions are relative to it.
double extent(const engine::Matrix& p) {
  return p.cols() ? (p.rowwise().maxCoeff() - p.rowwise().minCoeff()).norm() : 0.0;
}

}  // namespace

std::vector<int> frameSamples(int sample_count, int step) {
  std::vector<int> out;
  step = std::max(1, step);
  for (int s = 0; s < sample_count; s += step) out.push_back(s);
  if (sample_count > 0 && out.back() != sample_count - 1) out.push_back(sample_count - 1);
  return out;
}

std::vector<int> fixedVertices(const Scene& scene) {
  if (scene.render.animation.fixed_vertices) return *scene.render.animation.fixed_vertices;
  const engine::Geometry g = scene.model->geometry();
  // Pins fix the picture; a surface or the unit sphere of caps is fixed in space, so moving the
  // configuration would take it off what is drawn with it.
  if (!g.pinned.empty() || g.points < 2 || !g.surface.empty() || !g.caps.empty()) return {};
  if (g.dimension == 2 || g.points < 3) return {0, 1};
  const engine::Matrix p = scene.model->system().vertexPositions(scene.model->startCoordinates());
  const Eigen::Vector3d a = p.col(0), b = p.col(1), c = p.col(2);
  const double scale = std::max({(b - a).norm(), (c - a).norm(), 1e-300});
  return (b - a).cross(c - a).norm() > 1e-6 * scale * scale ? std::vector<int>{0, 1, 2} : std::vector<int>{0, 1};
}

void alignConfigurations(std::vector<engine::Matrix>& frames, const std::vector<int>& fixed,
                         const std::vector<double>& direction, std::vector<DisplayMap>* maps) {
  if (maps) maps->assign(frames.size(), DisplayMap::identity(frames.empty() ? 0 : static_cast<int>(frames[0].rows())));
  if (fixed.size() < 2 || frames.empty()) return;
  const int d = static_cast<int>(frames[0].rows());
  size_t f = 0;
  if (d == 2) {
    const double target = direction.size() == 2 ? std::atan2(direction[1], direction[0]) : 0.0;
    double angle = 0;
    for (engine::Matrix& p : frames) {
      const Eigen::Vector2d a = p.col(fixed[0]), b = p.col(fixed[1]) - a;
      const double scale = extent(p);
      if (b.norm() > 1e-12 * scale) angle = target - std::atan2(b.y(), b.x());
      const Eigen::Matrix2d r = Eigen::Rotation2Dd(angle).toRotationMatrix();
      p = r * (p.colwise() - a);
      if (maps) (*maps)[f] = {r, -r * a};
      ++f;
    }
    return;
  }
  Eigen::Vector3d dir = Eigen::Vector3d::UnitX();
  if (direction.size() == 3) dir = Eigen::Vector3d(direction[0], direction[1], direction[2]).normalized();
  // The half-plane for the third vertex: e_y (or e_z when dir is along e_y) made orthogonal to dir.
  Eigen::Vector3d up = Eigen::Vector3d::UnitY() - dir.y() * dir;
  if (up.norm() < 1e-6) up = Eigen::Vector3d::UnitZ() - dir.z() * dir;
  up.normalize();
  Eigen::Matrix3d rot = Eigen::Matrix3d::Identity();
  for (engine::Matrix& p : frames) {
    const Eigen::Vector3d a = p.col(fixed[0]);
    const Eigen::Vector3d b = p.col(fixed[1]) - a;
    const double scale = extent(p);
    if (b.norm() > 1e-12 * scale) {
      Eigen::Matrix3d r = Eigen::Quaterniond::FromTwoVectors(b, dir).toRotationMatrix();
      if (fixed.size() >= 3) {
        const Eigen::Vector3d c = r * (p.col(fixed[2]) - a);
        const Eigen::Vector3d perp = c - c.dot(dir) * dir;
        if (perp.norm() > 1e-12 * scale) {
          const Eigen::Vector3d u = perp.normalized();
          const double angle = std::atan2(u.cross(up).dot(dir), u.dot(up));
          r = Eigen::AngleAxisd(angle, dir).toRotationMatrix() * r;
        } else {
          r = rot;  // collinear: keep the previous frame's rotation
        }
      }
      rot = r;
    }
    p = rot * (p.colwise() - a);
    if (maps) (*maps)[f] = {rot, -rot * a};
    ++f;
  }
}

std::vector<int> fixedSimplex(const Scene& scene) {
  const scenes::AnimationSettings& as = scene.render.animation;
  if (as.fixed_simplex) return *as.fixed_simplex;
  const engine::Geometry g = scene.model->geometry();
  if (g.simplices.empty() || !g.pinned.empty() || as.fixed_vertices) return {};
  return g.simplices.list.front();
}

void normalizeEquiAffine(std::vector<engine::Matrix>& frames, const std::vector<int>& simplex, double t,
                         double tip, std::vector<DisplayMap>* maps) {
  if (maps) maps->assign(frames.size(), DisplayMap::identity(frames.empty() ? 0 : static_cast<int>(frames[0].rows())));
  if (frames.empty() || static_cast<int>(simplex.size()) != frames[0].rows() + 1) return;
  const int d = static_cast<int>(frames[0].rows());
  for (size_t f = 0; f < frames.size(); ++f) {
    engine::Matrix& p = frames[f];
    engine::Matrix E(d, d);
    for (int k = 0; k < d; ++k) E.col(k) = p.col(simplex[static_cast<size_t>(k) + 1]) - p.col(simplex[0]);
    const double det = E.determinant();
    const double scale = std::pow(E.colwise().norm().prod(), 1.0 / d);
    if (!(std::abs(det) > 1e-12 * std::pow(scale, d))) continue;
    // The reference simplex: upper triangular, the given stretch and tips, det(R) = det(E).
    engine::Matrix R = engine::Matrix::Zero(d, d);
    for (int k = 0; k + 1 < d; ++k) R(k, k) = t;
    for (int i = 0; i < d; ++i)
      for (int j = i + 1; j < d; ++j) R(i, j) = tip;
    R(d - 1, d - 1) = det / std::pow(t, d - 1);
    const engine::Matrix M = R * E.inverse();  // det M = 1
    const engine::Vector a = p.col(simplex[0]);
    p = M * (p.colwise() - a);
    if (maps) (*maps)[f] = {M, -M * a};
  }
}

}  // namespace flexure::present
