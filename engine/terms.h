// Concrete constraint terms. Each has an analytic Jacobian and second derivative, tested
// against finite differences in tests/engine/terms_test.cpp.
#pragma once

#include "engine/constraint_system.h"

namespace flexure::engine {

// ||x_a - x_b||^2 - length^2 = 0 (the paper's squared form; residual units are length^2).
class SquaredDistanceTerm final : public ConstraintTerm {
 public:
  SquaredDistanceTerm(int a, int b, double squared_length)
      : ConstraintTerm({a, b}), squared_length_(squared_length) {}
  int numResiduals() const override { return 1; }
  void evaluate(const double* x, int d, double* residuals, double* jacobian) const override;
  void secondDerivative(const double* x, const double* u, const double* w, int d,
                        double* out) const override;
  std::string label(int row, int index_base) const override;
  double residualScale() const override { return squared_length_; }
  double squaredLength() const { return squared_length_; }

 private:
  double squared_length_;
};

}  // namespace flexure::engine
