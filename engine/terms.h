// Concrete constraint terms, each listed once in engine/term_list.h. Each writes its formula
// once, as a template on the number type (residual<T>, defined at the end of this file), and
// keeps hand-written double derivatives as the fast path; tests/engine/terms_test.cpp checks
// both against finite differences and against each other.
#pragma once

#include <array>
#include <stdexcept>

#include "engine/constraint_system.h"
#include "engine/jet.h"

namespace flexure::engine {

// ||x_a - x_b||^2 - length^2 = 0 (the paper's squared form; residual units are length^2).
class SquaredDistanceTerm final : public ConstraintTerm {
 public:
  // A given squared length (a target, a sum of radii squared).
  SquaredDistanceTerm(int a, int b, double squared_length)
      : ConstraintTerm({a, b}), squared_length_(squared_length) {}
  // The squared length that a and b have in `start` (columns are blocks): the formula computes it
  // from the start in its own arithmetic.
  static std::unique_ptr<SquaredDistanceTerm> atStart(int a, int b, const Matrix& start) {
    auto t = std::make_unique<SquaredDistanceTerm>(a, b, (start.col(a) - start.col(b)).squaredNorm());
    t->from_start_ = true;
    return t;
  }
  int numResiduals() const override { return 1; }
  int degree(int) const override { return 2; }
  void accept(TermVisitor& visitor) const override { visitor.visit(*this); }
  template <class T>
  void residual(const T* x0, const T* x, int d, T* r) const;
  void evaluate(const double* x, int d, double* residuals, double* jacobian) const override;
  void secondDerivative(const double* x, const double* u, const double* w, int d,
                        double* out) const override;
  std::string label(int row, int index_base) const override;
  double residualScale() const override { return squared_length_; }
  double squaredLength() const { return squared_length_; }

 private:
  double squared_length_;
  bool from_start_ = false;
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
  int degree(int) const override { return 2; }
  void accept(TermVisitor& visitor) const override { visitor.visit(*this); }
  template <class T>
  void residual(const T* x0, const T* x, int d, T* r) const;
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
  int degree(int) const override { return 2; }
  void accept(TermVisitor& visitor) const override { visitor.visit(*this); }
  template <class T>
  void residual(const T* x0, const T* x, int d, T* r) const;
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
  int degree(int) const override { return 1; }
  double rowWeight() const override { return scale_; }
  void accept(TermVisitor& visitor) const override { visitor.visit(*this); }
  template <class T>
  void residual(const T* x0, const T* x, int d, T* r) const;
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
  int degree(int d) const override { return blocks().size() == 4 && d == 3 ? 2 : 1; }
  double rowWeight() const override { return scale_; }
  void accept(TermVisitor& visitor) const override { visitor.visit(*this); }
  template <class T>
  void residual(const T* x0, const T* x, int d, T* r) const;
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
  SimplexVolumeTerm(std::vector<int> blocks, double target, double scale, double factor = 1.0,
                    bool target_from_start = false)
      : ConstraintTerm(std::move(blocks)), target_(target), scale_(scale), factor_(factor),
        from_start_(target_from_start) {}
  int numResiduals() const override { return 1; }
  int degree(int d) const override { return d; }
  double rowWeight() const override { return factor_; }
  void accept(TermVisitor& visitor) const override { visitor.visit(*this); }
  template <class T>
  void residual(const T* x0, const T* x, int d, T* r) const;
  void evaluate(const double* x, int d, double* residuals, double* jacobian) const override;
  void secondDerivative(const double* x, const double* u, const double* w, int d,
                        double* out) const override;
  std::string label(int row, int index_base) const override;
  double residualScale() const override { return scale_; }

