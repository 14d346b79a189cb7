#include "render/provenance.h"

#include <mutex>

#include "flexure_build_info.h"  // generated at build time: FLEXURE_COMMIT (cmake/build_info.cmake)

namespace flexure::render {

namespace {
std::mutex g_mutex;
std::vector<std::string>& storedCommand() {
  static std::vector<std::string> words;
  return words;
}
}  // namespace

const std::string& flexureVersion() {
  static const std::string v = FLEXURE_VERSION_TEXT;
  return v;
}

const std::string& flexureCommit() {
  static const std::string c = FLEXURE_COMMIT;
  return c;
}

const std::string& flexureBuildType() {
  static const std::string t = FLEXURE_BUILD_TYPE;
  return t;
}

void setCommandLine(std::vector<std::string> words) {
  std::lock_guard<std::mutex> lock(g_mutex);
  storedCommand() = std::move(words);
}

std::vector<std::string> commandLine() {
  std::lock_guard<std::mutex> lock(g_mutex);
  return storedCommand();
}

std::string creatorText() {
  return "flexure " + flexureVersion() + " (commit " + flexureCommit() + ", " + flexureBuildType() + ")";
}

}  // namespace flexure::render
