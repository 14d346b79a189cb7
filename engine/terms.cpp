#include "engine/terms.h"

namespace flexure::engine {

void SquaredDistanceTerm::evaluate(const double* x, int d, double* residuals,
                                   double* jacobian) const {
  double s = 0.0;
  for (int k = 0; k < d; ++k) {
    const double diff = x[k] - x[d + k];
    s += diff * diff;
    if (jacobian) {
      jacobian[k] = 2.0 * diff;
      jacobian[d + k] = -2.0 * diff;
    }
  }
  residuals[0] = s - squared_length_;
}

void SquaredDistanceTerm::secondDerivative(const double*, const double* u, const double* w, int d,
                                           double* out) const {
  double s = 0.0;
  for (int k = 0; k < d; ++k) s += (u[k] - u[d + k]) * (w[k] - w[d + k]);
  out[0] = 2.0 * s;
}

std::string SquaredDistanceTerm::label(int, int index_base) const {
  return "edge " + std::to_string(blocks()[0] + index_base) + "-" +
         std::to_string(blocks()[1] + index_base);
}

}  // namespace flexure::engine
