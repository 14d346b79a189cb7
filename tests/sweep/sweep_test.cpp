// flexure sweep: families, determinism over threads and slices, resuming, merging, filters,
// bad items, and the Laman counts of OEIS A227117 through nauty's geng.
#include "sweep/sweep.h"

#include <catch2/catch.hpp>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <functional>
#include <fstream>
#include <sstream>

#include "pipeline/pipeline.h"
#include "scenes/importers.h"
#include "scenes/scene.h"
#include "sweep/slurm.h"

namespace {

namespace fs = std::filesystem;
using flexure::sweep::Json;
namespace sweep = flexure::sweep;

fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("flexure_sweep_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string readFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void writeFile(const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }

// What a command prints (nauty's geng).
std::string commandOutput(const std::string& cmd) {
  std::FILE* p = popen(cmd.c_str(), "r");
  REQUIRE(p);
  std::string out;
  char buf[4096];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  REQUIRE(pclose(p) == 0);
  return out;
}

// Every connected graph on n vertices with e edges, from nauty's geng (scripts/setup installs it).
std::string geng(int n, int e) {
  const std::string exe = fs::exists("/usr/bin/nauty-geng") ? "/usr/bin/nauty-geng" : "geng";
  return commandOutput(exe + " -c -q " + std::to_string(n) + " " + std::to_string(e) + ":" + std::to_string(e));
}

// The lines of an output without the fields whose names contain "time" (measurements).
std::vector<Json> untimed(const fs::path& file) {
  std::vector<Json> out;
  std::istringstream in(readFile(file));
  std::string line;
  std::function<Json(const Json&)> drop = [&](const Json& j) {
    if (!j.is_object()) return j;
    Json o = Json::object();
    for (auto it = j.begin(); it != j.end(); ++it)
      if (it.key().find("time") == std::string::npos) o[it.key()] = drop(*it);
    return o;
  };
  while (std::getline(in, line)) out.push_back(drop(Json::parse(line)));
  return out;
}

sweep::RunResult runSweep(const std::string& input, const sweep::Options& o, const fs::path& out) {
  auto family = sweep::openFamily(input, o);
  return sweep::run(*family, input, o, out.string());
}

Json summaryOf(const fs::path& file) { return untimed(file).back().at("summary"); }

}  // namespace

TEST_CASE("sweep: Laman graphs counted as OEIS A227117 (n = 5..8) in one process") {
  // The connected graphs with 2n-3 edges that are generically rigid in the plane are exactly the
  // Laman graphs; a random realization is generic with probability 1.
  const fs::path dir = scratch("laman");
  const std::pair<int, long long> known[] = {{5, 3}, {6, 13}, {7, 70}, {8, 608}};
  for (const auto& [n, laman] : known) {
    const fs::path g = dir / ("g" + std::to_string(n) + ".g6");
    writeFile(g, geng(n, 2 * n - 3));
    sweep::RunResult r = runSweep(g.string(), {}, dir / ("out" + std::to_string(n) + ".jsonl"));
    INFO("n = " << n);
    CHECK(r.complete);
    CHECK(r.tally.status["error"] == 0);
    CHECK(r.tally.verdicts["rigid"] == laman);
    // Each line says what the analysis says of that graph alone.
    long long inf_rigid = 0;
    for (const Json& j : untimed(dir / ("out" + std::to_string(n) + ".jsonl")))
      if (j.contains("inf_rigid") && j["inf_rigid"].get<bool>()) ++inf_rigid;
    CHECK(inf_rigid == laman);
  }
}

TEST_CASE("sweep: the same lines whatever the threads, slices and interruptions") {
  const fs::path dir = scratch("determinism");
  const fs::path g = dir / "g7.g6";
  writeFile(g, geng(7, 11));
  sweep::Options o;
  o.realizations = 2;
  o.seed = 11;
  o.threads = 1;
  runSweep(g.string(), o, dir / "one.jsonl");
  o.threads = 2;
  runSweep(g.string(), o, dir / "two.jsonl");
  const auto one = untimed(dir / "one.jsonl");
  REQUIRE(one.size() == 2 * 138 + 1);
  CHECK(one == untimed(dir / "two.jsonl"));
  // Realization seeds depend on the sweep's seed and the item, nothing else.
  CHECK(one[0]["realization_seed"] == sweep::itemSeed(11, 0, 0));
  CHECK(one[3]["realization_seed"] == sweep::itemSeed(11, 1, 1));
  CHECK(one[3]["realization"] == 1);
  CHECK(one[3]["input"] == g.string() + ":2");

  SECTION("slices merged are the single run") {
    std::vector<std::string> shards;
    for (int k = 0; k < 3; ++k) {
      sweep::Options s = o;
      s.slice = {k, 3};
      shards.push_back((dir / ("shard" + std::to_string(k) + ".jsonl")).string());
      runSweep(g.string(), s, shards.back());
      CHECK(summaryOf(shards.back())["sweep"]["slice"] == std::to_string(k) + "/3");
    }
    std::reverse(shards.begin(), shards.end());  // in any order
    sweep::merge(shards, (dir / "merged.jsonl").string());
    CHECK(untimed(dir / "merged.jsonl") == one);
    // Item lines are copied byte for byte.
    const std::string merged = readFile(dir / "merged.jsonl");
    const std::string shard0 = readFile(shards.back());
    CHECK(merged.find(shard0.substr(0, shard0.find('\n') + 1)) == 0);

    SECTION("an incomplete or foreign shard set is refused") {
      CHECK_THROWS_WITH(sweep::merge({shards[0], shards[1]}, (dir / "m2.jsonl").string()),
                        Catch::Contains("slice 0/3 is missing: the sweep has 3 slices, 2 shards are given"));
      CHECK_THROWS_WITH(sweep::merge({shards[0], shards[0], shards[2]}, (dir / "m3.jsonl").string()),
                        Catch::Contains("given twice"));
      const std::string text = readFile(shards[1]);
      writeFile(dir / "cut.jsonl", text.substr(0, text.rfind("{\"summary\"")));
      CHECK_THROWS_WITH(sweep::merge({shards[0], (dir / "cut.jsonl").string(), shards[2]}, (dir / "m4.jsonl").string()),
                        Catch::Contains("no summary"));
      CHECK_FALSE(fs::exists(dir / "m4.jsonl"));
      CHECK_THROWS_WITH(sweep::merge({shards[0], (dir / "one.jsonl").string()}, (dir / "m5.jsonl").string()),
                        Catch::Contains("another sweep"));
      CHECK_THROWS_WITH(sweep::merge({shards[0], shards[1], (dir / "one.jsonl").string()}, (dir / "m5.jsonl").string()),
                        Catch::Contains("one.jsonl") && Catch::Contains("(slice 0/1, where that one is of 3)"));
    }

    SECTION("a shard that lost lines, a field of the wrong type or a forged count is refused at its line") {
      // Issue 42: a shard that lost item lines but kept its summary was merged (432 of 853
      // items, exit 0); a field of the wrong type aborted (the JSON library's type_error); a
      // summary's slice "0/2000000000" allocated per slice.
      const std::string text = readFile(shards[1]);
      std::vector<std::string> lines;
      for (size_t at = 0; at < text.size();) {
        const size_t end = text.find('\n', at);
        lines.push_back(text.substr(at, end + 1 - at));
        at = end + 1;
      }
      REQUIRE(lines.size() >= 4);
      const auto refusedWith = [&](const std::string& bad, const std::string& what) {
        writeFile(dir / "bad.jsonl", bad);
        CHECK_THROWS_WITH(sweep::merge({shards[0], (dir / "bad.jsonl").string(), shards[2]}, (dir / "m6.jsonl").string()),
                          Catch::Contains("bad.jsonl") && Catch::Contains(what));
        CHECK_FALSE(fs::exists(dir / "m6.jsonl"));
      };
      std::string lost;  // the second item line gone, the summary kept
      for (size_t i = 0; i < lines.size(); ++i)
        if (i != 1) lost += lines[i];
      refusedWith(lost, "lines were lost");
      std::string wrong = text;
      wrong.replace(wrong.find("\"status\":\"ok\""), 13, "\"status\":5");
      refusedWith(wrong, ":1:1: \"status\" is not a string");
      std::string forged = text;
      forged.replace(forged.find("\"slice\":\"1/3\""), 13, "\"slice\":\"1/2000000000\"");
      refusedWith(forged, "(slice 1/2000000000, where that one is of 3)");
      writeFile(dir / "bad.jsonl", forged);  // first: its N is the sweep's, and nothing is allocated for it
      CHECK_THROWS_WITH(sweep::merge({(dir / "bad.jsonl").string(), shards[0], shards[2]}, (dir / "m6.jsonl").string()),
                        Catch::Contains("bad.jsonl:2:1: item 4 where slice 1/2000000000 has item 2000000001"));
      std::string sliced = text;
      sliced.replace(sliced.find("\"slice\":\"1/3\""), 13, "\"slice\":7");
      refusedWith(sliced, "\"summary.sweep.slice\" is not a string");
    }
  }

  SECTION("a run cut short continues where it stopped") {
    const std::string full = readFile(dir / "one.jsonl");
    // Killed in the middle of a line: the partial line is dropped and recomputed.
    writeFile(dir / "cut.jsonl", full.substr(0, full.size() / 2));
    sweep::RunResult r = runSweep(g.string(), o, dir / "cut.jsonl");
    CHECK(r.resumed > 100);
    CHECK(r.resumed + r.computed == 276);
    CHECK(untimed(dir / "cut.jsonl") == one);
    // Run again: nothing to do.
    sweep::RunResult again = runSweep(g.string(), o, dir / "cut.jsonl");
    CHECK(again.complete);
    CHECK(again.computed == 0);
    CHECK(again.tally.items == 276);
    // Another sweep into the same output is refused, and the file is left as it was.
    sweep::Options other = o;
    other.seed = 12;
    CHECK_THROWS_WITH(runSweep(g.string(), other, dir / "cut.jsonl"), Catch::Contains("another sweep"));
    writeFile(dir / "cut2.jsonl", full.substr(0, full.size() / 2));
    CHECK_THROWS_WITH(runSweep(g.string(), other, dir / "cut2.jsonl"), Catch::Contains("another sweep"));
    CHECK(readFile(dir / "cut2.jsonl") == full.substr(0, full.size() / 2));  // not even its partial line cut
    // More items than the family has: another sweep too.
    writeFile(dir / "g6.g6", geng(6, 9));
    writeFile(dir / "long.jsonl", full.substr(0, full.size() / 2));
    CHECK_THROWS_WITH(runSweep((dir / "g6.g6").string(), o, dir / "long.jsonl"), Catch::Contains("another sweep"));
    CHECK(untimed(dir / "cut.jsonl") == one);
  }

  SECTION("a stop request writes the finished items in order and no summary") {
    int polls = 0;
    auto family = sweep::openFamily(g.string(), o);
    sweep::RunResult r =
        sweep::run(*family, g.string(), o, (dir / "stopped.jsonl").string(), [&] { return ++polls > 1; });
    CHECK(r.interrupted);
    CHECK_FALSE(r.complete);
    const auto lines = untimed(dir / "stopped.jsonl");
    for (size_t i = 0; i < lines.size(); ++i) CHECK(lines[i] == one[i]);
    runSweep(g.string(), o, dir / "stopped.jsonl");
    CHECK(untimed(dir / "stopped.jsonl") == one);
  }
}

TEST_CASE("sweep: a bad item is reported on its line and the sweep goes on") {
  const fs::path dir = scratch("bad");
  writeFile(dir / "bad.g6", ">>graph6<<Bw\n\nG~~~~\n@\nBo\n");
  sweep::RunResult r = runSweep((dir / "bad.g6").string(), {}, dir / "out.jsonl");
  const auto lines = untimed(dir / "out.jsonl");
  REQUIRE(lines.size() == 5);
  CHECK(lines[0]["status"] == "ok");
  CHECK(lines[0]["rigid"] == "rigid");  // the triangle
  CHECK(lines[1]["status"] == "error");
  CHECK(lines[1]["input"] == (dir / "bad.g6").string() + ":3");
  CHECK(lines[1]["error"].get<std::string>().find("bad.g6:3:") != std::string::npos);
  CHECK(lines[2]["error"].get<std::string>().find("bad.g6:4:1: the graph has no edge") != std::string::npos);
  CHECK(lines[3]["status"] == "ok");
  CHECK(lines[3]["rigid"] == "flexible");  // a path of two edges
  CHECK(lines[4]["summary"]["status"]["error"] == 2);
  CHECK(r.tally.items == 4);
}

TEST_CASE("sweep: --where keeps the interesting items and counts the others") {
  const fs::path dir = scratch("where");
  writeFile(dir / "g6.g6", geng(6, 9));
  sweep::Options o;
  o.where = "rigid == 'flexible' and stress_dim > 0";
  runSweep((dir / "g6.g6").string(), o, dir / "out.jsonl");
  runSweep((dir / "g6.g6").string(), {}, dir / "all.jsonl");
  const auto kept = untimed(dir / "out.jsonl"), all = untimed(dir / "all.jsonl");
  REQUIRE(kept.size() == all.size());
  int n = 0;
  for (size_t i = 0; i + 1 < all.size(); ++i) {
    const bool match = all[i]["rigid"] == "flexible" && all[i]["stress_dim"].get<int>() > 0;
    n += match;
    if (match) CHECK(kept[i] == all[i]);
    else CHECK((kept[i]["status"] == "filtered" && kept[i]["rigid"] == all[i]["rigid"] && !kept[i].contains("reason")));
  }
  CHECK(n > 0);
  CHECK(kept.back()["summary"]["kept"] == n);
  CHECK(kept.back()["summary"]["verdicts"] == all.back()["summary"]["verdicts"]);
  o.where = "rigd == 'flexible'";
  CHECK_THROWS_WITH(runSweep((dir / "g6.g6").string(), o, dir / "x.jsonl"), Catch::Contains("did you mean 'rigid'"));
}

TEST_CASE("sweep: --certify proves verdicts, and --where certified keeps the proved ones") {
  // Generic realizations of the connected graphs on 6 vertices with 8 and 9 edges (unpinned, 12
  // variables, 3 trivial flexes). A verdict is provable in floating point exactly when the
  // rigidity matrix has full row rank (no stress): then either 9 independent rows (rigid) or 8
  // (flexible at a regular point). A stressed one is rank deficient, which intervals cannot
  // prove.
  const fs::path dir = scratch("certify");
  writeFile(dir / "g.g6", geng(6, 8) + geng(6, 9));
  sweep::Options o;
  o.overrides = {"analysis.certify=true"};
  const sweep::RunResult all = runSweep((dir / "g.g6").string(), o, dir / "all.jsonl");
  o.where = "certified";
  runSweep((dir / "g.g6").string(), o, dir / "kept.jsonl");
  const auto lines = untimed(dir / "all.jsonl"), kept = untimed(dir / "kept.jsonl");
  REQUIRE(lines.size() == kept.size());
  long long proved = 0, rigid = 0, flexible = 0;
  for (size_t i = 0; i + 1 < lines.size(); ++i) {
    const Json& j = lines[i];
    INFO("line " << i << ": " << j["input"]);
    REQUIRE(j.contains("certificate"));
    const bool stressed = j["stress_dim"].get<int>() > 0;
    CHECK(j["certified"].get<bool>() == !stressed);
    if (!stressed) {
      ++proved;
      if (j["rigid"] == "rigid") {
        ++rigid;
        CHECK(j["certificate"]["inf_rigid"] == true);
      } else {
        ++flexible;
        CHECK(j["certificate"]["flexible"] == true);
      }
    }
    CHECK(kept[i]["status"] == (j["certified"].get<bool>() ? "ok" : "filtered"));
    CHECK(kept[i]["certified"] == j["certified"]);
  }
  CHECK(rigid == 13);  // the Laman graphs on 6 vertices (OEIS A227117)
  CHECK(flexible > 0);
  CHECK(all.tally.certified == proved);
  CHECK(lines.back()["summary"]["certified"] == proved);
  CHECK(kept.back()["summary"]["kept"] == proved);
  CHECK(kept.back()["summary"]["certified"] == proved);
}

TEST_CASE("sweep: track --certify certifies each path of a family") {
  // The crank-rocker four-bar with the coupler's far end moved along the rocker's circle: every
  // path is a smooth closed curve away from singular points, certified whole.
  const fs::path dir = scratch("certify_track");
  writeFile(dir / "fourbar.toml", R"X(title = "four-bar"
[system]
type = "framework"
vertices = [[0,0],[4,0],[0,1],[4,3]]
edges = [[1,3],[3,4],[2,4]]
pinned = [1,2]
[motion]
steps = 20
step_size = 0.05
[sweep]
"system.vertices[3][1]" = "linspace(2.5, 3.5, 3)"
)X");
  sweep::Options o;
  o.job = sweep::Job::Track;
  o.overrides = {"motion.certify=true"};
  o.where = "certified";
  const sweep::RunResult r = runSweep((dir / "fourbar.toml").string(), o, dir / "out.jsonl");
  const auto lines = untimed(dir / "out.jsonl");
  REQUIRE(lines.size() == 4);
  for (int i = 0; i < 3; ++i) {
    INFO(lines[i].dump());
    CHECK(lines[i]["status"] == "ok");
    CHECK(lines[i]["certified"] == true);
    CHECK(lines[i]["certificate"]["steps"].size() == 20);
  }
  CHECK(r.tally.certified == 3);
}

TEST_CASE("sweep: certificates read back from a file are not counted as certified") {
  // Issue 62: an item line edited to say "certified": true was counted as certified by the
  // rerun that resumed the output and by the merge of the shards. A certificate is not checked
  // when a line is read back: only the lines a run computes count, the others apart.
  const fs::path dir = scratch("forged_certificates");
  writeFile(dir / "g.g6", geng(6, 8));
  sweep::Options o;
  o.overrides = {"analysis.certify=true"};
  const sweep::RunResult all = runSweep((dir / "g.g6").string(), o, dir / "all.jsonl");
  REQUIRE(all.tally.with_certificate == all.tally.items);
  CHECK(all.tally.certified_unverified == 0);
  CHECK(summaryOf(dir / "all.jsonl")["certified"] == all.tally.certified);
  CHECK(summaryOf(dir / "all.jsonl")["certified_unverified"] == 0);
  std::vector<std::string> lines;
  {
    std::istringstream in(readFile(dir / "all.jsonl"));
    for (std::string line; std::getline(in, line);) lines.push_back(line + "\n");
  }
  lines.pop_back();  // the summary
  const auto forge = [](std::string line) {
    for (size_t at; (at = line.find("\"certified\":false")) != std::string::npos;) line.replace(at, 17, "\"certified\":true");
    return line;
  };
  const auto proved = [](const std::string& line) { return Json::parse(line)["certified"].get<bool>(); };
  long long not_proved = 0;
  for (const std::string& l : lines) not_proved += !proved(l);
  REQUIRE(not_proved > 0);  // stressed realizations: not provable in floating point
  REQUIRE(all.tally.certified > 0);

  SECTION("a rerun counts only what it computed") {
    // The first half, every line forged to say "certified": true, as a run cut short.
    const size_t half = lines.size() / 2;
    std::string cut;
    long long computed_proved = 0;
    for (size_t i = 0; i < lines.size(); ++i) {
      if (i < half) cut += forge(lines[i]);
      else computed_proved += proved(lines[i]);
    }
    writeFile(dir / "cut.jsonl", cut);
    const sweep::RunResult r = runSweep((dir / "g.g6").string(), o, dir / "cut.jsonl");
    CHECK(r.resumed == static_cast<long long>(half));
    CHECK(r.tally.certified == computed_proved);
    CHECK(r.tally.certified_unverified == static_cast<long long>(half));
    CHECK(summaryOf(dir / "cut.jsonl")["certified"] == computed_proved);
    CHECK(summaryOf(dir / "cut.jsonl")["certified_unverified"] == half);
    // Run again: the whole output read back, nothing counted as certified.
    const sweep::RunResult again = runSweep((dir / "g.g6").string(), o, dir / "cut.jsonl");
    CHECK(again.computed == 0);
    CHECK(again.tally.certified == 0);
    CHECK(again.tally.certified_unverified == static_cast<long long>(half) + computed_proved);
  }

  SECTION("a merge counts the shards' certificates as unverified claims") {
    std::vector<std::string> shards;
    for (int k = 0; k < 2; ++k) {
      sweep::Options s = o;
      s.slice = {k, 2};
      shards.push_back((dir / ("shard" + std::to_string(k) + ".jsonl")).string());
      runSweep((dir / "g.g6").string(), s, shards.back());
    }
    sweep::Tally t = sweep::merge(shards, (dir / "merged.jsonl").string());
    CHECK(t.certified == 0);
    CHECK(t.certified_unverified == all.tally.certified);
    CHECK(summaryOf(dir / "merged.jsonl")["certified"] == 0);
    CHECK(summaryOf(dir / "merged.jsonl")["certified_unverified"] == all.tally.certified);
    // Every line of shard 0 forged: the merge still counts nothing as certified.
    std::string text = readFile(shards[0]);
    const size_t summary = text.rfind("{\"summary\"");
    writeFile(shards[0], forge(text.substr(0, summary)) + text.substr(summary));
    long long claims = 0;
    for (size_t i = 0; i < lines.size(); ++i) claims += i % 2 == 0 || proved(lines[i]);
    t = sweep::merge(shards, (dir / "merged2.jsonl").string());
    CHECK(t.certified == 0);
    CHECK(t.certified_unverified == claims);
    CHECK(claims > all.tally.certified);
  }
}

TEST_CASE("sweep: a [sweep] table varies keys over ranges and lists") {
  // The 3-prism (two triangles joined by three bars) is flexible where the bars are parallel
  // and of equal length, and infinitesimally rigid once one end of a bar moves off that.
  const fs::path dir = scratch("params");
  writeFile(dir / "prism.toml", R"X(title = "3-prism"
[system]
type = "framework"
vertices = [[0,0],[0,1],["sqrt(3)/2",0.5],[1.05,0],[1.05,1],["1.05+sqrt(3)/2",0.5]]
edges = [[1,2],[1,3],[2,3],[4,5],[5,6],[4,6],[1,4],[2,5],[3,6]]
pinned = [1,4]

[sweep]
"system.vertices[5][1]" = "linspace(0.25, 0.75, 3)"
analysis.seed = [3, 4]
)X");
  sweep::RunResult r = runSweep((dir / "prism.toml").string(), {}, dir / "out.jsonl");
  const auto lines = untimed(dir / "out.jsonl");
  REQUIRE(lines.size() == 7);
  // The first key varies slowest.
  CHECK(lines[0]["parameters"] == Json::parse(R"({"system.vertices[5][1]": 0.25, "analysis.seed": 3})"));
  CHECK(lines[1]["parameters"] == Json::parse(R"({"system.vertices[5][1]": 0.25, "analysis.seed": 4})"));
  CHECK(lines[2]["parameters"]["system.vertices[5][1]"] == 0.5);
  CHECK(lines[1]["second_order"]["seed"] == 4);
  for (int i = 0; i < 6; ++i) CHECK(lines[i]["rigid"] == (i / 2 == 1 ? "flexible" : "rigid"));
  CHECK(r.tally.verdicts["flexible"] == 2);
  // `flexure analyze` reads the same scene as its start (it ignores [sweep]).
  CHECK(flexure::scenes::loadScene((dir / "prism.toml").string()).title == "3-prism");

  SECTION("ranges of integers, logspace, and keys that name nothing") {
    writeFile(dir / "k.toml", R"X([system]
type = "catalog"
name = "square"
[sweep]
motion.seed = 3..5                              # the shorthand: unquoted
analysis.rank_tolerance = logspace(-10, -8, 2)
)X");
    sweep::RunResult k = runSweep((dir / "k.toml").string(), {}, dir / "k.jsonl");
    CHECK(k.tally.items == 6);
    const auto kl = untimed(dir / "k.jsonl");
    CHECK(kl[5]["parameters"] == Json::parse(R"({"motion.seed": 5, "analysis.rank_tolerance": 1e-8})"));
    CHECK(kl[5]["numerics"]["rank_tolerance"] == 1e-8);
    auto bad = [&](const std::string& key_line, const std::string& message) {
      writeFile(dir / "b.toml", "[system]\ntype = \"catalog\"\nname = \"square\"\n[sweep]\n" + key_line + "\n");
      CHECK_THROWS_WITH(sweep::openFamily((dir / "b.toml").string(), {}), Catch::Contains(message));
      try {
        sweep::openFamily((dir / "b.toml").string(), {});
      } catch (const flexure::scenes::SceneError& e) {
        CHECK(e.line == 5);
      }
    };
    bad("\"motion.sed\" = [1, 2]", "[motion] has no key 'sed'");
    bad("\"system.vertices[9][0]\" = [1]", "the scene has no 'vertices'");
    bad("\"motion.seed\" = \"5..3\"", "from a smaller to a larger");
    bad("\"motion.seed\" = []", "at least one value");
    bad("\"motion.step_size\" = \"linspace(0, 1)\"", "(start, stop, count)");
    bad("\"system.vertices[x]\" = [1]", "an array position is a number");
  }
}

TEST_CASE("sweep: lists and directories of scene files") {
  const fs::path dir = scratch("lists");
  fs::create_directories(dir / "scenes" / "more");
  for (const char* name : {"triangle", "square", "k24"})
    fs::copy_file(std::string(FLEXURE_EXAMPLES_DIR) + "/" + name + ".toml", dir / "scenes" / "more" / (std::string(name) + ".toml"));
  writeFile(dir / "scenes" / "broken.toml", "[system]\ntype = \"framework\"\nvertices = [[0, 0]]\n");
  sweep::RunResult r = runSweep((dir / "scenes").string(), {}, dir / "d.jsonl");
  const auto lines = untimed(dir / "d.jsonl");
  REQUIRE(lines.size() == 5);
  CHECK(lines[0]["input"] == (dir / "scenes" / "broken.toml").string());  // in name order
  CHECK(lines[0]["status"] == "error");
  CHECK(lines[0]["error"].get<std::string>().find("broken.toml:") != std::string::npos);
  CHECK(lines[1]["title"] == flexure::scenes::loadScene(std::string(FLEXURE_EXAMPLES_DIR) + "/k24.toml").title);
  CHECK(r.tally.status["ok"] == 3);
  // A list: files relative to it, catalog names, comments.
  writeFile(dir / "list.txt", "# the study\nscenes/more/square.toml\n\ndouble_watt\n  scenes/missing.toml  \n");
  runSweep((dir / "list.txt").string(), {}, dir / "l.jsonl");
  const auto l = untimed(dir / "l.jsonl");
  REQUIRE(l.size() == 4);
  CHECK(l[0]["rigid"] == "flexible");
  CHECK(l[1]["input"] == "double_watt");
  CHECK(l[1]["nontrivial_inf_flexes"] == 2);
  CHECK(l[2]["status"] == "error");
  CHECK(l[2]["error"].get<std::string>().find("cannot open") != std::string::npos);
  writeFile(dir / "empty.txt", "# nothing\n");
  CHECK_THROWS_WITH(sweep::openFamily((dir / "empty.txt").string(), {}), Catch::Contains("names no scene file"));
}

TEST_CASE("sweep: track lines carry the path summary, events and, asked for, the samples") {
  const fs::path dir = scratch("track");
  writeFile(dir / "list.txt", "square\ntriangle\n");
  sweep::Options o;
  o.job = sweep::Job::Track;
  o.samples = true;
  o.overrides = {"motion.steps=5"};
  runSweep((dir / "list.txt").string(), o, dir / "t.jsonl");
  const auto lines = untimed(dir / "t.jsonl");
  REQUIRE(lines.size() == 3);
  CHECK(lines[0]["status"] == "ok");
  CHECK(lines[0]["path_status"] == "success");
  CHECK(lines[0]["steps_done"] == 5);
  CHECK(lines[0]["samples"].size() == 6);
  CHECK(lines[0]["max_residual"].get<double>() < 1e-9);
  CHECK(lines[1]["path_status"] == "stopped_early");
  CHECK(lines[2]["summary"]["verdicts"] == Json::parse(R"({"stopped_early": 1, "success": 1})"));
}

TEST_CASE("sweep: the Slurm scripts run the slices and merge them after the array") {
  sweep::SlurmPlan p;
  p.flexure = "/opt/flexure/bin/flexure";
  p.workdir = "/home/u/study";
  p.output = "laman 9.jsonl";
  p.shard_dir = "laman 9.jsonl.shards";
  p.sweep_args = {"analyze", "-", "--where", "rigid == 'flexible'"};
  p.stdin_file = "laman 9.jsonl.shards/input.g6";
  p.tasks = 8;
  p.max_running = 3;
  p.cpus_per_task = 2;
  p.partition = "short";
  p.time_limit = "1:00:00";
  const std::string a = p.arrayScript(), m = p.mergeScript();
  CHECK(a.find("#SBATCH --array=0-7%3\n") != std::string::npos);
  CHECK(a.find("#SBATCH --cpus-per-task=2\n") != std::string::npos);
  CHECK(a.find("#SBATCH --partition=short\n") != std::string::npos);
  CHECK(a.find("#SBATCH --time=1:00:00\n") != std::string::npos);
  CHECK(a.find("#SBATCH --requeue\n#SBATCH --signal=B:TERM@60\n") != std::string::npos);
  CHECK(a.find("/opt/flexure/bin/flexure sweep analyze - --where 'rigid == '\\''flexible'\\''' --quiet "
               "--threads \"${SLURM_CPUS_PER_TASK:-1}\" --slice \"${SLURM_ARRAY_TASK_ID}/8\" -o \"$shard\" "
               "< 'laman 9.jsonl.shards/input.g6' &\n") != std::string::npos);
  CHECK(a.find("shard='laman 9.jsonl.shards'/shard-\"${SLURM_ARRAY_TASK_ID}\"-of-8.jsonl\n") != std::string::npos);
  CHECK(a.find("scontrol requeue \"${SLURM_ARRAY_JOB_ID}_${SLURM_ARRAY_TASK_ID}\"") != std::string::npos);
  // The merge names the shard directory, not each shard (50,000 shards exceeded ARG_MAX).
  CHECK(m.find("exec /opt/flexure/bin/flexure sweep merge 'laman 9.jsonl.shards' --tasks 8 -o 'laman 9.jsonl'\n") !=
        std::string::npos);
  // Paths reach sbatch as its own arguments, with Slurm's % escaped.
  p.shard_dir = "run%3.shards";
  const auto args = p.arraySubmission();
  CHECK(args == std::vector<std::string>{"--parsable", "--chdir=/home/u/study",
                                         "--output=/home/u/study/run%%3.shards/slurm-%A_%a.log", "run%3.shards/array.sbatch"});
  p.workdir = "/home/u/%x";  // the logs' path is absolute, every % escaped; --chdir is literal
  CHECK(p.arraySubmission()[1] == "--chdir=/home/u/%x");
  CHECK(p.arraySubmission()[2] == "--output=/home/u/%%x/run%%3.shards/slurm-%A_%a.log");
  CHECK_NOTHROW(p.check());
}

TEST_CASE("sweep: values that would break out of a Slurm script are refused by one check") {
  // Issue 42: a newline in --partition, --account, --time, the working directory or the output
  // name ran a command when the script ran; a blank smuggled in sbatch options.
  const auto plan = [] {
    sweep::SlurmPlan p;
    p.flexure = "/opt/flexure";
    p.workdir = "/home/u/My Projects";
    p.output = "Bob's run#3 %1.jsonl";
    p.shard_dir = p.output + ".shards";
    p.sweep_args = {"analyze", "in.g6"};
    return p;
  };
  CHECK_NOTHROW(plan().check());
  const std::vector<std::pair<std::function<void(sweep::SlurmPlan&)>, std::string>> bad = {
      {[](sweep::SlurmPlan& p) { p.partition = "short\ntouch /tmp/pwned"; }, "control character"},
      {[](sweep::SlurmPlan& p) { p.account = "a b"; }, "--account 'a b' is not a Slurm name"},
      {[](sweep::SlurmPlan& p) { p.partition = "x'y"; }, "is not a Slurm name"},
      {[](sweep::SlurmPlan& p) { p.time_limit = "1:00:00 --export=ALL,LD_PRELOAD=/tmp/x.so"; }, "not a Slurm time limit"},
      {[](sweep::SlurmPlan& p) { p.time_limit = "1:00:00\r"; }, "control character"},
      {[](sweep::SlurmPlan& p) { p.workdir = "/home/u/a\nb"; }, "the working directory '/home/u/a\\x0Ab'"},
      {[](sweep::SlurmPlan& p) { p.output = "r\x1b[2J.jsonl"; }, "the output"},
      {[](sweep::SlurmPlan& p) { p.sweep_args.push_back("x\ny"); }, "the argument"},
      {[](sweep::SlurmPlan& p) { p.workdir = "/home/u/back\\slash"; }, "holds a backslash"},
  };
  for (const auto& [edit, what] : bad) {
    sweep::SlurmPlan p = plan();
    edit(p);
    CHECK_THROWS_WITH(p.check(), Catch::Contains(what));
  }
  for (const char* ok : {"10", "10:00", "1:00:00", "2-12", "2-12:30", "2-12:30:00", "UNLIMITED"}) {
    sweep::SlurmPlan p = plan();
    p.time_limit = ok;
    CHECK_NOTHROW(p.check());
  }
  for (const char* bad_time : {"1:", ":1", "1::2", "1:2:3:4", "-1", "1-", "1-2-3", "a", "1 ", "1-2:3:4:5"}) {
    sweep::SlurmPlan q = plan();
    q.time_limit = bad_time;
    INFO("'" << bad_time << "'");
    CHECK_THROWS_WITH(q.check(), Catch::Contains("not a Slurm time limit"));
  }
  for (const char* bad_name : {",a", "a,", "a,,b", "a b", "a/b"}) {
    sweep::SlurmPlan q = plan();
    q.partition = bad_name;
    CHECK_THROWS_WITH(q.check(), Catch::Contains("is not a Slurm name"));
  }
  // Long values are scanned, not matched by a recursive regex (which overflowed the stack on
  // a 20 KB partition name: the slurm fuzz target).
  sweep::SlurmPlan q = plan();
  q.partition = std::string(200000, 'Q');
  q.account = std::string(100000, 'a') + "," + std::string(100000, 'b');
  q.time_limit = std::string(100000, '1') + "-" + std::string(100000, '2') + ":00";
  CHECK_NOTHROW(q.check());
  q.partition += "'";
  CHECK_THROWS_WITH(q.check(), Catch::Contains("is not a Slurm name"));
  sweep::SlurmPlan p = plan();
  p.partition = "short,long";
  p.account = "proj_1.x-2";
  CHECK_NOTHROW(p.check());
}

TEST_CASE("sweep: words are quoted for a POSIX shell") {
  CHECK(sweep::shellQuote("it's") == "'it'\\''s'");
  CHECK(sweep::shellQuote("plain/path-1.g6") == "plain/path-1.g6");
}

TEST_CASE("sweep: the motion check sees a mechanism that moves in a small loop (found by the Laman study)") {
  // G?bNdw (8 vertices, 13 edges) at this realization moves along a small closed loop: the
  // distances change by 2.5e-2 (relative) within the check's 8 steps and by 4.6e-4 at its end.
  // Comparing only the end with the start left it "unknown".
  const auto g = flexure::scenes::readGraph6("G?bNdw\n", "g.g6");
  const flexure::scenes::Scene s = flexure::scenes::loadGraphScene(g[0], 2, 1206806062115306247ull, "g.g6", "g");
  const auto rep = flexure::pipeline::analyze(s);
  CHECK_FALSE(rep.inf_rigid);
  CHECK(rep.rigid == flexure::engine::Verdict::Flexible);
  CHECK(rep.motion_check_change > 1e-2);
}

TEST_CASE("sweep: a graph's scene made without a document is the scene its document loads") {
  // loadGraphScene builds the framework directly (no TOML document) when nothing can differ;
  // the document it writes on demand must load to the same system, and a sparse6 multigraph
  // still gets the document path's message.
  const auto graphs = flexure::scenes::readGraph6("G?bNdw\nH?AFB`Y\nG{O`?_\n", "g.g6");
  for (int dimension : {2, 3})
    for (const auto& g : graphs) {
      const flexure::scenes::Scene s = flexure::scenes::loadGraphScene(g, dimension, 77, "g.g6:1", "title");
      const flexure::scenes::Scene t = flexure::scenes::loadSceneFromString(s.document(), "g.g6:1");
      CHECK(s.type == t.type);
      CHECK(s.title == t.title);
      CHECK(s.index_base == t.index_base);
      const auto& a = s.model->system();
      const auto& b = t.model->system();
      REQUIRE(a.numVariables() == b.numVariables());
      REQUIRE(a.numEquations() == b.numEquations());
      const flexure::engine::Vector x = s.model->startCoordinates(), y = t.model->startCoordinates();
      CHECK(x == y);
      CHECK(flexure::engine::Matrix(a.jacobian(x)) == flexure::engine::Matrix(b.jacobian(y)));
      const auto ra = flexure::pipeline::analyze(s), rb = flexure::pipeline::analyze(t);
      CHECK(ra.rank == rb.rank);
      CHECK(ra.nontrivial == rb.nontrivial);
      CHECK(ra.rigid == rb.rigid);
    }
  flexure::scenes::ImportedGraph loop;
  loop.vertices = 3;
  loop.edges = {{0, 1}, {1, 1}};
  CHECK_THROWS_WITH(flexure::scenes::loadGraphScene(loop, 2, 1, "m.s6", "m"), Catch::Contains("itself"));
}
