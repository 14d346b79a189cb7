// Frameworks on surfaces (engine/systems/framework_on_surface.h).
#include "engine/systems/framework_on_surface.h"

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <algorithm>
#include <Eigen/SVD>
#include <cmath>
#include <map>
#include <random>

#include "engine/corrector.h"
#include "engine/systems/common.h"
#include "engine/terms.h"

namespace flexure::engine {

using systems_detail::addEdge;
using systems_detail::requireDistinct;

struct FrameworkOnSurface::Built {
  ConstraintSystem system;
  Matrix start;
  std::vector<Edge> edges;
  std::shared_ptr<const ScalarField> surface;
  Matrix killing;
  Eigen::Vector3d centre;
  double scale;
};

namespace {

// Newton's method along the gradient: the nearby point of f = 0 (false if it does not converge).
bool projectOntoSurface(const ScalarField& f, Eigen::Vector3d& x, double scale) {
  for (int it = 0; it < 60; ++it) {
    double v, g[3];
    f.evaluate(x.data(), &v, g, nullptr);
    const Eigen::Vector3d grad(g[0], g[1], g[2]);
    const double gn = grad.squaredNorm();
    if (!std::isfinite(v) || !(gn > 0)) return false;
    if (std::abs(v) <= 1e-13 * std::sqrt(gn) * std::max(scale, 1e-300)) return true;
    x -= v * grad / gn;
  }
  return false;
}

// True when f is a polynomial of degree at most 2 (a sphere, an ellipsoid, a hyperboloid, a
// cylinder, a cone or a pair of planes written as a quadric): its Hessian is the same at every
// point, and f equals its second-order Taylor expansion about the vertices' centre. Checked at
// points sampled around the vertices (a fixed seed) to rounding relative to the size of the
// terms; an expression is analytic, so a constant Hessian on these points is a constant Hessian.
bool isQuadricField(const ScalarField& f, const Matrix& points, double extent) {
  const Eigen::Vector3d centre = points.rowwise().mean();
  // Sampled within the framework's extent (one vertex: within its distance from the origin).
  const double scale = extent > 1e-250 ? extent : std::max(centre.norm(), 1.0);
  double f0, g0[3], h0[9];
  f.evaluate(centre.data(), &f0, g0, h0);
  const Eigen::Vector3d grad0(g0[0], g0[1], g0[2]);
  const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> H0(h0);
  if (!std::isfinite(f0) || !grad0.allFinite() || !H0.allFinite()) return false;
  std::mt19937_64 rng(0x9aad);
  std::normal_distribution<double> gauss(0.0, 1.0);
  for (int k = 0; k < 24; ++k) {
    const Eigen::Vector3d r = scale * Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng));
    const Eigen::Vector3d x = (k < points.cols() ? Eigen::Vector3d(points.col(k)) : centre) + r;
    const Eigen::Vector3d dx = x - centre;
    double fx, gx[3], hx[9];
    f.evaluate(x.data(), &fx, gx, hx);
    const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> Hx(hx);
    if (!std::isfinite(fx) || !Hx.allFinite()) return false;
    const double h_size = std::max(H0.cwiseAbs().maxCoeff(), Hx.cwiseAbs().maxCoeff());
    if ((Hx - H0).cwiseAbs().maxCoeff() > 1e-9 * h_size) return false;
    const double lin = grad0.dot(dx), quad = 0.5 * dx.dot(H0 * dx);
    const double size = std::abs(f0) + std::abs(lin) + std::abs(quad) + std::abs(fx);
    if (std::abs(fx - (f0 + lin + quad)) > 1e-9 * size) return false;
  }
  return true;
}

// Killing fields omega x (p - centre) + t (as (L omega, t)) tangent to the surface at points
// sampled near the vertices: the null space of the tangency conditions.
Matrix surfaceIsometries(const ScalarField& f, const Matrix& points, double scale) {
  const Eigen::Vector3d centre = points.rowwise().mean();
  std::mt19937_64 rng(0x5eed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::vector<Eigen::Vector3d> samples;
  const int per_vertex = std::max(8, 240 / static_cast<int>(points.cols()));
  for (int v = 0; v < points.cols(); ++v) {
    samples.push_back(points.col(v));
    for (int k = 0; k < per_vertex; ++k) {
      Eigen::Vector3d x = points.col(v);
      for (int c = 0; c < 3; ++c) x[c] += 0.5 * scale * gauss(rng);
      if (projectOntoSurface(f, x, scale) && (x - Eigen::Vector3d(points.col(v))).norm() < 4 * scale) samples.push_back(x);
    }
  }
  Matrix A(static_cast<Eigen::Index>(samples.size()), 6);
  for (size_t i = 0; i < samples.size(); ++i) {
    double v, g[3];
    f.evaluate(samples[i].data(), &v, g, nullptr);
    Eigen::Vector3d grad(g[0], g[1], g[2]);
    grad /= grad.norm();
    const Eigen::Vector3d r = (samples[i] - centre) / scale;
    A.block(static_cast<Eigen::Index>(i), 0, 1, 3) = r.cross(grad).transpose();  // grad . (omega x r)
    A.block(static_cast<Eigen::Index>(i), 3, 1, 3) = grad.transpose();
  }
  Eigen::JacobiSVD<Matrix> svd(A, Eigen::ComputeFullV);
  const Vector& s = svd.singularValues();
  int rank = 0;
  while (rank < s.size() && s[rank] > 1e-7 * s[0]) ++rank;
  return svd.matrixV().rightCols(6 - rank);
}

}  // namespace

