// Seeded randomness that is the same on every platform: std::mt19937_64 is fully specified,
// and the Gaussian transform is written out here (std::normal_distribution is not portable).
#pragma once

#include <cmath>
#include <cstdint>
#include <random>

namespace flexure::engine {

class Random {
 public:
  explicit Random(std::uint64_t seed) : gen_(seed) {}
  // Uniform in (0, 1), never 0.
  double uniform() { return (static_cast<double>(gen_() >> 11) + 0.5) * 0x1.0p-53; }
  // Standard normal by the Box-Muller transform.
  double gaussian() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double r = std::sqrt(-2.0 * std::log(uniform()));
    const double t = 2.0 * M_PI * uniform();
    spare_ = r * std::sin(t);
    has_spare_ = true;
    return r * std::cos(t);
  }

 private:
  std::mt19937_64 gen_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace flexure::engine
