#include <catch2/catch.hpp>
#include <Eigen/Dense>
#include <cmath>

#include "engine/drag.h"
#include "engine/factorization.h"
#include "engine/systems/framework.h"
#include "../test_common.h"

using namespace flexure;
using engine::Framework;
using engine::Matrix;
using engine::Vector;

namespace {

using test::makeFramework;

// A parallelogram four-bar with a rigid triangle on its coupler: pins 0 = (0,0), 1 = (2,0);
// cranks 0-2 and 1-3 of length 1; coupler 2-3 of length 2; vertex 4 one unit above the
// coupler's midpoint. Crank angles theta (vertex 2) and phi (vertex 3).
Framework fourBar(double theta, double phi) {
  const double x2 = std::cos(theta), y2 = std::sin(theta), x3 = 2 + std::cos(phi), y3 = std::sin(phi);
  // The triangle's apex: the midpoint of 2-3 plus the unit normal to the coupler.
  const double mx = 0.5 * (x2 + x3), my = 0.5 * (y2 + y3), l = std::hypot(x3 - x2, y3 - y2);
  const double nx = -(y3 - y2) / l, ny = (x3 - x2) / l;
  return makeFramework({{0, 0}, {2, 0}, {x2, y2}, {x3, y3}, {mx + nx, my + ny}},
                       {{1, 3}, {2, 4}, {3, 4}, {3, 5}, {4, 5}}, {1, 2});
}

// The crank angles of a configuration of fourBar.
std::pair<double, double> angles(const Framework& f, const Vector& x) {
  const Matrix p = f.system().vertexPositions(x);
  return {std::atan2(p(1, 2), p(0, 2)), std::atan2(p(1, 3), p(0, 3) - 2)};
}

double residual(const Framework& f, const Vector& x) {
  return f.system().residuals(x).cwiseAbs().maxCoeff() / f.system().residualScale();
}

// Drags `vertex` through the pointer positions `at(i)`, i = 1..moves, as a mouse does; every
// state must satisfy the constraints. Returns the last result, with the branch choices of all.
template <class At>
engine::DragResult dragAlong(const Framework& f, Vector& x, int vertex, At at, int moves) {
  engine::DragOptions o;
  o.tolerance = 1e-9;
  o.regular_flexes = 1;
  engine::DragResult r;
  int choices = 0;
  for (int i = 1; i <= moves; ++i) {
    r = engine::dragVertex(f, x, vertex, at(i), o);
    REQUIRE(residual(f, r.x) <= 1e-10);
    x = r.x;
    choices += r.branch_choices;
  }
  r.branch_choices = choices;
  return r;
}

engine::DragResult dragInMoves(const Framework& f, Vector& x, int vertex, const Vector& to, int moves) {
  const Vector from = f.system().vertexPositions(x).col(vertex);
  return dragAlong(f, x, vertex, [&](int i) { return Vector(from + (to - from) * (double(i) / moves)); }, moves);
}

}  // namespace

TEST_CASE("factorization: projection onto the kernel and the transposed solve, dense and sparse", "[drag]") {
  const Framework f = fourBar(0.4, 0.4);
  const engine::SparseMatrix J = f.system().jacobian(f.startCoordinates());
  for (int dense_limit : {500, 0}) {
    engine::FactorizationOptions o;
    o.dense_limit = dense_limit;
    const engine::JacobianFactorization F(J, o);
    REQUIRE(F.dense() == (dense_limit > 0));
    const Vector v = Vector::LinSpaced(J.cols(), -1.0, 2.0);
    const Vector u = F.projectOntoKernel(v);
    CHECK((J * u).norm() <= 1e-12 * v.norm());
    // v - u lies in the row space: orthogonal to every kernel vector.
    CHECK((F.kernel().transpose() * (v - u)).norm() <= 1e-12 * v.norm());
    const Vector y = F.solveTransposed(v - u);
    CHECK((Matrix(J).transpose() * y - (v - u)).norm() <= 1e-10 * v.norm());
  }
}

