#include "render/libav.h"

#include <dlfcn.h>

#include <mutex>
#include <stdexcept>

#ifndef FLEXURE_LIBAV_MODULE
#error "FLEXURE_LIBAV_MODULE: the path of libflexure-av.so in the build tree"
#endif

namespace flexure::render::libav {

namespace {

constexpr const char* kName = "libflexure-av.so";

// The folder of the executable or shared library this function is in, "" if unknown.
std::string ownFolder() {
  Dl_info info{};
  if (!::dladdr(reinterpret_cast<void*>(&ownFolder), &info) || !info.dli_fname) return "";
  const std::string file = info.dli_fname;
  const auto slash = file.rfind('/');
  return slash == std::string::npos ? std::string() : file.substr(0, slash);
}

const Api* load() {
  std::string tried;
  const std::string folder = ownFolder();
  for (const std::string& path : {folder.empty() ? std::string() : folder + "/" + kName, std::string(FLEXURE_LIBAV_MODULE)}) {
    if (path.empty()) continue;
    void* handle = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      const char* why = ::dlerror();
      tried += "\n  " + path + ": " + (why ? why : "cannot be loaded");
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
