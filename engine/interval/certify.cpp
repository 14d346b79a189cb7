#include "engine/interval/certify.h"

#include <cmath>

#include "engine/evaluate_in.h"
#include "engine/exact/exact_rigidity.h"
#include "engine/interval/interval.h"
#include "engine/interval/verified.h"

namespace flexure::engine::certify {

namespace {

// An interval that holds the rational q (its double is within an ulp of it).
Interval enclose(const Rational& q) {
  const double d = q.get_d();
  if (Rational(d) == q) return Interval(d);
  return Interval(Interval::down(d), Interval::up(d));
}

}  // namespace

StartCertificate certifyStart(const Model& model, const Vector& x, const RigidityReport& numeric,
                              const CertifyOptions& opt) {
  StartCertificate c;
  const ConstraintSystem& sys = model.system();
  const int d = sys.dimension(), N = sys.numVariables(), m = sys.numEquations();
  if (N == 0) {  // nothing moves: the statement is exact, with no bound to give
    c.inf_rigid = c.prestress_stable = true;
    c.flexible = false;
    c.reason = "no free coordinate: every point is pinned";
    return c;
  }
  if (!model.symmetryGroup()) {
    c.reason = "the " + model.typeName() + "'s symmetries are computed numerically: its trivial flexes have no "
               "verified form";
    return c;
  }
  // The start's block positions: the doubles are exact points.
  const Matrix P = sys.positions(x);
  std::vector<Interval> pos(static_cast<size_t>(P.size()));
  std::vector<Rational> exact_pos(static_cast<size_t>(P.size()));
  for (int b = 0; b < P.cols(); ++b)
    for (int k = 0; k < d; ++k) {
      pos[static_cast<size_t>(b * d + k)] = Interval(P(k, b));
      exact_pos[static_cast<size_t>(b * d + k)] = Rational(P(k, b));
    }
  std::vector<JacobianEntry<Interval>> jac;
  std::vector<Interval> res;
  try {
    res = evaluateSystemIn(sys, pos, pos, &jac);
  } catch (const std::domain_error& e) {
    c.reason = std::string("the equations cannot be enclosed at the start: ") + e.what();
    return c;
  }
  for (int i = 0; i < m; ++i)
    if (!res[static_cast<size_t>(i)].contains(0.0)) {
      c.reason = "the start does not satisfy " + sys.equationLabel(i, opt.index_base) +
                 " (its residual is proved nonzero): the certificate is about exact solutions";
      return c;
    }
  // The trivial flexes exactly (the doubles are rationals), enclosed, each column scaled to
  // about unit length (any scaling spans the same space).
  const RationalMatrix T = exact::trivialFlexBasis(model, exact_pos);
  const int t = T.cols;
  if (N > opt.max_dense || m > opt.max_dense) {
    c.reason = std::to_string(N) + " variables and " + std::to_string(m) +
               " equations: beyond the dense verified bound's size limit (" + std::to_string(opt.max_dense) + ")";
    return c;
  }
  std::vector<Interval> Ti(static_cast<size_t>(N) * static_cast<size_t>(t));
  for (int j = 0; j < t; ++j) {
    double norm = 0;
    for (int i = 0; i < N; ++i) norm += T(i, j).get_d() * T(i, j).get_d();
    const Interval scale = Interval(1.0) / Interval(std::sqrt(norm));
    for (int i = 0; i < N; ++i) Ti[static_cast<size_t>(i * t + j)] = enclose(T(i, j)) * scale;
  }
  // Rows of J as (column, value) lists.
  std::vector<std::vector<std::pair<int, Interval>>> rows(static_cast<size_t>(m));
  for (const auto& e : jac) rows[static_cast<size_t>(e.row)].push_back({e.column, e.value});

  // Infinitesimally rigid: B = [J; T^T] has full column rank (then ker J, which holds the t
  // trivial flexes, has dimension t), proved by B^T B = J^T J + T T^T positive definite; for
  // v orthogonal to the trivial flexes |J v| = |B v| >= sqrt(lambda_min) |v|.
  {
    verified::IntervalMatrix A(N);
    for (const auto& row : rows)
      for (const auto& [i, a] : row)
        for (const auto& [j, b] : row) A(i, j) += a * b;
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < N; ++j)
        for (int k = 0; k < t; ++k)
          A(i, j) += Ti[static_cast<size_t>(i * t + k)] * Ti[static_cast<size_t>(j * t + k)];
    if (const std::optional<double> lambda = verified::smallestEigenvalueLowerBound(A)) {
      c.inf_rigid = true;
      c.flexible = false;
      c.prestress_stable = true;
      c.sigma_lower_bound = sqrt(Interval(*lambda)).lo;
      c.reason = "infinitesimally rigid: the rigidity matrix's smallest singular value on the complement of the " +
                 std::to_string(t) + " trivial flexes is at least " + shortNumber(c.sigma_lower_bound) +
                 " (interval arithmetic)";
      return c;
    }
  }
  // Flexible: J has full row rank (J J^T positive definite), so the start is a regular point,
  // and N - m > t: the realizations near it form a manifold larger than the orbit.
  if (m < N - t) {
    verified::IntervalMatrix A(m);
    // (J J^T)_ij = sum over shared columns.
    std::vector<std::vector<std::pair<int, Interval>>> cols(static_cast<size_t>(N));
    for (int i = 0; i < m; ++i)
      for (const auto& [j, v] : rows[static_cast<size_t>(i)]) cols[static_cast<size_t>(j)].push_back({i, v});
    for (const auto& col : cols)
      for (const auto& [i, a] : col)
        for (const auto& [k, b] : col) A(i, k) += a * b;
    if (verified::smallestEigenvalueLowerBound(A)) {
      c.inf_rigid = false;
      c.flexible = true;
      c.prestress_stable = false;
      c.reason = "flexible: the " + std::to_string(m) + " equations are independent (J J^T proved positive "
                 "definite) and " + std::to_string(N) + " variables leave " + std::to_string(N - m - t) +
                 " nontrivial degrees of freedom at a regular point";
      return c;
    }
  }
  c.reason = numeric.nontrivial > 0
                 ? "the floating-point analysis finds " + std::to_string(numeric.nontrivial) + " nontrivial flex(es) and " +
                       std::to_string(numeric.stresses) + " stress(es): a rank deficiency cannot be proved in floating "
                       "point (analyze --exact proves it for rational coordinates)"
                 : "the rigidity matrix's smallest singular value is too close to rounding to be proved positive";
  return c;
}

void applyCertificate(RigidityReport& rep, const StartCertificate& c) {
  RigidityReport::Certificate rc;
  rc.inf_rigid = c.inf_rigid;
  rc.flexible = c.flexible;
  rc.prestress_stable = c.prestress_stable;
  rc.reason = c.reason;
  rc.sigma_lower_bound = c.sigma_lower_bound;
  rep.certificate = rc;
  const Verdict proved = c.inf_rigid == true ? Verdict::Rigid : c.flexible == true ? Verdict::Flexible : Verdict::Unknown;
  if (proved != Verdict::Unknown && rep.rigid != proved) {
    rep.warnings.push_back(std::string("the floating-point verdict '") + toString(rep.rigid) +
                           "' contradicts the certificate, which proves '" + toString(proved) + "'");
    rep.rigid = proved;
    rep.reason = "certified: " + c.reason;
  }
}

}  // namespace flexure::engine::certify
