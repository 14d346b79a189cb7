// `flexure sweep ... --slurm`: a Slurm job array that runs the sweep's slices, and a merge job
// that depends on it (afterok) and joins the shards into the output a single run writes.
#pragma once

#include <string>
#include <vector>

namespace flexure::sweep {

struct SlurmPlan {
  std::string flexure;      // the executable the tasks run (absolute)
  std::string workdir;      // where the tasks start (absolute): relative paths resolve there
  std::string output;       // the merged result
  std::string shard_dir;    // shards, logs and the scripts
  std::vector<std::string> sweep_args;  // job, input and options, without --slice, -o, --threads
  std::string stdin_file;   // for input "-": the file the tasks read as standard input
  int tasks = 4;            // array size: slices
  int max_running = 0;      // at most this many tasks at once (0: Slurm's choice)
  int cpus_per_task = 1;    // each task's threads
  std::string partition, time_limit, account;

  std::string shard(int k) const;  // the k-th shard's file
  std::string arrayScript() const;
  std::string mergeScript() const;
};

// `s` quoted for a POSIX shell.
std::string shellQuote(const std::string& s);

}  // namespace flexure::sweep
