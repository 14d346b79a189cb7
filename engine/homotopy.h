// Homotopy continuation for small square polynomial systems f(x) = 0, x in C^n (the solver
// behind second-order rigidity, paper section 4.4). Total-degree start system with the gamma
// trick, tracked in projective space on a random affine patch (so no path diverges: solutions
// at infinity end with x_0 = 0), adaptive Runge-Kutta predictor and Newton corrector, and an
// endgame that tells nonsingular, singular and infinite endpoints apart. Every nonsingular
// finite solution is refined by Newton's method on f and certified by Smale's alpha test with
// computable constants (gamma bounded from the coefficients); real ones are certified real
// (Hauenstein-Sottile). Deterministic for a given seed.
#pragma once

#include <complex>
#include <cstdint>
#include <Eigen/Core>
#include <vector>

namespace flexure::engine {

using Complex = std::complex<double>;
using CVector = Eigen::VectorXcd;
using CMatrix = Eigen::MatrixXcd;

struct Monomial {
  Complex coefficient;
  std::vector<int> exponents;  // one per variable, >= 0
};

// f_1 .. f_m in n variables, each a sum of monomials.
class PolynomialSystem {
 public:
  explicit PolynomialSystem(int variables) : n_(variables) {}
  // Throws std::invalid_argument when an exponent vector has the wrong length or a negative
  // entry, or when the polynomial is zero.
  void add(std::vector<Monomial> polynomial);
  int variables() const { return n_; }
  int size() const { return static_cast<int>(polys_.size()); }
  int degree(int i) const;
  const std::vector<Monomial>& polynomial(int i) const { return polys_[static_cast<size_t>(i)]; }
  // f(x) and, when J is not null, the Jacobian (size() x variables()).
  void evaluate(const CVector& x, CVector& f, CMatrix* J = nullptr) const;
  // Upper bound of the operator norm of D^k f(x) / k! (k >= 2), from the coefficients.
  double derivativeBound(const CVector& x, int k) const;

 private:
  int n_;
  std::vector<std::vector<Monomial>> polys_;
  struct Term {
    Complex c;
    std::vector<std::pair<int, int>> powers;  // (variable, exponent > 0)
  };
  std::vector<std::vector<Term>> sparse_;  // the same polynomials, for evaluation
};

struct HomotopyOptions {
  std::uint64_t seed = 1;        // gamma and the projective patch derive from it
  double max_step = 0.05;        // in t (the homotopy runs from t = 1 to t = 0)
  double min_step = 1e-14;
  int max_steps = 20000;         // per path
  double corrector_tolerance = 1e-10;  // relative Newton step size at each predicted point
  double endgame_start = 1e-2;   // below this t, steps shrink and the endpoint is classified
  double infinity_tolerance = 1e-8;    // |x_0| / |x| below this: a solution at infinity
  double singular_condition = 1e8;     // condition number of the Jacobian above this: singular
  double distinct_tolerance = 1e-8;    // relative distance below which solutions coincide
};

struct Solution {
  CVector x;                // affine coordinates
  double residual = 0;      // max |f_i(x)|
  double condition = 0;     // of the Jacobian at x
  double alpha = 0, beta = 0, gamma = 0;  // Smale's constants at x
  bool certified = false;   // alpha < (13 - 3 sqrt 17) / 4: x is an approximate zero
  bool real = false;        // x is (numerically) real
  bool certified_real = false;  // its associated zero is real (alpha < 0.03 and close to Re x)
  int multiplicity = 1;     // how many paths ended here
  int path = 0;             // the first path that ended here
};

struct HomotopyResult {
  int paths = 0;                     // the Bezout number: product of the degrees
  std::vector<Solution> solutions;   // finite, nonsingular, distinct
  std::vector<Solution> singular;    // finite, singular (Jacobian rank-deficient): approximate
  int at_infinity = 0;               // paths that ended at infinity
  int failed = 0;                    // paths that could not be tracked to the end
  std::vector<Solution> realSolutions() const;
};

// All isolated solutions of the square system f (f.size() == f.variables()).
HomotopyResult solveTotalDegree(const PolynomialSystem& f, const HomotopyOptions& options = {});

}  // namespace flexure::engine
