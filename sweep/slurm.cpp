#include "sweep/slurm.h"

#include <sstream>

namespace flexure::sweep {

std::string shellQuote(const std::string& s) {
  if (!s.empty() && s.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-./=:,+@%") ==
                        std::string::npos)
    return s;
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string SlurmPlan::shard(int k) const {
  return shard_dir + "/shard-" + std::to_string(k) + "-of-" + std::to_string(tasks) + ".jsonl";
}

namespace {

void commonHeader(std::ostringstream& o, const SlurmPlan& p, const std::string& name, const std::string& log) {
  o << "#!/bin/bash\n";
  o << "#SBATCH --job-name=" << name << "\n";
  o << "#SBATCH --output=" << log << "\n";
  o << "#SBATCH --chdir=" << p.workdir << "\n";
  if (!p.partition.empty()) o << "#SBATCH --partition=" << p.partition << "\n";
  if (!p.account.empty()) o << "#SBATCH --account=" << p.account << "\n";
}

}  // namespace

std::string SlurmPlan::arrayScript() const {
  std::ostringstream o;
  commonHeader(o, *this, "flexure-sweep", shard_dir + "/slurm-%A_%a.log");
  o << "#SBATCH --array=0-" << tasks - 1;
  if (max_running > 0) o << "%" << max_running;
  o << "\n#SBATCH --ntasks=1\n#SBATCH --cpus-per-task=" << cpus_per_task << "\n";
  if (!time_limit.empty()) o << "#SBATCH --time=" << time_limit << "\n";
  // A task that Slurm stops (time limit, preemption) gets SIGTERM, writes what it finished and
  // exits; requeued, it continues its shard where it stopped.
  o << "#SBATCH --requeue\n#SBATCH --signal=TERM@60\n";
  o << "# Slice $SLURM_ARRAY_TASK_ID of " << tasks << " of a flexure sweep; its shard: " << shard_dir
    << "/shard-$SLURM_ARRAY_TASK_ID-of-" << tasks << ".jsonl\n";
  o << "set -eu\n";
  o << "exec " << shellQuote(flexure) << " sweep";
  for (const auto& a : sweep_args) o << " " << shellQuote(a);
  o << " --quiet --threads \"${SLURM_CPUS_PER_TASK:-1}\" --slice \"${SLURM_ARRAY_TASK_ID}/" << tasks << "\" -o "
    << shellQuote(shard_dir) << "/shard-\"${SLURM_ARRAY_TASK_ID}\"-of-" << tasks << ".jsonl";
  if (!stdin_file.empty()) o << " < " << shellQuote(stdin_file);
  o << "\n";
  return o.str();
}

std::string SlurmPlan::mergeScript() const {
  std::ostringstream o;
  commonHeader(o, *this, "flexure-merge", shard_dir + "/slurm-merge-%j.log");
  o << "#SBATCH --ntasks=1\n#SBATCH --cpus-per-task=1\n";
  if (!time_limit.empty()) o << "#SBATCH --time=" << time_limit << "\n";
  o << "# Joins the " << tasks << " shards into " << output << " (submitted with --dependency=afterok:ARRAY_JOB).\n";
  o << "set -eu\n";
  o << "exec " << shellQuote(flexure) << " sweep merge";
  for (int k = 0; k < tasks; ++k) o << " " << shellQuote(shard(k));
  o << " -o " << shellQuote(output) << "\n";
  return o.str();
}

}  // namespace flexure::sweep
