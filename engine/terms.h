// Concrete constraint terms. Each has an analytic Jacobian and second derivative, tested
// against finite differences in tests/engine/terms_test.cpp.
#pragma once

#include <array>

#include "engine/constraint_system.h"

namespace flexure::engine {

// ||x_a - x_b||^2 - length^2 = 0 (the paper's squared form; residual units are length^2).
class SquaredDistanceTerm final : public ConstraintTerm {
 public:
  SquaredDistanceTerm(int a, int b, double squared_length)
      : ConstraintTerm({a, b}), squared_length_(squared_length) {}
  int numResiduals() const override { return 1; }
  void evaluate(const double* x, int d, double* residuals, double* jacobian) const override;
  void secondDerivative(const double* x, const double* u, const double* w, int d,
                        double* out) const override;
  std::string label(int row, int index_base) const override;
  double residualScale() const override { return squared_length_; }
  double squaredLength() const { return squared_length_; }

 private:
  double squared_length_;
};

}  // namespace flexure::engine

namespace flexure::engine {

// Facet planarity with a normal block n (paper B.2): n . (x_v - x_a) = 0 for the facet's
// anchor vertex a and another vertex v. Bilinear, and regular wherever the facet is a proper
// polygon (unlike the polar form n . x = 1, singular for planes through the origin).
// Blocks: {normal, a, v}. Residual units: length.
class FacetPlaneTerm final : public ConstraintTerm {
 public:
  FacetPlaneTerm(int normal, int a, int v, int facet, double scale)
      : ConstraintTerm({normal, a, v}), facet_(facet), scale_(scale) {}
  int numResiduals() const override { return 1; }
  void evaluate(const double* x, int d, double* residuals, double* jacobian) const override;
  void secondDerivative(const double* x, const double* u, const double* w, int d,
                        double* out) const override;
  std::string label(int row, int index_base) const override;
  double residualScale() const override { return scale_; }

 private:
  int facet_;
  double scale_;
};

// ||n||^2 - length^2 = 0 for an auxiliary normal vector of fixed length (a facet normal).
// Polytopes give their normals the length of the polytope, so that every variable is a length
// and the tracker's steps, measured over all of them, mean the same at every unit of length.
class UnitNormTerm final : public ConstraintTerm {
 public:
  UnitNormTerm(int block, int facet, double length = 1.0)
      : ConstraintTerm({block}), facet_(facet), length_(length) {}
  double residualScale() const override { return length_ * length_; }
  int numResiduals() const override { return 1; }
  void evaluate(const double* x, int d, double* residuals, double* jacobian) const override;
  void secondDerivative(const double* x, const double* u, const double* w, int d,
                        double* out) const override;
  std::string label(int row, int index_base) const override;

 private:
  int facet_;
  double length_;
};

// A vertex held in the frame of others: scale * (x_v - sum_j weights_j x_{b_j}) = 0, d residuals,
// with affine weights (summing to 1), so the term commutes with every rigid motion (and every
// affine map). Blocks: {v, b_1, ..., b_k}. Linear: the second derivative is zero. `scale` (a
// length: the body's size) gives the residuals the units of the squared-distance terms (length^2)
// and Jacobian entries of the same size. A rigid body is a simplex of bars with its other vertices
// held this way: rigid whatever its shape, flat or collinear.
class AffineCombinationTerm final : public ConstraintTerm {
 public:
  AffineCombinationTerm(int dimension, std::vector<int> blocks, std::vector<double> weights, double scale,
                        std::string owner)
      : ConstraintTerm(std::move(blocks)), d_(dimension), weights_(std::move(weights)), scale_(scale),
        owner_(std::move(owner)) {}
  int numResiduals() const override { return d_; }
  void evaluate(const double* x, int d, double* residuals, double* jacobian) const override;
  void secondDerivative(const double* x, const double* u, const double* w, int d,
                        double* out) const override;
  std::string label(int row, int index_base) const override;
  double residualScale() const override { return scale_ * scale_; }
  const std::vector<double>& weights() const { return weights_; }

 private:
  int d_;
  std::vector<double> weights_;  // one per frame block
  double scale_;
  std::string owner_;  // e.g. "body 2"
};

// A point attached to a frame of two or three other vertices (a coupler point, a point of a
// ternary link, a point at a fixed ratio along a bar): with e1 = x_b - x_a, e2 = x_c - x_a,
//   2D, frame {a, b}:    x_v = x_a + s e1 + t J e1          (J the quarter turn)
//   3D, frame {a, b}:    x_v = x_a + s e1                   (on the bar's line; t must be 0)
//   2D, frame {a, b, c}: x_v = x_a + s e1 + t e2
//   3D, frame {a, b, c}: x_v = x_a + s e1 + t e2 + u e1 x e2
// d residuals, scale * (x_v - that), linear but for the cross product. Blocks {v, a, b(, c)}.
// Residual units: length times scale.
class FramePointTerm final : public ConstraintTerm {
 public:
  FramePointTerm(int dimension, std::vector<int> blocks, std::array<double, 3> coefficients, double scale);
  int numResiduals() const override { return d_; }
  void evaluate(const double* x, int d, double* residuals, double* jacobian) const override;
  void secondDerivative(const double* x, const double* u, const double* w, int d,
                        double* out) const override;
  std::string label(int row, int index_base) const override;
  double residualScale() const override { return scale_ * scale_; }

