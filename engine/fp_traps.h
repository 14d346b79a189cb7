// Floating-point traps (the test suite turns them on, so that a NaN or an infinity made by our
// code stops the test where it is made) are masked in a scope that runs code which computes
// NaNs on purpose and is checked for them afterwards: Eigen 3.4.0's BDCSVD takes square roots
// of negative numbers in its secular-equation solver and its NaN output is caught and sent to
// LAPACK (engine/factorization.cpp).
#pragma once

#include <cfenv>

namespace flexure::engine {

class MaskedFloatingPointTraps {
 public:
  MaskedFloatingPointTraps() {
#if defined(__GLIBC__)
    saved_ = fegetexcept();
    if (saved_) fedisableexcept(saved_);
#endif
  }
  ~MaskedFloatingPointTraps() {
#if defined(__GLIBC__)
    if (saved_) {
      feclearexcept(saved_);
      feenableexcept(saved_);
    }
#endif
  }
  MaskedFloatingPointTraps(const MaskedFloatingPointTraps&) = delete;
  MaskedFloatingPointTraps& operator=(const MaskedFloatingPointTraps&) = delete;

 private:
  int saved_ = 0;
};

}  // namespace flexure::engine