 private:
  double target_;  // what the start has where from_start_: the formula then computes it
  double scale_;
  double factor_;
  bool from_start_;
};

// The angle at vertex j between the arms to i and k, blocks {i, j, k}, u = x_i - x_j,
// w = x_k - x_j, with the start's cos c0 and sin s0 (2D: signed, from the cross product).
//  2D: s0 (u . w) - c0 (u x w) = |u||w| sin(theta0 - theta): a quadratic polynomial, regular
//      at every angle, keeping the orientation of the angle (theta0 + pi is the other branch).
//  3D: u . w - c0 |u||w| (algebraic, not polynomial; regular unless the angle is 0 or pi).
// Residual units: length^2. `scale` is |u0||w0| at the start. The formula (residual<T>) is the
// same times |u0||w0|, with S0 = u0 x w0 and C0 = u0 . w0 from the start: in 2D
// S0 (u . w) - C0 (u x w), whose coefficients are rational where the start is; its row weight
// 1 / scale gives back the double path's residual.
class AngleTerm final : public ConstraintTerm {
 public:
  AngleTerm(int i, int j, int k, double cos0, double sin0, double scale)
      : ConstraintTerm({i, j, k}), c0_(cos0), s0_(sin0), scale_(scale) {}
  int numResiduals() const override { return 1; }
  int degree(int d) const override { return d == 2 ? 2 : -1; }
  double rowWeight() const override { return 1.0 / scale_; }
  void accept(TermVisitor& visitor) const override { visitor.visit(*this); }
  template <class T>
  void residual(const T* x0, const T* x, int d, T* r) const;
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
  int degree(int) const override { return -1; }
  void accept(TermVisitor& visitor) const override { visitor.visit(*this); }
  template <class T>
  void residual(const T* x0, const T* x, int d, T* r) const;
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
  // `degree`: f's degree as a polynomial where it is known (2 for a quadric), else -1.
  SurfaceTerm(int v, std::shared_ptr<const ScalarField> f, double scale, double factor = 1.0, int degree = -1)
      : ConstraintTerm({v}), f_(std::move(f)), scale_(scale), factor_(factor), degree_(degree) {}
  int numResiduals() const override { return 1; }
  int degree(int) const override { return degree_; }
  double rowWeight() const override { return factor_; }
  void accept(TermVisitor& visitor) const override { visitor.visit(*this); }
  template <class T>
  void residual(const T* x0, const T* x, int d, T* r) const;
  void evaluate(const double* x, int d, double* residuals, double* jacobian) const override;
  void secondDerivative(const double* x, const double* u, const double* w, int d,
                        double* out) const override;
  std::string label(int row, int index_base) const override;
  double residualScale() const override { return scale_; }

