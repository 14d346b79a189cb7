// Floating-point traps (invalid operation, division by zero) for the test executables that link
// this file: on in every test build, Release and sanitizer builds included, so that a NaN or an
// infinity born in our code fails loudly where it is made. They are enabled as the program
// starts, before Catch2's main (tests/catch_session.cpp) runs. Test executables that drive
// third-party code which computes with NaNs on purpose (Mesa's llvmpipe, libav) do not link it.
#include <cfenv>

namespace {

#if defined(__GLIBC__)
[[maybe_unused]] const bool kTrapsOn = [] {
  feenableexcept(FE_INVALID | FE_DIVBYZERO);
  return true;
}();
#endif

}  // namespace
