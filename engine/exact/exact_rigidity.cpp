#include "engine/exact/exact_rigidity.h"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <ctime>
#include <limits>

#include "engine/evaluate_in.h"
#include "engine/exact/exact_cost.h"
#include "engine/exact/exact_generators.h"
#include "engine/exact/exact_linear_algebra.h"
#include "engine/interrupt.h"

namespace flexure::engine::exact {

namespace {

// The calling thread's CPU time: the budget's "work so far" must not count what other threads
// of the process (a sweep's items, a Python program's threads) spend meanwhile.
double cpuSeconds() {
  timespec t{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// Refuses what cannot be exact: a symmetry group known only numerically, unknowns that are not
// the scene's vertices, a term that is not a polynomial.
void checkModel(const Model& model, const ExactOptions& opt) {
  const ConstraintSystem& sys = model.system();
  const std::string type = "a " + model.typeName();
  if (!model.symmetryGroup())
    throw Refusal(type + "'s symmetries are computed numerically (from its surface), so its trivial flexes have "
                  "no exact form: the exact mode takes frameworks, bodies, angles, volumes, packings and caps");
  if (sys.numBlocks() != sys.numVertices())
    throw Refusal(type + " has " + std::to_string(sys.numBlocks() - sys.numVertices()) +
                  " unknowns besides its vertices (facet normals, frames) that are computed from the vertices in "
                  "floating point; the exact mode takes systems whose unknowns are the scene's vertices");
  const int d = sys.dimension();
  for (size_t i = 0; i < sys.activeTerms().size(); ++i) {
    const ConstraintTerm& t = *sys.terms()[static_cast<size_t>(sys.activeTerms()[i])];
    if (t.degree(d) < 0)
      throw Refusal("the equation " + t.label(0, opt.index_base) +
                    " is not a polynomial in the coordinates; the exact mode takes polynomial systems");
  }
}

// The points as block positions (block-major), checked against the model's own start: the
// rationals must be the coordinates the model was built from.
std::vector<Rational> blockPositions(const Model& model, const RationalMatrix& points, const ExactOptions& opt) {
  const ConstraintSystem& sys = model.system();
  const int d = sys.dimension(), n = sys.numVertices();
  // A flat pattern given in the plane for a model in space (origami): its points at z = 0, which
  // the comparison with the model's start below confirms.
  if (points.rows == d - 1 && points.cols == n) {
    RationalMatrix lifted(d, n);
    for (int b = 0; b < n; ++b)
      for (int k = 0; k + 1 < d; ++k) lifted(k, b) = points(k, b);
    return blockPositions(model, lifted, opt);
  }
  if (points.rows != d || points.cols != n)
    throw std::invalid_argument("exact: " + std::to_string(points.cols) + " points of dimension " +
                                std::to_string(points.rows) + " for a model of " + std::to_string(n) +
                                " vertices in dimension " + std::to_string(d));
  const Matrix& start = model.startPositions();
  const double extent = std::max(1.0, start.cwiseAbs().maxCoeff());
  std::vector<Rational> pos(static_cast<size_t>(d) * static_cast<size_t>(n));
  for (int b = 0; b < n; ++b)
    for (int k = 0; k < d; ++k) {
      const Rational& q = points(k, b);
      if (std::abs(q.get_d() - start(k, b)) > 1e-12 * extent)
        throw Refusal("vertex " + std::to_string(b + opt.index_base) + " is at " + shortNumber(start(k, b)) +
                      " in coordinate " + std::to_string(k + 1) + ", not at the scene's " + toString(q) +
                      ": the model moved it (onto a surface, or by an import), so the scene's rationals are not "
                      "its start");
      pos[static_cast<size_t>(b * d + k)] = q;
    }
  return pos;
}

// A double as a rational with a 2^-30 grid relative to `size` (a candidate to check exactly).
Rational rationalize(double v, double size) {
  const double unit = std::ldexp(size, -30);
  if (size == 0 || !std::isfinite(v)) return Rational(0);
  return Rational(std::round(v / unit)) * Rational(unit);  // both exact: an integer-valued double, a power of 2 times size
}

// q as m 2^e with 0.5 <= |m| < 1 (m = 0 for q = 0), whatever the size of its numerator and
// denominator (get_d of a huge rational overflows).
double mantissa(const Rational& q, long& e) {
  if (q == 0) {
    e = 0;
    return 0;
  }
  long en = 0, ed = 0;
  const double mn = mpz_get_d_2exp(&en, q.get_num_mpz_t()), md = mpz_get_d_2exp(&ed, q.get_den_mpz_t());
  int k = 0;
  const double m = std::frexp(mn / md, &k);
  e = en - ed + k;
  return m;
}

// The columns of A in double, column j scaled by 2^-shift[j] so that its largest entry is about
// 1 (the exact bases' integers can be far beyond double's range).
Matrix scaledColumns(const RationalMatrix& A, std::vector<long>& shift) {
  Matrix M(A.rows, A.cols);
  shift.assign(static_cast<size_t>(A.cols), 0);
  std::vector<long> e(static_cast<size_t>(A.rows));
  std::vector<double> m(static_cast<size_t>(A.rows));
  for (int j = 0; j < A.cols; ++j) {
    long top = std::numeric_limits<long>::min();
    for (int i = 0; i < A.rows; ++i) {
      m[static_cast<size_t>(i)] = mantissa(A(i, j), e[static_cast<size_t>(i)]);
      if (m[static_cast<size_t>(i)] != 0) top = std::max(top, e[static_cast<size_t>(i)]);
    }
    if (top == std::numeric_limits<long>::min()) top = 0;
    shift[static_cast<size_t>(j)] = top;
    for (int i = 0; i < A.rows; ++i) {
      const long rel = e[static_cast<size_t>(i)] - top;
      M(i, j) = rel < -1100 ? 0.0 : std::ldexp(m[static_cast<size_t>(i)], static_cast<int>(rel));
    }
  }
  return M;
}

// 2^k exactly.
Rational powerOfTwo(long k) {
  mpz_class p(1);
  mpz_mul_2exp(p.get_mpz_t(), p.get_mpz_t(), static_cast<mp_bitcnt_t>(std::labs(k)));
  return k >= 0 ? Rational(p) : Rational(mpz_class(1), p);
}

// Least-squares coefficients of v in the columns of B (in double, the columns scaled),
// rationalized: B c is then a rational combination near v; empty when the solve is not finite.
std::vector<Rational> coefficientsIn(const RationalMatrix& B, const Vector& v) {
  std::vector<long> shift;
  const Matrix Bd = scaledColumns(B, shift);
  const Vector c = Bd.colPivHouseholderQr().solve(v);
  if (!c.allFinite()) return {};
  const double size = c.cwiseAbs().maxCoeff();
  std::vector<Rational> out;
  for (int i = 0; i < c.size(); ++i) out.push_back(rationalize(c[i], size) * powerOfTwo(-shift[static_cast<size_t>(i)]));
  return out;
}

// The stress-energy forms Q_c(a, b) = sum_i S(i, c) f_a^T H_i f_b on the flex basis F, one per
// stress basis column.
std::vector<RationalMatrix> energyForms(const ConstraintSystem& sys, const std::vector<Rational>& pos,
                                        const RationalMatrix& F, const RationalMatrix& S) {
  const int d = sys.dimension(), k = F.cols, m = S.rows, s = S.cols;
  // Each flex as a full displacement of the block coordinates (pinned coordinates zero).
  std::vector<std::vector<Rational>> full(static_cast<size_t>(k), std::vector<Rational>(pos.size()));
  for (int b = 0; b < sys.numBlocks(); ++b)
    for (int c = 0; c < d; ++c) {
      const int v = sys.variableIndex(b, c);
      if (v < 0) continue;
      for (int a = 0; a < k; ++a) full[static_cast<size_t>(a)][static_cast<size_t>(b * d + c)] = F(v, a);
    }
  std::vector<RationalMatrix> forms(static_cast<size_t>(s), RationalMatrix(k, k));
  std::vector<Rational> h(static_cast<size_t>(m)), local, lu, lw, out;
  for (int a = 0; a < k; ++a)
    for (int b = a; b < k; ++b) {
      interruptionPoint();
      for (size_t i = 0; i < sys.activeTerms().size(); ++i) {
        const ConstraintTerm& t = *sys.terms()[static_cast<size_t>(sys.activeTerms()[i])];
        const size_t n = t.blocks().size() * static_cast<size_t>(d);
        local.resize(n), lu.resize(n), lw.resize(n), out.resize(static_cast<size_t>(t.numResiduals()));
        size_t c = 0;
        for (int blk : t.blocks())
          for (int q = 0; q < d; ++q, ++c) {
            const size_t g = static_cast<size_t>(blk * d + q);
            local[c] = pos[g], lu[c] = full[static_cast<size_t>(a)][g], lw[c] = full[static_cast<size_t>(b)][g];
          }
        termSecondDerivative(t, local.data(), local.data(), lu.data(), lw.data(), d, out.data());
        for (int r = 0; r < t.numResiduals(); ++r) h[static_cast<size_t>(sys.rowOffset(static_cast<int>(i)) + r)] = out[static_cast<size_t>(r)];
      }
      for (int c = 0; c < s; ++c) {
        Rational q = 0;
        for (int i = 0; i < m; ++i)
          if (S(i, c) != 0 && h[static_cast<size_t>(i)] != 0) q += S(i, c) * h[static_cast<size_t>(i)];
        forms[static_cast<size_t>(c)](a, b) = q;
        forms[static_cast<size_t>(c)](b, a) = q;
      }
    }
  return forms;
}

// The free variables block by block in reverse Cuthill-McKee order of the blocks' graph (two
// blocks adjacent when a term holds both): a banded order whatever order the file lists them
// in, which keeps the fill of the modular elimination small.
std::vector<int> bandedColumnOrder(const ConstraintSystem& sys) {
  const int B = sys.numBlocks(), d = sys.dimension();
  std::vector<std::vector<int>> adj(static_cast<size_t>(B));
  for (int ti : sys.activeTerms()) {
    const std::vector<int>& b = sys.terms()[static_cast<size_t>(ti)]->blocks();
    for (size_t i = 0; i < b.size(); ++i)
      for (size_t j = i + 1; j < b.size(); ++j) {
        adj[static_cast<size_t>(b[i])].push_back(b[j]);
        adj[static_cast<size_t>(b[j])].push_back(b[i]);
      }
  }
  for (auto& a : adj) {
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
  }
  auto degree = [&](int v) { return adj[static_cast<size_t>(v)].size(); };
  std::vector<int> order, level(static_cast<size_t>(B), -1);
  std::vector<char> done(static_cast<size_t>(B), 0);
  // Breadth-first from `root` over the unvisited blocks, neighbours by increasing degree; returns
  // the visit order (levels in `level`).
  auto bfs = [&](int root) {
    std::vector<int> visit{root};
    level[static_cast<size_t>(root)] = 0;
    for (size_t h = 0; h < visit.size(); ++h) {
      std::vector<int> next;
      for (int w : adj[static_cast<size_t>(visit[h])])
        if (level[static_cast<size_t>(w)] < 0 && !done[static_cast<size_t>(w)]) {
          level[static_cast<size_t>(w)] = level[static_cast<size_t>(visit[h])] + 1;
          next.push_back(w);
        }
      std::stable_sort(next.begin(), next.end(), [&](int a, int b) { return degree(a) < degree(b); });
      visit.insert(visit.end(), next.begin(), next.end());
    }
    return visit;
  };
  std::vector<int> by_degree(static_cast<size_t>(B));
  for (int v = 0; v < B; ++v) by_degree[static_cast<size_t>(v)] = v;
  std::stable_sort(by_degree.begin(), by_degree.end(), [&](int a, int b) { return degree(a) < degree(b); });
  for (int start : by_degree) {
    if (done[static_cast<size_t>(start)]) continue;
    // A pseudo-peripheral root: the last block of a search from the lowest-degree one.
    std::vector<int> visit = bfs(start);
    const int root = visit.back();
    for (int v : visit) level[static_cast<size_t>(v)] = -1;
    visit = bfs(root);
    for (int v : visit) done[static_cast<size_t>(v)] = 1;
    order.insert(order.end(), visit.rbegin(), visit.rend());
  }
  std::vector<int> columns;
  for (int b : order)
    for (int k = 0; k < d; ++k)
      if (const int v = sys.variableIndex(b, k); v >= 0) columns.push_back(v);
  return columns;
}

RationalMatrix combination(const std::vector<RationalMatrix>& forms, const std::vector<Rational>& c) {
  RationalMatrix Q(forms[0].rows, forms[0].cols);
  for (size_t j = 0; j < forms.size(); ++j)
    if (c[j] != 0)
      for (size_t e = 0; e < Q.data.size(); ++e) Q.data[e] += c[j] * forms[j].data[e];
  return Q;
}

// Prestress stability decided exactly where possible: a stress whose energy is positive definite
// on the flexes (the candidates: the double analysis's blocking stress, each basis stress and its
// negative), or a flex on which every stress's energy vanishes (none can then be definite).
void decidePrestress(const ConstraintSystem& sys, const std::vector<Rational>& pos, const RigidityReport* numeric,
                     ExactAnalysis& ex) {
  const int s = ex.stresses, k = ex.nontrivial, m = ex.equations;
  const std::vector<RationalMatrix> forms = energyForms(sys, pos, ex.flex_basis, ex.stress_basis);
  std::vector<std::pair<std::vector<Rational>, std::string>> candidates;
  if (numeric && numeric->prestress_stable == true && numeric->blocking_stress.size() == m) {
    // The double stress is in the weighted equations: the formula's rows times rowWeight().
    Vector w = numeric->blocking_stress;
    for (size_t i = 0; i < sys.activeTerms().size(); ++i) {
      const ConstraintTerm& t = *sys.terms()[static_cast<size_t>(sys.activeTerms()[i])];
      for (int r = 0; r < t.numResiduals(); ++r) w[sys.rowOffset(static_cast<int>(i)) + r] *= t.rowWeight();
    }
    std::vector<Rational> c = coefficientsIn(ex.stress_basis, w);
    if (!c.empty()) candidates.push_back({std::move(c), "the floating-point analysis's blocking stress (rounded to rationals)"});
  }
  for (int j = 0; j < s; ++j)
    for (int sign : {1, -1}) {
      std::vector<Rational> c(static_cast<size_t>(s));
      c[static_cast<size_t>(j)] = sign;
      candidates.push_back({c, s == 1 ? (sign > 0 ? "the stress" : "the negated stress")
                                      : "basis stress " + std::to_string(j + 1) + (sign > 0 ? "" : ", negated")});
    }
  for (const auto& [c, what] : candidates)
    if (positiveDefinite(combination(forms, c))) {
      ex.prestress_stable = true;
      ex.blocking_stress = RationalMatrix(m, 1);
      for (int i = 0; i < m; ++i)
        for (int j = 0; j < s; ++j) ex.blocking_stress(i, 0) += c[static_cast<size_t>(j)] * ex.stress_basis(i, j);
      ex.note = "prestress stable: the energy of " + what + " is positive definite on the " + std::to_string(k) +
                " nontrivial flexes (exact LDL^T)";
      return;
    }
  if (s == 1) {
    ex.prestress_stable = false;
    ex.note = "not prestress stable: the one stress (up to scale) has an energy that is not definite on the "
              "nontrivial flexes (exact LDL^T of both signs)";
    return;
  }
  // A flex with zero energy under every basis stress: each basis flex, and the double
  // analysis's unblocked flex.
  std::vector<std::pair<std::vector<Rational>, std::string>> flexes;
  for (int a = 0; a < k; ++a) {
    std::vector<Rational> y(static_cast<size_t>(k));
    y[static_cast<size_t>(a)] = 1;
    flexes.push_back({y, "basis flex " + std::to_string(a + 1)});
  }
  if (numeric && numeric->second_order_rigid == false && numeric->flex_basis_computed &&
      numeric->auto_flex.size() == numeric->flex_basis.cols() && numeric->flex_basis.rows() == ex.variables) {
    std::vector<Rational> y = coefficientsIn(ex.flex_basis, numeric->flex_basis * numeric->auto_flex);
    if (!y.empty()) flexes.push_back({std::move(y), "the floating-point analysis's unblocked flex (rounded to rationals)"});
  }
  for (const auto& [y, what] : flexes) {
    bool isotropic = true;
    for (const RationalMatrix& Q : forms) {
      Rational e = 0;
      for (int a = 0; a < k; ++a)
        for (int b = 0; b < k; ++b) e += y[static_cast<size_t>(a)] * Q(a, b) * y[static_cast<size_t>(b)];
      if (e != 0) {
        isotropic = false;
        break;
      }
    }
    if (isotropic) {
      ex.prestress_stable = false;
      ex.note = "not prestress stable: every stress's energy vanishes on " + what + " (exact)";
      return;
    }
  }
  ex.note = "prestress stability not decided exactly: no candidate stress (" + std::to_string(candidates.size()) +
            ") has a positive definite energy, and no flex with zero energy under every stress was found";
}

}  // namespace

RationalMatrix trivialFlexBasis(const Model& model, const std::vector<Rational>& pos) {
  const ConstraintSystem& sys = model.system();
  const int d = sys.dimension(), N = sys.numVariables();
  if (!model.symmetryGroup()) throw Refusal("the " + model.typeName() + "'s symmetries are computed numerically");
  // The group's generators on the free coordinates, restricted to those that fix the pinned
  // blocks.
  RationalMatrix block_positions(d, sys.numBlocks());
  for (int b = 0; b < sys.numBlocks(); ++b)
    for (int k = 0; k < d; ++k) block_positions(k, b) = pos[static_cast<size_t>(b * d + k)];
  const RationalMatrix G = symmetryGenerators(*model.symmetryGroup(), block_positions);
  int pinned_rows = 0;
  for (int b = 0; b < sys.numBlocks(); ++b) pinned_rows += d - sys.freeCoordinatesOf(b);
  RationalMatrix free_rows(N, G.cols), A(pinned_rows, G.cols);
  int a = 0;
  for (int b = 0; b < sys.numBlocks(); ++b)
    for (int k = 0; k < d; ++k) {
      const int v = sys.variableIndex(b, k);
      for (int j = 0; j < G.cols; ++j) (v >= 0 ? free_rows(v, j) : A(a, j)) = G(b * d + k, j);
      if (v < 0) ++a;
    }
  RationalMatrix stabiliser;
  if (pinned_rows > 0) {
    stabiliser = nullSpace(A);
  } else {
    stabiliser = RationalMatrix(G.cols, G.cols);
    for (int j = 0; j < G.cols; ++j) stabiliser(j, j) = 1;
  }
  return independentColumns(multiply(free_rows, stabiliser));
}

ExactAnalysis analyzeExact(const Model& model, const RationalMatrix& points, const RigidityReport* numeric,
                           const ExactOptions& opt) {
  const double t0 = cpuSeconds();
  const std::clock_t process_t0 = std::clock();
  checkModel(model, opt);
  const ConstraintSystem& sys = model.system();
  const std::vector<Rational> pos = blockPositions(model, points, opt);
  ExactAnalysis ex;
  ex.variables = sys.numVariables();
  ex.equations = sys.numEquations();
  const int N = ex.variables, m = ex.equations;

  std::vector<JacobianEntry<Rational>> jac;
  const std::vector<Rational> res = evaluateSystemIn(sys, pos, pos, &jac);
  for (int i = 0; i < m; ++i)
    if (res[static_cast<size_t>(i)] != 0)
      throw Refusal("the start does not satisfy " + sys.equationLabel(i, opt.index_base) + " exactly (residual " +
                    toString(res[static_cast<size_t>(i)]) +
                    "): the exact mode analyses exact solutions, so the scene's lengths, radii and targets must "
                    "hold exactly at its rational coordinates");
  std::vector<SparseEntry> J, Jt;
  J.reserve(jac.size());
  for (const auto& e : jac)
    if (e.value != 0) J.push_back({e.row, e.column, e.value});

  const RationalMatrix T = trivialFlexBasis(model, pos);
  ex.trivial = T.cols;
  // Every trivial flex is a flex: J T = 0 exactly, or the term formulas or the group are wrong.
  {
    RationalMatrix JT(m, T.cols);
    for (const SparseEntry& e : J)
      for (int c = 0; c < T.cols; ++c) JT(e.row, c) += e.value * T(e.column, c);
    for (const Rational& q : JT.data)
      if (q != 0) throw std::logic_error("exact analysis: a trivial motion of the " + model.typeName() + " is not an infinitesimal flex");
  }

  const bool bases = N <= opt.max_basis_size && m <= opt.max_basis_size;
  Jt.reserve(J.size());
  for (const SparseEntry& e : J) Jt.push_back({e.column, e.row, e.value});
  // The cost, estimated before the eliminations (engine/exact/exact_cost.h): the modular rank,
  // then, where it does not prove the rank, FLINT's dense elimination of J or of its transpose
  // (whichever has the fewer null vectors), and the bases where they are formed. The double
  // analysis's rank predicts which steps run; the modular rank, known before the dense steps,
  // checks the estimate again.
  const std::vector<int> order = bandedColumnOrder(sys);
  const MatrixShape shape = shapeOf(m, N, J), shape_t = shapeOf(N, m, Jt);
  const double modular_work = modularWork(m, N, J, order);
  const std::string what = "the exact analysis of " + std::to_string(N) + " variables and " + std::to_string(m) +
                           " equations";
  const bool quadratic = model.quadraticConstraints();
  // Whether the bases are formed at rank r: for the second-order step, or for the report when
  // the exact counts differ from the double ones (applyExact then takes the exact bases).
  auto secondOrder = [&](int r) {
    const int nontrivial = N - r - ex.trivial, stresses = m - r;
    return bases && nontrivial > 0 && quadratic && stresses > 0 && nontrivial <= opt.max_second_order_size &&
           stresses <= opt.max_second_order_size;
  };
  auto wantBases = [&](int r) {
    if (!bases || N - r - ex.trivial <= 0) return false;
    const bool second_order = secondOrder(r);
    const bool differs = !numeric || numeric->rank != r || numeric->trivial != ex.trivial ||
                         numeric->variables != N || numeric->equations != m;
    return second_order || differs;
  };
  auto denseCost = [&](int r) {
    ExactCost c;
    if (r >= N - ex.trivial) return c;
    if (wantBases(r)) {
      c = denseEliminationCost(shape, r, true, false);
      if (m - r > 0) c.add(denseEliminationCost(shape_t, r, true, true));
      c.add(basisCost(N, N - r, ex.trivial, nullSpaceBits(shape, r)));
      if (secondOrder(r)) c.add(secondOrderCost(m, N - r - ex.trivial, m - r, nullSpaceBits(shape, r)));
    } else {
      const ExactCost a = denseEliminationCost(shape, r, false, false), b = denseEliminationCost(shape_t, r, false, true);
      c = a.seconds <= b.seconds ? a : b;
    }
    return c;
  };
  double modular_seconds = 0;
  {
    const int predicted = numeric && numeric->variables == N && numeric->equations == m
                              ? std::clamp(numeric->rank, 0, N - ex.trivial)
                              : std::min(m, N - ex.trivial);
    // Refused here on the modular rank's cost alone: the dense steps are checked against the
    // modular rank below, before they start (a start that floating point finds flexible may be
    // rigid exactly, and then they do not run).
    const ExactCost modular = modularRankCost(shape, modular_work);
    requireExactBudget(what, modular, opt.budget_seconds);
    modular_seconds = modular.seconds;
    ExactCost cost = modular;
    cost.add(denseCost(predicted));
    ex.estimated_seconds = cost.seconds;
    ex.estimated_bytes = cost.bytes;
  }
  interruptionPoint();
  // The rank modulo a prime is a lower bound; the trivial flexes (exactly in the kernel) bound
  // it from above: when the two meet, the rank is proved without a rational elimination.
  const int lower = modularRankLowerBound(m, N, J, order);
  RationalMatrix K;
  bool have_K = false;
  if (lower == N - ex.trivial) {
    ex.rank = lower;
  } else if (static_cast<double>(N) * m <= static_cast<double>(opt.max_dense_entries)) {
    {
      ExactCost cost;
      cost.add("the work so far", cpuSeconds() - t0, 0);
      const ExactCost dense = denseCost(lower);
      cost.add(dense);
      ex.estimated_seconds = modular_seconds + dense.seconds;  // the estimate, without what was measured
      ex.estimated_bytes = std::max(ex.estimated_bytes, dense.bytes);
      requireExactBudget(what, cost, opt.budget_seconds);
    }
    interruptionPoint();
    if (wantBases(lower)) {
      sparseRank(m, N, J, &K);  // the null space gives the rank: N - its columns
      have_K = true;
      ex.rank = N - K.cols;
    } else if (denseEliminationCost(shape, lower, false, false).seconds <=
               denseEliminationCost(shape_t, lower, false, true).seconds) {
      ex.rank = sparseRank(m, N, J);
    } else {
      ex.rank = sparseRank(N, m, Jt);
    }
  } else {
    throw Refusal("the system has " + std::to_string(N) + " variables and " + std::to_string(m) +
                  " equations and is not infinitesimally rigid modulo a prime (rank at least " + std::to_string(lower) +
                  " of the " + std::to_string(N - ex.trivial) + " that would make it so); its exact rank needs a "
                  "dense elimination beyond the exact mode's size limit (" + std::to_string(opt.max_dense_entries) +
                  " entries)");
  }
  interruptionPoint();
  ex.inf_flexes = N - ex.rank;
  ex.nontrivial = ex.inf_flexes - ex.trivial;
  ex.stresses = m - ex.rank;
  if (ex.nontrivial < 0) throw std::logic_error("exact analysis: more trivial flexes than flexes");
  ex.inf_rigid = ex.nontrivial == 0;
  if (ex.inf_rigid) {
    ex.prestress_stable = true;
    ex.flexible = false;
    ex.note = "infinitesimally rigid";
  } else if (ex.stresses == 0) {
    ex.prestress_stable = false;
    ex.flexible = true;
    ex.note = "a regular point (no stress) with " + std::to_string(ex.nontrivial) +
              " nontrivial flex(es): the realizations near the start form a manifold of larger dimension than "
              "the orbit of the symmetries";
  }
  if (wantBases(ex.rank)) {
    if (!wantBases(lower)) {
      // The rank differs from the modular bound, and the bases now wanted were not priced:
      // check them against the budget before forming them.
      ExactCost cost;
      cost.add("the work so far", cpuSeconds() - t0, 0);
      cost.add(denseCost(ex.rank));
      ex.estimated_bytes = std::max(ex.estimated_bytes, cost.bytes);
      requireExactBudget(what, cost, opt.budget_seconds);
    }
    if (!have_K) sparseRank(m, N, J, &K);
    interruptionPoint();
    ex.flex_basis = independentColumns(orthogonalToColumns(K, T));
    if (ex.flex_basis.cols != ex.nontrivial) throw std::logic_error("exact analysis: the flex basis has the wrong size");
    interruptionPoint();
    if (ex.stresses > 0) sparseRank(N, m, Jt, &ex.stress_basis);
    interruptionPoint();
  }
  if (!ex.inf_rigid && ex.stresses > 0) {
    if (!model.quadraticConstraints())
      ex.note = "the second-order theory needs quadratic constraints";
    else if (!bases || ex.nontrivial > opt.max_second_order_size || ex.stresses > opt.max_second_order_size)
      ex.note = std::to_string(ex.nontrivial) + " nontrivial flexes and " + std::to_string(ex.stresses) +
                " stresses: beyond the exact second-order step's size limit";
    else
      decidePrestress(sys, pos, numeric, ex);
  }
  // The process's CPU time: FLINT's large calls run on a worker thread (what a sweep's other
  // threads spend meanwhile counts here too; the budget's checks use this thread's time alone).
  ex.seconds = static_cast<double>(std::clock() - process_t0) / CLOCKS_PER_SEC;
  return ex;
}

RationalMatrix pointsFromDoubles(const Model& model) {
  const Matrix& p = model.startPositions();
  const int n = model.system().numVertices();
  RationalMatrix out(static_cast<int>(p.rows()), n);
  for (int b = 0; b < n; ++b)
    for (int k = 0; k < p.rows(); ++k) out(k, b) = shortestDecimal(p(k, b));
  return out;
}

namespace {

// Orthonormal columns spanning A's (doubles).
Matrix orthonormal(const RationalMatrix& A) {
  std::vector<long> shift;
  const Matrix M = scaledColumns(A, shift);
  if (M.cols() == 0) return M;
  Eigen::HouseholderQR<Matrix> qr(M);
  return qr.householderQ() * Matrix::Identity(M.rows(), M.cols());
}

}  // namespace

void applyExact(RigidityReport& rep, const ExactAnalysis& ex) {
  const bool agree = rep.variables == ex.variables && rep.equations == ex.equations && rep.rank == ex.rank &&
                     rep.trivial == ex.trivial;
  // The double verdict stands (marked numerical) only where nothing exact contradicts it.
  const bool consistent = agree && (!ex.prestress_stable || rep.prestress_stable == ex.prestress_stable);
  if (agree && !consistent)
    rep.warnings.push_back(std::string("floating point found the start ") +
                           (*ex.prestress_stable ? "not " : "") + "prestress stable; the exact analysis proves it " +
                           (*ex.prestress_stable ? "is" : "is not"));
  if (!agree) {
    rep.warnings.push_back("floating point gave rank " + std::to_string(rep.rank) + " with " +
                           std::to_string(rep.trivial) + " trivial flexes (threshold " + shortNumber(rep.tolerance) +
                           "); the exact rank is " + std::to_string(ex.rank) + " with " + std::to_string(ex.trivial) +
                           ": a position floating point does not resolve. The counts, bases and verdict are the "
                           "exact analysis's");
    rep.second_order_rigid.reset();
    rep.stress_margin = std::numeric_limits<double>::quiet_NaN();
    rep.blocking_stress = Vector();
    rep.flex_basis_computed = ex.flex_basis.cols == ex.nontrivial && ex.flex_basis.rows == ex.variables;
    rep.flex_basis = rep.flex_basis_computed ? orthonormal(ex.flex_basis) : Matrix(ex.variables, 0);
    rep.stress_basis_computed = ex.stress_basis.cols == ex.stresses && ex.stress_basis.rows == ex.equations;
    rep.stress_basis = rep.stress_basis_computed ? orthonormal(ex.stress_basis) : Matrix(ex.equations, 0);
    rep.auto_flex = ex.nontrivial > 0 ? Vector(Vector::Constant(ex.nontrivial, 1.0 / std::sqrt(double(ex.nontrivial))))
                                      : Vector();
    rep.auto_flex_note = "equal coefficients in the exact flex basis";
    rep.motion_check_change = std::numeric_limits<double>::quiet_NaN();
  }
  rep.rank = ex.rank;
  rep.inf_flexes = ex.inf_flexes;
  rep.trivial = ex.trivial;
  rep.nontrivial = ex.nontrivial;
  rep.stresses = ex.stresses;
  rep.inf_rigid = ex.inf_rigid;
  rep.prestress_stable = ex.prestress_stable;
  RigidityReport::Certificate c;
  c.inf_rigid = ex.inf_rigid;
  c.prestress_stable = ex.prestress_stable;
  c.flexible = ex.flexible;
  if (ex.inf_rigid || ex.prestress_stable == true) c.flexible = false;
  if (ex.inf_rigid) {
    rep.second_order_rigid = true;
    rep.rigid = Verdict::Rigid;
    rep.reason = "infinitesimally rigid (exact rank)";
  } else if (ex.flexible == true) {
    rep.second_order_rigid = false;
    rep.rigid = Verdict::Flexible;
    rep.reason = "exact: " + ex.note;
  } else if (ex.prestress_stable == true) {
    rep.second_order_rigid = true;
    rep.rigid = Verdict::Rigid;
    rep.reason = "exact: " + ex.note;
  } else if (consistent) {
    rep.reason += " (numerical: exactly, " + ex.note + ")";
  } else {
    rep.rigid = Verdict::Unknown;
    rep.reason = "exactly " + std::to_string(ex.nontrivial) + " nontrivial flexes and " + std::to_string(ex.stresses) +
                 " stresses (" + ex.note + "); whether the framework moves is not decided exactly";
  }
  c.reason = ex.inf_rigid ? "the exact rank leaves no nontrivial flex"
             : c.flexible == true ? "the exact rank shows a regular point with nontrivial flexes"
             : c.prestress_stable == true ? ex.note
             : ex.note + "; flexibility is not proved";
  rep.exact = true;
  rep.certificate = c;
}

}  // namespace flexure::engine::exact
