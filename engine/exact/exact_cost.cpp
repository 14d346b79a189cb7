#include "engine/exact/exact_cost.h"

#include <gmp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "engine/resources.h"

namespace flexure::engine::exact {

namespace {

// CPU seconds per unit of each step's work (calibrated: bench/exact_budget_bench.cpp).
constexpr double kSecondsPerEntry = 1.2e-5;        // one nonzero: its rational Jacobian entry, scalings, checks
constexpr double kSecondsPerDenseEntry = 5e-9;      // one entry of a dense FLINT matrix (set, reduced, copied)
constexpr double kSecondsPerModularStep = 1.5e-10;  // one unit of modularWork (its envelope overestimates the fill)
constexpr double kSecondsPerWordOp = 3.0e-11;       // one multiply-add modulo a word-size prime (FLINT, blocked)
constexpr double kSecondsPerLimbProduct = 4.0e-10;  // one limb x limb product inside GMP/FLINT big integers
// FLINT's solve for the null space of J^T (the stresses) took 9 to 19 times as long as the one
// of J with as many null vectors, on the random frameworks of the calibration.
constexpr double kTransposedFactor = 12;
constexpr double kSecondsPerFormEntry = 5e-6;       // the second-order step, per flex pair, stress and limb
constexpr double kFixedSeconds = 1e-3;              // the analysis's fixed part

std::string secondsText(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, s < 10 ? "%.2g s" : "%.0f s", s);
  return buf;
}

// A round number of seconds at least s ("120").
std::string wholeSeconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.0f", std::ceil(std::max(1.0, s)));
  return buf;
}

// log2 |z| (0 for 0), whatever z's size.
double log2Size(const mpz_class& z) {
  if (z == 0) return 0;
  long e = 0;
  const double m = mpz_get_d_2exp(&e, z.get_mpz_t());  // |m| in [0.5, 1)
  return static_cast<double>(e) + std::log2(std::fabs(m));
}

}  // namespace

void ExactCost::add(const std::string& what, double s, double b) {
  seconds += s;
  bytes = std::max(bytes, b);
  if (s >= 0.05) detail += (detail.empty() ? "" : ", ") + what + " " + secondsText(s);
}

void ExactCost::add(const ExactCost& other) {
  seconds += other.seconds;
  bytes = std::max(bytes, other.bytes);
  if (!other.detail.empty()) detail += (detail.empty() ? "" : ", ") + other.detail;
}

MatrixShape shapeOf(int m, int n, const std::vector<SparseEntry>& entries) {
  MatrixShape s;
  s.rows = m, s.cols = n;
  std::vector<mpz_class> lcm(static_cast<size_t>(m), mpz_class(1));
  for (const SparseEntry& e : entries)
    if (e.value != 0)
      mpz_lcm(lcm[static_cast<size_t>(e.row)].get_mpz_t(), lcm[static_cast<size_t>(e.row)].get_mpz_t(),
              e.value.get_den_mpz_t());
  std::vector<double> row_norm(static_cast<size_t>(m), 0.0);  // log2 of the sum of squares, as a sum of 4^bits
  std::vector<double> row_top(static_cast<size_t>(m), 0.0);
  double bits = 0;
  for (const SparseEntry& e : entries) {
    if (e.value == 0) continue;
    const double b = log2Size(e.value.get_num()) + log2Size(lcm[static_cast<size_t>(e.row)]) -
                     log2Size(e.value.get_den());
    bits += b;
    s.nonzeros += 1;
    double& top = row_top[static_cast<size_t>(e.row)];
    double& sum = row_norm[static_cast<size_t>(e.row)];  // sum of 4^(b - top), rescaled when top grows
    if (b > top) sum = sum * std::pow(4.0, top - b), top = b;
    sum += std::pow(4.0, b - top);
  }
  s.mean_bits = s.nonzeros > 0 ? bits / s.nonzeros : 0;
  int rows = 0;
  for (int i = 0; i < m; ++i)
    if (row_norm[static_cast<size_t>(i)] > 0) {
      const double l = row_top[static_cast<size_t>(i)] + 0.5 * std::log2(row_norm[static_cast<size_t>(i)]);
      s.max_row_log = std::max(s.max_row_log, l);
      s.mean_row_log += l;
      ++rows;
    }
  if (rows > 0) s.mean_row_log /= rows;
  return s;
}

