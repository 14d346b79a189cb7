#include "engine/resources.h"

#include <sys/resource.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>
#include <utility>
#include <vector>
#include <unistd.h>

namespace flexure::engine {

namespace {

constexpr std::uint64_t kUnlimited = std::numeric_limits<std::uint64_t>::max();

// The first number in a file ("max", no file, or cgroup v1's "no limit", near 2^63: unlimited).
std::uint64_t numberIn(const std::string& path) {
  std::ifstream in(path);
  std::string s;
  if (!(in >> s) || s == "max") return kUnlimited;
  try {
    const std::uint64_t v = std::stoull(s);
    return v >= (std::uint64_t{1} << 60) ? kUnlimited : v;
  } catch (...) {
    return kUnlimited;
  }
}

// The value of `key` in a "key value" file (/proc/meminfo in kB, memory.stat in bytes; 0 if
// absent).
std::uint64_t fieldIn(const std::string& path, const std::string& key) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line))
    if (line.compare(0, key.size() + 1, key + " ") == 0 || line.compare(0, key.size() + 1, key + ":") == 0) {
      try {
        return std::stoull(line.substr(key.size() + 1));
      } catch (...) {
        return 0;
      }
    }
  return 0;
}

// What the process's memory cgroup leaves: its limit less its usage, the page cache it could
// drop (inactive files) counted as free. v2 ("0::/path") and v1 ("N:...memory...:/path"), at
// the process's own cgroup (a Slurm job's), else at the mount's root (a container's namespace).
std::uint64_t cgroupLeft() {
  std::ifstream in("/proc/self/cgroup");
  std::string line, v2, v1;
  while (std::getline(in, line)) {
    const size_t a = line.find(':'), b = line.find(':', a + 1);
    if (a == std::string::npos || b == std::string::npos) continue;
    const std::string controllers = line.substr(a + 1, b - a - 1), path = line.substr(b + 1);
    if (line.compare(0, a, "0") == 0 && controllers.empty()) v2 = path;
    std::istringstream list(controllers);
    for (std::string c; std::getline(list, c, ',');)
      if (c == "memory") v1 = path;
  }
  struct Layout {
    std::string root, limit, usage, inactive;
  };
  std::vector<std::pair<Layout, std::string>> tries;
  if (!v1.empty()) tries.push_back({{"/sys/fs/cgroup/memory", "memory.limit_in_bytes", "memory.usage_in_bytes",
                                     "total_inactive_file"}, v1});
  tries.push_back({{"/sys/fs/cgroup", "memory.max", "memory.current", "inactive_file"}, v2.empty() ? "/" : v2});
  std::uint64_t left = kUnlimited;
  for (const auto& [l, path] : tries) {
    for (const std::string& dir : {l.root + path, l.root}) {
      std::ifstream probe(dir + "/" + l.limit);
      if (!probe) continue;
      const std::uint64_t limit = numberIn(dir + "/" + l.limit);
      if (limit != kUnlimited) {
        const std::uint64_t usage = numberIn(dir + "/" + l.usage);
        const std::uint64_t cache = fieldIn(dir + "/memory.stat", l.inactive);
        const std::uint64_t used = usage == kUnlimited ? 0 : usage - std::min(usage, cache);
        left = std::min(left, limit > used ? limit - used : 0);
      }
      break;
    }
  }
  return left;
}

// A limit less what counts against it: the address space (VmSize) for RLIMIT_AS, the data
// segment (VmData) for RLIMIT_DATA.
std::uint64_t limitLeft(int resource, const char* counted) {
  rlimit r{};
  if (::getrlimit(resource, &r) != 0 || r.rlim_cur == RLIM_INFINITY) return kUnlimited;
  const std::uint64_t used = fieldIn("/proc/self/status", counted) * 1024;
  return r.rlim_cur > used ? r.rlim_cur - used : 0;
}

}  // namespace

std::uint64_t availableMemory() {
  std::uint64_t m = fieldIn("/proc/meminfo", "MemAvailable") * 1024;
  if (m == 0) m = kUnlimited;
  m = std::min(m, cgroupLeft());
  m = std::min(m, limitLeft(RLIMIT_AS, "VmSize"));
  m = std::min(m, limitLeft(RLIMIT_DATA, "VmData"));
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
