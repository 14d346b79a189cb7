// Floating-point traps (the test suite turns them on, so that a NaN or an infinity made by our
// code stops the test where it is made) are masked in a scope that runs library code whose
// output is checked afterwards instead: the dense SVD (LAPACK's dgesdd, then JacobiSVD; a
// non-finite or unsorted result is caught, engine/factorization.cpp) and Mesa's shaders.
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
