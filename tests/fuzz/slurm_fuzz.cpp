// libFuzzer target: any bytes as the values `flexure sweep --slurm` writes into its scripts
// (partition, account, time limit, working directory, output name, the sweep's arguments),
// split at NUL bytes. Either SlurmPlan::check() refuses them (std::invalid_argument), or the
// scripts keep their shape: as many lines as with plain values (no value ends a line), every
// #SBATCH line one option with a value without blanks, and the flexure command lines split by
// a POSIX shell into words that hold each value whole (no value is run or splits into options).
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "sweep/slurm.h"

namespace {

// The words of a shell line, as a POSIX shell splits them (quotes removed; $... in double quotes
// kept as written, which is all the scripts put there). Traps on unbalanced quotes.
std::vector<std::string> shellWords(const std::string& line) {
  std::vector<std::string> words;
  std::string w;
  bool in_word = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (c == ' ' || c == '\t') {
      if (in_word) words.push_back(w), w.clear(), in_word = false;
      continue;
    }
    in_word = true;
    if (c == '\'') {
      const size_t end = line.find('\'', i + 1);
      if (end == std::string::npos) __builtin_trap();
      w += line.substr(i + 1, end - i - 1);
      i = end;
    } else if (c == '"') {
      size_t j = i + 1;
      for (; j < line.size() && line[j] != '"'; ++j) {
        if (line[j] == '\\' && j + 1 < line.size()) ++j;
        w += line[j];
      }
      if (j >= line.size()) __builtin_trap();
      i = j;
    } else if (c == '\\' && i + 1 < line.size()) {
      w += line[++i];
    } else {
      // Unquoted: only characters with no meaning to the shell may come from a value.
      w += c;
    }
  }
  if (in_word) words.push_back(w);
  return words;
}

std::vector<std::string> lines(const std::string& s) {
  std::vector<std::string> out;
  std::istringstream in(s);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

bool holdsWord(const std::vector<std::string>& words, const std::string& w) {
  for (const auto& x : words)
    if (x == w) return true;
  return false;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::vector<std::string> f(1);
  for (size_t i = 0; i < size; ++i) {
    if (data[i] == 0) f.emplace_back();
    else f.back() += static_cast<char>(data[i]);
  }
  f.resize(std::max<size_t>(f.size(), 7));
  flexure::sweep::SlurmPlan p;
  p.flexure = "/opt/flexure";
  p.partition = f[0];
  p.account = f[1];
  p.time_limit = f[2];
  p.workdir = "/home/" + f[3];
  p.output = f[4].empty() ? "out.jsonl" : f[4];
  p.shard_dir = p.output + ".shards";
  p.sweep_args = {"analyze", f[5].empty() ? "in.g6" : f[5], "--where", f[6]};
  p.tasks = 3;
  try {
    p.check();
  } catch (const std::invalid_argument&) {
    return 0;
  }
  flexure::sweep::SlurmPlan plain = p;
  plain.partition = p.partition.empty() ? "" : "p";
  plain.account = p.account.empty() ? "" : "a";
  plain.time_limit = p.time_limit.empty() ? "" : "1";
  plain.workdir = "/home/w";
  plain.output = "out.jsonl";
  plain.shard_dir = "out.jsonl.shards";
  plain.sweep_args = {"analyze", "in.g6", "--where", "x"};
  for (const bool array : {true, false}) {
    const auto got = lines(array ? p.arrayScript() : p.mergeScript());
    const auto want = lines(array ? plain.arrayScript() : plain.mergeScript());
    if (got.size() != want.size()) __builtin_trap();
    for (const auto& l : got) {
      if (l.rfind("#SBATCH ", 0) == 0 && l.find_first_of(" \t", 8) != std::string::npos) __builtin_trap();
      if (l.rfind("/opt/flexure ", 0) == 0) {  // the array's task
        const auto w = shellWords(l);
        for (const auto& a : p.sweep_args)
          if (!holdsWord(w, a)) __builtin_trap();
      }
      if (l.rfind("exec /opt/flexure ", 0) == 0) {  // the merge
        const auto w = shellWords(l);
        if (!holdsWord(w, p.output) || !holdsWord(w, p.shard_dir)) __builtin_trap();
      }
      if (l.rfind("shard=", 0) == 0 && shellWords(l.substr(6)).size() != 1) __builtin_trap();
    }
  }
  return 0;
}
