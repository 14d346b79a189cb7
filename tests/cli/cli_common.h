// Running the flexure binary from a test: its status, stdout and stderr; scratch folders.
#pragma once

#include <catch2/catch.hpp>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace flexure_cli_test {

namespace fs = std::filesystem;

struct Result {
  int status;
  std::string out;
  std::string err;
};

inline std::string readFile(const fs::path& p) {
  std::ifstream in(p);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline fs::path scratchDir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("flexure_cli_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

inline Result run(const std::string& args) {
  const fs::path err = scratchDir("stderr") / "err.txt";
  const std::string cmd = std::string(FLEXURE_BINARY) + " " + args + " 2>" + err.string();
  Result r;
  std::FILE* p = popen(cmd.c_str(), "r");
  REQUIRE(p);
  char buf[4096];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) r.out.append(buf, n);
  const int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  r.err = readFile(err);
  return r;
}

// What a shell script (run by sh -c, as popen runs it) prints on stdout.
inline std::string shellOutput(const std::string& script) {
  std::FILE* p = popen(script.c_str(), "r");
  REQUIRE(p);
  std::string out;
  char buf[256];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  pclose(p);
  return out;
}

inline std::string example(const std::string& name) {
  return std::string(FLEXURE_EXAMPLES_DIR) + "/" + name + ".toml";
}

}  // namespace flexure_cli_test
