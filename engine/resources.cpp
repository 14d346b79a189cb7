#include "engine/resources.h"

#include <sys/resource.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>
#include <unistd.h>

namespace flexure::engine {

namespace {

constexpr std::uint64_t kUnlimited = std::numeric_limits<std::uint64_t>::max();

// A number read from a file ("max" or no file: unlimited).
std::uint64_t numberIn(const char* path) {
  std::ifstream in(path);
  std::string s;
  if (!(in >> s) || s == "max") return kUnlimited;
  try {
    return std::stoull(s);
  } catch (...) {
    return kUnlimited;
  }
}

std::uint64_t memAvailable() {
  std::ifstream in("/proc/meminfo");
  std::string key;
  std::uint64_t kb = 0;
  std::string unit;
  while (in >> key >> kb >> unit)
    if (key == "MemAvailable:") return kb * 1024;
  return kUnlimited;
}

// What this process has mapped (VmSize) and holds in its data segment, for the rlimits.
std::uint64_t mappedBytes() {
  std::ifstream in("/proc/self/statm");
  std::uint64_t pages = 0;
  if (!(in >> pages)) return 0;
  return pages * static_cast<std::uint64_t>(::sysconf(_SC_PAGESIZE));
}

std::uint64_t limitLeft(int resource) {
  rlimit r{};
  if (::getrlimit(resource, &r) != 0 || r.rlim_cur == RLIM_INFINITY) return kUnlimited;
  const std::uint64_t used = mappedBytes();
  return r.rlim_cur > used ? r.rlim_cur - used : 0;
}

}  // namespace

std::uint64_t availableMemory() {
  std::uint64_t m = memAvailable();
  const std::uint64_t cg_max = numberIn("/sys/fs/cgroup/memory.max");
  if (cg_max != kUnlimited) {
    const std::uint64_t cg_used = numberIn("/sys/fs/cgroup/memory.current");
    m = std::min(m, cg_used != kUnlimited && cg_used < cg_max ? cg_max - cg_used : 0);
  }
  m = std::min(m, limitLeft(RLIMIT_AS));
  m = std::min(m, limitLeft(RLIMIT_DATA));
  return m;
}

std::string bytesText(double bytes) {
  const char* units[] = {"bytes", "kB", "MB", "GB", "TB", "PB"};
  int u = 0;
  while (bytes >= 1000 && u < 5) bytes /= 1000, ++u;
  char buf[32];
  std::snprintf(buf, sizeof buf, u == 0 ? "%.0f %s" : bytes < 10 ? "%.1f %s" : "%.0f %s", bytes, units[u]);
  return buf;
}

void requireMemory(const std::string& what, double bytes) {
  if (bytes < 64e6) return;
  const std::uint64_t have = availableMemory();
  if (bytes > static_cast<double>(have))
    throw ResourceError(what + " needs about " + bytesText(bytes) + " of memory, more than the " +
                        bytesText(static_cast<double>(have)) + " this process can have");
}

}  // namespace flexure::engine