double modularWork(int m, int n, const std::vector<SparseEntry>& entries, const std::vector<int>& column_order) {
  if (m == 0 || n == 0) return 0;
  std::vector<int> position(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) position[static_cast<size_t>(column_order[static_cast<size_t>(i)])] = i;
  std::vector<int> first(static_cast<size_t>(m), n), last(static_cast<size_t>(m), -1);
  for (const SparseEntry& e : entries) {
    if (e.value == 0) continue;
    const int p = position[static_cast<size_t>(e.column)];
    first[static_cast<size_t>(e.row)] = std::min(first[static_cast<size_t>(e.row)], p);
    last[static_cast<size_t>(e.row)] = std::max(last[static_cast<size_t>(e.row)], p);
  }
  std::vector<int> order(static_cast<size_t>(m));
  for (int i = 0; i < m; ++i) order[static_cast<size_t>(i)] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return first[static_cast<size_t>(a)] < first[static_cast<size_t>(b)]; });
  // Row i (in the elimination's order) meets at most the pivots between its first position and
  // the farthest position of the rows before it, each at most that long.
  double work = 0;
  int reach = -1, pivots = 0;
  for (int i : order) {
    if (last[static_cast<size_t>(i)] < 0) continue;
    reach = std::max(reach, last[static_cast<size_t>(i)]);
    const double width = reach - first[static_cast<size_t>(i)] + 1;
    work += width * (1 + std::min<double>(pivots, width));
    pivots = std::min(pivots + 1, n);
  }
  return work;
}

ExactCost modularRankCost(const MatrixShape& s, double work) {
  ExactCost c;
  c.add("the modular rank", kFixedSeconds + kSecondsPerEntry * s.nonzeros + kSecondsPerModularStep * work,
        24.0 * std::min(work, static_cast<double>(s.cols) * s.cols) + 64.0 * s.nonzeros);
  return c;
}

double nullSpaceBits(const MatrixShape& s, int r) {
  // Hadamard: an r x r minor is at most the product of its rows' norms (r times their mean log).
  return std::max(1.0, r * std::max(1.0, s.mean_row_log) + 64);
}

ExactCost denseEliminationCost(const MatrixShape& s, int r, bool null_space, bool transposed) {
  ExactCost c;
  const double a = s.rows, b = s.cols, k = b - r, rr = r;
  const double limbs = nullSpaceBits(s, r) / 64;
  // Multimodular reduced echelon form: the matrix modulo a word prime (a b r), then, with
  // k = b - r null vectors, a Dixon solve of the r x r pivot block (its LU, and per lifting step
  // a product with the k columns) and the check of the other a - r rows against the solution.
  double t = kSecondsPerDenseEntry * a * b + kSecondsPerWordOp * a * b * std::max(rr, 1.0);
  double bytes = 16 * a * b;
  if (k > 0 && r > 0) {
    const double f = transposed ? kTransposedFactor : 1;
    t += kSecondsPerWordOp * rr * rr * rr;
    t += f * kSecondsPerLimbProduct * (2 * limbs) * rr * rr * k;  // lifting: 2 D / 64 steps of r^2 k
    t += f * kSecondsPerLimbProduct * rr * k * limbs * limbs;     // rational reconstruction
    t += kSecondsPerLimbProduct * (a - rr) * b * k * limbs;       // the check of the other rows
    bytes += (transposed ? 6 : 1) * 8 * limbs * rr * k + 8 * limbs * (a - rr) * k;
  }
  if (null_space) t += 20 * kSecondsPerDenseEntry * b * k * limbs;  // the basis out of FLINT, into rationals
  c.add(!null_space ? "the exact rank" : transposed ? "the stresses' null space" : "the flexes' null space", t, bytes);
  return c;
}

ExactCost basisCost(int n, int k, int t, double bits) {
  ExactCost c;
  const double limbs = bits / 64;
  // T^T K, (T^T T)^-1 and T C in rationals (t small), then the reduced echelon form of the
  // n x k result (fraction-free: k^2 n products of numbers growing to k times the bits).
  const double secs = kSecondsPerLimbProduct * (4.0 * n * k * t * limbs + static_cast<double>(k) * k * n * k * limbs);
  c.add("the flex basis", secs, 8 * limbs * n * k * (2 + k));
  return c;
}

ExactCost secondOrderCost(int m, int k, int s, double bits) {
  ExactCost c;
  const double limbs = bits / 64, kk = k, ss = s;
  // The forms (per pair of flexes and stress, a sum over the equations of products of bases'
  // entries), then the LDL^T of 2s + 2 candidate forms. The stresses are supported on the
  // overbraced parts, so most products are of zeros: measured, the step grew as k^2 s times
  // the entries' size, not with m or the products' sizes (calibration: random frameworks of
  // 100 and 200 vertices).
  c.add("the second-order step", kSecondsPerFormEntry * kk * kk * ss * limbs, 8 * 3 * limbs * kk * kk * ss);
  (void)m;
  return c;
}

void requireExactBudget(const std::string& what, const ExactCost& cost, double budget_seconds) {
  const std::string estimate = "about " + secondsText(cost.seconds) + " of CPU and " + bytesText(cost.bytes) +
                               " of memory" + (cost.detail.empty() ? "" : " (" + cost.detail + ")");
  if (cost.seconds > budget_seconds)
    throw ResourceError(what + " needs " + estimate + ", more than the exact mode's budget of " +
                        secondsText(budget_seconds) + ": raise it with [analysis] exact_budget = " +
                        wholeSeconds(cost.seconds * 2) + " in the scene or --set analysis.exact_budget=SECONDS (Python: analyze(exact=True, "
                        "exact_budget=SECONDS))");
  requireMemory(what + " (" + estimate + ")", cost.bytes);
}

}  // namespace flexure::engine::exact
