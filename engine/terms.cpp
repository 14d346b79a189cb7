#include "engine/terms.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace flexure::engine {

void SquaredDistanceTerm::evaluate(const double* x, int d, double* residuals,
                                   double* jacobian) const {
  double s = 0.0;
  for (int k = 0; k < d; ++k) {
    const double diff = x[k] - x[d + k];
    s += diff * diff;
    if (jacobian) {
      jacobian[k] = 2.0 * diff;
      jacobian[d + k] = -2.0 * diff;
    }
  }
  residuals[0] = s - squared_length_;
}

void SquaredDistanceTerm::secondDerivative(const double*, const double* u, const double* w, int d,
                                           double* out) const {
  double s = 0.0;
  for (int k = 0; k < d; ++k) s += (u[k] - u[d + k]) * (w[k] - w[d + k]);
  out[0] = 2.0 * s;
}

std::string SquaredDistanceTerm::label(int, int index_base) const {
  return "edge " + std::to_string(blocks()[0] + index_base) + "-" +
         std::to_string(blocks()[1] + index_base);
}

}  // namespace flexure::engine

namespace flexure::engine {

namespace {

double dot(const double* a, const double* b, int d) {
  double s = 0.0;
  for (int k = 0; k < d; ++k) s += a[k] * b[k];
  return s;
}

std::string vertexName(int block, int index_base) { return std::to_string(block + index_base); }

// det of the d x d matrix with columns c[0..d-1] (d = 2 or 3).
double det(const double* const* c, int d) {
  if (d == 2) return c[0][0] * c[1][1] - c[0][1] * c[1][0];
  return c[0][0] * (c[1][1] * c[2][2] - c[1][2] * c[2][1]) - c[0][1] * (c[1][0] * c[2][2] - c[1][2] * c[2][0]) +
         c[0][2] * (c[1][0] * c[2][1] - c[1][1] * c[2][0]);
}

}  // namespace

void FacetPlaneTerm::evaluate(const double* x, int d, double* residuals, double* jacobian) const {
  const double* n = x;
  const double* a = x + d;
  const double* v = x + 2 * d;
  double r = 0.0;
  for (int k = 0; k < d; ++k) {
    r += n[k] * (v[k] - a[k]);
    if (jacobian) {
      jacobian[k] = v[k] - a[k];
      jacobian[d + k] = -n[k];
      jacobian[2 * d + k] = n[k];
    }
  }
  residuals[0] = r;
}

void FacetPlaneTerm::secondDerivative(const double*, const double* u, const double* w, int d,
                                      double* out) const {
  double s = 0.0;
  for (int k = 0; k < d; ++k)
    s += u[k] * (w[2 * d + k] - w[d + k]) + w[k] * (u[2 * d + k] - u[d + k]);
  out[0] = s;
}

std::string FacetPlaneTerm::label(int, int index_base) const {
  return "facet " + std::to_string(facet_ + index_base) + " plane at vertex " + vertexName(blocks()[2], index_base);
}

void UnitNormTerm::evaluate(const double* x, int d, double* residuals, double* jacobian) const {
  residuals[0] = dot(x, x, d) - length_ * length_;
  if (jacobian)
    for (int k = 0; k < d; ++k) jacobian[k] = 2.0 * x[k];
}

void UnitNormTerm::secondDerivative(const double*, const double* u, const double* w, int d, double* out) const {
  out[0] = 2.0 * dot(u, w, d);
}

std::string UnitNormTerm::label(int, int index_base) const {
  return "facet " + std::to_string(facet_ + index_base) + " normal";
}

void AffineCombinationTerm::evaluate(const double* x, int d, double* residuals, double* jacobian) const {
  const int n = static_cast<int>(blocks().size());
  for (int k = 0; k < d; ++k) {
    double r = x[k];
    for (int j = 1; j < n; ++j) r -= weights_[static_cast<size_t>(j - 1)] * x[j * d + k];
    residuals[k] = scale_ * r;
  }
  if (!jacobian) return;
  const int cols = n * d;
  std::fill(jacobian, jacobian + d * cols, 0.0);
  for (int k = 0; k < d; ++k) {
    jacobian[k * cols + k] = scale_;
    for (int j = 1; j < n; ++j) jacobian[k * cols + j * d + k] = -scale_ * weights_[static_cast<size_t>(j - 1)];
  }
}

void AffineCombinationTerm::secondDerivative(const double*, const double*, const double*, int d, double* out) const {
  std::fill(out, out + d, 0.0);  // linear
}

std::string AffineCombinationTerm::label(int row, int index_base) const {
  std::string s = owner_ + ": vertex " + vertexName(blocks()[0], index_base) + " held by";
  for (size_t j = 1; j < blocks().size(); ++j) s += " " + vertexName(blocks()[j], index_base);
  return s + " (" + std::string(1, "xyz"[row]) + ")";
}

FramePointTerm::FramePointTerm(int dimension, std::vector<int> blocks, std::array<double, 3> coefficients,
                               double scale)
    : ConstraintTerm(std::move(blocks)), d_(dimension), c_(coefficients), scale_(scale) {
  const size_t k = this->blocks().size() - 1;
  if ((d_ != 2 && d_ != 3) || (k != 2 && k != 3))
    throw std::invalid_argument("a frame point lives in 2D or 3D, on a frame of 2 or 3 vertices");
  if (d_ == 3 && k == 2 && c_[1] != 0.0) throw std::invalid_argument("in 3D a point held by a bar lies on its line");
}

void FramePointTerm::evaluate(const double* x, int d, double* residuals, double* jacobian) const {
  const bool three = blocks().size() == 4;
  const double *v = x, *a = x + d, *b = x + 2 * d, *c = three ? x + 3 * d : nullptr;
  double e1[3] = {}, e2[3] = {}, n[3] = {};
  for (int k = 0; k < d; ++k) {
    e1[k] = b[k] - a[k];
    if (three) e2[k] = c[k] - a[k];
  }
  if (three && d == 3) {
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
  }
  const double s = c_[0], t = c_[1], u = c_[2];
  for (int k = 0; k < d; ++k) {
    double p = a[k] + s * e1[k];
    if (three) p += t * e2[k] + (d == 3 ? u * n[k] : 0.0);
    else if (d == 2) p += t * (k == 0 ? -e1[1] : e1[0]);  // J e1 = (-e1_y, e1_x)
    residuals[k] = scale_ * (v[k] - p);
  }
  if (!jacobian) return;
  const int cols = static_cast<int>(blocks().size()) * d;
  std::fill(jacobian, jacobian + d * cols, 0.0);
  auto J = [&](int row, int block, int col) -> double& { return jacobian[row * cols + block * d + col]; };
  for (int k = 0; k < d; ++k) {
    J(k, 0, k) = scale_;
    if (three) {
      J(k, 1, k) = -scale_ * (1.0 - s - t);
      J(k, 2, k) = -scale_ * s;
      J(k, 3, k) = -scale_ * t;
    } else {
      J(k, 1, k) = -scale_ * (1.0 - s);
      J(k, 2, k) = -scale_ * s;
    }
  }
  if (!three && d == 2) {
    // -t J e1 with e1 = b - a: d/db = -t J, d/da = +t J; J = [[0, -1], [1, 0]].
    J(0, 2, 1) += scale_ * t, J(1, 2, 0) -= scale_ * t;
    J(0, 1, 1) -= scale_ * t, J(1, 1, 0) += scale_ * t;
  }
  if (three && d == 3) {
    // -u (e1 x e2): d/db w = -u (w x e2) = u [e2]x w, d/dc w = -u (e1 x w) = -u [e1]x w,
    // d/da = -(d/db + d/dc).
    const double X1[3][3] = {{0, -e1[2], e1[1]}, {e1[2], 0, -e1[0]}, {-e1[1], e1[0], 0}};
    const double X2[3][3] = {{0, -e2[2], e2[1]}, {e2[2], 0, -e2[0]}, {-e2[1], e2[0], 0}};
    for (int r = 0; r < 3; ++r)
      for (int q = 0; q < 3; ++q) {
        const double db = scale_ * u * X2[r][q], dc = -scale_ * u * X1[r][q];
        J(r, 2, q) += db;
        J(r, 3, q) += dc;
        J(r, 1, q) -= db + dc;
      }
  }
}

void FramePointTerm::secondDerivative(const double*, const double* U, const double* W, int d, double* out) const {
  std::fill(out, out + d, 0.0);
  if (blocks().size() != 4 || d != 3) return;  // linear
  // -u scale (e1 x e2)'' [U, W] = -u scale (U1 x W2 + W1 x U2), with U1 = U_b - U_a, U2 = U_c - U_a.
  double U1[3], U2[3], W1[3], W2[3];
  for (int k = 0; k < 3; ++k) {
    U1[k] = U[6 + k] - U[3 + k], U2[k] = U[9 + k] - U[3 + k];
    W1[k] = W[6 + k] - W[3 + k], W2[k] = W[9 + k] - W[3 + k];
  }
  auto cross = [](const double* p, const double* q, int k) {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    return p[i] * q[j] - p[j] * q[i];
  };
  for (int k = 0; k < 3; ++k) out[k] = -scale_ * c_[2] * (cross(U1, W2, k) + cross(W1, U2, k));
}

std::string FramePointTerm::label(int row, int index_base) const {
  std::string s = "vertex " + vertexName(blocks()[0], index_base) + " attached to";
  for (size_t j = 1; j < blocks().size(); ++j) s += " " + vertexName(blocks()[j], index_base);
  return s + " (" + std::string(1, "xyz"[row]) + ")";
}

void SimplexVolumeTerm::evaluate(const double* x, int d, double* residuals, double* jacobian) const {
  // Edge vectors e_i = x_i - x_0.
  double e[3][3] = {};
  const double* cols[3] = {e[0], e[1], e[2]};
  for (int i = 0; i < d; ++i) {
    for (int k = 0; k < d; ++k) e[i][k] = x[(i + 1) * d + k] - x[k];
    cols[i] = e[i];
  }
  residuals[0] = factor_ * (det(cols, d) - target_);
  if (!jacobian) return;
  // d det / d e_i[k]: replace column i by the unit vector e_k.
  for (int k = 0; k < d; ++k) jacobian[k] = 0.0;
  for (int i = 0; i < d; ++i)
    for (int k = 0; k < d; ++k) {
      double unit[3] = {0, 0, 0};
      unit[k] = 1.0;
      const double* c[3] = {cols[0], cols[1], d == 3 ? cols[2] : nullptr};
      c[i] = unit;
      const double g = factor_ * det(c, d);
      jacobian[(i + 1) * d + k] = g;
      jacobian[k] -= g;
    }
}

void SimplexVolumeTerm::secondDerivative(const double* x, const double* u, const double* w, int d,
                                         double* out) const {
  // det is multilinear in the columns: the second derivative replaces two distinct columns,
  // one by u's and one by w's edge displacement, in both orders.
  double e[3][3] = {}, eu[3][3] = {}, ew[3][3] = {};
  for (int i = 0; i < d; ++i)
    for (int k = 0; k < d; ++k) {
      e[i][k] = x[(i + 1) * d + k] - x[k];
      eu[i][k] = u[(i + 1) * d + k] - u[k];
      ew[i][k] = w[(i + 1) * d + k] - w[k];
    }
  double s = 0.0;
  for (int i = 0; i < d; ++i)
    for (int j = 0; j < d; ++j) {
      if (i == j) continue;
      const double* c[3] = {e[0], e[1], d == 3 ? e[2] : nullptr};
      c[i] = eu[i];
      c[j] = ew[j];
      s += det(c, d);
    }
  out[0] = factor_ * s;
}

std::string SimplexVolumeTerm::label(int, int index_base) const {
  std::string s = "simplex";
  for (int b : blocks()) s += " " + vertexName(b, index_base);
  return s;
}

void AngleTerm::evaluate(const double* x, int d, double* residuals, double* jacobian) const {
  const double* pi = x;
  const double* pj = x + d;
  const double* pk = x + 2 * d;
  double u[3], w[3];
  for (int k = 0; k < d; ++k) u[k] = pi[k] - pj[k], w[k] = pk[k] - pj[k];
  double gu[3], gw[3];  // d r / d u, d r / d w
  if (d == 2) {
    // s0 (u . w) - c0 (u_x w_y - u_y w_x)
    residuals[0] = s0_ * dot(u, w, 2) - c0_ * (u[0] * w[1] - u[1] * w[0]);
    gu[0] = s0_ * w[0] - c0_ * w[1];
    gu[1] = s0_ * w[1] + c0_ * w[0];
    gw[0] = s0_ * u[0] + c0_ * u[1];
    gw[1] = s0_ * u[1] - c0_ * u[0];
  } else {
    const double nu = std::sqrt(dot(u, u, d)), nw = std::sqrt(dot(w, w, d));
    residuals[0] = dot(u, w, d) - c0_ * nu * nw;
    for (int k = 0; k < d; ++k) {
      gu[k] = w[k] - c0_ * nw * u[k] / nu;
      gw[k] = u[k] - c0_ * nu * w[k] / nw;
    }
  }
  if (jacobian)
    for (int k = 0; k < d; ++k) {
      jacobian[k] = gu[k];
      jacobian[d + k] = -gu[k] - gw[k];
      jacobian[2 * d + k] = gw[k];
    }
}

void AngleTerm::secondDerivative(const double* x, const double* u, const double* w, int d, double* out) const {
  double a[3], b[3], ua[3], ub[3], wa[3], wb[3];  // arms and their displacements under u and w
  for (int k = 0; k < d; ++k) {
    a[k] = x[k] - x[d + k], b[k] = x[2 * d + k] - x[d + k];
    ua[k] = u[k] - u[d + k], ub[k] = u[2 * d + k] - u[d + k];
    wa[k] = w[k] - w[d + k], wb[k] = w[2 * d + k] - w[d + k];
  }
  if (d == 2) {
    auto cross = [](const double* p, const double* q) { return p[0] * q[1] - p[1] * q[0]; };
    out[0] = s0_ * (dot(ua, wb, 2) + dot(wa, ub, 2)) - c0_ * (cross(ua, wb) + cross(wa, ub));
    return;
  }
  // u.w - c0 g h with g = |a|, h = |b|.
  const double g = std::sqrt(dot(a, a, d)), h = std::sqrt(dot(b, b, d));
  auto hess = [&](const double* p, double n, const double* s, const double* t) {  // s^T (I - p p^T / n^2) t / n
    return (dot(s, t, d) - dot(p, s, d) * dot(p, t, d) / (n * n)) / n;
  };
  const double gs = dot(a, ua, d) / g, gt = dot(a, wa, d) / g;  // grad g . displacement
  const double hs = dot(b, ub, d) / h, ht = dot(b, wb, d) / h;
  const double d2gh = h * hess(a, g, ua, wa) + g * hess(b, h, ub, wb) + gs * ht + gt * hs;
  out[0] = dot(ua, wb, d) + dot(wa, ub, d) - c0_ * d2gh;
}

std::string AngleTerm::label(int, int index_base) const {
  return "angle " + vertexName(blocks()[0], index_base) + "-" + vertexName(blocks()[1], index_base) + "-" +
         vertexName(blocks()[2], index_base);
}

void InversiveDistanceTerm::evaluate(const double* x, int d, double* residuals, double* jacobian) const {
  const double* a = x;
  const double* b = x + d;
  const double ab = dot(a, b, d) - 1.0, aa = dot(a, a, d) - 1.0, bb = dot(b, b, d) - 1.0;
  const double root = std::sqrt(aa * bb);
  residuals[0] = ab - I_ * root;
  if (jacobian)
    for (int k = 0; k < d; ++k) {
      // d sqrt(aa bb) / da = bb a / root
      jacobian[k] = b[k] - I_ * bb * a[k] / root;
      jacobian[d + k] = a[k] - I_ * aa * b[k] / root;
    }
}

void InversiveDistanceTerm::secondDerivative(const double* x, const double* u, const double* w, int d,
                                             double* out) const {
  const double* a = x;
  const double* b = x + d;
  const double aa = dot(a, a, d) - 1.0, bb = dot(b, b, d) - 1.0;
  // Second derivative of the bilinear part: u_a . w_b + w_a . u_b.
  const double bil = dot(u, w + d, d) + dot(w, u + d, d);
  // S = sqrt(P) with P = aa bb: d2S = d2P / (2S) - dP[u] dP[w] / (4 S^3).
  const double S = std::sqrt(aa * bb);
  const double dPu = 2.0 * dot(a, u, d) * bb + 2.0 * aa * dot(b, u + d, d);
  const double dPw = 2.0 * dot(a, w, d) * bb + 2.0 * aa * dot(b, w + d, d);
  const double d2P = 2.0 * dot(u, w, d) * bb + 2.0 * aa * dot(u + d, w + d, d) +
                     4.0 * dot(a, u, d) * dot(b, w + d, d) + 4.0 * dot(a, w, d) * dot(b, u + d, d);
  const double d2S = d2P / (2.0 * S) - dPu * dPw / (4.0 * S * S * S);
  out[0] = bil - I_ * d2S;
}

std::string InversiveDistanceTerm::label(int, int index_base) const {
  return "contact " + vertexName(blocks()[0], index_base) + "-" + vertexName(blocks()[1], index_base);
}

void SurfaceTerm::evaluate(const double* x, int d, double* residuals, double* jacobian) const {
  if (d != 3) throw std::invalid_argument("a surface lives in 3D");
  double g[3];
  f_->evaluate(x, residuals, g, nullptr);
  residuals[0] *= factor_;
  if (jacobian)
    for (int k = 0; k < 3; ++k) jacobian[k] = factor_ * g[k];
}

void SurfaceTerm::secondDerivative(const double* x, const double* u, const double* w, int, double* out) const {
  double f, g[3], H[9];
  f_->evaluate(x, &f, g, H);
  double s = 0.0;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) s += u[r] * H[3 * r + c] * w[c];
  out[0] = factor_ * s;
}

std::string SurfaceTerm::label(int, int index_base) const {
  return "vertex " + vertexName(blocks()[0], index_base) + " on the surface";
}

}  // namespace flexure::engine
