// Catch2 main. Floating-point exceptions are on in debug builds, so that a NaN fails loudly.
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>
#include <cfenv>

int main(int argc, char* argv[]) {
#if !defined(NDEBUG) && defined(__GLIBC__)
  feenableexcept(FE_INVALID | FE_DIVBYZERO);
#endif
  return Catch::Session().run(argc, argv);
}