TEST_CASE("tangent cone: the flat four-bar has the parallelogram and the antiparallelogram branches", "[drag]") {
  // At the flat position the crank velocities (theta', phi') are free to first order; the
  // coupler's second-order equation is 3 theta'^2 - 2 theta' phi' - phi'^2 = 0, that is
  // phi' = theta' (parallelogram) or phi' = -3 theta' (antiparallelogram).
  const Framework f = fourBar(0, 0);
  const engine::TangentCone cone = engine::tangentCone(f, f.startCoordinates());
  REQUIRE(cone.computed);
  CHECK(cone.kernel_dimension == 2);
  CHECK(cone.stresses == 1);
  REQUIRE(cone.directions.size() == 4);
  int parallel = 0, anti = 0;
  const auto& sys = f.system();
  for (const Vector& b : cone.directions) {
    const double t = b[sys.variableIndex(2, 1)], p = b[sys.variableIndex(3, 1)];
    REQUIRE(std::abs(t) > 0.1);
    if (std::abs(p / t - 1) < 1e-6) ++parallel;
    if (std::abs(p / t + 3) < 1e-6) ++anti;
  }
  CHECK(parallel == 2);
  CHECK(anti == 2);
  // Away from the flat position: a smooth curve, one line, two half-branches.
  const Framework g = fourBar(0.5, 0.5);
  const engine::TangentCone smooth = engine::tangentCone(g, g.startCoordinates());
  CHECK(smooth.kernel_dimension == 1);
  CHECK(smooth.directions.size() == 2);
}

TEST_CASE("drag: through the flat four-bar the drag keeps the branch closest to the pointer", "[drag]") {
  SECTION("straight up: the parallelogram continues") {
    const Framework f = fourBar(-0.3, -0.3);
    Vector x = f.startCoordinates();
    // The pointer goes up along the arc of vertex 4 on the parallelogram, (1 + cos theta,
    // 1 + sin theta), through the flat position (theta = 0), where the antiparallelogram's
    // tangent at vertex 4 is (2, -1): further from the pointer's direction.
    const auto arc = [](int i) {
      const double t = -0.3 + 0.6 * i / 30.0;
      return Vector(Eigen::Vector2d(1 + std::cos(t), 1 + std::sin(t)));
    };
    const engine::DragResult r = dragAlong(f, x, 4, arc, 30);
    CHECK(r.reached);
    const auto [t, p] = angles(f, x);
    CHECK(t == Approx(0.3).margin(1e-6));
    CHECK(p == Approx(0.3).margin(1e-6));
  }
  SECTION("sideways at the flat position: the antiparallelogram") {
    const Framework f = fourBar(0, 0);
    Vector x = f.startCoordinates();
    // On the parallelogram vertex 4 cannot pass x = 2; the antiparallelogram carries it right.
    const engine::DragResult r = dragInMoves(f, x, 4, Eigen::Vector2d(2.3, 1.0), 30);
    const Matrix p = f.system().vertexPositions(x);
    CHECK(p(0, 4) > 2.15);
    CHECK(r.branch_choices >= 1);
    const auto [t, ph] = angles(f, x);
    CHECK(std::abs(t - ph) > 0.05);  // not a parallelogram
    // Pins stay.
    CHECK(p.col(0).norm() == 0);
    CHECK((p.col(1) - Eigen::Vector2d(2, 0)).norm() == 0);
  }
}

TEST_CASE("drag: a pull the mechanism cannot follow goes as far as it can and names the bar that holds it",
          "[drag]") {
  const Framework f = fourBar(0.5, 0.5);
  const Vector x = f.startCoordinates();
  // Vertex 2 on its crank, pulled straight out along the crank: the crank 0-2 holds it.
  const Eigen::Vector2d out(1.5 * std::cos(0.5), 1.5 * std::sin(0.5));
  const engine::DragResult r = engine::dragVertex(f, x, 2, out);
  CHECK_FALSE(r.reached);
  CHECK(r.stop == "held by the constraints");
  REQUIRE_FALSE(r.held.empty());
  CHECK(r.held[0].label == "edge 0-2");
  CHECK(std::abs(r.held[0].weight) == Approx(1.0));
  CHECK(r.remaining == Approx(0.5).margin(1e-6));
  CHECK(residual(f, r.x) <= 1e-10);
  // A pinned vertex cannot be dragged.
  CHECK_THROWS_WITH(engine::dragVertex(f, x, 0, Eigen::Vector2d(1, 1)), Catch::Contains("pinned"));
}

