#include "engine/drag.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "engine/factorization.h"
#include "engine/flex_space.h"
#include "engine/normal_equations.h"
#include "engine/random.h"

namespace flexure::engine {

namespace {

double cosine(const Vector& a, const Vector& b) {
  const double n = a.norm() * b.norm();
  return n > 0 ? a.dot(b) / n : 0.0;
}

// Unit vectors c (k values) with c^T Q_j c = 0 for every j, found by Gauss-Newton on the sphere
// from seeded starts; one per line (c and -c are the same line), in the order found.
std::vector<Vector> quadricLines(const std::vector<Matrix>& Q, int k, int starts, std::uint64_t seed) {
  std::vector<Vector> found;
  Random random(seed);
  const int s = static_cast<int>(Q.size());
  for (int start = 0; start < starts + k; ++start) {
    Vector c(k);
    if (start < k) c = Vector::Unit(k, start);
    else
      for (int i = 0; i < k; ++i) c[i] = random.gaussian();
    c.normalize();
    Vector r(s);
    for (int it = 0; it < 60; ++it) {
      Matrix A(s, k);
      for (int j = 0; j < s; ++j) {
        const Vector Qc = Q[j] * c;
        r[j] = c.dot(Qc);
        A.row(j) = 2 * Qc.transpose();
      }
      if (r.lpNorm<Eigen::Infinity>() < 1e-14) break;
      const Matrix P = Matrix::Identity(k, k) - c * c.transpose();
      const Matrix At = A * P;
      const Vector step = P * At.completeOrthogonalDecomposition().solve(-r);
      if (!step.allFinite()) break;
      c += step;
      c.normalize();
    }
    for (int j = 0; j < s; ++j) r[j] = c.dot(Q[j] * c);
    // Loose: near (not on) a singular point a double root splits or vanishes by about the
    // distance; the probe step decides.
    if (!(r.lpNorm<Eigen::Infinity>() < 1e-3)) continue;
    bool seen = false;
    for (const Vector& f : found) seen = seen || std::abs(f.dot(c)) > 1 - 1e-6;
    if (!seen) found.push_back(c);
  }
  return found;
}

// The dragged vertex's free coordinates among all N.
struct VertexCoordinates {
  std::vector<int> idx;  // one per dimension
  int N = 0;

  int d() const { return static_cast<int>(idx.size()); }
  // The vertex's position in x.
  Vector position(const Vector& x) const {
    Vector p(d());
    for (int k = 0; k < d(); ++k) p[k] = x[idx[static_cast<size_t>(k)]];
    return p;
  }
  // The displacement dvec of the vertex alone, in free coordinates.
  Vector wish(const Vector& dvec) const {
    Vector v = Vector::Zero(N);
    for (int k = 0; k < d(); ++k) v[idx[static_cast<size_t>(k)]] = dvec[k];
    return v;
  }
};

// Chord iterations: least-squares Gauss-Newton steps with the Jacobian of the point the move
// starts from (dense: its SVD; large: the damped normal equations, made once per move). A move
// is short, so they contract fast, and a large sparse system is factored once per move instead
// of once per iteration; the full corrector when they do not.
// When they contract slowly (a long move: by less than 4x per step), a large system's normal
// equations are formed again where the iteration is, a few times: Gauss-Newton on them, still
// far cheaper there than the QR that the full corrector makes at every iteration.
//
// Large systems' steps are least-squares over all the equations, d = (J^T J + mu I)^-1 J^T r
// (NormalEquations with kDamping). Not the sparse QR's minimum-norm solve: that one solves only
// the equations its QR kept as independent, and where stresses persist (a braced grid's rows of
// parallel bars) those alone cut out another set through x with the same tangent: chord steps
// then stall at a residual of the order of the step squared. The tiny mu (relative to J's
// largest column) makes the kernel's directions harmless; they are the tangent.
class ChordIterations {
 public:
  // J: the Jacobian of the point each move starts from (refilled by the caller per move).
  ChordIterations(const ConstraintSystem& sys, const SparseMatrix& J, const CorrectorOptions& o)
      : sys_(sys), J_(J), tolerance_(o.residual_tolerance * sys.residualScale()),
        stall_(o.stall_tolerance * sys.residualScale()), J_here_(J) {}

