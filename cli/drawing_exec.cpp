// In `flexure`: the commands that draw run in `flexure-draw`, the executable next to this one
// that links the renderer, the video encoder and the viewer. The command line has been checked
// here already; it is handed on unchanged, in the same process (exec), so signals, exit status
// and standard streams are those of the command.
#include <limits.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <string>

#include "cli/cli.h"

namespace flexure::cli {

namespace {

// The folder of this executable (from /proc/self/exe), "" if it cannot be read.
std::string ownFolder() {
  char buf[PATH_MAX];
  const ssize_t n = ::readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) return "";
  const std::string self(buf, static_cast<size_t>(n));
  const auto slash = self.find_last_of('/');
  return slash == std::string::npos ? "" : self.substr(0, slash);
}

}  // namespace

int drawingCommand(const Args& a) {
  if (g_interrupted) return interrupted("before " + a.command + " started; nothing was written");
  const std::string folder = ownFolder();
  const std::string draw = (folder.empty() ? std::string(".") : folder) + "/flexure-draw";
  std::cout.flush();
  std::cerr.flush();
  std::fflush(nullptr);
  ::execv(draw.c_str(), g_argv);
  const int e = errno;
  std::cerr << "flexure: '" << a.command << "' draws, and runs in " << draw << ", which cannot be started: "
            << std::strerror(e) << " (it is built next to flexure)\n";
  return kExitOutput;
}

}  // namespace flexure::cli
