// flexure sweep on the command line: geng's output on a pipe, usage errors, Ctrl-C and a rerun,
// and --slurm --dry-run.
#include "cli_common.h"

#include <algorithm>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

using namespace flexure_cli_test;

namespace {
// A sweep line without its "flexure" object: which command wrote the line (a shard's, a
// resumed run's) differs between runs that compute the same items.
std::string withoutProvenance(const std::string& line) {
  const size_t at = line.find(",\"flexure\":{");
  return at == std::string::npos ? line : line.substr(0, at) + line.substr(line.find('}', at) + 1);
}

std::string geng() { return fs::exists("/usr/bin/nauty-geng") ? "/usr/bin/nauty-geng" : "geng"; }

int countLines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

}  // namespace

TEST_CASE("cli: sweep analyze reads geng's output on a pipe and reports the counts", "[cli]") {
  const fs::path d = scratchDir("sweep_pipe");
  const std::string out = shellOutput(geng() + " -c -q 6 9:9 | " + FLEXURE_BINARY + " sweep analyze - --quiet 2>" +
                                      (d / "err.txt").string());
  CHECK(countLines(out) == 21);
  CHECK_THAT(out, Catch::Contains("{\"id\":0,\"input\":\"stdin:1\",\"graph6\":\"E?~w\""));
  CHECK_THAT(out, Catch::Contains("\"verdicts\":{\"flexible\":7,\"rigid\":13}"));
  CHECK_THAT(readFile(d / "err.txt"), Catch::StartsWith("sweep: 20 items (7 flexible, 13 rigid); 0 errors in "));
  fs::remove_all(d);
}

TEST_CASE("cli: sweep --fields keeps those fields and the counts alone equal the full report's", "[cli]") {
  // Every connected graph on 7 vertices with 11 edges (rigid, flexible with stresses, ...): the
  // counts of the full report and of the counts alone, item by item; a --where on counts too.
  const fs::path d = scratchDir("sweep_fields");
  const std::string g6 = (d / "g.g6").string();
  REQUIRE(std::system((geng() + " -c -q 7 11:11 > " + g6).c_str()) == 0);
  const std::string full = shellOutput(std::string(FLEXURE_BINARY) + " sweep analyze " + g6 + " --quiet");
  const std::string counts = shellOutput(std::string(FLEXURE_BINARY) + " sweep analyze " + g6 +
                                         " --quiet --fields 'rigidity_rank, nontrivial_inf_flexes,stress_dim,inf_rigid'");
  const std::string where = shellOutput(std::string(FLEXURE_BINARY) + " sweep analyze " + g6 +
                                        " --quiet --fields stress_dim --where 'nontrivial_inf_flexes > 0'");
  std::istringstream a(full), b(counts), c(where);
  std::string la, lb, lc;
  int items = 0, flexible = 0;
  while (std::getline(a, la) && std::getline(b, lb) && std::getline(c, lc)) {
    const auto ja = nlohmann::json::parse(la), jb = nlohmann::json::parse(lb), jc = nlohmann::json::parse(lc);
    if (ja.contains("summary")) {
      CHECK(jb["summary"]["sweep"]["fields"] == nlohmann::json({"rigidity_rank", "nontrivial_inf_flexes", "stress_dim", "inf_rigid"}));
      CHECK(jc["summary"]["kept"] == flexible);
      break;
    }
    ++items;
    INFO(la);
    for (const char* k : {"id", "graph6", "realization_seed", "status", "rigidity_rank", "nontrivial_inf_flexes", "stress_dim", "inf_rigid"})
      CHECK(ja[k] == jb[k]);
    CHECK_FALSE(jb.contains("rigid"));  // what was not asked for is not there
    CHECK_FALSE(jb.contains("second_order"));
    const bool flex = ja["nontrivial_inf_flexes"] > 0;
    flexible += flex;
    CHECK(jc["status"] == (flex ? "ok" : "filtered"));
    if (flex) CHECK(jc["stress_dim"] == ja["stress_dim"]);
    if (flex) CHECK_FALSE(jc.contains("nontrivial_inf_flexes"));
  }
  CHECK(items > 100);
  CHECK(flexible > 10);
  CHECK(flexible < items);
  // Unknown names, with the nearest.
  const Result r = run("sweep analyze " + g6 + " --fields rigidity_rnk");
  CHECK(r.status == 1);
  CHECK_THAT(r.err, Catch::Contains("--fields: unknown field 'rigidity_rnk' (did you mean 'rigidity_rank'?)"));
  fs::remove_all(d);
}