  // A new move: J holds the Jacobian of its start.
  void newMove() { normal_.reset(); }

  // From y with F, the factorization at the move's start: the point they converge to, if any.
  std::optional<Vector> operator()(const JacobianFactorization& F, Vector y) {
    NormalEquations* steps = nullptr;
    if (!F.dense()) {
      if (!normal_) factorAt(normal_, J_);
      steps = &*normal_;
    }
    int refreshes = 0;
    double previous = std::numeric_limits<double>::infinity();
    for (int it = 0; it < 30; ++it) {
      if (steps && !steps->factored()) return std::nullopt;
      const Vector r = sys_.residuals(y);
      const double res = r.lpNorm<Eigen::Infinity>();
      if (res <= tolerance_) return y;
      if (!(res < (steps ? 0.25 : 0.5) * previous)) {
        if (!steps || refreshes >= 6 || !(res < previous)) return res <= stall_ ? std::optional<Vector>(y) : std::nullopt;
        sys_.jacobian(y, J_here_);
        steps = &factorAt(here_, J_here_);
        ++refreshes;
        if (!steps->factored()) return std::nullopt;
      }
      previous = res;
      y -= steps ? steps->solveFactored(r) : F.solveMinNorm(r);
    }
    return std::nullopt;
  }

 private:
  // The damping of the chord steps' normal equations, relative to the largest diagonal entry
  // of J^T J.
  static constexpr double kDamping = 1e-10;

  static NormalEquations& factorAt(std::optional<NormalEquations>& slot, const SparseMatrix& J) {
    NormalEquations& n = slot.emplace();
    n.use({}, {}, kDamping);
    n.factor(J);
    return n;
  }

