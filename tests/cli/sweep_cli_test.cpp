// flexure sweep on the command line: geng's output on a pipe, usage errors, Ctrl-C and a rerun,
// and --slurm --dry-run.
#include "cli_common.h"

#include <algorithm>

using namespace flexure_cli_test;

namespace {

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
  CHECK_THAT(r.out, Catch::Contains("sweep merge " + (d / "res.jsonl.shards/shard-0-of-5.jsonl").string()));
  CHECK_THAT(r.out, Catch::Contains("--dependency=afterok:ARRAY_JOB"));
  CHECK(fs::is_empty(d));
  fs::remove_all(d);
}
