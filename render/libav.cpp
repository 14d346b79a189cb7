#include "render/libav.h"

#include <dlfcn.h>
#include <link.h>

#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#ifndef FLEXURE_AV_INSTALL_DIR
#error "FLEXURE_AV_INSTALL_DIR: the folder of libflexure-av.so in an installed tree, relative to its prefix (CMakeLists.txt)"
#endif

namespace flexure::render::libav {

namespace {

constexpr const char* kName = "libflexure-av.so";
constexpr const char* kVariable = "FLEXURE_AV_MODULE";

// `path` with its symbolic links resolved (absolute), or "" when it cannot be.
std::string realPath(const char* path) {
  char* real = ::realpath(path, nullptr);
  if (!real) return "";
  const std::string out = real;
  std::free(real);
  return out;
}

std::string folderOf(const std::string& path) { return path.substr(0, path.rfind('/')); }

// At most 300 bytes of a value from the environment, for a message.
std::string shown(const std::string& s) { return s.size() <= 300 ? s : s.substr(0, 300) + "..."; }

// A file the module may be loaded from, and why it is looked for there.
struct Place {
  std::string path;  // absolute
  std::string why;
};

// Where the module is looked for when FLEXURE_AV_MODULE is not set: beside the file that holds
// this code, as the kernel and the dynamic loader know it, never a name that depends on the
// working directory (dladdr's file name for the executable is argv[0], e.g. "flexure" started
// through PATH, which realpath would look up in the working directory):
//   - in an executable (flexure, flexure-draw): the folder of its real file (/proc/self/exe),
//     and for an installed one (PREFIX/bin, cmake/install.cmake) PREFIX/FLEXURE_AV_INSTALL_DIR;
//   - in a shared object (the Python module): the real folder of its file as it was loaded,
//     when that name is absolute (Python loads extensions by absolute paths); a relative one
//     would be resolved against whatever the working directory is now, and is not used.
// What could not be searched goes to `notes`.
std::vector<Place> ownPlaces(std::string& notes) {
  Dl_info info{};
  link_map* map = nullptr;
  if (!::dladdr1(reinterpret_cast<void*>(&ownPlaces), &info, reinterpret_cast<void**>(&map), RTLD_DL_LINKMAP) ||
      !map || !map->l_name) {
    notes += "\n  (the file that holds flexure's code is unknown: dladdr failed)";
    return {};
  }
  std::vector<Place> places;
  if (map->l_name[0] == '\0') {  // the executable (glibc names it "" in its link map)
    const std::string exe = realPath("/proc/self/exe");
    if (exe.empty()) {
      notes += "\n  (/proc/self/exe cannot be resolved: the executable's folder is unknown)";
      return {};
    }
    const std::string bin = folderOf(exe);
    places.push_back({bin + "/" + kName, "next to the executable " + exe});
    if (bin.size() >= 4 && bin.compare(bin.size() - 4, 4, "/bin") == 0)
      places.push_back({folderOf(bin) + "/" FLEXURE_AV_INSTALL_DIR "/" + kName, "in the installed tree of " + exe});
  } else if (map->l_name[0] == '/') {
    const std::string self = realPath(map->l_name);
    if (self.empty()) {
      notes += "\n  (" + std::string(map->l_name) + ", the module that holds flexure's code, cannot be resolved)";
      return {};
    }
    places.push_back({folderOf(self) + "/" + kName, "next to " + self});
  } else {
    notes += "\n  (the module that holds flexure's code was loaded by the relative name '" + shown(map->l_name) +
             "', which depends on the working directory: its folder is not searched)";
  }
  return places;
}

const Api* load() {
  std::string notes;
  std::vector<Place> places;
  const char* variable = std::getenv(kVariable);
  if (variable && *variable) {
    // An explicit choice: the only place tried. A relative path would name a file of whatever
    // the working directory is.
    if (variable[0] != '/')
      throw std::invalid_argument(std::string(kVariable) + "='" + shown(variable) + "' is not an absolute path: set it to " +
                                  "the absolute path of " + kName + " (a relative one would depend on the working directory)");
    places.push_back({variable, "from " + std::string(kVariable)});
  } else {
    places = ownPlaces(notes);
  }
  std::string tried;
  for (const Place& place : places) {
    // dlopen runs the library's constructors before anything can be checked: only the places
    // above are ever opened, by absolute path (no search of LD_LIBRARY_PATH or the cache).
    void* handle = ::dlopen(place.path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      const char* error = ::dlerror();
      std::string why = error ? error : "cannot be loaded";
      if (why.rfind(place.path + ": ", 0) == 0) why.erase(0, place.path.size() + 2);  // dlerror names the file too
      tried += "\n  " + place.path + " (" + place.why + "): " + why;
      continue;
    }
    using Entry = const Api* (*)();
    const auto entry = reinterpret_cast<Entry>(::dlsym(handle, "flexure_libav_api"));
    const Api* a = entry ? entry() : nullptr;
    if (a && a->version == kApiVersion) return a;  // stays loaded for the process
    tried += "\n  " + place.path + " (" + place.why + "): not this version's " + kName;
    ::dlclose(handle);
  }
  throw std::runtime_error(std::string("MP4 writing and video decoding need ") + kName +
                           " (FFmpeg's libraries), and none could be loaded; tried:" + (tried.empty() ? "\n  nothing" : tried) +
                           notes + "\n  (set " + kVariable + " to the absolute path of " + kName +
                           " to load it from elsewhere)");
}

}  // namespace

const Api& api() {
  static const Api* const loaded = load();
  return *loaded;
}

}  // namespace flexure::render::libav