TEST_CASE("cli: sweep usage errors exit 1 and name the option", "[cli]") {
  const std::string scene = example("triangle");
  const std::pair<std::string, std::string> cases[] = {
      {"sweep", "sweep needs a job"},
      {"sweep frobnicate " + scene, "sweep runs analyze or track"},
      {"sweep analyze", "takes one INPUT"},
      {"sweep analyze " + scene + " --dimension 3", "are for graph6/sparse6 input"},
      {"sweep analyze - --dimension 4", "--dimension needs 2 or 3"},
      {"sweep analyze - --slice 3/3", "--slice needs k/N with 0 <= k < N"},
      {"sweep analyze - --slice 1", "--slice needs k/N"},
      {"sweep analyze - --threads 0", "--threads needs a number of threads"},
      {"sweep analyze - --tasks 4", "go with --slurm"},
      {"sweep analyze - --samples", "--samples is for sweep track"},
      {"sweep analyze - --slurm", "--slurm needs -o"},
      {"sweep merge a.jsonl", "needs -o"},
      {"sweep analyze " + scene + " -o " + scene, "would replace an input"},
  };
  for (const auto& [args, message] : cases) {
    INFO(args);
    const Result r = run(args + " </dev/null");
    CHECK(r.status == 1);
    CHECK_THAT(r.err, Catch::Contains(message));
  }
  const Result w = run("sweep analyze " + scene + " --where \"stress_dim > 0 and rigd == 'x'\"");
  CHECK(w.status == 1);
  CHECK_THAT(w.err, Catch::Contains("unknown field 'rigd' (did you mean 'rigid'?)\n  stress_dim > 0 and rigd == 'x'\n"
                                    "                     ^"));
  // A family that cannot be read at all: the file, line and column.
  const fs::path d = scratchDir("sweep_bad");
  std::ofstream(d / "s.toml") << "[system]\ntype = \"catalog\"\nname = \"square\"\n[sweep]\n\"motion.seed\" = \"9..1\"\n";
  const Result b = run("sweep analyze " + (d / "s.toml").string());
  CHECK(b.status == 1);
  CHECK_THAT(b.err, Catch::Contains("s.toml:5:17: '9..1': the range runs from a smaller to a larger integer"));
  fs::remove_all(d);
}

TEST_CASE("cli: Ctrl-C stops a sweep with exit 130, keeps its lines, and a rerun finishes it", "[cli][slow]") {
  const fs::path d = scratchDir("sweep_int");
  shellOutput(geng() + " -c -q 9 15:15 > " + (d / "g9.g6").string());
  const std::string cmd = std::string(FLEXURE_BINARY) + " sweep analyze " + (d / "g9.g6").string() + " -o " +
                          (d / "out.jsonl").string() + " >/dev/null 2>" + (d / "err.txt").string() +
                          " & pid=$!; sleep 1; kill -INT $pid; wait $pid; echo $?";
  CHECK(shellOutput(cmd) == "130\n");
  CHECK_THAT(readFile(d / "err.txt"), Catch::Contains("rerun the same command to continue"));
  const std::string part = readFile(d / "out.jsonl");
  CHECK(countLines(part) > 0);
  CHECK(part.back() == '\n');
  CHECK(part.find("\"summary\"") == std::string::npos);
  const Result again = run("sweep analyze " + (d / "g9.g6").string() + " -o " + (d / "out.jsonl").string());
  CHECK(again.status == 0);
  CHECK_THAT(again.out, Catch::Contains("20303 items (13081 flexible, 7222 rigid"));
  CHECK_THAT(again.out, Catch::Contains(" were done before"));
  CHECK(countLines(readFile(d / "out.jsonl")) == 20304);
  fs::remove_all(d);
}

