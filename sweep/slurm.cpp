#include "sweep/slurm.h"

#include <cctype>
#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace flexure::sweep {

std::string shellQuote(const std::string& s) {
  if (!s.empty() && s.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-./=:,+@%") ==
                        std::string::npos)
    return s;
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

namespace {

// `s` with its control characters written as \xHH: a message must not carry the newline it is
// about.
std::string visible(const std::string& s) {
  std::string out;
  for (char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (c < 0x20 || c == 0x7F) {
      char code[8];
      std::snprintf(code, sizeof code, "\\x%02X", c);
      out += code;
    } else {
      out += ch;
    }
  }
  return out;
}

}  // namespace

void checkScriptValue(const std::string& what, const std::string& value) {
  for (size_t i = 0; i < value.size(); ++i) {
    const auto c = static_cast<unsigned char>(value[i]);
    if (c < 0x20 || c == 0x7F)
      throw std::invalid_argument(what + " '" + visible(value) + "' holds a control character (at byte " +
                                  std::to_string(i + 1) + "), which cannot be written into a Slurm script: rename it");
  }
}

namespace {

bool allDigits(const std::string& s, size_t from, size_t to) {
  if (from >= to) return false;
  for (size_t i = from; i < to; ++i)
    if (s[i] < '0' || s[i] > '9') return false;
  return true;
}

}  // namespace

// Both checks scan the value once: std::regex_match recursed once per character and overflowed
// the stack on a 20 KB partition name (found by the slurm fuzz target).
void checkSlurmName(const std::string& option, const std::string& value) {
  checkScriptValue(option, value);
  // [A-Za-z0-9_.-]+ joined by single commas.
  bool ok = !value.empty() && value.front() != ',' && value.back() != ',';
  for (size_t i = 0; ok && i < value.size(); ++i) {
    const char c = value[i];
    ok = std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.' || c == '-' ||
         (c == ',' && value[i + 1] != ',');
  }
  if (!ok)
    throw std::invalid_argument(option + " '" + visible(value) +
                                "' is not a Slurm name (letters, digits, '_', '.', '-'; a list joined by ',')");
}

void checkSlurmTime(const std::string& value) {
  checkScriptValue("--time", value);
  std::string lower;
  for (char c : value) lower += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  // minutes, MM:SS, HH:MM:SS, D-HH, D-HH:MM, D-HH:MM:SS: [D-] then one to three groups of digits.
  bool ok = lower == "unlimited" || lower == "infinite";
  if (!ok) {
    size_t from = 0;
    const size_t dash = value.find('-');
    if (dash != std::string::npos) {
      ok = allDigits(value, 0, dash);
      from = dash + 1;
    } else {
      ok = true;
    }
    int groups = 0;
    while (ok) {
      const size_t colon = value.find(':', from);
      const size_t to = colon == std::string::npos ? value.size() : colon;
      ok = allDigits(value, from, to) && ++groups <= 3;
      if (colon == std::string::npos) break;
      from = colon + 1;
    }
  }
  if (!ok)
    throw std::invalid_argument("--time '" + visible(value) +
                                "' is not a Slurm time limit (minutes, MM:SS, HH:MM:SS, D-HH, D-HH:MM:SS)");
}

std::string slurmFilePattern(const std::string& path) {
  std::string out;
  for (char c : path) out += c == '%' ? std::string("%%") : std::string(1, c);
  return out;
}

void SlurmPlan::check() const {
  checkScriptValue("the working directory", workdir);
  checkScriptValue("the output", output);
  checkScriptValue("the shard directory", shard_dir);
  // In sbatch's --output a backslash turns Slurm's % patterns off: every task would log into
  // one file named with a literal %A_%a.
  if (workdir.find('\\') != std::string::npos || shard_dir.find('\\') != std::string::npos)
    throw std::invalid_argument("the shard directory '" + logDirectory() +
                                "' holds a backslash, which turns Slurm's % patterns off in the logs' names (every "
                                "task would write one log): rename it, or run from another directory");
  checkScriptValue("the executable", flexure);
  checkScriptValue("the standard input's copy", stdin_file);
  for (const auto& a : sweep_args) checkScriptValue("the argument", a);
  if (!partition.empty()) checkSlurmName("--partition", partition);
  if (!account.empty()) checkSlurmName("--account", account);
  if (!time_limit.empty()) checkSlurmTime(time_limit);
}

std::string SlurmPlan::shard(int k) const {
  return shard_dir + "/shard-" + std::to_string(k) + "-of-" + std::to_string(tasks) + ".jsonl";
}
std::string SlurmPlan::logDirectory() const {
  if (!shard_dir.empty() && shard_dir[0] == '/') return shard_dir;
  return workdir + (!workdir.empty() && workdir.back() == '/' ? "" : "/") + shard_dir;
}
std::string SlurmPlan::arrayFile() const { return shard_dir + "/array.sbatch"; }
std::string SlurmPlan::mergeFile() const { return shard_dir + "/merge.sbatch"; }

namespace {

// The #SBATCH lines both jobs share: only checked names and numbers (paths go as sbatch's
// arguments, see submission()).
void commonHeader(std::ostringstream& o, const SlurmPlan& p, const std::string& name) {
  o << "#!/bin/bash\n";
  o << "#SBATCH --job-name=" << name << "\n";
  if (!p.partition.empty()) o << "#SBATCH --partition=" << p.partition << "\n";
  if (!p.account.empty()) o << "#SBATCH --account=" << p.account << "\n";
  if (!p.time_limit.empty()) o << "#SBATCH --time=" << p.time_limit << "\n";
}

void submittedWith(std::ostringstream& o, const std::vector<std::string>& args) {
  o << "# Submitted by flexure with (paths as sbatch's own arguments, never parsed from this file):\n#   sbatch";
  for (const auto& a : args) o << " " << shellQuote(a);
  o << "\n";
}

// --chdir is taken literally, but a relative --output is appended to it and the whole is read
// as a pattern (a directory named "%x" took the job's name in the logs' path: found by the real
// Slurm test): the logs' path is given absolute, every % of it escaped.
std::vector<std::string> submission(const SlurmPlan& p, const std::string& log, const std::string& script) {
  return {"--parsable", "--chdir=" + p.workdir, "--output=" + slurmFilePattern(p.logDirectory()) + "/" + log, script};
}

}  // namespace

std::vector<std::string> SlurmPlan::arraySubmission() const {
  return submission(*this, "slurm-%A_%a.log", arrayFile());
}
std::vector<std::string> SlurmPlan::mergeSubmission() const {
  auto args = submission(*this, "slurm-merge-%j.log", mergeFile());
  args.insert(args.begin() + 1, {"--dependency=afterok:ARRAY_JOB", "--kill-on-invalid-dep=yes"});
  return args;
}

std::string SlurmPlan::arrayScript() const {
  std::ostringstream o;
  commonHeader(o, *this, "flexure-sweep");
  o << "#SBATCH --array=0-" << tasks - 1;
  if (max_running > 0) o << "%" << max_running;
  o << "\n#SBATCH --ntasks=1\n#SBATCH --cpus-per-task=" << cpus_per_task << "\n";
  // At the time limit (or a preemption) Slurm sends SIGTERM to this shell (B:) 60 s early: the
  // shell passes it on to flexure, which writes the items it finished and stops, and the task
  // is requeued; run again, it continues its shard where it stopped.
  o << "#SBATCH --requeue\n#SBATCH --signal=B:TERM@60\n";
  submittedWith(o, arraySubmission());
  o << "# Slice $SLURM_ARRAY_TASK_ID of " << tasks << " of a flexure sweep, into its shard below.\n";
  o << "set -u\n";
  o << "shard=" << shellQuote(shard_dir) << "/shard-\"${SLURM_ARRAY_TASK_ID}\"-of-" << tasks << ".jsonl\n";
  o << "pid=\nterminated=\n";
  o << "trap 'terminated=1; kill -TERM \"$pid\" 2>/dev/null' TERM\n";
  o << shellQuote(flexure) << " sweep";
  for (const auto& a : sweep_args) o << " " << shellQuote(a);
  o << " --quiet --threads \"${SLURM_CPUS_PER_TASK:-1}\" --slice \"${SLURM_ARRAY_TASK_ID}/" << tasks
    << "\" -o \"$shard\"";
  o << " < " << (stdin_file.empty() ? std::string("/dev/null") : shellQuote(stdin_file)) << " &\n";
  o << "pid=$!\n";
  o << "status=0\n";
  o << "wait \"$pid\" || status=$?\n";
  o << "if [ -n \"$terminated\" ]; then\n";
  o << "  # The wait was cut short by the signal (or the task had just ended): a second wait gives the\n";
  o << "  # task's own exit status (bash keeps a reaped child's). Requeued unless it finished.\n";
  o << "  trap '' TERM\n";
  o << "  status=0\n";
  o << "  wait \"$pid\" || status=$?\n";
  o << "  if [ \"$status\" -ne 0 ]; then\n";
  o << "    scontrol requeue \"${SLURM_ARRAY_JOB_ID}_${SLURM_ARRAY_TASK_ID}\"\n";
  o << "  fi\n";
  o << "fi\n";
  o << "exit \"$status\"\n";
  return o.str();
}

std::string SlurmPlan::mergeScript() const {
  std::ostringstream o;
  commonHeader(o, *this, "flexure-merge");
  o << "#SBATCH --ntasks=1\n#SBATCH --cpus-per-task=1\n";
  submittedWith(o, mergeSubmission());
  o << "# Joins the " << tasks << " shards of the shard directory into the output, once the array is done.\n";
  o << "set -eu\n";
  o << "exec " << shellQuote(flexure) << " sweep merge " << shellQuote(shard_dir) << " --tasks " << tasks << " -o "
    << shellQuote(output) << "\n";
  return o.str();
}

}  // namespace flexure::sweep
