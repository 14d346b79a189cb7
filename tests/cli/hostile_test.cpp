// Hostile input and faults, second round (docs/reliability.md): every case that crashed,
// escaped, hung or lied before, as the flexure binary meets it.
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <catch2/catch.hpp>
#include <fcntl.h>
#include <sys/stat.h>

#include <nlohmann/json.hpp>

#include "cli_common.h"

using namespace flexure_cli_test;

namespace {

const char* kSquare = "[system]\ntype = \"catalog\"\nname = \"square_pinned\"\n";

void write(const fs::path& p, const std::string& text) {
  std::ofstream f(p, std::ios::binary);
  f << text;
}

// The names in `d`, sorted.
std::vector<std::string> listing(const fs::path& d) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(d)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace

TEST_CASE("hostile: keys nested 31,000 levels deep are refused with their position, not a crash", "[cli]") {
  const fs::path d = scratchDir("deep");
  std::string header = "[a", dotted = "a";
  for (int i = 0; i < 31000; ++i) header += ".a", dotted += ".a";
  write(d / "header.toml", header + "]\n");
  write(d / "dotted.toml", std::string(kSquare) + "[motion]\n" + dotted + " = 1\n");
  std::string inline_tables = "x = ";
  for (int i = 0; i < 200; ++i) inline_tables += "{a=";
  inline_tables += "1" + std::string(200, '}') + "\n";
  write(d / "inline.toml", inline_tables);
  const Result h = run("analyze " + (d / "header.toml").string());
  CHECK(h.status == 1);
  CHECK_THAT(h.err, Catch::Contains("header.toml:1:2: this key is nested more than 64 levels deep"));
  const Result k = run("analyze " + (d / "dotted.toml").string());
  CHECK(k.status == 1);
  CHECK_THAT(k.err, Catch::Contains("dotted.toml:5:1: this key is nested more than 64 levels deep"));
  const Result i = run("analyze " + (d / "inline.toml").string());
  CHECK(i.status == 1);
  CHECK_THAT(i.err, Catch::Contains("nested more than 64 levels deep"));
  // --set takes the same limit.
  CHECK(run("analyze " + (d / "inline.toml").string() + " --set 'motion.x=" + inline_tables.substr(4, 700) + "'").status == 1);
  fs::remove_all(d);
}

TEST_CASE("hostile: a non-UTF-8 file name gives valid JSON", "[cli]") {
  const fs::path d = scratchDir("utf8");
  const fs::path scene = d / "bad\xff\xfe name.toml";
  write(scene, std::string(kSquare));
  const Result r = run("analyze --json '" + scene.string() + "'");
  REQUIRE(r.status == 0);
  const nlohmann::json j = nlohmann::json::parse(r.out);
  CHECK(j.at("scene").get<std::string>().find("\xef\xbf\xbd") != std::string::npos);  // U+FFFD
  const Result t = run("track --quiet '" + scene.string() + "'");
  REQUIRE(t.status == 0);
  CHECK_NOTHROW(nlohmann::json::parse(t.out));
  fs::remove_all(d);
}

TEST_CASE("hostile: escape sequences in a title or an expression reach the terminal escaped", "[cli]") {
  const fs::path d = scratchDir("escape");
  write(d / "t.toml", "title = \"evil \\u001b]0;owned\\u0007 \\u001b[2J\\u009b done\"\n" + std::string(kSquare));
  const Result r = run("analyze " + (d / "t.toml").string());
  REQUIRE(r.status == 0);
  CHECK(r.out.find('\x1b') == std::string::npos);
  CHECK(r.out.find('\x07') == std::string::npos);
  CHECK_THAT(r.out, Catch::Contains("evil \\x1B]0;owned\\x07 \\x1B[2J\\xC2\\x9B done"));
  // An error message quoting the file's text.
  write(d / "e.toml", std::string(kSquare) + "[motion]\nstep_size = \"1 + \\u001b[31m\"\n");
  const Result e = run("analyze " + (d / "e.toml").string());
  CHECK(e.status == 1);
  CHECK(e.err.find('\x1b') == std::string::npos);
  fs::remove_all(d);
}

TEST_CASE("hostile: [[output]] stays in the scene's folder, and no output replaces an input", "[cli]") {
  const fs::path d = scratchDir("confine");
  const std::string track = std::string(kSquare) + "[motion]\nsteps = 3\n";
  write(d / "abs.toml", track + "[[output]]\nfile = \"" + (d / "abs.json").string() + "\"\n");
  write(d / "up.toml", track + "[[output]]\nfile = \"sub/../../up.json\"\n");
  const Result a = run("run " + (d / "abs.toml").string());
  CHECK(a.status == 1);
  CHECK_THAT(a.err, Catch::Contains("abs.toml:7:8: file must be a path inside the scene's folder, not the absolute"));
  const Result u = run("run " + (d / "up.toml").string());
  CHECK(u.status == 1);
  CHECK_THAT(u.err, Catch::Contains("up.toml:7:8: file must be a path inside the scene's folder; '..' leads out"));
  CHECK_FALSE(fs::exists(d / "abs.json"));
  CHECK_FALSE(fs::exists(d.parent_path() / "up.json"));
  // A folder inside the scene's folder that links out of it.
  fs::create_directories(d / "scene" / "real");
  fs::create_directory_symlink(d, d / "scene" / "out");
  write(d / "scene" / "s.toml", track + "[[output]]\nfile = \"out/escaped.json\"\n[[output]]\nfile = \"real/p.json\"\n");
  const Result l = run("run " + (d / "scene" / "s.toml").string());
  CHECK(l.status == 3);
  CHECK_THAT(l.err, Catch::Contains("leads out of"));
  CHECK_FALSE(fs::exists(d / "escaped.json"));
  CHECK_FALSE(fs::exists(d / "scene" / "real" / "p.json"));  // checked before anything is written
  // Files are placed beside the scene, or under --output-dir.
  write(d / "scene" / "ok.toml", track + "[[output]]\nfile = \"real/p.json\"\n");
  REQUIRE(run("run --quiet " + (d / "scene" / "ok.toml").string()).status == 0);
  CHECK(fs::exists(d / "scene" / "real" / "p.json"));
  REQUIRE(run("run --quiet " + (d / "scene" / "ok.toml").string() + " --output-dir " + (d / "o").string()).status == 0);
  CHECK(fs::exists(d / "o" / "real" / "p.json"));
  // An output that is the input: refused before any work, the input untouched.
  const std::string scene_text = track;
  write(d / "scene.png", scene_text);
  // render's default output is the scene's name with .png, in the current folder.
  CHECK(shellOutput("cd " + d.string() + " && " + FLEXURE_BINARY + " render scene.png 2>&1; echo $?") ==
        "flexure: cannot write scene.png: it is the input scene.png (choose another output name)\n3\n");
  CHECK(readFile(d / "scene.png") == scene_text);
  write(d / "x.json", scene_text);
  CHECK(run("track " + (d / "x.json").string() + " -o " + (d / "x.json").string()).status == 3);
  CHECK(readFile(d / "x.json") == scene_text);
  fs::create_symlink(d / "x.json", d / "link.json");  // the same file under another name
  CHECK(run("track " + (d / "x.json").string() + " -o " + (d / "link.json").string()).status == 3);
  CHECK(readFile(d / "x.json") == scene_text);
  fs::remove_all(d);
}

TEST_CASE("hostile: outputs are checked before the computation", "[cli]") {
  const fs::path d = scratchDir("early");
  // Ten million steps would take minutes: the bad output is found first.
  const auto t0 = std::chrono::steady_clock::now();
  const Result r = run("track " + example("double_watt") + " --set motion.steps=10000000 -o /proc/flexure-no/x.json");
  CHECK(r.status == 3);
  CHECK(std::chrono::steady_clock::now() - t0 < std::chrono::seconds(20));
  fs::create_directory(d / "dir.json");
  const Result dir = run("track " + example("double_watt") + " -o " + (d / "dir.json").string());
  CHECK(dir.status == 3);
  CHECK_THAT(dir.err, Catch::Contains("it is a directory"));
  fs::remove_all(d);
}

TEST_CASE("hostile: two Ctrl-C or a SIGKILL while writing leave no file at all", "[cli][slow]") {
  const fs::path d = scratchDir("twice");
  for (const char* ext : {"mp4", "gif"}) {
    const std::string out = (d / (std::string("a.") + ext)).string();
    // 5,000 frames: still being written after 2 s (a 1,000-frame GIF now takes under 2 s).
    const std::string cmd = std::string(FLEXURE_BINARY) + " animate " + example("double_watt") +
                            " --quiet --set motion.steps=5000 -o " + out + " >/dev/null 2>/dev/null & pid=$!; sleep 2; " +
                            "kill -INT $pid; sleep 0.01; kill -INT $pid; wait $pid; echo $?";
    CHECK(shellOutput(cmd) == "130\n");
  }
  const std::string kill9 = std::string(FLEXURE_BINARY) + " animate " + example("double_watt") +
                            " --quiet --set motion.steps=5000 -o " + (d / "k.mp4").string() +
                            " >/dev/null 2>/dev/null & pid=$!; sleep 2; kill -KILL $pid; wait $pid; echo $?";
  CHECK(shellOutput(kill9) == "137\n");
  CHECK(listing(d).empty());  // no temporary name was ever made
  fs::remove_all(d);
}

// Shell text, after "& pid=$!; ": waits (up to 10 s) until the process has its SIGTERM handler
// (bit 15 of SigCgt in /proc/PID/status), so that a delay counts from main and not from a
// start-up that a sanitizer makes slow; a signal before that kills by default (exit 143).
static const std::string kWaitForHandler =
    "i=0; while [ $i -lt 1000 ]; do c=$(sed -n 's/^SigCgt:[[:space:]]*//p' /proc/$pid/status 2>/dev/null); "
    "[ -z \"$c\" ] && break; [ $(( 0x${c#${c%????}} & 16384 )) -ne 0 ] && break; sleep 0.01; i=$((i+1)); done; ";

TEST_CASE("hostile: SIGTERM is obeyed within a second at every stage", "[cli][slow]") {
  const fs::path d = scratchDir("term");
  // A scene read from a FIFO that nobody writes: blocked in read().
  REQUIRE(::mkfifo((d / "fifo.toml").c_str(), 0600) == 0);
  const std::string fifo = std::string(FLEXURE_BINARY) + " analyze " + (d / "fifo.toml").string() +
                           " 2>/dev/null & pid=$!; " + kWaitForHandler + "sleep 2; kill -TERM $pid; s=$(date +%s%N); wait $pid; " +
                           "echo $? $(( ($(date +%s%N) - s) / 1000000 ))";
  const std::string out = shellOutput(fifo);
  int status = 0, ms = 99999;
  std::sscanf(out.c_str(), "%d %d", &status, &ms);
  CHECK(status == 130);
  CHECK(ms < 2500);  // one second, and room for a loaded machine
  // Tracking stops at its next step and keeps the path.
  const std::string track = std::string(FLEXURE_BINARY) + " track " + example("k24") +
                            " --quiet --set motion.steps=1000000 -o " +
                            (d / "p.json").string() + " >/dev/null 2>/dev/null & pid=$!; " + kWaitForHandler + "sleep 3; kill -TERM $pid; wait $pid; echo $?";
  CHECK(shellOutput(track) == "130\n");
  CHECK(nlohmann::json::parse(readFile(d / "p.json")).at("reason") == "stopped on request");
  // A 3,000-point polytope (facets from the hull: a Fibonacci sphere, every point a vertex):
  // signalled while it loads and while it is analysed, analyze exits 130 with no report (it
  // finished the analysis after the signal and exited 0 before).
  std::string hull = "[system]\ntype = \"polytope\"\nfacets = \"hull\"\nvertices = [";
  for (int i = 0; i < 3000; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / 3000.0, r = std::sqrt(1.0 - z * z), phi = 2.399963229728653 * i;
    char point[96];
    std::snprintf(point, sizeof point, "%s[%.17g, %.17g, %.17g]", i ? ", " : "", r * std::cos(phi), r * std::sin(phi), z);
    hull += point;
  }
  write(d / "hull.toml", hull + "]\n");
  // A valid scene: it is the signal that stops it. Its whole report, and how long it takes here.
  const auto started = std::chrono::steady_clock::now();
  const Result whole = run("analyze " + (d / "hull.toml").string());
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  REQUIRE(whole.status == 0);
  int signalled = 0;
  for (const char* delay : {"0.1", "0.2", "0.3", "0.4", "0.5", "0.6", "0.8", "1.0", "1.3"}) {
    const std::string cmd = std::string(FLEXURE_BINARY) + " analyze " + (d / "hull.toml").string() + " >" +
                            (d / "report.txt").string() + " 2>/dev/null & pid=$!; " + kWaitForHandler + "sleep " + delay +
                            "; sent=0; st=; read -r _ _ st _ < /proc/$pid/stat 2>/dev/null; " +
                            "if [ -n \"$st\" ] && [ \"$st\" != Z ]; then kill -TERM $pid 2>/dev/null && sent=1; fi; " +
                            "s=$(date +%s%N); wait $pid; echo $sent $? $(( ($(date +%s%N) - s) / 1000000 ))";
    int sent = 0, status = -1, ms = 99999;
    std::sscanf(shellOutput(cmd).c_str(), "%d %d %d", &sent, &status, &ms);
    if (!sent) continue;  // it had finished (a zombie counts as finished)
    ++signalled;
    INFO("SIGTERM after " << delay << " s; the whole analysis took " << seconds << " s; exit after " << ms << " ms");
    CHECK(ms < 2500);
    if (std::atof(delay) < 0.6 * seconds) {
      // Well before the end: stopped, no report.
      CHECK(status == 130);
      CHECK(readFile(d / "report.txt").empty());
    } else {
      // A signal landing as the analysis finishes may find the report written: then it is the
      // whole report and the exit is prompt; otherwise it is stopped with no report.
      CHECK((status == 130 || status == 0));
      if (status == 130) CHECK(readFile(d / "report.txt").empty());
      if (status == 0) {
        CHECK(readFile(d / "report.txt") == whole.out);
        CHECK(ms < 500);
      }
    }
  }
  CHECK(signalled > 0);
  // A certified track of a 40 x 40 sheared grid (3,358 coordinates: a sparse anchor per step,
  // seconds of certification): signalled while it certifies (or, on a slow machine, still
  // tracks), it exits 130 at once and keeps the path, with what was certified and "stopped on
  // request".
  {
    const int w = 40, h = 40;
    const auto id = [&](int i, int r) { return r * (w + 1) + i + 1; };
    std::string grid = "[system]\ntype = \"framework\"\nvertices = [";
    for (int r = 0; r <= h; ++r)
      for (int i = 0; i <= w; ++i) grid += (r || i ? ", [" : "[") + std::to_string(i) + ", " + std::to_string(r) + "]";
    grid += "]\nedges = [";
    std::vector<std::pair<int, int>> edges;
    for (int r = 0; r <= h; ++r)
      for (int i = 0; i < w; ++i) edges.push_back({id(i, r), id(i + 1, r)});
    for (int r = 0; r < h; ++r)
      for (int i = 0; i <= w; ++i) edges.push_back({id(i, r), id(i, r + 1)});
    for (int i = 0; i < w; ++i) edges.push_back({id(i, 0), id(i + 1, 1)});
    for (int r = 1; r < h - 1; ++r) edges.push_back({id(0, r), id(1, r + 1)});
    for (size_t e = 0; e < edges.size(); ++e)
      grid += (e ? ", [" : "[") + std::to_string(edges[e].first) + ", " + std::to_string(edges[e].second) + "]";
    grid += "]\npinned = [1, 2]\n[motion]\nsteps = 100\nstep_size = 0.01\ncertify = true\n";
    write(d / "grid.toml", grid);
    const std::string cmd = std::string(FLEXURE_BINARY) + " track " + (d / "grid.toml").string() + " --quiet -o " +
                            (d / "grid.json").string() + " >/dev/null 2>/dev/null & pid=$!; " + kWaitForHandler + "sleep 1.5; kill -TERM $pid; " +
                            "s=$(date +%s%N); wait $pid; echo $? $(( ($(date +%s%N) - s) / 1000000 ))";
    int status = -1, ms = 99999;
    std::sscanf(shellOutput(cmd).c_str(), "%d %d", &status, &ms);
    CHECK(status == 130);
    CHECK(ms < 2500);
    const nlohmann::json path = nlohmann::json::parse(readFile(d / "grid.json"));
    REQUIRE(path.contains("certificate"));
    const std::string why = path["certificate"]["reason"].get<std::string>();
    INFO(why);
    CHECK(why.find("stopped on request") != std::string::npos);
    CHECK(path["certified"] == false);
  }
  fs::remove_all(d);
}

TEST_CASE("hostile: a full standard output is an error, not a success", "[cli]") {
  CHECK(shellOutput(std::string(FLEXURE_BINARY) + " analyze --json " + example("double_watt") +
                    " >/dev/full 2>/dev/null; echo $?") == "3\n");
  CHECK(shellOutput(std::string(FLEXURE_BINARY) + " track --quiet " + example("double_watt") +
                    " >/dev/full 2>/dev/null; echo $?") == "3\n");
}

TEST_CASE("hostile: every resource is bounded, with the limit in the message", "[cli]") {
  const fs::path d = scratchDir("bounds");
  const Result ghost = run("render " + example("double_watt") + " --set render.ghost=100000000");
  CHECK(ghost.status == 1);
  CHECK_THAT(ghost.err, Catch::Contains("0..10000000"));
  CHECK(run("render " + example("double_watt") + " --sample 100000000").status == 1);
  // Steps are bounded by count, and by the path's memory before any work (the double Watt goes
  // round its closed orbit for ever, so a run within both limits is long, not endless).
  const Result many = run("track " + example("double_watt") + " --set motion.steps=100000000");
  CHECK(many.status == 1);
  CHECK_THAT(many.err, Catch::Contains("steps must be between 0 and 10000000"));
  const Result huge = run("track " + example("dodecahedron") + " --set motion.steps=10000000");
  CHECK(huge.status == 1);
  CHECK_THAT(huge.err, Catch::Contains("10000000 steps of 96 coordinates would hold 9.6e+08 numbers; a path holds at most 2.5e+08"));
  const Result far = run("track " + example("dodecahedron") + " --set motion.target_length=1e300");
  CHECK(far.status == 1);
  CHECK_THAT(far.err, Catch::Contains("steps; at most"));
  const Result zero = run("analyze /dev/zero");
  CHECK(zero.status == 1);
  CHECK_THAT(zero.err, Catch::Contains("larger than 256 MiB"));
  // A body of 400 vertices costs 3 equations per vertex (a frame and affine combinations), not
  // a bar between every two of them (79,800). All of it lies in the plane z = x + 7y: a flat
  // body (6 motions), a rod (5: its spin moves no vertex) and three parallel coplanar bars
  // between them (rank 2, so 1 stress): 6 + 5 - 6 - 2 = 3 nontrivial flexes.
  std::string body = "[system]\ntype = \"body_bar\"\nvertices = [";
  for (int i = 0; i < 403; ++i) body += (i ? ", [" : "[") + std::to_string(i % 7) + ", " + std::to_string(i / 7 % 11) + ", " + std::to_string(i) + "]";
  body += "]\nbodies = [[";
  for (int i = 1; i <= 400; ++i) body += (i > 1 ? ", " : "") + std::to_string(i);
  body += "], [401, 402, 403]]\nbars = [[1, 401], [2, 402], [3, 403]]\n";
  write(d / "body.toml", body);
  const Result big = run("analyze " + (d / "body.toml").string());
  CHECK(big.status == 0);
  CHECK_THAT(big.out, Catch::Contains("1209 variables, 1201 equations"));
  CHECK_THAT(big.out, Catch::Contains("infinitesimal flexes 9 = 6 trivial + 3 nontrivial"));
  CHECK_THAT(big.out, Catch::Contains("equilibrium stresses 1"));
  const Result dir = run("analyze " + d.string());
  CHECK(dir.status == 1);
  CHECK_THAT(dir.err, Catch::Contains("is a directory, not a scene file"));
  fs::remove_all(d);
}

TEST_CASE("hostile: a square at 1e154 or 1e-200 is out of range, not 'coincident' or 'flexible'", "[cli]") {
  const fs::path d = scratchDir("scale");
  for (const char* s : {"1e154", "1e-160", "1e-200"}) {
    write(d / "sq.toml", std::string("[system]\ntype = \"framework\"\nvertices = [[0, 0], [") + s + ", 0], [" + s +
                             ", " + s + "], [0, " + s + "]]\nedges = [[1, 2], [2, 3], [3, 4], [4, 1]]\n");
    const Result r = run("analyze " + (d / "sq.toml").string());
    CHECK(r.status == 1);
    CHECK_THAT(r.err, Catch::Contains("rescale"));
    CHECK(r.err.find("coincide") == std::string::npos);
  }
  fs::remove_all(d);
}
