#include "present/surface_mesh.h"

#include <algorithm>
#include <cmath>

namespace flexure::present {

namespace {

using P3 = std::array<double, 3>;

P3 crossing(const P3& a, double fa, const P3& b, double fb) {
  const double t = fa / (fa - fb);
  return {a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2])};
}

// The part of f = 0 in one tetrahedron (f linear there): nothing, a triangle or a quad.
void cutTetrahedron(const P3 (&p)[4], const double (&v)[4], std::vector<Triangle3>& out) {
  int inside[4], outside[4], ni = 0, no = 0;
  for (int i = 0; i < 4; ++i) (v[i] < 0 ? inside[ni++] : outside[no++]) = i;
  if (ni == 0 || no == 0) return;
  if (ni == 1 || no == 1) {
    const int lone = ni == 1 ? inside[0] : outside[0];
    const int* others = ni == 1 ? outside : inside;
    Triangle3 t;
    for (int k = 0; k < 3; ++k) t[static_cast<size_t>(k)] = crossing(p[lone], v[lone], p[others[k]], v[others[k]]);
    out.push_back(t);
    return;
  }
  const int a = inside[0], b = inside[1], c = outside[0], d = outside[1];
  const P3 ac = crossing(p[a], v[a], p[c], v[c]), ad = crossing(p[a], v[a], p[d], v[d]);
  const P3 bd = crossing(p[b], v[b], p[d], v[d]), bc = crossing(p[b], v[b], p[c], v[c]);
  out.push_back({ac, ad, bd});
  out.push_back({ac, bd, bc});
}

}  // namespace

std::vector<Triangle3> meshImplicitSurface(const std::function<double(const double*)>& f, const P3& lo,
                                           const P3& hi, int samples) {
  const int n = std::max(1, samples), m = n + 1;
  std::vector<double> value(static_cast<size_t>(m) * m * m);
  auto at = [&](int i, int j, int k) -> P3 {
    return {lo[0] + (hi[0] - lo[0]) * i / n, lo[1] + (hi[1] - lo[1]) * j / n, lo[2] + (hi[2] - lo[2]) * k / n};
  };
  auto index = [&](int i, int j, int k) { return (static_cast<size_t>(k) * m + j) * m + i; };
  for (int k = 0; k < m; ++k)
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < m; ++i) {
        const P3 x = at(i, j, k);
        const double v = f(x.data());
        value[index(i, j, k)] = std::isfinite(v) ? v : 1.0;
      }
  // Kuhn triangulation: from corner 0 to corner 7 along the axes in each of the 6 orders.
  static const int kOrders[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  std::vector<Triangle3> out;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        double lo_v = value[index(i, j, k)], hi_v = lo_v;
        for (int c = 1; c < 8; ++c) {
          const double v = value[index(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1))];
          lo_v = std::min(lo_v, v), hi_v = std::max(hi_v, v);
        }
        if (lo_v >= 0 || hi_v < 0) continue;  // the surface does not pass through this cube
        for (const auto& order : kOrders) {
          int off[3] = {0, 0, 0};
          P3 p[4];
          double v[4];
          for (int s = 0; s < 4; ++s) {
            if (s > 0) off[order[s - 1]] = 1;
            p[s] = at(i + off[0], j + off[1], k + off[2]);
            v[s] = value[index(i + off[0], j + off[1], k + off[2])];
          }
          cutTetrahedron(p, v, out);
        }
      }
  return out;
}

}  // namespace flexure::present
