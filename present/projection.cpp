#include "present/projection.h"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "engine/random.h"

namespace flexure::present {

namespace {

render::Color hex(unsigned rgb) {
  return {((rgb >> 16) & 255) / 255.f, ((rgb >> 8) & 255) / 255.f, (rgb & 255) / 255.f, 1};
}

}  // namespace

engine::Matrix randomProjection(int n, int k, std::uint64_t seed) {
  engine::Random rng(seed);
  engine::Matrix g(n, k);
  for (int j = 0; j < k; ++j)
    for (int i = 0; i < n; ++i) g(i, j) = rng.gaussian();
  Eigen::HouseholderQR<engine::Matrix> qr(g);
  engine::Matrix q = qr.householderQ() * engine::Matrix::Identity(n, k);
  // A sign convention so that Q does not depend on the QR implementation: R's diagonal > 0.
  const engine::Matrix r = qr.matrixQR().topRows(k).triangularView<Eigen::Upper>();
  for (int j = 0; j < k; ++j)
    if (r(j, j) < 0) q.col(j) = -q.col(j);
  return q;
}

Projection projectPaths(const Scene& scene, const std::vector<ProjectionPath>& paths, std::uint64_t seed) {
  Projection pr;
  pr.seed = seed;
  const int n = paths.empty() || paths[0].samples.empty() ? 0 : static_cast<int>(paths[0].samples[0].size());
  pr.q = randomProjection(std::max(n, 2), 2, seed).topRows(n);
  const scenes::ProjectionSettings& ps = scene.projection;
  static const std::vector<unsigned> palette = {0x4682B4, 0xCD0000, 0x00A000, 0xFF8C00, 0x800080,
                                                0x008080, 0x595959, 0xB8860B, 0xFF1493, 0x000080};
  for (size_t j = 0; j < paths.size(); ++j) {
    render::PlotSeries ser;
    for (const auto& x : paths[j].samples) {
      const engine::Vector y = pr.q.transpose() * x;
      ser.points.push_back({y[0], y[1]});
    }
    pr.curves.push_back(ser.points);
    pr.starts.push_back(paths[j].start);
    ser.color = !ps.colors.empty() ? ps.colors[j % ps.colors.size()]
                : paths.size() == 1 ? hex(0x595959)  // gray35, as in the reference
                                    : hex(palette[j % palette.size()]);
    ser.label = paths.size() > 1 ? paths[j].label : "";
    ser.marks = paths[j].singular;
    pr.plot.series.push_back(std::move(ser));
  }
  if (!pr.curves.empty() && !pr.curves[0].empty()) pr.plot.start = pr.curves[0][static_cast<size_t>(paths[0].start)];
  if (ps.flex_arrows && pr.plot.start) {
    double span = 0;
    for (const auto& c : pr.curves)
      for (const auto& p : c)
        span = std::max({span, std::abs(p[0] - (*pr.plot.start)[0]), std::abs(p[1] - (*pr.plot.start)[1])});
    if (!(span > 0)) span = 1;
    for (size_t j = 0; j < paths.size(); ++j) {
      if (paths[j].flex.size() != n) continue;
      const engine::Vector v = pr.q.transpose() * paths[j].flex;
      if (!(v.norm() > 1e-12)) continue;
      const engine::Vector tip = v / v.norm() * 0.35 * span;
      const render::Point2 from = pr.curves[j][static_cast<size_t>(paths[j].start)];
      pr.plot.arrows.push_back({from, {from[0] + tip[0], from[1] + tip[1]}, scene.render.style.flex_color});
    }
  }
  pr.plot.title = scene.render.title.value_or(scene.title.empty() ? std::string("Deformation path") : scene.title);
  pr.plot.subtitle = scene.render.subtitle.value_or("random orthonormal projection of the deformation path (seed " +
                                                    std::to_string(seed) + ")");
  pr.plot.xlabel = "projection axis 1";
  pr.plot.ylabel = "projection axis 2";
  return pr;
}

std::string projectionCsv(const std::vector<ProjectionPath>& paths, const Projection& pr) {
  std::ostringstream o;
  o << "path,sample,p1,p2\n";
  char buf[96];
  for (size_t j = 0; j < paths.size(); ++j)
    for (size_t i = 0; i < pr.curves[j].size(); ++i) {
      std::snprintf(buf, sizeof buf, "%zu,%d,%.17g,%.17g\n", j + 1, paths[j].sample_numbers[i], pr.curves[j][i][0],
                    pr.curves[j][i][1]);
      o << buf;
    }
  return o.str();
}

render::PlotStyle projectionStyle(const Scene& scene, int width, int height) {
  render::PlotStyle st;
  st.width = width, st.height = height;
  st.background = scene.render.style.background;
  st.line_width = scene.projection.line_width;
  st.marker_size = scene.projection.marker_size;
  st.arrow_size = scene.render.style.arrow_size;
  if (scene.render.style.unit_px > 0 && scene.render.height > 0)  // sized in lengths: sizes in points
    st.unit_px = scene.render.style.unit_px * height / scene.render.height;
  return st;
}

}  // namespace flexure::present
