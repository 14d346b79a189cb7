// The other constraint-system types of the paper's appendix B: body-hinge and body-bar
// frameworks, angular frameworks, volume hypergraphs, spherical disk packings and frameworks on
// surfaces. Each is a Model: its constraint terms, its symmetry group (analytic generators, or
// for a surface its isometries found numerically once), and what to draw. Constructors throw
// ModelError pointing at the offending item; messages number vertices from `index_base`.
#pragma once

#include <array>
#include <Eigen/Core>
#include <memory>
#include <vector>

#include "engine/model.h"
#include "engine/terms.h"

namespace flexure::engine {

// Rigid bodies (vertex lists) sharing vertices (hinges), plus bars. type_name is "body_hinge"
// or "body_bar". Each body is rigid whatever its shape (flat, collinear, two vertices, one):
// a frame of up to d + 1 of its vertices spanning its affine hull is held by bars (a simplex,
// infinitesimally rigid in any dimension), and every other vertex is an affine combination of
// the frame (AffineCombinationTerm). Not the paper's complete graph K_n, which is not
// infinitesimally rigid on four coplanar points in 3D or three collinear ones in 2D and adds
// n(n-1)/2 - (dn - d(d+1)/2) dependent bars per body. Constraints an earlier body already
// imposes (the distance of a hinge's two vertices) are left out, so a hinge adds no stress.
// Bodies are drawn as polygons in the order given.
class BodyFramework : public Model {
 public:
  using Edge = std::array<int, 2>;
  BodyFramework(std::string type_name, const Matrix& points, std::vector<std::vector<int>> bodies,
                const std::vector<Edge>& bars, const std::vector<int>& pinned, int index_base = 1);
  std::string typeName() const override { return type_; }
  Matrix symmetryGenerators(const Matrix& positions) const override;
  Geometry geometry() const override;
  // The first body (rigid: a body, or a panel of a sheet) holding both vertices, or -1.
  int bodyHolding(int a, int b) const;

 private:
  struct Built;
  BodyFramework(std::string type_name, Built&& b);
  std::string type_;
  std::vector<std::vector<int>> bodies_;
  std::vector<Edge> drawn_;  // body boundaries and bars
};

// Angles (i, j, k) at j (AngleTerm). Symmetries: similarities.
class AngularFramework final : public Model {
 public:
  using Angle = std::array<int, 3>;
  AngularFramework(const Matrix& points, std::vector<Angle> angles, const std::vector<int>& pinned,
                   int index_base = 1);
  std::string typeName() const override { return "angular_framework"; }
  Matrix symmetryGenerators(const Matrix& positions) const override;
  // The pairwise distances divided by their mean (similarities keep ratios).
  Vector congruenceInvariants(const Matrix& positions) const override;
  // The 2D angle constraint is a quadratic polynomial; the 3D one is not.
  bool quadraticConstraints() const override { return system().dimension() == 2; }
  Geometry geometry() const override;
  // 2D: the first angle at x turned by more than 90 degrees from its start (-1: none). The 2D
  // equation |u||w| sin(theta0 - theta) = 0 also holds at theta0 + 180 degrees, reached when a
  // vertex passes through the angle's apex (an arm of length zero): a motion of the angles ends
  // before that.
  int turnedAngle(const Vector& x) const;
  std::function<bool(const Vector&)> admissibleFrom(const Vector& start) const override;
  std::string outsideReason(const Vector& y, int index_base) const override;

 private:
  std::vector<Angle> angles_;
  std::vector<std::array<double, 2>> start_cos_sin_;  // per angle
};

// Signed volumes of simplices (d + 1 vertices each, d = 2 or 3). Symmetries: equi-affine maps.
class VolumeHypergraph final : public Model {
 public:
  VolumeHypergraph(const Matrix& points, std::vector<std::vector<int>> simplices, const std::vector<int>& pinned,
                   int index_base = 1);
  std::string typeName() const override { return "volume_hypergraph"; }
  Matrix symmetryGenerators(const Matrix& positions) const override;
  // Signed volumes of the simplices on (d + 1)-subsets of the points (the first 20,000 in
  // lexicographic order), which equi-affine maps keep.
  Vector congruenceInvariants(const Matrix& positions) const override;
  // In 2D the volume (an area) is quadratic; in 3D it is cubic.
  bool quadraticConstraints() const override { return system().dimension() == 2; }
  Geometry geometry() const override;
  const std::vector<std::vector<int>>& simplices() const { return simplices_; }

 private:
  std::vector<std::vector<int>> simplices_;
};

// Caps on the unit sphere (points a, |a| > 1) whose contacts keep their inversive distances
// (InversiveDistanceTerm). Symmetries: the 6-dimensional Moebius group.
class SphericalDiskPacking final : public Model {
 public:
  using Contact = std::array<int, 2>;
  SphericalDiskPacking(const Matrix& points, std::vector<Contact> contacts, const std::vector<int>& pinned,
                       int index_base = 1);
  std::string typeName() const override { return "spherical_disk_packing"; }
  Matrix symmetryGenerators(const Matrix& positions) const override;
  // The inversive distances of all pairs of caps, which Moebius maps keep.
  Vector congruenceInvariants(const Matrix& positions) const override;
  bool quadraticConstraints() const override { return false; }
  Geometry geometry() const override;
  const std::vector<double>& inversiveDistances() const { return inversive_; }

 private:
  std::vector<Contact> contacts_;
  std::vector<double> inversive_;
};

// A bar-joint framework in R^3 with every vertex on the surface f = 0. Symmetries: the
// Euclidean motions tangent to the surface (its isometries), found once by sampling the surface
// near the start. With project_start, a start off the surface is first corrected onto the
// constraint set (keeping the bar lengths of the given realization); without it, a vertex off
// the surface is an error.
class FrameworkOnSurface final : public Model {
 public:
  using Edge = std::array<int, 2>;
  FrameworkOnSurface(const Matrix& points, std::vector<Edge> edges, const std::vector<int>& pinned,
                     std::shared_ptr<const ScalarField> surface, bool project_start, int index_base = 1);
  std::string typeName() const override { return "framework_on_surface"; }
  Matrix symmetryGenerators(const Matrix& positions) const override;
  // Quadratic when the surface is a quadric (f of degree at most 2): the bars are quadratic, and
  // so is L/|grad f(start)| * f. The second-order theory (prestress stability, second-order
  // rigidity) then applies as it does to bar frameworks.
  bool quadraticConstraints() const override { return quadratic_; }
  Geometry geometry() const override;
  // The isometries as (omega, t) columns: velocity omega x p + t, orthonormal.
  const Matrix& isometries() const { return killing_; }
  const ScalarField& surface() const { return *surface_; }

 private:
  struct Built;
  explicit FrameworkOnSurface(Built&& b);
  std::vector<Edge> edges_;
  std::shared_ptr<const ScalarField> surface_;
  Matrix killing_;  // 6 x k: (scale_ omega, t) about centre_
  Eigen::Vector3d centre_;
  double scale_;
  bool quadratic_;
};

}  // namespace flexure::engine