  const ConstraintSystem& sys_;
  const SparseMatrix& J_;
  const double tolerance_, stall_;
  std::optional<NormalEquations> normal_;  // of the move's J, once made
  SparseMatrix J_here_;
  std::optional<NormalEquations> here_;    // of J_here_, where the iteration is
};

// Near a singular point: small singular values that the rank counts as nonzero, or (on one)
// more flexes than at a regular point.
bool nearSingular(const Model& model, const JacobianFactorization& F, const Vector& x, const DragOptions& o) {
  if (!F.dense() || F.rank() <= 0) return false;
  const int N = model.system().numVariables();
  const Vector& s = F.singularValues();
  if (s[F.rank() - 1] < o.singular_ratio * s[0]) return true;
  return o.regular_flexes >= 0 && N - F.rank() > o.regular_flexes &&
         N - F.rank() - trivialFlexes(model, x, 1e-8).cols() > o.regular_flexes;
}

// One move's wish: from x, the vertex displacement dvec (of length dist) to the target, v its
// free coordinates; the tangent cone at x once computed.
struct Move {
  const Model& model;
  const DragOptions& o;
  const VertexCoordinates& vertex;
  const Vector& x;
  Vector dvec;
  double dist;
  Vector v;
  double max_len;
  std::optional<TangentCone> cone;
};

// Along the cone's direction closest to the wish (any direction, or only where branches
// cross), as far as the wish goes linearly, on a sphere about x so that the corrector lands
// on that branch and not on the nearest one.
std::optional<Vector> alongCone(Move& m, bool crossing_only) {
  const DragOptions& o = m.o;
  if (!m.cone) {
    TangentConeOptions co = o.cone;
    co.loose_tolerance = o.singular_ratio;
    m.cone = tangentCone(m.model, m.x, co);
  }
  const Vector& v = m.v;
  const Vector* best = nullptr;
  for (const Vector& b : m.cone->directions)
    if (!best || b.dot(v) > best->dot(v)) best = &b;
  if ((crossing_only && !m.cone->branched) || !best || !(best->dot(v) > o.held_gain * v.norm())) return std::nullopt;
  const double along = m.vertex.position(*best).dot(m.dvec) / m.dist;  // vertex travel per unit step
  double h = std::min(m.max_len, along > 0 ? m.dist / along : m.max_len);
  return branchStep(m.model.system(), m.x, *best, h, o.corrector);
}

// The tangent u = P wish(z) whose vertex part is dvec: P_vv z = dvec with P_vv (d x d) the
// vertex's block of the projector onto the kernel; directions in which the vertex cannot move
// (eigenvalues of P_vv, in [0, 1], at rounding level or below weak_direction times the largest)
// are left out. A small eigenvalue is a vertex that moves little while others move much:
// reaching the pointer that way would swing the rest of the figure. Nothing when the vertex is
// held (it gains too little towards the target along u).
std::optional<Vector> reachableTangent(const Move& m, const JacobianFactorization& F) {
  const int N = m.vertex.N, d = m.vertex.d();
  const Vector& dvec = m.dvec;
  Matrix cols(N, d), Pvv(d, d);
  for (int k = 0; k < d; ++k) {
    cols.col(k) = F.projectOntoKernel(m.vertex.wish(Vector::Unit(d, k)));
    Pvv.col(k) = m.vertex.position(cols.col(k));
  }
  const Eigen::SelfAdjointEigenSolver<Matrix> eig(0.5 * (Pvv + Pvv.transpose()));
  const double top = eig.eigenvalues()[d - 1];
  Vector z = Vector::Zero(d), reachable = Vector::Zero(d);
  for (int k = 0; k < d; ++k) {
    const double lambda = eig.eigenvalues()[k];
    const auto e = eig.eigenvectors().col(k);
    if (lambda > 1e-9 && lambda > m.o.weak_direction * top) {
      z += e * (e.dot(dvec) / lambda);
      reachable += e * e.dot(dvec);
    }
  }
  // What is left of the wish lies in the directions in which the vertex cannot move: it
  // is as near as it gets, at the foot of the pointer on its curve.
  if (reachable.norm() <= m.o.tolerance) return std::nullopt;
  const Vector u = cols * z;
  const double gain = m.vertex.position(u).dot(dvec) / (m.dist * m.dist);
  if (!(gain > m.o.held_gain) || !(u.norm() > 0)) return std::nullopt;
  return u;
}

// The first step length along u: no vertex moves more than max_len in one move (a shear of a
// large grid moves every vertex a little: the 2-norm of the whole step says nothing about any
// one of them), nor more than swing times the wish: a pointer a little off the vertex's reach
// does not swing the rest of the figure far.
double firstStepLength(const Move& m, const Vector& u) {
  const ConstraintSystem& sys = m.model.system();
  const int d = m.vertex.d();
  double largest = 0;
  for (int b = 0; b < sys.numBlocks(); ++b) {
    double s2 = 0;
    for (int k = 0; k < d; ++k)
      if (const int j = sys.variableIndex(b, k); j >= 0) s2 += u[j] * u[j];
    largest = std::max(largest, s2);
  }
  return std::min(1.0, std::min(m.max_len, m.o.swing * m.dist) / std::max(std::sqrt(largest), 1e-300));
}

// Shorter and shorter steps along u with the cheap chord iterations first, then with the full
// corrector: the first point they reach that lies ahead along u.
std::optional<Vector> halving(const Move& m, ChordIterations& chord, const JacobianFactorization& F,
                              const Vector& u) {
  const double t0 = firstStepLength(m, u);
  std::optional<Vector> next;
  for (int pass = 0; pass < 2 && !next; ++pass) {
    double t = t0;
    for (int halving = 0; halving < 8 && !next; ++halving, t *= 0.5) {
      std::optional<Vector> y;
      if (pass == 0) {
        y = chord(F, m.x + t * u);
      } else if (const CorrectorResult c = correct(m.model.system(), m.x + t * u, m.o.corrector);
                 c.status == CorrectorStatus::Converged) {
        y = c.x;
      }
      if (y && cosine(*y - m.x, u) >= 0.8) next = y;
    }
  }
  return next;
}

// The move's end: along the tangent cone near a singular point, else along the reachable
// tangent, else (on a singular point) along the closest branch. Nothing, with the reason in
// `stop`, when the vertex is held or the corrector finds no point.
std::optional<Vector> nextPoint(Move& m, ChordIterations& chord, const JacobianFactorization& F, bool near_singular,
                                int& branch_choices, std::string& stop) {
  const auto viaCone = [&](bool crossing_only) {
    std::optional<Vector> y = alongCone(m, crossing_only);
    if (y) ++branch_choices;
    return y;
  };
  if (near_singular)
    if (std::optional<Vector> y = viaCone(true)) return y;
  const std::optional<Vector> u = reachableTangent(m, F);
  if (!u) {
    stop = "held by the constraints";
    return std::nullopt;
  }
  std::optional<Vector> next = halving(m, chord, F, *u);
  // On a singular point the kernel holds more than the branches: off them the corrector
  // fails; then along the closest branch.
  if (!next && F.dense()) next = viaCone(false);
  // No branch leaves towards the wish: the singular point holds it.
  if (!next)
    stop = m.cone && !m.cone->directions.empty() ? "held by the constraints"
                                                 : "the corrector found no nearby point on the constraint set";
  return next;
}

// The stress that balances the pull v (free coordinates) at F's point: which equations hold
// the vertex back, the largest weights first.
std::vector<Holding> holdingStress(const ConstraintSystem& sys, const JacobianFactorization& F, const Vector& v) {
  std::vector<Holding> held;
  const Vector y = F.solveTransposed(v - F.projectOntoKernel(v));
  const double top = y.lpNorm<Eigen::Infinity>();
  if (top > 0) {
    std::vector<int> rows;
    for (int r = 0; r < y.size(); ++r)
      if (std::abs(y[r]) >= 0.1 * top) rows.push_back(r);
    std::stable_sort(rows.begin(), rows.end(), [&](int a, int b) { return std::abs(y[a]) > std::abs(y[b]); });
    if (rows.size() > 12) rows.resize(12);
    for (int r : rows) held.push_back({r, sys.equationLabel(r, 0), y[r] / top, sys.equationVertices(r)});
  }
  return held;
}

}  // namespace

std::optional<Vector> branchStep(const ConstraintSystem& system, const Vector& x, const Vector& direction, double h,
                                 const CorrectorOptions& options) {
  for (int halving = 0; halving < 8; ++halving, h *= 0.5) {
    const Sphere sphere{x, h};
    const CorrectorResult c = correct(system, x + h * direction, options, {}, nullptr, &sphere);
    if (c.status == CorrectorStatus::Converged && cosine(c.x - x, direction) >= 0.8) return c.x;
  }
  return std::nullopt;
}

Vector locateSingularPoint(const Model& model, const Vector& before, const Vector& at, const Vector& after,
                           const CorrectorOptions& options, int evaluations) {
  const ConstraintSystem& sys = model.system();
  if (sys.numEquations() == 0 || sys.numVariables() == 0) return at;
  const auto singularValues = [&](const Vector& x) {
    Vector s;
    denseSvd(Matrix(sys.jacobian(x)), s, nullptr, nullptr, false);
    return s;
  };
  // The rank at a regular point: that of the neighbours (the larger, if they differ).
  int r = 0;
  for (const Vector* x : {&before, &after}) {
    const Vector s = singularValues(*x);
    int rank = 0;
    while (rank < s.size() && s[rank] > 1e-6 * s[0]) ++rank;
    r = std::max(r, rank);
  }
  if (r == 0) return at;
  // sigma_r / sigma_1 at the point of the curve at t in [-1, 1] (t = -1, 0, 1: the samples).
  const Vector mid = 0.5 * (after - before), bend = 0.5 * (after - 2.0 * at + before);
  const auto ratioAt = [&](const Vector& x) {
    const Vector s = singularValues(x);
    return r - 1 < s.size() && s[0] > 0 ? s[r - 1] / s[0] : 0.0;
  };
  // The sample itself, unless a point of the curve is more singular.
  Vector best = at;
  double best_ratio = ratioAt(at);
  const auto ratio = [&](double t) {
    const CorrectorResult c = correct(sys, at + t * mid + t * t * bend, options);
    if (c.status != CorrectorStatus::Converged) return std::numeric_limits<double>::infinity();
    const double q = ratioAt(c.x);
    if (q < best_ratio) best_ratio = q, best = c.x;
    return q;
  };
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double a = -1.0, b = 1.0, c = b - g * (b - a), d = a + g * (b - a);
  double fc = ratio(c), fd = ratio(d);
  for (int i = 2; i < evaluations; ++i) {
    if (fc < fd) {
      b = d, d = c, fd = fc;
      c = b - g * (b - a);
      fc = ratio(c);
    } else {
      a = c, c = d, fc = fd;
      d = a + g * (b - a);
      fd = ratio(d);
    }
  }
  return best;
}

TangentCone tangentCone(const Model& model, const Vector& x, const TangentConeOptions& o) {
  const ConstraintSystem& sys = model.system();
  const int N = sys.numVariables(), m = sys.numEquations();
  TangentCone cone;
  if (N > o.dense_limit) {
    cone.note = "not computed: " + std::to_string(N) + " free coordinates (more than " +
                std::to_string(o.dense_limit) + ")";
    return cone;
  }
  cone.computed = true;
  if (N == 0) {
    cone.note = "no free coordinates";
    return cone;
  }
  // The kernel and cokernel of J at the loose tolerance.
  Matrix K_all, W;
  if (m == 0) {
    K_all = Matrix::Identity(N, N);
    W = Matrix(0, 0);
  } else {
    Vector s;
    Matrix U, V;
    denseSvd(Matrix(sys.jacobian(x)), s, &U, &V, true);
    int r = 0;
    while (r < s.size() && s[r] > o.loose_tolerance * s[0]) ++r;
    if (s[0] == 0) r = 0;
    cone.sigma_ratio = r < s.size() && s[0] > 0 ? s[r] / s[0] : 0.0;
    K_all = V.rightCols(N - r);
    W = U.rightCols(m - r);
  }
  const Matrix K = nontrivialPart(K_all, trivialFlexes(model, x, 1e-8));
  const int k = static_cast<int>(K.cols());
  cone.kernel_dimension = k;
  cone.stresses = static_cast<int>(W.cols());
  if (k == 0) {
    cone.note = "no nontrivial flex: rigid here";
    return cone;
  }
  // The second-order equations on the kernel: w_j^T F''(Kc, Kc) = 0 for every stress w_j.
  std::vector<Matrix> Q;
  double largest = 0;
  if (W.cols() > 0) {
    std::vector<Matrix> H(static_cast<size_t>(W.cols()), Matrix::Zero(k, k));
    for (int a = 0; a < k; ++a)
      for (int b = a; b < k; ++b) {
        const Vector h = W.transpose() * sys.secondDerivative(x, K.col(a), K.col(b));
        for (int j = 0; j < W.cols(); ++j) H[static_cast<size_t>(j)](a, b) = H[static_cast<size_t>(j)](b, a) = h[j];
      }
    // A form is an equation when it is not rounding: against the size of F'' on the kernel.
    double hscale = 0;
    for (int a = 0; a < k; ++a) hscale = std::max(hscale, sys.secondDerivative(x, K.col(a), K.col(a)).norm());
    for (const Matrix& q : H) largest = std::max(largest, q.norm());
    for (Matrix& q : H)
      if (q.norm() > 1e-6 * hscale && q.norm() > 1e-8 * largest) Q.push_back(q / q.norm());
  }
  std::vector<Vector> lines;
  if (Q.empty() || k == 1) {
    // No second-order condition (a smooth point), or one line: the kernel's own directions.
    const Matrix B = canonicalBasis(K);
    for (int i = 0; i < k; ++i) lines.push_back(B.col(i));
    cone.note = Q.empty() ? "no second-order equation: the kernel's basis" : "one flex: the kernel";
  } else {
    cone.branched = true;
    for (const Vector& c : quadricLines(Q, k, o.starts, o.seed)) lines.push_back(K * c);
    cone.note = "second-order equations of " + std::to_string(Q.size()) + " stress(es) on " + std::to_string(k) +
                " flexes";
  }
  // Keep the half-branches the corrector confirms.
  const double h = o.probe * std::max(extentOf(sys.positions(x)), 1e-300);
  CorrectorOptions probe = o.corrector;  // near a tangency (a cusp) Gauss-Newton is slow
  probe.max_iterations = std::max(probe.max_iterations, 100);
  std::vector<Vector> secants;
  for (const Vector& line : lines)
    for (double sign : {1.0, -1.0}) {
      const Vector b = sign * line.normalized();
      // The corrector from x + h b (minimum-norm steps): along a branch it lands away from x
      // in direction b (at a cusp closer than h: the branch bends away from its tangent);
      // where no branch leaves, it does not converge or falls back towards x.
      const CorrectorResult c = correct(sys, x + h * b, probe);
      const bool on_set = c.status == CorrectorStatus::Converged && (c.x - x).norm() >= 0.1 * h;
      if (!on_set || cosine(c.x - x, b) < o.min_cos) continue;
      // One direction per branch: near (not on) a singular point the equations' roots scatter
      // about the branch's direction, and their probes land on the same branch.
      const Vector secant = (c.x - x).normalized();
      bool seen = false;
      for (const Vector& f : secants) seen = seen || f.dot(secant) > 0.99;
      if (seen) continue;
      secants.push_back(secant);
      cone.directions.push_back(b);
      cone.landings.push_back(c.x);
    }
  return cone;
}

DragResult dragVertex(const Model& model, const Vector& x0, int vertex, const Vector& target, const DragOptions& o) {
  const ConstraintSystem& sys = model.system();
  const int d = sys.dimension();
  if (vertex < 0 || vertex >= sys.numVertices())
    throw std::invalid_argument("vertex " + std::to_string(vertex) + " does not exist (0.." +
                                std::to_string(sys.numVertices() - 1) + ")");
  if (sys.isPinned(vertex)) throw std::invalid_argument("vertex " + std::to_string(vertex) + " is pinned");
  if (target.size() != d || !target.allFinite())
    throw std::invalid_argument("the target needs " + std::to_string(d) + " finite coordinates");
  VertexCoordinates coords;
  coords.idx.resize(static_cast<size_t>(d));
  for (int k = 0; k < d; ++k) coords.idx[static_cast<size_t>(k)] = sys.variableIndex(vertex, k);
  coords.N = sys.numVariables();
  const double scale = std::max(extentOf(sys.positions(x0)), 1e-300);
  const double max_len = o.max_move * scale;

  DragResult out;
  out.x = x0;
  SparseMatrix J = sys.jacobianPattern();
  ChordIterations chord(sys, J, o.corrector);
  int stalled = 0;
  std::unique_ptr<JacobianFactorization> at_x;  // the factorization at out.x, once made
  // The last move's factorization (at the point it started from).
  std::unique_ptr<JacobianFactorization> last;
  out.stop = "move limit";
  for (; out.moves < o.max_moves; ++out.moves) {
    const Vector dvec = target - coords.position(out.x);
    const double dist = dvec.norm();
    if (dist <= o.tolerance) {
      out.reached = true;
      out.stop = "reached";
      break;
    }
    Move m{model, o, coords, out.x, dvec, dist, coords.wish(dvec), max_len, std::nullopt};
    sys.jacobian(out.x, J);
    chord.newMove();
    at_x = std::make_unique<JacobianFactorization>(J, orderedFor(o.factorization, model.system()));
    const JacobianFactorization& F = *at_x;
    const std::optional<Vector> next =
        nextPoint(m, chord, F, nearSingular(model, F, out.x, o), out.branch_choices, out.stop);
    if (!next) break;
    const double before = dist;
    out.x = *next;
    last = std::move(at_x);  // of the point left
    const double after = (target - coords.position(out.x)).norm();
    stalled = before - after < o.held_gain * before ? stalled + 1 : 0;
    if (stalled >= 3) {
      out.stop = "held by the constraints";
      ++out.moves;
      break;
    }
  }
  const Vector dvec = target - coords.position(out.x);
  out.remaining = dvec.norm();
  out.reached = out.reached || out.remaining <= o.tolerance;
  if (out.reached) out.stop = "reached";
  out.residual = sys.numEquations() > 0 ? sys.residuals(out.x).lpNorm<Eigen::Infinity>() : 0.0;
  if (!out.reached && sys.numEquations() > 0) {
    // The stress that balances the pull. A large system takes the last move's factorization
    // (a move is short; the weights are what is shown); a small one is factored where it
    // stopped.
    if (!at_x && last && !last->dense()) at_x = std::move(last);
    if (!at_x) {
      sys.jacobian(out.x, J);
      at_x = std::make_unique<JacobianFactorization>(J, orderedFor(o.factorization, model.system()));
    }
    out.held = holdingStress(sys, *at_x, coords.wish(dvec));
  }
  return out;
}

}  // namespace flexure::engine