TEST_CASE("cli: sweep --slurm --dry-run prints the array and merge scripts and writes nothing", "[cli]") {
  const fs::path d = scratchDir("sweep_dry");
  const Result r = run("sweep track " + example("square") + " --slurm --dry-run --tasks 5 --max-running 2 --time 10:00 "
                       "--partition short -o " + (d / "res.jsonl").string());
  CHECK(r.status == 0);
  CHECK_THAT(r.out, Catch::Contains("#SBATCH --array=0-4%2\n"));
  CHECK_THAT(r.out, Catch::Contains("#SBATCH --partition=short\n"));
  CHECK_THAT(r.out, Catch::Contains(" sweep track " + example("square") + " --quiet --threads"));
  CHECK_THAT(r.out, Catch::Contains("sweep merge " + (d / "res.jsonl.shards").string() + " --tasks 5 -o"));
  CHECK_THAT(r.out, Catch::Contains("--dependency=afterok:ARRAY_JOB"));
  CHECK_THAT(r.out, Catch::Contains("#SBATCH --signal=B:TERM@60"));
  CHECK(fs::is_empty(d));
  fs::remove_all(d);
}

TEST_CASE("cli: --slurm scripts run from awkward directories and requeue on SIGTERM and the merge joins the shard directory",
          "[cli][slow]") {
  // Issue 42: names such as "My Projects", "Bob's runs", "run#3" and a % in the output broke the
  // scripts; --signal=TERM@60 without B: never reached flexure, so a task at its time limit was
  // neither stopped early nor requeued; the merge job's one command line listed every shard.
  const fs::path base = scratchDir("sweep_slurm_names");
  const fs::path d = base / "Bob's runs #3 %x";
  fs::create_directories(d / "bin");
  // sbatch and scontrol stand-ins: they record their arguments.
  const std::string log = (base / "calls.log").string();
  for (const char* tool : {"sbatch", "scontrol"}) {
    const fs::path f = d / "bin" / tool;
    std::ofstream(f) << "#!/bin/sh\nprintf '%s\\n' \"" << tool << " $*\" >> \"" << log << "\"\necho 77\n";
    fs::permissions(f, fs::perms::owner_all);
  }
  // Words quoted for the shell these commands run in (the names hold ', # and %).
  const auto q = [](const std::string& s) {
    std::string out = "'";
    for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
  };
  shellOutput(geng() + " -c -q 9 15:15 > " + q((d / "g9.g6").string()));
  const std::string in_dir = "cd " + q(d.string()) + " && PATH=" + q((d / "bin").string()) + ":\"$PATH\" ";
  CHECK(shellOutput(in_dir + FLEXURE_BINARY + " sweep analyze g9.g6 --slurm --tasks 2 -o 'res 50%.jsonl' >/dev/null; echo $?") ==
        "0\n");
  const std::string calls = readFile(log);
  CHECK_THAT(calls, Catch::Contains("--chdir=" + d.string()));
  CHECK_THAT(calls, Catch::Contains("--output=" + base.string() + "/Bob's runs #3 %%x/res 50%%.jsonl.shards/slurm-%A_%a.log"));
  CHECK_THAT(calls, Catch::Contains("--dependency=afterok:77"));
  // The array task, as Slurm runs it, stopped by the time limit's SIGTERM to the batch shell.
  const std::string task = in_dir + "SLURM_ARRAY_TASK_ID=0 SLURM_ARRAY_JOB_ID=77 bash 'res 50%.jsonl.shards/array.sbatch' "
                                    ">/dev/null 2>&1 & pid=$!; sleep 1; kill -TERM $pid; wait $pid; echo $?";
  CHECK(shellOutput(task) == "130\n");
  CHECK_THAT(readFile(log), Catch::Contains("scontrol requeue 77_0"));
  const std::string part = readFile(d / "res 50%.jsonl.shards" / "shard-0-of-2.jsonl");
  CHECK(countLines(part) > 0);
  CHECK(part.find("\"summary\"") == std::string::npos);
  // Requeued, both tasks finish; the merge job's command joins the directory.
  for (const char* k : {"0", "1"})
    CHECK(shellOutput(in_dir + "SLURM_ARRAY_TASK_ID=" + k + " SLURM_ARRAY_JOB_ID=77 bash 'res 50%.jsonl.shards/array.sbatch' "
                               ">/dev/null 2>&1; echo $?") == "0\n");
  CHECK(shellOutput(in_dir + "bash 'res 50%.jsonl.shards/merge.sbatch' >/dev/null 2>&1; echo $?") == "0\n");
  CHECK(shellOutput(in_dir + FLEXURE_BINARY + " sweep analyze g9.g6 --quiet -o " + q((base / "local.jsonl").string()) +
                    " >/dev/null; echo $?") == "0\n");
  const auto items = [](const std::string& text) {
    std::string out;  // the item lines without their timing
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);)
      if (line.rfind("{\"summary\"", 0) != 0) out += withoutProvenance(line.substr(0, line.find(",\"time_ms\""))) + "\n";
    return out;
  };
  CHECK(items(readFile(d / "res 50%.jsonl")) == items(readFile(base / "local.jsonl")));
  // A name with a newline (here: the working directory) is refused before anything is written.
  const fs::path nl = base / "a\nb";
  fs::create_directories(nl);
  CHECK(shellOutput("cd " + q(nl.string()) + " && " + FLEXURE_BINARY + " sweep analyze " + q((d / "g9.g6").string()) +
                    " --slurm -o r.jsonl 2>&1; echo $?")
            .find("holds a control character") != std::string::npos);
  CHECK_FALSE(fs::exists(nl / "r.jsonl.shards"));
  fs::remove_all(base);
}

