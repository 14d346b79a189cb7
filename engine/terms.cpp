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
