// `flexure sweep ... --slurm`: a Slurm job array that runs the sweep's slices, and a merge job
// that depends on it (afterok) and joins the shards into the output a single run writes.
//
// Nothing a user typed or a directory is named reaches a script unchecked: every value passes
// checkScriptValue() (no control character: a newline would end a #SBATCH line or a comment and
// start a command), Slurm's own names and times pass checkSlurmName()/checkSlurmTime() before
// they are written into #SBATCH lines, paths reach sbatch as arguments of its own (argv, no
// shell: `--chdir`, `--output`, with Slurm's % patterns escaped) and the scripts' shell lines
// as shellQuote()d words.
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

  // Throws std::invalid_argument naming the option or path that cannot go into a script.
  void check() const;
  std::string shard(int k) const;  // the k-th shard's file
  std::string logDirectory() const;  // the shard directory, absolute: where Slurm writes the logs
  std::string arrayFile() const;   // where the scripts are written
  std::string mergeFile() const;
  std::string arrayScript() const;
  std::string mergeScript() const;
  // sbatch's arguments for each script (after "sbatch"; the merge job's dependency aside).
  std::vector<std::string> arraySubmission() const;
  std::vector<std::string> mergeSubmission() const;
};

// `s` quoted for a POSIX shell.
std::string shellQuote(const std::string& s);
// Throws std::invalid_argument("WHAT holds a control character ...") for a value that would
// break out of the line it is written on.
void checkScriptValue(const std::string& what, const std::string& value);
// A partition or account: letters, digits, '_', '.', '-' (a partition list: names joined by ',').
void checkSlurmName(const std::string& option, const std::string& value);
// A time limit in Slurm's forms: minutes, MM:SS, HH:MM:SS, D-HH, D-HH:MM, D-HH:MM:SS, or
// UNLIMITED/INFINITE (in any case).
void checkSlurmTime(const std::string& value);
// A file name for sbatch's --output: its % escaped as %% (Slurm reads %j, %A... in it).
std::string slurmFilePattern(const std::string& path);

}  // namespace flexure::sweep