TEST_CASE("drag: a large braced grid (sparse factorization, persistent stresses) shears after its top vertex",
          "[drag]") {
  // 20 x 14 unit grid, squares braced in every other row, the bottom row pinned: 520 free
  // coordinates (above the dense limit), 6 shear flexes plus the top row's, and the stresses
  // of the rows of parallel bars between braced strips (they persist along the motion).
  const int cols = 20, rows = 14;
  Matrix p(2, cols * rows);
  std::vector<Framework::Edge> edges;
  std::vector<int> pinned;
  const auto id = [&](int c, int r) { return r * cols + c; };
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      p.col(id(c, r)) << c, r;
      if (c + 1 < cols) edges.push_back({id(c, r), id(c + 1, r)});
      if (r + 1 < rows) edges.push_back({id(c, r), id(c, r + 1)});
      if (c + 1 < cols && r + 1 < rows && r % 2 == 0) edges.push_back({id(c, r), id(c + 1, r + 1)});
      if (r == 0) pinned.push_back(id(c, r));
    }
  const Framework f(p, edges, pinned);
  REQUIRE(f.system().numVariables() > engine::FactorizationOptions().dense_limit);
  const int top = id(10, rows - 1);
  engine::DragOptions o;
  o.tolerance = 1e-3;
  o.max_moves = 3;
  Vector x = f.startCoordinates();
  for (int i = 1; i <= 10; ++i) {
    const Eigen::Vector2d target(10 - 0.1 * i, rows - 1);
    const engine::DragResult r = engine::dragVertex(f, x, top, target, o);
    INFO("pointer move " << i << ": " << r.stop);
    REQUIRE(residual(f, r.x) <= 1e-10);
    x = r.x;
    const Matrix q = f.system().vertexPositions(x);
    for (int c = 0; c < cols; ++c) CHECK((q.col(id(c, 0)) - p.col(id(c, 0))).norm() == 0);
    CHECK(q(1, top) < rows - 1);  // the shear lowers it
    // Held: what is left of the pull is orthogonal to the direction in which the vertex can
    // move (the top eigenvector of its block of the projector onto the kernel, from an SVD of
    // the dense Jacobian): the vertex is at the foot of the pointer on its curve.
    if (r.stop == "held by the constraints") {
      Eigen::JacobiSVD<Matrix> svd(Matrix(f.system().jacobian(x)), Eigen::ComputeFullV);
      const Eigen::Index rank = (svd.singularValues().array() > 1e-9 * svd.singularValues()[0]).count();
      const Matrix K = svd.matrixV().rightCols(svd.matrixV().cols() - rank);
      Matrix Kv(2, K.cols());
      for (int k = 0; k < 2; ++k) Kv.row(k) = K.row(f.system().variableIndex(top, k));
      const Eigen::SelfAdjointEigenSolver<Matrix> eig(Kv * Kv.transpose());
      const Vector rest = target - q.col(top);
      CHECK(std::abs(eig.eigenvectors().col(1).dot(rest)) <= 2 * o.tolerance);
    } else {
      CHECK((r.stop == "reached" || r.stop == "move limit"));
    }
    if (r.stop == "reached") CHECK((q.col(top) - target).norm() <= o.tolerance);
  }
  // A unit pull to the left: the vertex has gone most of the way, and down.
  const Matrix q = f.system().vertexPositions(x);
  CHECK(q(0, top) < 9.1);
  CHECK((q.col(top) - Eigen::Vector2d(9, rows - 1)).norm() < 0.2);
}

TEST_CASE("drag: an unpinned rigid tetrahedron follows its vertex by a rigid motion", "[drag]") {
  const Framework f = makeFramework({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
                                    {{1, 2}, {1, 3}, {1, 4}, {2, 3}, {2, 4}, {3, 4}});
  Vector x = f.startCoordinates();
  const engine::DragResult r = dragInMoves(f, x, 3, Eigen::Vector3d(0.4, 0.3, 1.2), 5);
  CHECK(r.reached);
  const Matrix p = f.system().vertexPositions(x);
  CHECK((p.col(3) - Eigen::Vector3d(0.4, 0.3, 1.2)).norm() <= 1e-9);
  CHECK((p.col(1) - p.col(0)).norm() == Approx(1.0).epsilon(1e-12));
  CHECK((p.col(3) - p.col(2)).norm() == Approx(std::sqrt(2.0)).epsilon(1e-12));
}

TEST_CASE("constraint system: one equation's label and vertices agree with the whole list", "[drag]") {
  const Framework f = fourBar(0.4, 0.4);
  const auto& sys = f.system();
  const std::vector<std::string> all = sys.equationLabels(1);
  REQUIRE(static_cast<int>(all.size()) == sys.numEquations());
  for (int r = 0; r < sys.numEquations(); ++r) {
    CHECK(sys.equationLabel(r, 1) == all[static_cast<size_t>(r)]);
    CHECK(sys.equationVertices(r).size() == 2);
  }
  CHECK(sys.equationVertices(2) == std::vector<int>{2, 3});  // the coupler 3-4, numbered from 0
}