 private:
  int d_;
  std::array<double, 3> c_;  // s, t, u
  double scale_;
};

// Signed volume of a simplex: det[x_1 - x_0, ..., x_d - x_0] - target = 0 (d! times the signed
// volume; orientation is kept). d + 1 blocks, d = 2 or 3. Residual units: length^d.
class SimplexVolumeTerm final : public ConstraintTerm {
 public:
  // factor multiplies the residual (and its derivatives): 1/length makes a flatness condition
  // (target 0) a residual in length^2, the units of the distance terms beside it.
  SimplexVolumeTerm(std::vector<int> blocks, double target, double scale, double factor = 1.0)
      : ConstraintTerm(std::move(blocks)), target_(target), scale_(scale), factor_(factor) {}
  int numResiduals() const override { return 1; }
  void evaluate(const double* x, int d, double* residuals, double* jacobian) const override;
  void secondDerivative(const double* x, const double* u, const double* w, int d,
                        double* out) const override;
  std::string label(int row, int index_base) const override;
  double residualScale() const override { return scale_; }

 private:
  double target_;
  double scale_;
  double factor_;
};

// The angle at vertex j between the arms to i and k, blocks {i, j, k}, u = x_i - x_j,
// w = x_k - x_j, with the start's cos c0 and sin s0 (2D: signed, from the cross product).
//  2D: s0 (u . w) - c0 (u x w) = |u||w| sin(theta0 - theta): a quadratic polynomial, regular
//      at every angle, keeping the orientation of the angle (theta0 + pi is the other branch).
//  3D: u . w - c0 |u||w| (algebraic, not polynomial; regular unless the angle is 0 or pi).
// Residual units: length^2.
class AngleTerm final : public ConstraintTerm {
 public:
  AngleTerm(int i, int j, int k, double cos0, double sin0, double scale)
      : ConstraintTerm({i, j, k}), c0_(cos0), s0_(sin0), scale_(scale) {}
  int numResiduals() const override { return 1; }
  void evaluate(const double* x, int d, double* residuals, double* jacobian) const override;
  void secondDerivative(const double* x, const double* u, const double* w, int d,
                        double* out) const override;
  std::string label(int row, int index_base) const override;
  double residualScale() const override { return scale_; }

 private:
  double c0_, s0_, scale_;
};

// Inversive distance of two caps of the unit sphere (3D), each a point a with |a| > 1 standing
// for the plane a . y = 1: with the Lorentz product <a, b> = a . b - 1,
//   <a, b> - I sqrt(<a, a> <b, b>) = 0,
// which keeps the sign of I (the reference squares it away) and is regular for caps.
class InversiveDistanceTerm final : public ConstraintTerm {
 public:
  InversiveDistanceTerm(int a, int b, double inversive_distance)
      : ConstraintTerm({a, b}), I_(inversive_distance) {}
  int numResiduals() const override { return 1; }
  void evaluate(const double* x, int d, double* residuals, double* jacobian) const override;
  void secondDerivative(const double* x, const double* u, const double* w, int d,
                        double* out) const override;
  std::string label(int row, int index_base) const override;

 private:
  double I_;
};

// A smooth scalar field f: R^3 -> R with its gradient and Hessian (the surface of a framework on
// a surface). Implementations must be exact (e.g. automatic differentiation).
class ScalarField {
 public:
  virtual ~ScalarField() = default;
  virtual double value(const double* x) const = 0;
  // Writes f, grad f (3) and, when hessian != nullptr, the 3x3 Hessian (row-major).
  virtual void evaluate(const double* x, double* f, double* gradient, double* hessian) const = 0;
  virtual std::string text() const = 0;
};

// factor * f(x_v) = 0: vertex v on the surface. Frameworks on surfaces take factor = L / |grad f|
// at the start (L the framework's extent): the residual is then about L times the distance from
// the surface, a length^2 like the edges' residuals, and the rows are as large as theirs, at
// every unit of length and whatever the scale of f.
class SurfaceTerm final : public ConstraintTerm {
 public:
  SurfaceTerm(int v, std::shared_ptr<const ScalarField> f, double scale, double factor = 1.0)
      : ConstraintTerm({v}), f_(std::move(f)), scale_(scale), factor_(factor) {}
  int numResiduals() const override { return 1; }
  void evaluate(const double* x, int d, double* residuals, double* jacobian) const override;
  void secondDerivative(const double* x, const double* u, const double* w, int d,
                        double* out) const override;
  std::string label(int row, int index_base) const override;
  double residualScale() const override { return scale_; }

 private:
  std::shared_ptr<const ScalarField> f_;
  double scale_;
  double factor_;
};

}  // namespace flexure::engine
