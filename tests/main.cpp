// Catch2 main. Floating-point traps (invalid operation, division by zero) are on in every test
// build, Release and sanitizer builds included, so that a NaN or an infinity born in our code
// fails loudly where it is made. Test executables that drive third-party code which computes
// with NaNs on purpose (Mesa's llvmpipe, libav) are built without FLEXURE_FP_TRAPS.
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>
#include <cfenv>

int main(int argc, char* argv[]) {
#if defined(FLEXURE_FP_TRAPS) && defined(__GLIBC__)
  feenableexcept(FE_INVALID | FE_DIVBYZERO);
#endif
  return Catch::Session().run(argc, argv);
}
