// Helpers for the viewer tests: a scratch directory with a copy of an example scene.
#pragma once

#include <unistd.h>

#include <catch2/catch.hpp>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

namespace flexure::test {

class ScratchScene {
 public:
  explicit ScratchScene(const std::string& example) {
    char tmpl[] = "/tmp/flexure-viewer-test-XXXXXX";
    REQUIRE(::mkdtemp(tmpl) != nullptr);
    dir = tmpl;
    path = dir + "/" + example + ".toml";
    text = read(std::string(FLEXURE_EXAMPLES_DIR) + "/" + example + ".toml");
    write(text);
  }
  ~ScratchScene() { std::system(("rm -rf '" + dir + "'").c_str()); }
  static std::string read(const std::string& file) {
    std::ifstream in(file);
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }
  // Replaces the file (by rename, as editors do) and makes sure its time stamp moves.
  void write(const std::string& t) const {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const std::string tmp = path + ".tmp";
    std::ofstream(tmp) << t;
    REQUIRE(std::rename(tmp.c_str(), path.c_str()) == 0);
  }
  std::string dir, path, text;
};

}  // namespace flexure::test
