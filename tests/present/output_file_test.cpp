#include <catch2/catch.hpp>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "present/output_file.h"
#include "present/text.h"

namespace fs = std::filesystem;
using namespace flexure::present;

namespace {

fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("flexure_output_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

size_t entries(const fs::path& d) { return static_cast<size_t>(std::distance(fs::directory_iterator(d), {})); }

}  // namespace

TEST_CASE("output file: nothing has a name until commit, and a planted link is never followed", "[present]") {
  const fs::path d = scratch("pending");
  std::ofstream(d / "victim") << "keep";
  // Links planted at every name the old scheme used (PATH.tmp-PID) and a few more.
  for (const char* n : {"out.json.tmp-1", "out.json.tmp-2"}) fs::create_symlink(d / "victim", d / n);
  fs::create_symlink(d / "victim", d / ("out.json.tmp-" + std::to_string(::getpid())));
  const size_t before = entries(d);
  {
    TemporaryOutput out((d / "out.json").string());
    out.write("{\"a\": 1}\n");
    CHECK(entries(d) == before);  // unnamed while pending
    // A library that takes a path writes to the same file through temp().
    std::ofstream(out.temp(), std::ios::app) << "more\n";
    out.commit();
  }
  CHECK(read(d / "out.json") == "{\"a\": 1}\nmore\n");
  CHECK(read(d / "victim") == "keep");
  CHECK(entries(d) == before + 1);
  {
    TemporaryOutput dropped((d / "dropped.json").string());
    dropped.write("x");
  }
  CHECK_FALSE(fs::exists(d / "dropped.json"));
  CHECK(entries(d) == before + 1);
  // Replacing: the old content stays until the new file is complete.
  writeFileAtomically((d / "out.json").string(), "new");
  CHECK(read(d / "out.json") == "new");
  CHECK(entries(d) == before + 1);
  fs::remove_all(d);
}

TEST_CASE("output file: checkWritable refuses directories, inputs and unwritable places", "[present]") {
  const fs::path d = scratch("check");
  std::ofstream(d / "in.toml") << "x";
  CHECK_NOTHROW(checkWritable((d / "sub" / "x.png").string(), {(d / "in.toml").string()}));
  CHECK(fs::is_directory(d / "sub"));
  CHECK(entries(d / "sub") == 0);
  CHECK_THROWS_WITH(checkWritable((d / "in.toml").string(), {(d / "in.toml").string()}), Catch::Contains("it is the input"));
  fs::create_hard_link(d / "in.toml", d / "hard.toml");
  CHECK_THROWS_WITH(checkWritable((d / "hard.toml").string(), {(d / "in.toml").string()}), Catch::Contains("it is the input"));
  CHECK_THROWS_WITH(checkWritable((d / "sub").string()), Catch::Contains("it is a directory"));
  CHECK_THROWS_AS(checkWritable("/proc/flexure-nowhere/x.png"), OutputError);
  // Issue 62: the system cuts a name at its NUL ("a.csv\0.json" would be a.csv, written as
  // JSON): refused, and nothing is made.
  const std::string nul = (d / "a.csv").string() + std::string(1, '\0') + ".json";
  CHECK_THROWS_WITH(writeFileAtomically(nul, "{}"), Catch::Contains("a.csv\\0.json") && Catch::Contains("NUL"));
  CHECK_THROWS_AS(checkWritable(nul), OutputError);
  CHECK(!fs::exists(d / "a.csv"));
  fs::remove_all(d);
}

TEST_CASE("text: control characters and broken UTF-8 are escaped for the terminal, and JSON stays valid", "[present]") {
  CHECK(terminalSafe("plain, ünïcode ✓\n\ttab") == "plain, ünïcode ✓\n\ttab");
  CHECK(terminalSafe("\x1b[31mred\x07\x7f") == "\\x1B[31mred\\x07\\x7F");
  CHECK(terminalSafe("c1 \xc2\x9b end") == "c1 \\xC2\\x9B end");
  CHECK(terminalSafe("bad \xff\xfe and cut \xe2\x9c") == "bad \\xFF\\xFE and cut \\xE2\\x9C");
  CHECK(terminalSafe("overlong \xc0\xaf surrogate \xed\xa0\x80") == "overlong \\xC0\\xAF surrogate \\xED\\xA0\\x80");
  const nlohmann::ordered_json j = {{"name", std::string("a\xff" "b")}};
  CHECK(jsonText(j) == "{\"name\":\"a\xef\xbf\xbd" "b\"}");
  // Through a stream: whole lines are filtered, whatever the pieces.
  std::ostringstream target;
  {
    TerminalFilter filter(target.rdbuf());
    std::ostream out(&filter);
    out << "title: " << "\x1b]0;x\x07" << "\n" << "partial " << 3;
    out.flush();
  }
  CHECK(target.str() == "title: \\x1B]0;x\\x07\npartial 3");
}

TEST_CASE("output file: a symbolic link, a FIFO or a device named as an output is refused and stays what it was") {
  // Issue 42: the write-then-rename turned a device node, a FIFO or a symlink named as the
  // output into a regular file (run as root, `p.write('/dev/null')` replaced the device).
  const fs::path d = fs::temp_directory_path() / ("flexure_special_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  std::ofstream(d / "target.png") << "kept";
  fs::create_symlink(d / "target.png", d / "link.png");
  fs::create_symlink(d / "nowhere.png", d / "dangling.png");
  REQUIRE(::mkfifo((d / "fifo.png").c_str(), 0644) == 0);
  std::vector<std::pair<fs::path, std::string>> special = {
      {d / "link.png", "a symbolic link"}, {d / "dangling.png", "a symbolic link"}, {d / "fifo.png", "a FIFO"}};
  if (::geteuid() == 0 && ::mknod((d / "null.png").c_str(), S_IFCHR | 0666, makedev(1, 3)) == 0)
    special.push_back({d / "null.png", "a character device"});
  for (const auto& [path, kind] : special) {
    INFO(path);
    CHECK_THROWS_WITH(writeFileAtomically(path.string(), "data"), Catch::Contains("it is " + kind) &&
                                                                      Catch::Contains("only replaces regular files"));
    CHECK_THROWS_AS(checkWritable(path.string()), OutputError);
    CHECK_FALSE(fs::is_regular_file(fs::symlink_status(path)));
  }
  std::ifstream in(d / "target.png");
  std::string kept;
  in >> kept;
  CHECK(kept == "kept");
  CHECK_NOTHROW(writeFileAtomically((d / "target.png").string(), "new"));  // a regular file is replaced
  fs::remove_all(d);
}
