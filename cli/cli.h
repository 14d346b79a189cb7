// The command line shared by the two executables (SPEC section 1): `flexure-draw` has every
// command; `flexure` runs analyze, track, catalog and keys itself and hands the commands that
// draw to the `flexure-draw` next to it, so that it starts without loading OpenGL, the video
// codecs, fonts or the HTTP server.
#pragma once

#include <csignal>
#include <cstdint>
#include <chrono>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "engine/deformation_path.h"
#include "pipeline/pipeline.h"

namespace flexure::cli {

constexpr int kExitOk = 0;
constexpr int kExitInput = 1;
constexpr int kExitStopped = 2;
constexpr int kExitOutput = 3;
constexpr int kExitInterrupted = 130;  // 128 + SIGINT, as shells report it

struct Args {
  std::string command;
  std::vector<std::string> positional;
  std::vector<std::string> overrides;
  std::string output;
  bool json = false;
  bool exact = false;  // analyze --exact
  bool certify = false;  // analyze --certify, track --certify
  bool types = false;  // keys --types
  bool quiet = false;
  int sample = 0;     // render: which sample
  std::vector<int> frame_samples;  // render --samples: a filmstrip of these
  bool flex = false;  // render: draw the flex arrows
  std::optional<std::uint64_t> seed;  // project: the projection's seed
  std::string data;   // project: CSV of the projected coordinates
  std::optional<int> port;  // view
  std::string output_dir;   // run: where the [[output]] files go instead of the scene's folder
  // sweep: option values as given (checked by sweepCommand), and its flags
  std::string dimension, realizations, slice, threads, cpus, where, tasks, max_running, partition, time_limit, account, fields;
  std::optional<std::string> sweep_seed;
  bool samples = false, slurm = false, dry_run = false;
};

// The whole program: parse, run, exit status.
int main(int argc, char** argv);

// The command line as given (the drawing commands may be handed on with it).
extern char** g_argv;

// render, animate, project, run, demo, view: cli/drawing.cpp in flexure-draw, an exec of
// flexure-draw in flexure (cli/drawing_exec.cpp).
int drawingCommand(const Args& a);

// flexure sweep analyze|track|merge (cli/sweep.cpp).
int sweepCommand(const Args& a);

// A nonnegative integer no larger than `max`, from the text of `option`'s value; a usage error
// naming the option (and what it `needs`) otherwise.
unsigned long long parseCount(const std::string& option, const std::string& text, unsigned long long max,
                              const std::string& needs);

// JSON (already escaped) goes here; std::cout and std::cerr escape control characters.
std::ostream& rawOut();
// The exit status once standard output has reached its file (a failed write: exit 3).
int finish(int status);
// One line saying what is wrong and where to look, exit 1.
[[noreturn]] void usageError(const std::string& message);

// Ctrl-C and SIGTERM (see cli.cpp): set by the first signal; g_noticed once a computation
// has seen it (otherwise it is cut short after a second).
extern volatile std::sig_atomic_t g_interrupted;
extern volatile std::sig_atomic_t g_noticed;
// True once interrupted; the interruption counts as noticed.
bool interruptNoticed();
// Says where an interruption stopped things; the exit status for it.
int interrupted(const std::string& where);

// A progress bar on stderr (when it is a terminal): done/total, rate and time left.
class ProgressBar {
 public:
  ProgressBar(bool enabled, std::string unit, std::string label = "");
  bool operator()(int done, int total);
  // Ends an unfinished bar's line.
  void end();
  ~ProgressBar() { end(); }

 private:
  using Clock = std::chrono::steady_clock;
  bool enabled_;
  std::string unit_, label_;
  Clock::time_point t0_, last_{};
  bool open_ = false;
};

// The progress of a study as bars on stderr: one per stage, a new one when a stage starts over
// (the next output's frames). Ctrl-C stops the study at its next step or frame.
class StudyProgress {
 public:
  explicit StudyProgress(bool quiet) : quiet_(quiet) {}
  bool operator()(pipeline::Stage stage, int done, int total);
  void end() {
    if (bar_) bar_->end();
  }

 private:
  bool quiet_;
  pipeline::Stage stage_ = pipeline::Stage::Tracking;
  int last_ = 0;
  std::optional<ProgressBar> bar_;
};

pipeline::StudyOptions studyOptions(const Args& a, StudyProgress& progress);
// The exit status of a tracked path (interrupted, stopped early or complete).
int trackStatus(const engine::DeformationPath& r);
// What the summary line adds after it: one line per origami intersection event ("sample 67:
// faces 1 and 3 pass through each other"), each ending in a newline; "" without them.
std::string eventLines(const engine::DeformationPath& r);

}  // namespace flexure::cli
