// Catch2's implementation and main, compiled once for every test executable (the longest
// compile of the tests). tests/fp_traps.cpp turns floating-point traps on before it runs.
#define CATCH_CONFIG_MAIN
#include <catch2/catch.hpp>
