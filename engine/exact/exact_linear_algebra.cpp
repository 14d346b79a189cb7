#include "engine/exact/exact_linear_algebra.h"

#include <flint/flint.h>
#include <flint/fmpz.h>
#include <flint/fmpz_mat.h>

#include <algorithm>
#include <cstdint>
#include <functional>
#include <queue>
#include <stdexcept>

#include "engine/exact/number_memory.h"
#include "engine/fp_traps.h"
#include "engine/interrupt.h"

namespace flexure::engine::exact {

namespace {

// FLINT keeps caches per thread (its pool of big integers) that only flint_cleanup() frees: a
// thread that used FLINT frees them when it ends (a sweep's workers, the viewer's compute
// thread; they leaked before, as LeakSanitizer found).
struct FlintThreadCleanup {
  ~FlintThreadCleanup() { flint_cleanup(); }
};
void usingFlint() {
  installNumberAllocators();
  thread_local FlintThreadCleanup cleanup;
  (void)cleanup;
}

// An owned FLINT integer matrix.
class IntegerMatrix {
 public:
  IntegerMatrix(int rows, int cols) {
    usingFlint();
    fmpz_mat_init(m_, rows, cols);
  }
  ~IntegerMatrix() { fmpz_mat_clear(m_); }
  IntegerMatrix(const IntegerMatrix&) = delete;
  IntegerMatrix& operator=(const IntegerMatrix&) = delete;
  fmpz_mat_struct* get() { return m_; }
  const fmpz_mat_struct* get() const { return m_; }
  fmpz* at(int i, int j) { return fmpz_mat_entry(m_, i, j); }
  int rows() const { return static_cast<int>(fmpz_mat_nrows(m_)); }
  int cols() const { return static_cast<int>(fmpz_mat_ncols(m_)); }

