// libFuzzer target: any bytes as the files a sweep reads back: an output being resumed and the
// shards `sweep merge` joins (split into two shards at the first NUL byte). Either a SceneError
// naming the file (or an OutputError), or a result: never a crash, an abort on a JSON value of
// the wrong type, or an allocation sized by a forged count.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>

#include "present/output_file.h"
#include "scenes/scene.h"
#include "sweep/sweep.h"

namespace {

std::string scratch(const char* name) { return "/tmp/flexure-fuzz-" + std::to_string(::getpid()) + "-" + name; }

void write(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << text;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace flexure;
  const std::string text(reinterpret_cast<const char*>(data), size);
  const size_t nul = text.find('\0');
  const std::string a = scratch("s0.jsonl"), b = scratch("s1.jsonl"), out = scratch("merged.jsonl");
  const std::string graphs = scratch("g.g6"), resumed = scratch("out.jsonl");
  write(a, text.substr(0, nul));
  write(b, nul == std::string::npos ? std::string() : text.substr(nul + 1));
  try {
    sweep::merge({a, b}, out);
  } catch (const scenes::SceneError&) {
  } catch (const present::OutputError&) {
  }
  try {
    sweep::merge({a}, out);
  } catch (const scenes::SceneError&) {
  } catch (const present::OutputError&) {
  }
  // A resume: the bytes as the output of a sweep of three small graphs (analysed on one thread;
  // the items the output does not hold are computed).
  write(graphs, "Bw\nCw\nC~\n");
  write(resumed, text.substr(0, nul));
  sweep::Options o;
  o.threads = 1;
  try {
    auto family = sweep::openFamily(graphs, o);
    (void)sweep::run(*family, graphs, o, resumed);
  } catch (const scenes::SceneError&) {
  } catch (const present::OutputError&) {
  }
  for (const auto& f : {a, b, out, graphs, resumed}) std::remove(f.c_str());
  return 0;
}
