#include "render/libav.h"

#include <dlfcn.h>

#include <algorithm>
#include <cstdlib>
#include <stdexcept>
#include <vector>

#ifndef FLEXURE_LIBAV_MODULE
#error "FLEXURE_LIBAV_MODULE: the path of libflexure-av.so in the build tree"
#endif

namespace flexure::render::libav {

namespace {

constexpr const char* kName = "libflexure-av.so";

std::string folderOf(const char* file) {
  if (!file) return "";
  char* real = ::realpath(file, nullptr);
  if (!real) return "";
  const std::string path = real;
  std::free(real);
  return path.substr(0, path.rfind('/'));
}

// The folder of the executable or shared library (the Python module) this function is in, ""
// if unknown.
std::string ownFolder() {
  Dl_info info{};
  if (!::dladdr(reinterpret_cast<void*>(&ownFolder), &info)) return "";
  return folderOf(info.dli_fname);
}

const Api* load() {
  std::string tried;
  std::vector<std::string> candidates;
  // Next to this code; next to the executable (dladdr names the main program as it was
  // started, which is relative to a working directory that may have changed since); for an
  // installed flexure or flexure-draw, PREFIX/lib/flexure beside its PREFIX/bin
  // (cmake/install.cmake; not for another program, such as python3 running the module, which
  // has its copy beside it); then the build tree.
  const std::string exe = folderOf("/proc/self/exe");
  for (const std::string& folder : {ownFolder(), exe})
    if (!folder.empty()) candidates.push_back(folder + "/" + kName);
  char* self = ::realpath("/proc/self/exe", nullptr);
  if (self && !exe.empty() && std::string(self).rfind(exe + "/flexure", 0) == 0)
    candidates.push_back(exe.substr(0, exe.rfind('/')) + "/lib/flexure/" + kName);
  std::free(self);
  candidates.push_back(FLEXURE_LIBAV_MODULE);
  candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
  for (const std::string& path : candidates) {
    void* handle = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      const char* why = ::dlerror();
      tried += "\n  " + (why ? std::string(why) : path + ": cannot be loaded");  // dlerror names the file
      continue;
    }
    using Entry = const Api* (*)();
    const auto entry = reinterpret_cast<Entry>(::dlsym(handle, "flexure_libav_api"));
    const Api* a = entry ? entry() : nullptr;
    if (a && a->version == kApiVersion) return a;  // stays loaded for the process
    tried += "\n  " + path + ": not this version's " + kName;
    ::dlclose(handle);
  }
  throw std::runtime_error(std::string("MP4 and video decoding need ") + kName + " (FFmpeg's libraries):" + tried);
}

}  // namespace

const Api& api() {
  static const Api* const loaded = load();
  return *loaded;
}

}  // namespace flexure::render::libav