 private:
  fmpz_mat_t m_;
};

void setInteger(fmpz* out, const mpz_class& z) { fmpz_set_mpz(out, z.get_mpz_t()); }

mpz_class getInteger(const fmpz* f) {
  mpz_class z;
  fmpz_get_mpz(z.get_mpz_t(), f);
  return z;
}

// Row i of A times the least common multiple of its denominators: integer rows with the same
// row space.
void scaleRowsToIntegers(const RationalMatrix& A, IntegerMatrix& out) {
  mpz_class l;
  for (int i = 0; i < A.rows; ++i) {
    if (i % 64 == 0) interruptionPoint();
    l = 1;
    for (int j = 0; j < A.cols; ++j) mpz_lcm(l.get_mpz_t(), l.get_mpz_t(), A(i, j).get_den_mpz_t());
    for (int j = 0; j < A.cols; ++j) {
      const Rational& q = A(i, j);
      if (q == 0) continue;
      setInteger(out.at(i, j), mpz_class(q.get_num() * (l / q.get_den())));
    }
  }
}

RationalMatrix nullSpaceOf(IntegerMatrix& A) {
  IntegerMatrix K(A.cols(), A.cols());
  const int k = static_cast<int>(fmpz_mat_nullspace(K.get(), A.get()));
  RationalMatrix out(A.cols(), k);
  for (int i = 0; i < A.cols(); ++i)
    for (int j = 0; j < k; ++j) out(i, j) = Rational(getInteger(K.at(i, j)));
  return out;
}

// Runs `f`, FLINT's work on a matrix of `entries` entries: when it is large, on a worker that an
// interruption cancels within a fraction of a second (number_memory.h: FLINT's eliminations are
// single calls that take up to the exact mode's budget); small ones here.
// FLINT computes with doubles where its results are then checked or exact (n_mulmod_precomp's
// quotient estimates): floating-point traps (the test suite's) are masked around it, as around
// LAPACK (engine/fp_traps.h).
template <class F>
void flintWork(double entries, F&& f) {
  auto masked = [&f] {
    MaskedFloatingPointTraps masked_traps;
    f();
  };
  if (entries < 2e4) {
    masked();
    return;
  }
  runCancellable(masked, [] { interruptionPoint(); });
}

}  // namespace

int rank(const RationalMatrix& A) {
  if (A.rows == 0 || A.cols == 0) return 0;
  int r = 0;
  flintWork(static_cast<double>(A.rows) * A.cols, [&] {
    IntegerMatrix M(A.rows, A.cols);
    scaleRowsToIntegers(A, M);
    r = static_cast<int>(fmpz_mat_rank(M.get()));
  });
  return r;
}

RationalMatrix nullSpace(const RationalMatrix& A) {
  if (A.cols == 0) return RationalMatrix(0, 0);
  if (A.rows == 0) {
    RationalMatrix I(A.cols, A.cols);
    for (int i = 0; i < A.cols; ++i) I(i, i) = 1;
    return I;
  }
  RationalMatrix out;
  flintWork(static_cast<double>(A.rows) * A.cols, [&] {
    IntegerMatrix M(A.rows, A.cols);
    scaleRowsToIntegers(A, M);
    out = nullSpaceOf(M);
  });
  return out;
}

RationalMatrix independentColumns(const RationalMatrix& A) {
  if (A.rows == 0 || A.cols == 0) return RationalMatrix(A.rows, 0);
  std::vector<int> pivots;
  int r = 0;
  flintWork(static_cast<double>(A.rows) * A.cols, [&] {
    IntegerMatrix M(A.rows, A.cols), R(A.rows, A.cols);
    scaleRowsToIntegers(A, M);
    fmpz_t den;
    fmpz_init(den);
    r = static_cast<int>(fmpz_mat_rref(R.get(), den, M.get()));
    fmpz_clear(den);
    int j = 0;
    for (int i = 0; i < r; ++i) {
      while (j < A.cols && fmpz_is_zero(R.at(i, j))) ++j;
      pivots.push_back(j++);
    }
  });
  RationalMatrix out(A.rows, r);
  for (int c = 0; c < r; ++c)
    for (int i = 0; i < A.rows; ++i) out(i, c) = A(i, pivots[static_cast<size_t>(c)]);
  return out;
}

RationalMatrix transpose(const RationalMatrix& A) {
  RationalMatrix T(A.cols, A.rows);
  for (int i = 0; i < A.rows; ++i)
    for (int j = 0; j < A.cols; ++j) T(j, i) = A(i, j);
  return T;
}

RationalMatrix multiply(const RationalMatrix& A, const RationalMatrix& B) {
  if (A.cols != B.rows) throw std::invalid_argument("exact::multiply: sizes do not match");
  RationalMatrix C(A.rows, B.cols);
  for (int i = 0; i < A.rows; ++i)
    for (int k = 0; k < A.cols; ++k) {
      if (k == 0) interruptionPoint();
      const Rational& a = A(i, k);
      if (a == 0) continue;
      for (int j = 0; j < B.cols; ++j)
        if (B(k, j) != 0) C(i, j) += a * B(k, j);
    }
  return C;
}

namespace {

// Solves the symmetric positive definite G X = B in place of B (Gaussian elimination; G is
// copied).
void solveSymmetric(RationalMatrix G, RationalMatrix& B) {
  const int n = G.rows;
  for (int p = 0; p < n; ++p) {
    interruptionPoint();
    if (G(p, p) == 0) throw std::logic_error("exact::orthogonalToColumns: the columns are dependent");
    for (int i = p + 1; i < n; ++i) {
      if (G(i, p) == 0) continue;
      const Rational f = G(i, p) / G(p, p);
      for (int j = p; j < n; ++j) G(i, j) -= f * G(p, j);
      for (int j = 0; j < B.cols; ++j) B(i, j) -= f * B(p, j);
    }
  }
  for (int p = n - 1; p >= 0; --p)
    for (int j = 0; j < B.cols; ++j) {
      Rational s = B(p, j);
      for (int k = p + 1; k < n; ++k) s -= G(p, k) * B(k, j);
      B(p, j) = s / G(p, p);
    }
}

}  // namespace

RationalMatrix orthogonalToColumns(const RationalMatrix& K, const RationalMatrix& T) {
  if (T.cols == 0) return K;
  const RationalMatrix Tt = transpose(T);
  RationalMatrix C = multiply(Tt, K);  // T^T K
  solveSymmetric(multiply(Tt, T), C);  // (T^T T)^-1 T^T K
  const RationalMatrix TC = multiply(T, C);
  RationalMatrix P = K;
  for (size_t i = 0; i < P.data.size(); ++i) P.data[i] -= TC.data[i];
  return P;
}

bool positiveDefinite(const RationalMatrix& Q) {
  RationalMatrix A = Q;
  const int n = A.rows;
  for (int p = 0; p < n; ++p) {
    interruptionPoint();
    if (A(p, p) <= 0) return false;
    for (int i = p + 1; i < n; ++i) {
      if (A(i, p) == 0) continue;
      const Rational f = A(i, p) / A(p, p);
      for (int j = p; j < n; ++j) A(i, j) -= f * A(p, j);
    }
  }
  return true;
}

int sparseRank(int m, int n, const std::vector<SparseEntry>& entries, RationalMatrix* null_space) {
  if (n == 0) {
    if (null_space) *null_space = RationalMatrix(0, 0);
    return 0;
  }
  int r = 0;
  flintWork(static_cast<double>(m) * n, [&] {
    // Each row's common denominator, then its entries as integers.
    std::vector<mpz_class> lcm(static_cast<size_t>(m), mpz_class(1));
    for (const SparseEntry& e : entries)
      mpz_lcm(lcm[static_cast<size_t>(e.row)].get_mpz_t(), lcm[static_cast<size_t>(e.row)].get_mpz_t(),
              e.value.get_den_mpz_t());
    IntegerMatrix M(m, n);
    mpz_class v;
    usingFlint();
    fmpz_t add;
    fmpz_init(add);
    for (const SparseEntry& e : entries) {
      if (e.value == 0) continue;
      v = e.value.get_num() * (lcm[static_cast<size_t>(e.row)] / e.value.get_den());
      fmpz_set_mpz(add, v.get_mpz_t());
      fmpz_add(M.at(e.row, e.column), M.at(e.row, e.column), add);
    }
    fmpz_clear(add);
    if (null_space) {
      *null_space = nullSpaceOf(M);
      r = n - null_space->cols;
    } else {
      r = m == 0 ? 0 : static_cast<int>(fmpz_mat_rank(M.get()));
    }
  });
  return r;
}

namespace {

constexpr std::uint64_t kPrime = (std::uint64_t{1} << 61) - 1;

std::uint64_t mulMod(std::uint64_t a, std::uint64_t b) {
  return static_cast<std::uint64_t>((static_cast<unsigned __int128>(a) * b) % kPrime);
}

std::uint64_t powMod(std::uint64_t a, std::uint64_t e) {
  std::uint64_t r = 1;
  for (; e; e >>= 1, a = mulMod(a, a))
    if (e & 1) r = mulMod(r, a);
  return r;
}

std::uint64_t inverseMod(std::uint64_t a) { return powMod(a, kPrime - 2); }

}  // namespace

int modularRankLowerBound(int m, int n, const std::vector<SparseEntry>& entries, const std::vector<int>& column_order) {
  if (static_cast<int>(column_order.size()) != n) throw std::invalid_argument("modularRankLowerBound: order size");
  std::vector<int> position(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) position[static_cast<size_t>(column_order[static_cast<size_t>(i)])] = i;
  // Rows as (position, value mod p), each scaled to integers first.
  std::vector<mpz_class> lcm(static_cast<size_t>(m), mpz_class(1));
  for (const SparseEntry& e : entries)
    mpz_lcm(lcm[static_cast<size_t>(e.row)].get_mpz_t(), lcm[static_cast<size_t>(e.row)].get_mpz_t(),
            e.value.get_den_mpz_t());
  using Row = std::vector<std::pair<int, std::uint64_t>>;
  std::vector<Row> rows(static_cast<size_t>(m));
  mpz_class v;
  for (const SparseEntry& e : entries) {
    if (e.value == 0) continue;
    v = e.value.get_num() * (lcm[static_cast<size_t>(e.row)] / e.value.get_den());
    const std::uint64_t r = mpz_fdiv_ui(v.get_mpz_t(), kPrime);
    rows[static_cast<size_t>(e.row)].push_back({position[static_cast<size_t>(e.column)], r});
  }
  // Rows by their first position: a banded sweep.
  std::vector<int> row_order(static_cast<size_t>(m));
  std::vector<int> first(static_cast<size_t>(m), n);
  for (int i = 0; i < m; ++i) {
    row_order[static_cast<size_t>(i)] = i;
    for (const auto& [c, x] : rows[static_cast<size_t>(i)]) first[static_cast<size_t>(i)] = std::min(first[static_cast<size_t>(i)], c);
  }
  std::stable_sort(row_order.begin(), row_order.end(),
                   [&](int a, int b) { return first[static_cast<size_t>(a)] < first[static_cast<size_t>(b)]; });
  // Echelon rows by their leading position (leading value 1), and a dense work row.
  std::vector<Row> pivot(static_cast<size_t>(n));
  std::vector<char> has_pivot(static_cast<size_t>(n), 0), queued(static_cast<size_t>(n), 0);
  std::vector<std::uint64_t> w(static_cast<size_t>(n), 0);
  std::priority_queue<int, std::vector<int>, std::greater<int>> heap;
  int rank = 0;
  for (int i : row_order) {
    interruptionPoint();  // a row's elimination: at most n pivots of at most n entries
    for (const auto& [c, x] : rows[static_cast<size_t>(i)]) {
      const size_t cc = static_cast<size_t>(c);
      w[cc] = (w[cc] + x) % kPrime;
      if (!queued[cc]) queued[cc] = 1, heap.push(c);
    }
    while (!heap.empty()) {
      const int c = heap.top();
      const size_t cc = static_cast<size_t>(c);
      if (w[cc] == 0) {
        heap.pop();
        queued[cc] = 0;
        continue;
      }
      if (has_pivot[cc]) {
        heap.pop();
        queued[cc] = 0;
        const std::uint64_t f = w[cc];
        w[cc] = 0;
        for (const auto& [c2, x] : pivot[cc]) {
          const size_t k = static_cast<size_t>(c2);
          if (k == cc) continue;
          w[k] = (w[k] + kPrime - mulMod(f, x)) % kPrime;
          if (!queued[k]) queued[k] = 1, heap.push(c2);
        }
        continue;
      }
      // A new pivot: the rest of the work row, scaled to a leading 1.
      const std::uint64_t inv = inverseMod(w[cc]);
      Row r;
      while (!heap.empty()) {
        const int c2 = heap.top();
        heap.pop();
        const size_t k = static_cast<size_t>(c2);
        queued[k] = 0;
        if (w[k] != 0) r.push_back({c2, mulMod(w[k], inv)});
        w[k] = 0;
      }
      pivot[cc] = std::move(r);
      has_pivot[cc] = 1;
      ++rank;
    }
  }
  return rank;
}

}  // namespace flexure::engine::exact
