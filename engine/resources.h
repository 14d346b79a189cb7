// Memory, estimated from counts before the work that needs it: a computation that cannot fit is
// refused at once with the estimate, instead of being killed (or crashing) part way through.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

namespace flexure::engine {

// A computation (or a read) that would need more than the process can have. The front ends
// report it as bad input (exit 1): the input asks for too much.
struct ResourceError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Bytes this process can still allocate: the least of the memory the system has available
// (MemAvailable), its memory cgroup's limit less its usage (v1 or v2; page cache it could drop
// counted as free), and the address-space and data limits (RLIMIT_AS less VmSize, RLIMIT_DATA
// less VmData).
std::uint64_t availableMemory();

// "9.5 GB", "310 MB", "12 kB".
std::string bytesText(double bytes);

// Throws ResourceError("WHAT needs about X of memory, more than the Y this process can have")
// when `bytes` exceeds availableMemory(). Below 64 MB it returns at once, without reading
// /proc (it is called per JSON line and per factorization).
void requireMemory(const std::string& what, double bytes);

}  // namespace flexure::engine