FrameworkOnSurface::FrameworkOnSurface(const Matrix& points, std::vector<Edge> edges, const std::vector<int>& pinned,
                                       std::shared_ptr<const ScalarField> surface, bool project_start, int base)
    : FrameworkOnSurface([&]() -> Built {
        const int n = static_cast<int>(points.cols());
        if (points.rows() != 3) throw ModelError("vertices", -1, "a framework on a surface lives in 3D");
        const double L = std::max(extentOf(points), 1e-300);
        std::map<std::pair<int, int>, std::string> seen;
        for (size_t e = 0; e < edges.size(); ++e) {
          addEdge(seen, edges[e][0], edges[e][1], "edge " + std::to_string(e + 1), "edges", static_cast<int>(e), base);
          requireDistinct(points, edges[e][0], edges[e][1], "edges", static_cast<int>(e), base,
                          "edge " + std::to_string(e + 1));
        }
        std::vector<char> is_pinned(static_cast<size_t>(n), 0);
        for (int v : pinned) is_pinned[static_cast<size_t>(v)] = 1;
        auto build = [&](const Matrix& p) {
          // f's degree where it is a quadric: the second-order theory then applies (engine/rigidity.cpp
          // asks the terms' degrees).
          const int degree = isQuadricField(*surface, p, L) ? 2 : -1;
          ConstraintSystem sys(3, n, n);
          for (int v : pinned) sys.pin(v);
          for (const auto& e : edges)
            sys.addTerm(std::make_unique<SquaredDistanceTerm>(e[0], e[1], (points.col(e[0]) - points.col(e[1])).squaredNorm()));
          for (int v = 0; v < n; ++v) {
            double f, g[3];
            surface->evaluate(p.col(v).data(), &f, g, nullptr);
            const double gn = Eigen::Vector3d(g[0], g[1], g[2]).norm();
            if (!std::isfinite(f) || !std::isfinite(gn))
              throw ModelError("vertices", v, "the surface " + surface->text() + " is not finite at vertex " +
                                                  std::to_string(v + base));
            if (!(gn > 0))
              throw ModelError("vertices", v, "the surface " + surface->text() + " has zero gradient at vertex " +
                                                  std::to_string(v + base) + " (a singular point)");
            sys.addTerm(std::make_unique<SurfaceTerm>(v, surface, L * L, L / gn, degree));
          }
          sys.finalize(p);
          return sys;
        };
        // Distance of each vertex from the surface, to first order |f| / |grad f|.
        auto offSurface = [&](const Matrix& p, int v) {
          double f, g[3];
          surface->evaluate(p.col(v).data(), &f, g, nullptr);
          return std::abs(f) / Eigen::Vector3d(g[0], g[1], g[2]).norm();
        };
        ConstraintSystem sys = build(points);
        Matrix start = points;
        for (int v = 0; v < n; ++v) {
          const double off = offSurface(points, v);
          if (off <= 1e-9 * L) continue;
          const std::string where = "vertex " + std::to_string(v + base) + " is about " + shortNumber(off) +
                                    " away from the surface " + surface->text();
          if (is_pinned[static_cast<size_t>(v)])
            throw ModelError("vertices", v, where + "; a pinned vertex must lie on it");
          if (!project_start)
            throw ModelError("vertices", v, where + " (set [system] project_start = true to move the start onto it)");
        }
        if (project_start) {
          CorrectorOptions opt;
          opt.max_iterations = 100;
          const CorrectorResult r = correct(sys, sys.freeCoordinates(points), opt);
          if (r.status != CorrectorStatus::Converged)
            throw ModelError("vertices", -1, "project_start: no configuration with these bar lengths on the surface " +
                                                 surface->text() + " was found near the start (" + toString(r.status) + ")");
          start = sys.positions(r.x);
          sys = build(start);
        }
        Matrix killing = surfaceIsometries(*surface, start, L);
        const Eigen::Vector3d centre = start.rowwise().mean();
        return Built{std::move(sys), std::move(start), std::move(edges), std::move(surface), std::move(killing),
                     centre, L};
      }()) {}

FrameworkOnSurface::FrameworkOnSurface(Built&& b)
    : Model(std::move(b.system), std::move(b.start)), edges_(std::move(b.edges)), surface_(std::move(b.surface)),
      killing_(std::move(b.killing)), centre_(b.centre), scale_(b.scale) {}

Matrix FrameworkOnSurface::symmetryGenerators(const Matrix& positions) const {
  const int d = 3, blocks = static_cast<int>(positions.cols()), n = system().numVertices();
  Matrix g = Matrix::Zero(static_cast<Eigen::Index>(blocks) * d, killing_.cols());
  for (int j = 0; j < killing_.cols(); ++j) {
    const Eigen::Vector3d omega = killing_.col(j).head(3) / scale_, t = killing_.col(j).tail(3);
    for (int i = 0; i < n; ++i)
      g.block(i * d, j, d, 1) = omega.cross(Eigen::Vector3d(positions.col(i)) - centre_) + t;
    const double norm = g.col(j).norm();
    if (norm > 0) g.col(j) /= norm;
  }
  return g;
}

Geometry FrameworkOnSurface::geometry() const {
  Geometry g = Model::geometry();
  g.bars.edges = edges_;
  g.surface.field = surface_.get();
  return g;
}

}  // namespace flexure::engine