 private:
  std::shared_ptr<const ScalarField> f_;
  double scale_;
  double factor_;
  int degree_;
};

// ---------------------------------------------------------------------------------------------
// The formulas, once, in any arithmetic T (without the double path's rowWeight()). x0 holds the
// term's local coordinates at the start configuration, in T: a parameter that the start decides
// (a bar's length, an angle, a simplex's volume) is computed from it here, so that it is exact
// where the start is; so are a held vertex's affine weights and frame coordinates. Parameters
// given as numbers (targets, radii, a unit normal's length, an inversive distance) are the
// double values the term holds.

namespace term_detail {

template <class T>
T dot(const T* a, const T* b, int d) {
  T s(0);
  for (int k = 0; k < d; ++k) s += a[k] * b[k];
  return s;
}

// det of the d x d matrix with columns c[0..d-1] (d = 2 or 3).
template <class T>
T det(const T* const* c, int d) {
  if (d == 2) return c[0][0] * c[1][1] - c[0][1] * c[1][0];
  return c[0][0] * (c[1][1] * c[2][2] - c[1][2] * c[2][1]) - c[0][1] * (c[1][0] * c[2][2] - c[1][2] * c[2][0]) +
         c[0][2] * (c[1][0] * c[2][1] - c[1][1] * c[2][0]);
}

// The frame's axes at local coordinates x {v, a, b(, c)}: e1 = b - a, e2 = c - a, n = e1 x e2 (3D).
template <class T>
void frameAxes(const T* x, int d, bool three, T* e1, T* e2, T* n) {
  for (int k = 0; k < d; ++k) {
    e1[k] = x[2 * d + k] - x[d + k];
    if (three) e2[k] = x[3 * d + k] - x[d + k];
  }
  if (three && d == 3) {
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
  }
}

// Solves G w = h for a symmetric positive definite n x n G (row stride 3, n <= 3) by elimination
// without pivoting (G's pivots are positive), in any arithmetic with division.
template <class T>
void solveSpd(T* G, T* h, T* w, int n) {
  for (int p = 0; p < n; ++p)
    for (int i = p + 1; i < n; ++i) {
      const T f = G[i * 3 + p] / G[p * 3 + p];
      for (int j = p; j < n; ++j) G[i * 3 + j] -= f * G[p * 3 + j];
      h[i] -= f * h[p];
    }
  for (int i = n - 1; i >= 0; --i) {
    T s = h[i];
    for (int j = i + 1; j < n; ++j) s -= G[i * 3 + j] * w[j];
    w[i] = s / G[i * 3 + i];
  }
}

}  // namespace term_detail

template <class T>
void SquaredDistanceTerm::residual(const T* x0, const T* x, int d, T* r) const {
  T s(0);
  for (int k = 0; k < d; ++k) {
    const T diff = x[k] - x[d + k];
    s += diff * diff;
  }
  if (from_start_) {
    T s0(0);
    for (int k = 0; k < d; ++k) {
      const T diff = x0[k] - x0[d + k];
      s0 += diff * diff;
    }
    r[0] = s - s0;
  } else {
    r[0] = s - T(squared_length_);
  }
}

template <class T>
void FacetPlaneTerm::residual(const T* /*x0*/, const T* x, int d, T* r) const {
  const T *n = x, *a = x + d, *v = x + 2 * d;
  T s(0);
  for (int k = 0; k < d; ++k) s += n[k] * (v[k] - a[k]);
  r[0] = s;
}

template <class T>
void UnitNormTerm::residual(const T* /*x0*/, const T* x, int d, T* r) const {
  r[0] = term_detail::dot(x, x, d) - T(length_) * T(length_);
}

// The weights are v's affine coordinates in the frame at the start, in T: with e_j = b_j - b_1,
// the least-squares w_2.. of sum_j w_j e_j = v - b_1 (exact where v is in the frame's span, as
// the builders make it), w_1 = 1 - sum. The residual is then (v - b_1) - sum_j w_j e_j.
template <class T>
void AffineCombinationTerm::residual(const T* x0, const T* x, int d, T* r) const {
  const int n = static_cast<int>(blocks().size()), m = n - 2;  // frame blocks 1..n-1; unknowns w_2..w_{n-1}
  T G[9], h[3], w[3];
  for (int i = 0; i < m; ++i) {
    T e_i[3], q[3];
    for (int k = 0; k < d; ++k) e_i[k] = x0[(i + 2) * d + k] - x0[d + k], q[k] = x0[k] - x0[d + k];
    h[i] = term_detail::dot(e_i, q, d);
    for (int j = 0; j < m; ++j) {
      T e_j[3];
      for (int k = 0; k < d; ++k) e_j[k] = x0[(j + 2) * d + k] - x0[d + k];
      G[i * 3 + j] = term_detail::dot(e_i, e_j, d);
    }
  }
  term_detail::solveSpd(G, h, w, m);
  for (int k = 0; k < d; ++k) {
    T s = x[k] - x[d + k];
    for (int j = 0; j < m; ++j) s -= w[j] * (x[(j + 2) * d + k] - x[d + k]);
    r[k] = s;
  }
}

// The coordinates (s, t, u) are v's in the frame at the start, in T, as the framework's builder
// solves for them: on the bar's line its projection, in 2D by a's quarter turn as well, and in a
// frame of three by the axes e1, e2 (and e1 x e2 in 3D).
template <class T>
void FramePointTerm::residual(const T* x0, const T* x, int d, T* r) const {
  using term_detail::dot;
  const bool three = blocks().size() == 4;
  T e1[3], e2[3], n[3], f1[3], f2[3], m[3], q[3];
  term_detail::frameAxes(x, d, three, e1, e2, n);
  term_detail::frameAxes(x0, d, three, f1, f2, m);
  for (int k = 0; k < d; ++k) q[k] = x0[k] - x0[d + k];  // v - a at the start
  T s, t(0), u(0);
  if (!three) {
    const T l = dot(f1, f1, d);
    s = dot(q, f1, d) / l;
    if (d == 2) t = (f1[0] * q[1] - f1[1] * q[0]) / l;  // q . J f1
  } else if (d == 2) {
    const T D = f1[0] * f2[1] - f1[1] * f2[0];
    s = (q[0] * f2[1] - q[1] * f2[0]) / D;
    t = (f1[0] * q[1] - f1[1] * q[0]) / D;
  } else {  // m = f1 x f2 is orthogonal to both: u from it, s and t from the 2 x 2 Gram system
    const T g11 = dot(f1, f1, 3), g12 = dot(f1, f2, 3), g22 = dot(f2, f2, 3), b1 = dot(q, f1, 3), b2 = dot(q, f2, 3);
    const T D = g11 * g22 - g12 * g12;
    s = (b1 * g22 - b2 * g12) / D;
    t = (g11 * b2 - g12 * b1) / D;
    u = dot(q, m, 3) / dot(m, m, 3);
  }
  const T* a = x + d;
  const T* v = x;
  for (int k = 0; k < d; ++k) {
    T p = a[k] + s * e1[k];
    if (three) {
      p += t * e2[k];
      if (d == 3) p += u * n[k];
    } else if (d == 2) {
      p += t * (k == 0 ? -e1[1] : e1[0]);  // J e1 = (-e1_y, e1_x)
    }
    r[k] = v[k] - p;
  }
}

template <class T>
void SimplexVolumeTerm::residual(const T* x0, const T* x, int d, T* r) const {
  T e[3][3];
  const T* cols[3] = {e[0], e[1], e[2]};
  for (int i = 0; i < d; ++i)
    for (int k = 0; k < d; ++k) e[i][k] = x[(i + 1) * d + k] - x[k];
  if (from_start_) {
    T e0[3][3];
    const T* cols0[3] = {e0[0], e0[1], e0[2]};
    for (int i = 0; i < d; ++i)
      for (int k = 0; k < d; ++k) e0[i][k] = x0[(i + 1) * d + k] - x0[k];
    r[0] = term_detail::det(cols, d) - term_detail::det(cols0, d);
  } else {
    r[0] = term_detail::det(cols, d) - T(target_);
  }
}

template <class T>
void AngleTerm::residual(const T* x0, const T* x, int d, T* r) const {
  T u[3], w[3], u0[3], w0[3];
  for (int k = 0; k < d; ++k) {
    u[k] = x[k] - x[d + k], w[k] = x[2 * d + k] - x[d + k];
    u0[k] = x0[k] - x0[d + k], w0[k] = x0[2 * d + k] - x0[d + k];
  }
  const T C0 = term_detail::dot(u0, w0, d);
  if (d == 2) {
    const T S0 = u0[0] * w0[1] - u0[1] * w0[0];
    r[0] = S0 * term_detail::dot(u, w, 2) - C0 * (u[0] * w[1] - u[1] * w[0]);
  } else {
    using term_detail::dot;
    r[0] = dot(u, w, d) * root(dot(u0, u0, d)) * root(dot(w0, w0, d)) - C0 * root(dot(u, u, d)) * root(dot(w, w, d));
  }
}

template <class T>
void InversiveDistanceTerm::residual(const T* /*x0*/, const T* x, int d, T* r) const {
  const T *a = x, *b = x + d;
  const T ab = term_detail::dot(a, b, d) - T(1), aa = term_detail::dot(a, a, d) - T(1),
          bb = term_detail::dot(b, b, d) - T(1);
  r[0] = ab - T(I_) * root(aa * bb);
}

// A field is given in double, with its exact gradient and Hessian: it is evaluated in double and
// in HyperDual<double> and Dual<double> (by its Taylor expansion, exact for the derivatives the
// jet carries); another arithmetic needs the field in that arithmetic and is refused.
template <class T>
void SurfaceTerm::residual(const T* /*x0*/, const T* x, int d, T* r) const {
  if (d != 3) throw std::invalid_argument("a surface lives in 3D");
  if constexpr (std::is_same_v<T, double>) {
    r[0] = f_->value(x);
  } else if constexpr (std::is_same_v<T, HyperDual<double>>) {
    double p[3], f, g[3], H[9];
    for (int k = 0; k < 3; ++k) p[k] = x[k].v;
    f_->evaluate(p, &f, g, H);
    HyperDual<double> out(f);
    for (int i = 0; i < 3; ++i) {
      out.a += g[i] * x[i].a, out.b += g[i] * x[i].b, out.ab += g[i] * x[i].ab;
      for (int j = 0; j < 3; ++j) out.ab += x[i].a * H[3 * i + j] * x[j].b;
    }
    r[0] = out;
  } else if constexpr (std::is_same_v<T, Dual<double>>) {
    double p[3], f, g[3], H[9];
    for (int k = 0; k < 3; ++k) p[k] = x[k].v;
    f_->evaluate(p, &f, g, H);
    Dual<double> out(f);
    for (int i = 0; i < 3; ++i) out.a += g[i] * x[i].a;
    r[0] = out;
  } else {
    (void)x, (void)r;
    throw std::domain_error("the surface " + f_->text() + " is evaluated in floating point only");
  }
}

}  // namespace flexure::engine