TEST_CASE("cli: two sweeps on one output: the second is refused and the file keeps one copy of each item", "[cli]") {
  const fs::path d = scratchDir("sweep_lock");
  shellOutput(geng() + " -c -q 9 15:15 > " + (d / "g9.g6").string());
  const std::string out = (d / "out.jsonl").string();
  const std::string cmd = std::string(FLEXURE_BINARY) + " sweep analyze " + (d / "g9.g6").string() + " -o " + out +
                          " --quiet >/dev/null 2>&1 & pid=$!; sleep 0.5; " + FLEXURE_BINARY + " sweep analyze " +
                          (d / "g9.g6").string() + " -o " + out + " 2>" + (d / "err.txt").string() +
                          " >/dev/null; echo $?; wait $pid";
  CHECK(shellOutput(cmd) == "3\n");
  CHECK_THAT(readFile(d / "err.txt"), Catch::Contains("another flexure is writing it"));
  CHECK(countLines(readFile(d / "out.jsonl")) == 20304);
  fs::remove_all(d);
}

TEST_CASE("cli: merge of a shard directory with more shards than open files and a stale shard of another count",
          "[cli]") {
  // The merge job of a large array names the directory; the shards' files cannot all stay open
  // (here at most 100 files for 70 shards: each read reopens a file where it stopped); a shard
  // left from an earlier submission with another --tasks is left aside.
  const fs::path d = scratchDir("sweep_many_shards");
  shellOutput(geng() + " -c -q 7 9:9 > " + (d / "g.g6").string());  // 107 graphs
  CHECK(shellOutput("cd " + d.string() + " && " + FLEXURE_BINARY + " sweep analyze g.g6 --quiet -o local.jsonl >/dev/null; echo $?") ==
        "0\n");
  fs::create_directories(d / "shards");
  std::string cmd = "cd " + d.string() + " && for k in $(seq 0 69); do " + FLEXURE_BINARY +
                    " sweep analyze g.g6 --quiet --threads 1 --slice $k/70 -o shards/shard-$k-of-70.jsonl >/dev/null || echo fail; done";
  CHECK(shellOutput(cmd).empty());
  std::ofstream(d / "shards" / "shard-0-of-3.jsonl") << "stale\n";
  const std::string merge = "cd " + d.string() + " && (ulimit -n 100; " + FLEXURE_BINARY +
                            " sweep merge shards --tasks 70 -o merged.jsonl >/dev/null 2>err.txt; echo $?)";
  CHECK(shellOutput(merge) == "0\n");
  CHECK(readFile(d / "err.txt").empty());
  const auto untimed = [](const std::string& text) {
    std::string out;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);)
      out += withoutProvenance(line.substr(
                 0, line.rfind("{\"summary\"", 0) == 0 ? line.find("\"items_time_s\"") : line.find(",\"time_ms\""))) +
             "\n";
    return out;
  };
  CHECK(untimed(readFile(d / "merged.jsonl")) == untimed(readFile(d / "local.jsonl")));
  fs::remove_all(d);
}
