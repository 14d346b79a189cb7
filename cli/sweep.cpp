// flexure sweep analyze|track INPUT and flexure sweep merge SHARD... (SPEC section 4): the
// command line of sweep/, its progress and report on stderr, and the Slurm submission.
#include <sys/wait.h>
#include <csignal>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <climits>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <thread>

#include "cli/cli.h"
#include "present/output_file.h"
#include "scenes/importers.h"
#include "scenes/keys.h"
#include "sweep/slurm.h"
#include "sweep/sweep.h"
#include "sweep/where.h"

namespace flexure::cli {

namespace {

std::string verdictText(const sweep::Tally& t) {
  std::ostringstream o;
  o << t.items << " item" << (t.items == 1 ? "" : "s");
  std::string v;
  for (const auto& [k, n] : t.verdicts) v += (v.empty() ? "" : ", ") + std::to_string(n) + " " + k;
  if (!v.empty()) o << " (" << v << ")";
  if (t.with_certificate > 0) {
    o << "; " << t.certified << " certified";
    // Lines read back from a file (a resumed output, a merge's shards): their "certified" is a
    // claim nothing here has checked, so it is not counted as certified.
    if (t.certified_unverified > 0)
      o << " (" << t.certified_unverified << " more line" << (t.certified_unverified == 1 ? "" : "s")
        << " read back from a file claim" << (t.certified_unverified == 1 ? "s" : "")
        << " a certificate: not verified, not counted)";
  }
  const auto count = [&](const char* k) { return t.status.count(k) ? t.status.at(k) : 0; };
  o << "; " << count("error") << " error" << (count("error") == 1 ? "" : "s");
  if (count("filtered")) o << "; " << t.kept << " kept by --where, " << count("filtered") << " filtered out";
  return o.str();
}

// Runs `argv` (no shell); its standard output, and whether it exited 0.
bool runCommand(const std::vector<std::string>& argv, std::string& out) {
  int pipefd[2];
  if (::pipe(pipefd) != 0) return false;
  const pid_t pid = ::fork();
  if (pid < 0) return false;
  if (pid == 0) {
    ::signal(SIGPIPE, SIG_DFL);  // flexure ignores it; sbatch gets the usual behaviour
    ::dup2(pipefd[1], 1);
    ::close(pipefd[0]);
    ::close(pipefd[1]);
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    ::execvp(args[0], args.data());
    std::fprintf(stderr, "flexure: cannot run %s: %s\n", args[0], std::strerror(errno));
    ::_exit(127);
  }
  ::close(pipefd[1]);
  char buf[4096];
  ssize_t n;
  while ((n = ::read(pipefd[0], buf, sizeof buf)) > 0) out.append(buf, static_cast<size_t>(n));
  ::close(pipefd[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

std::string absolute(const std::string& p) {
  std::error_code ec;
  const auto a = std::filesystem::absolute(p, ec);
  return ec ? p : a.lexically_normal().string();
}

std::string selfExecutable() {
  char buf[PATH_MAX];
  const ssize_t n = ::readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) return "flexure";
  return std::string(buf, static_cast<size_t>(n));
}

int submitSlurm(const Args& a, const std::string& input, const std::vector<std::string>& sweep_args,
                int threads) {
  if (a.output.empty() || a.output == "-") usageError("--slurm needs -o OUT.jsonl: where the merge job writes");
  if (!a.slice.empty()) usageError("--slurm makes the slices itself: leave out --slice");
  sweep::SlurmPlan p;
  p.flexure = selfExecutable();
  p.workdir = absolute(".");
  p.output = a.output;
  p.shard_dir = a.output + ".shards";
  p.tasks = a.tasks.empty() ? 4 : static_cast<int>(parseCount("--tasks", a.tasks, 100000, "a number of tasks 1..100000"));
  if (p.tasks < 1) usageError("--tasks needs a number of tasks 1..100000");
  if (!a.max_running.empty()) p.max_running = static_cast<int>(parseCount("--max-running", a.max_running, 100000, "a number 1..100000"));
  p.cpus_per_task = threads > 0 ? threads : 1;
  p.partition = a.partition;
  p.time_limit = a.time_limit;
  p.account = a.account;
  p.sweep_args = sweep_args;
  p.check();  // std::invalid_argument: exit 1, before anything is written
  if (input == "-") {
    // The tasks cannot read this process's standard input: it is kept next to the shards, and
    // each task reads it as its own standard input (so the items are named as in a local run).
    p.stdin_file = p.shard_dir + "/input.g6";
    if (!a.dry_run) {
      std::ostringstream data;
      data << std::cin.rdbuf();
      present::makeDirectories(p.shard_dir);
      present::writeFileAtomically(p.stdin_file, data.str());
    }
  }
  const std::string array = p.arrayScript(), merge = p.mergeScript();
  const auto commandLine = [](std::vector<std::string> args) {
    std::string line = "sbatch";
    for (auto& x : args) line += " " + sweep::shellQuote(x);
    return line;
  };
  if (a.dry_run) {
    std::cout << "# " << p.arrayFile() << "\n" << array << "\n# " << p.mergeFile() << "\n" << merge << "\n"
              << "# submitted with:\n#   " << commandLine(p.arraySubmission()) << "   -> ARRAY_JOB\n#   "
              << commandLine(p.mergeSubmission()) << "\n";
    return kExitOk;
  }
  present::makeDirectories(p.shard_dir);
  present::writeFileAtomically(p.arrayFile(), array);
  present::writeFileAtomically(p.mergeFile(), merge);
  std::vector<std::string> args = p.arraySubmission();
  args.insert(args.begin(), "sbatch");
  std::string out;
  if (!runCommand(args, out)) {
    std::cerr << "flexure: sbatch did not take " << p.arrayFile()
              << " (is this a Slurm login node? --dry-run prints the scripts)\n";
    return kExitOutput;
  }
  const std::string job = out.substr(0, out.find_first_of(";\n"));
  std::vector<std::string> margs = p.mergeSubmission();
  for (auto& x : margs)
    if (x == "--dependency=afterok:ARRAY_JOB") x = "--dependency=afterok:" + job;
  margs.insert(margs.begin(), "sbatch");
  std::string out2;
  if (!runCommand(margs, out2)) {
    std::cerr << "flexure: the array job " << job << " is submitted, but sbatch did not take the merge job "
              << p.mergeFile() << "; run it by hand once the array is done\n";
    return kExitOutput;
  }
  const std::string merge_job = out2.substr(0, out2.find_first_of(";\n"));
  std::cout << "submitted array job " << job << " (" << p.tasks << " tasks) and merge job " << merge_job
            << "\nshards and logs: " << p.shard_dir << "/\nresult: " << p.output << " once job " << merge_job
            << " is done\n";
  rawOut() << job << " " << merge_job << "\n";
  return kExitOk;
}

// The shards of a shard directory (as --slurm makes it): its files shard-K-of-N.jsonl, for the
// N of --tasks (shards of other counts, from an earlier submission, are left aside) or, without
// it, the one N they share. In K order; a missing K is merge's to name.
std::vector<std::string> shardsIn(const std::string& dir, const std::string& tasks) {
  long long want = tasks.empty() ? -1 : parseCount("--tasks", tasks, 10000000, "the number of shards 1..10000000");
  std::vector<std::pair<long long, std::string>> found;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    long long k = -1, n = -1;
    char tail[8] = {};
    if (std::sscanf(name.c_str(), "shard-%lld-of-%lld.jsonl%7s", &k, &n, tail) != 2 ||
        name != "shard-" + std::to_string(k) + "-of-" + std::to_string(n) + ".jsonl")
      continue;
    if (!tasks.empty() && n != want) continue;  // another run's shards, left in the directory
    if (want < 0) want = n;
    if (n != want)
      throw scenes::SceneError(e.path().string(), 1, 1,
                               "is a shard of " + std::to_string(n) + " where the directory's others are of " +
                                   std::to_string(want) + ": give --tasks N to choose");
    found.push_back({k, e.path().string()});
  }
  if (ec) throw scenes::SceneError(dir, 1, 1, "cannot read the directory: " + ec.message());
  if (found.empty()) throw scenes::SceneError(dir, 1, 1, "holds no shard (files shard-K-of-N.jsonl)");
  std::sort(found.begin(), found.end());
  std::vector<std::string> out;
  for (auto& f : found) out.push_back(std::move(f.second));
  return out;
}

int sweepMerge(const Args& a) {
  if (a.positional.size() < 2)
    usageError("sweep merge takes the shards, or their directory: sweep merge SHARD...|DIR -o OUT.jsonl");
  if (a.output.empty() || a.output == "-") usageError("sweep merge needs -o OUT.jsonl");
  std::vector<std::string> shards;
  for (size_t i = 1; i < a.positional.size(); ++i) {
    std::error_code ec;
    if (std::filesystem::is_directory(a.positional[i], ec)) {
      for (auto& s : shardsIn(a.positional[i], a.tasks)) shards.push_back(std::move(s));
    } else {
      shards.push_back(a.positional[i]);
    }
  }
  present::checkWritable(a.output, shards);
  const sweep::Tally t = sweep::merge(shards, a.output);
  std::cout << "merged " << shards.size() << " shard" << (shards.size() == 1 ? "" : "s") << ": " << verdictText(t)
            << "\nwrote " << a.output << "\n";
  return kExitOk;
}

}  // namespace

int sweepCommand(const Args& a) {
  if (a.positional.empty()) usageError("sweep needs a job: sweep analyze|track INPUT, or sweep merge SHARD...");
  const std::string job = a.positional[0];
  if (job == "merge") return sweepMerge(a);
  if (job != "analyze" && job != "track")
    usageError("sweep runs analyze or track (or merges shards: sweep merge), not '" + job + "'");
  if (a.positional.size() != 2) usageError("sweep " + job + " takes one INPUT");
  const std::string input = a.positional[1];
  sweep::Options o;
  o.job = job == "analyze" ? sweep::Job::Analyze : sweep::Job::Track;
  o.overrides = a.overrides;
  o.samples = a.samples;
  o.where = a.where;
  // In the items' settings, so that a resume or a merge compares them.
  if (a.certify) o.overrides.push_back(o.job == sweep::Job::Analyze ? "analysis.certify=true" : "motion.certify=true");
  if (a.samples && o.job != sweep::Job::Track) usageError("--samples is for sweep track");
  const bool graphs = input == "-" || scenes::isGraphFile(input);
  std::vector<std::string> sweep_args = {job, input};
  if (!a.dimension.empty()) {
    o.dimension = static_cast<int>(parseCount("--dimension", a.dimension, 3, "2 or 3"));
    if (o.dimension < 2) usageError("--dimension needs 2 or 3, not '" + a.dimension + "'");
  }
  if (a.sweep_seed) o.seed = parseCount("--seed", *a.sweep_seed, (1ull << 63) - 1, "a nonnegative integer below 2^63");
  if (!a.realizations.empty()) {
    o.realizations = static_cast<int>(parseCount("--realizations", a.realizations, 1000000, "a number 1..1000000"));
    if (o.realizations < 1) usageError("--realizations needs a number 1..1000000");
  }
  if (!graphs && (!a.dimension.empty() || a.sweep_seed || !a.realizations.empty()))
    usageError("--dimension, --seed and --realizations are for graph6/sparse6 input (scenes carry their own)");
  if (graphs) {
    sweep_args.insert(sweep_args.end(), {"--dimension", std::to_string(o.dimension), "--seed", std::to_string(o.seed),
                                         "--realizations", std::to_string(o.realizations)});
  }
  if (!a.slice.empty()) {
    const size_t slash = a.slice.find('/');
    if (slash == std::string::npos) usageError("--slice needs k/N (k from 0 to N-1), not '" + a.slice + "'");
    o.slice.k = static_cast<int>(parseCount("--slice", a.slice.substr(0, slash), 10000000, "k/N with k from 0 to N-1"));
    o.slice.n = static_cast<int>(parseCount("--slice", a.slice.substr(slash + 1), 10000000, "k/N with N from 1"));
    if (o.slice.n < 1 || o.slice.k >= o.slice.n) usageError("--slice needs k/N with 0 <= k < N, not '" + a.slice + "'");
  }
  if (!a.threads.empty()) {
    o.threads = static_cast<int>(parseCount("--threads", a.threads, 1024, "a number of threads 1..1024"));
    if (o.threads < 1) usageError("--threads needs a number of threads 1..1024");
  }
  if (!o.where.empty()) {
    try {
      sweep::Where(o.where, sweep::itemFields(o.job));
    } catch (const sweep::WhereError& e) {
      usageError("--where: " + std::string(e.what()) + "\n  " + o.where + "\n  " + std::string(e.offset, ' ') + "^");
    }
    sweep_args.insert(sweep_args.end(), {"--where", o.where});
    // Without --certify the lines have no certificate unless the scenes ask for one.
    if (!a.certify && o.where.find("certif") != std::string::npos && !a.quiet)
      std::cerr << "flexure: note: --where reads the certificate, which the lines have only with --certify (or "
                   "certify = true in the scenes)\n";
  }
  if (!a.fields.empty()) {
    const std::vector<std::string> known = sweep::itemFields(o.job);
    for (size_t at = 0; at != std::string::npos;) {
      const size_t comma = a.fields.find(',', at);
      std::string f = a.fields.substr(at, comma == std::string::npos ? std::string::npos : comma - at);
      f.erase(0, f.find_first_not_of(' '));
      f.erase(f.find_last_not_of(' ') + 1);
      at = comma == std::string::npos ? comma : comma + 1;
      if (f.empty()) usageError("--fields needs field names separated by commas, e.g. rigidity_rank,stress_dim");
      if (std::find(known.begin(), known.end(), f) == known.end()) {
        std::string best;
        int best_d = 4;
        for (const auto& k : known)
          if (const int d = scenes::editDistance(f, k); d < best_d) best_d = d, best = k;
        usageError("--fields: unknown field '" + f + "'" + (best.empty() ? "" : " (did you mean '" + best + "'?)"));
      }
      if (std::find(o.fields.begin(), o.fields.end(), f) == o.fields.end()) o.fields.push_back(f);
    }
    sweep_args.insert(sweep_args.end(), {"--fields", a.fields});
  }
  if (a.samples) sweep_args.push_back("--samples");
  if (a.certify) sweep_args.push_back("--certify");
  for (const auto& s : a.overrides) sweep_args.insert(sweep_args.end(), {"--set", s});
  const bool slurm_only = !a.tasks.empty() || !a.max_running.empty() || !a.partition.empty() || !a.time_limit.empty() ||
                          !a.account.empty() || !a.cpus.empty() || a.dry_run;
  if (a.slurm) {
    const int cpus = a.cpus.empty() ? 1 : static_cast<int>(parseCount("--cpus-per-task", a.cpus, 1024, "a number 1..1024"));
    return submitSlurm(a, input, sweep_args, cpus);
  }
  if (slurm_only) usageError("--tasks, --max-running, --partition, --time, --account, --cpus-per-task and --dry-run go with --slurm");

  const bool to_file = !a.output.empty() && a.output != "-";
  if (to_file) {
    if (present::extensionOf(a.output) == "toml" || a.output == input)
      usageError("the output '" + a.output + "' would replace an input");
    if (input != "-") present::checkWritable(a.output, {input});
  }
  auto family = sweep::openFamily(input, o);
  const auto t0 = std::chrono::steady_clock::now();
  const bool bar = !a.quiet && ::isatty(2);
  auto last = t0;
  const auto progress = [&](long long done) {
    if (!bar) return;
    const auto now = std::chrono::steady_clock::now();
    if (now - last < std::chrono::milliseconds(200)) return;
    last = now;
    const double s = std::chrono::duration<double>(now - t0).count();
    std::fprintf(stderr, "\r%lld items  %.0f/s   ", done, s > 0 ? done / s : 0.0);
  };
  const sweep::RunResult r = sweep::run(*family, input, o, to_file ? a.output : "", [] { return interruptNoticed(); },
                                        progress);
  if (bar) std::fputc('\n', stderr);
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const int threads = o.threads > 0 ? o.threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  std::ostream& report = to_file ? std::cout : std::cerr;
  if (r.interrupted) {
    std::cerr << "\nflexure: interrupted; the sweep stopped after " << r.tally.items << " items"
              << (to_file ? "; " + a.output + " keeps them: rerun the same command to continue" : std::string()) << "\n";
    return kExitInterrupted;
  }
  if (r.computed == 0 && r.resumed > 0) {
    report << "sweep: " << a.output << " already holds the whole sweep: " << verdictText(r.tally) << "\n";
    return kExitOk;
  }
  char rate[128];
  std::snprintf(rate, sizeof rate, " in %.2f s, %.0f items/s on %d thread%s", secs, secs > 0 ? r.computed / secs : 0.0,
                threads, threads == 1 ? "" : "s");
  report << "sweep: " << verdictText(r.tally) << rate
         << (r.resumed ? "; " + std::to_string(r.resumed) + " were done before" : std::string()) << "\n";
  if (to_file) report << "wrote " << a.output << "\n";
  return kExitOk;
}

}  // namespace flexure::cli
