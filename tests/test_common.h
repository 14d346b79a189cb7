// Helpers shared by the test executables.
#pragma once

#include <catch2/catch.hpp>
#include <random>

#include "engine/constraint_system.h"

namespace flexure::test {

using engine::Matrix;
using engine::Vector;

inline Vector randomVector(std::mt19937& rng, int n, double scale = 1.0) {
  std::normal_distribution<double> g(0.0, scale);
  Vector v(n);
  for (int i = 0; i < n; ++i) v[i] = g(rng);
  return v;
}

// Central differences of the residuals against the analytic Jacobian, column by column.
inline void requireJacobianMatchesFiniteDifferences(const engine::ConstraintSystem& sys,
                                                    const Vector& x) {
  const Matrix J(sys.jacobian(x));
  const double h = 1e-6;
  for (int c = 0; c < sys.numVariables(); ++c) {
    Vector xp = x, xm = x;
    xp[c] += h;
    xm[c] -= h;
    const Vector fd = (sys.residuals(xp) - sys.residuals(xm)) / (2 * h);
    const double scale = std::max(1.0, J.col(c).cwiseAbs().maxCoeff());
    INFO("column " << c);
    REQUIRE((fd - J.col(c)).cwiseAbs().maxCoeff() <= 1e-6 * scale);
  }
}

// u^T H_i w against central differences of J(x + t w) u.
inline void requireSecondDerivativeMatchesFiniteDifferences(const engine::ConstraintSystem& sys,
                                                            const Vector& x, const Vector& u,
                                                            const Vector& w) {
  const double h = 1e-5;
  const Vector fd = (sys.jacobian(x + h * w) * u - sys.jacobian(x - h * w) * u) / (2 * h);
  const Vector an = sys.secondDerivative(x, u, w);
  const double scale = std::max(1.0, an.cwiseAbs().maxCoeff());
  REQUIRE((fd - an).cwiseAbs().maxCoeff() <= 1e-6 * scale);
}

}  // namespace flexure::test
