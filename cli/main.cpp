// flexure: continuous motions of geometric constraint systems. The command line (SPEC section 1).
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cerrno>

#include <algorithm>
#include <csignal>
#include <memory>
#include <optional>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include <filesystem>
#include <functional>

#include "engine/deformation_path.h"
#include "engine/rigidity.h"
#include "pipeline/pipeline.h"
#include "present/output_file.h"
#include "present/path_output.h"
#include "present/report.h"
#include "present/text.h"
#include "render/renderer.h"
#include "render/video.h"
#include "scenes/catalog.h"
#include "scenes/keys.h"
#include "scenes/scene.h"
#include "viewer/server.h"
#include "viewer/session.h"

namespace {

using namespace flexure;

constexpr int kExitOk = 0;
constexpr int kExitInput = 1;
constexpr int kExitStopped = 2;
constexpr int kExitOutput = 3;
constexpr int kExitInterrupted = 130;  // 128 + SIGINT, as shells report it

const char* kDescription = "flexure " FLEXURE_VERSION " - continuous motions of geometric constraint systems";
const char* kFooter =
    "Exit status: 0 success, 1 wrong input, 2 computation stopped early, 3 output not written,\n"
    "130 interrupted (Ctrl-C). 'flexure COMMAND --help' shows a command's options.";

struct Args {
  std::string command;
  std::vector<std::string> positional;
  std::vector<std::string> overrides;
  std::string output;
  bool json = false;
  bool quiet = false;
  int sample = 0;     // render: which sample
  bool flex = false;  // render: draw the flex arrows
  std::optional<std::uint64_t> seed;  // project: the projection's seed
  std::string data;   // project: CSV of the projected coordinates
  std::optional<int> port;  // view
  std::string output_dir;   // run: where the [[output]] files go instead of the scene's folder
};

// What the program prints goes through terminal filters (present::TerminalFilter): a scene's
// title or expression cannot send escape sequences to the terminal. JSON, already escaped,
// goes to the raw standard output.
std::ostream& rawOut() {
  static std::ostream raw(std::cout.rdbuf());
  return raw;
}

class SafeStreams {
 public:
  SafeStreams() : out_(std::cout.rdbuf()), err_(std::cerr.rdbuf()) {
    rawOut();
    std::cout.rdbuf(&out_);
    std::cerr.rdbuf(&err_);
  }
  ~SafeStreams() {
    std::cout.flush(), std::cerr.flush();
    std::cout.rdbuf(out_target_), std::cerr.rdbuf(err_target_);
  }

 private:
  std::streambuf* out_target_ = std::cout.rdbuf();
  std::streambuf* err_target_ = std::cerr.rdbuf();
  present::TerminalFilter out_, err_;
};

// The exit status once standard output has reached its file: a full device or a closed pipe
// is an output that could not be written (exit 3), never a success with truncated JSON.
int finish(int status) {
  std::cout.flush();
  rawOut().flush();
  errno = 0;
  const bool failed = std::fflush(stdout) != 0 || std::ferror(stdout) || !std::cout || !rawOut();
  if (!failed) return status;
  const int e = errno;
  std::cerr << "flexure: cannot write to standard output" << (e ? std::string(": ") + std::strerror(e) : "") << "\n";
  return kExitOutput;
}

// One line saying what is wrong and where to look, exit 1.
[[noreturn]] void usageError(const std::string& message) {
  std::cerr << "flexure: " << message << "\nRun 'flexure --help' for the commands, 'flexure COMMAND --help' for "
            << "a command's options.\n";
  std::exit(kExitInput);
}

// A nonnegative integer no larger than `max`, from the text of `option`'s value.
unsigned long long parseCount(const std::string& option, const std::string& text, unsigned long long max,
                              const std::string& needs) {
  if (text.empty() || text[0] == '-' || text[0] == '+')
    usageError(option + " needs " + needs + (text.empty() ? "" : ", not '" + text + "'"));
  char* end = nullptr;
  errno = 0;
  const unsigned long long v = std::strtoull(text.c_str(), &end, 10);
  if (*end != '\0' || errno == ERANGE || v > max) usageError(option + " needs " + needs + ", not '" + text + "'");
  return v;
}

// The command line through CLI11: one subcommand, its positional arguments and its options;
// --set and --quiet anywhere. Values are checked here, with messages that name the option.
Args parseArgs(int argc, char** argv) {
  Args a;
  CLI::App app{kDescription, "flexure"};
  app.footer(kFooter);
  app.set_version_flag("--version", "flexure " FLEXURE_VERSION);
  app.require_subcommand(1);
  app.fallthrough();
  app.add_option("--set", a.overrides, "override a scene key, e.g. --set motion.steps=50 (repeatable)")
      ->type_name("KEY=VALUE")
      ->allow_extra_args(false);
  app.add_flag("-q,--quiet", a.quiet, "no progress on stderr");
  std::string sample_text, seed_text, port_text;
  auto scene = [&](CLI::App* c, const char* what = "SCENE") {
    c->add_option(what, a.positional, std::string(what) == "DIR" ? "where to write (default flexure-demo)"
                                                                  : "a scene file (TOML)")
        ->type_name("");
    return c;
  };
  auto output = [&](CLI::App* c, const std::string& help) { c->add_option("-o,--output", a.output, help)->type_name("FILE"); };
  auto seed = [&](CLI::App* c) {
    c->add_option("--seed", seed_text, "the projection's seed (default: [projection] seed, else [motion] seed)")
        ->type_name("S");
  };
  CLI::App* analyze = scene(app.add_subcommand("analyze", "rigidity report of the start configuration"));
  analyze->add_flag("--json", a.json, "machine-readable output (the fields of docs/scene-format.md)");
  output(scene(app.add_subcommand("track", "the deformation path (JSON on stdout without -o)")),
         "PATH.json or PATH.csv");
  CLI::App* render = scene(app.add_subcommand("render", "one frame: the start, or sample K of the path"));
  output(render, "OUT.png (default: the scene's name)");
  render->add_option("--sample", sample_text, "the sample to draw (0: the start)")->type_name("K");
  render->add_flag("--flex", a.flex, "draw the selected infinitesimal flex as arrows");
  CLI::App* animate = scene(app.add_subcommand("animate", "animation of the deformation path"));
  output(animate, "OUT.mp4 or OUT.gif");
  seed(animate);
  CLI::App* project = scene(app.add_subcommand("project", "random 2D projection of the deformation path"));
  output(project, "OUT.png, or OUT.mp4/OUT.gif for the animated projection");
  seed(project);
  project->add_option("--data", a.data, "the projected coordinates as CSV")->type_name("OUT.csv");
  CLI::App* run = scene(app.add_subcommand("run", "every [[output]] the scene declares, in the scene's folder"));
  seed(run);
  run->add_option("--output-dir", a.output_dir, "write the [[output]] files under DIR instead of the scene's folder")
      ->type_name("DIR");
  CLI::App* demo = scene(app.add_subcommand("demo", "the default scene (double Watt mechanism): report, path, PNG, "
                                                    "MP4, GIF, projection, into DIR (default flexure-demo)"),
                         "DIR");
  seed(demo);
  app.add_subcommand("catalog", "the built-in named systems");
  app.add_subcommand("keys", "every scene key: table, type, range, default, what it is (Markdown)");
  CLI::App* view = scene(app.add_subcommand("view", "interactive viewer in the browser, on 127.0.0.1 only; follows "
                                                    "the scene file as it is edited"));
  view->add_option("--port", port_text, "the port (default 8765 or the next free one; 0: any free port)")
      ->type_name("P");
  for (CLI::Option* o : {render->get_option("--sample"), view->get_option("--port")}) o->expected(0, 1);
  for (CLI::App* c : {animate, project, run, demo}) c->get_option("--seed")->expected(0, 1);
  // The first word that is neither an option nor an option's value must be a command.
  for (int i = 1; i < argc; ++i) {
    const std::string w = argv[i];
    if (w == "--set") {
      ++i;
      continue;
    }
    if (!w.empty() && w[0] == '-') continue;
    const auto commands = app.get_subcommands([](const CLI::App*) { return true; });
    if (std::none_of(commands.begin(), commands.end(), [&](const CLI::App* c) { return c->get_name() == w; }))
      usageError("unknown command '" + w + "'");
    break;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    std::exit(app.exit(e));
  } catch (const CLI::CallForAllHelp& e) {
    std::exit(app.exit(e));
  } catch (const CLI::CallForVersion& e) {
    std::exit(app.exit(e));
  } catch (const CLI::ParseError& e) {
    usageError(e.what());
  }
  a.command = app.get_subcommands().front()->get_name();
  if (render->count("--sample")) a.sample = static_cast<int>(parseCount("--sample", sample_text, scenes::kMaxSteps, "a sample number 0..10000000"));
  for (CLI::App* c : {animate, project, run, demo})
    if (c->count("--seed")) a.seed = parseCount("--seed", seed_text, ~0ull, "a nonnegative integer");
  if (view->count("--port")) a.port = static_cast<int>(parseCount("--port", port_text, 65535, "a port number 0..65535"));
  return a;
}

int cmdAnalyze(const Args& a) {
  if (a.positional.size() != 1) usageError("analyze takes one SCENE");
  const scenes::Scene scene = scenes::loadScene(a.positional[0], a.overrides);
  const engine::RigidityReport rep = pipeline::analyze(scene);
  if (a.json) rawOut() << present::jsonText(present::analysisJson(scene, rep), 2) << "\n";
  else std::cout << present::analysisText(scene, rep);
  return kExitOk;
}

// Ctrl-C and SIGTERM. The first asks a computation to stop at its next step or frame and keep
// what it has; a stage that has not noticed within a second (a scene read from a FIFO, one
// long factorization) is cut short, and so is everything at a second signal. Cutting short
// removes any temporary name first (outputs in progress are unnamed files: nothing is left).
volatile std::sig_atomic_t g_interrupted = 0;
volatile std::sig_atomic_t g_noticed = 0;

[[noreturn]] void cutShort() {
  present::removePendingOutputs();
  static const char message[] = "\nflexure: interrupted; nothing more was written\n";
  [[maybe_unused]] const ssize_t n = ::write(2, message, sizeof message - 1);
  ::_exit(kExitInterrupted);
}

extern "C" void onInterrupt(int) {
  if (g_interrupted) cutShort();
  g_interrupted = 1;
  ::alarm(1);
}

extern "C" void onAlarm(int) {
  if (!g_noticed) cutShort();
}

// True once interrupted; the interruption counts as noticed (no cut after a second).
bool interruptNoticed() {
  if (!g_interrupted) return false;
  g_noticed = 1;
  return true;
}

void installSignalHandlers() {
  struct sigaction sa {};
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  sa.sa_handler = onInterrupt;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  sa.sa_handler = onAlarm;
  sigaction(SIGALRM, &sa, nullptr);
  // A file-size limit (ulimit -f) or a full disk must fail a write, not kill the process.
  sa.sa_handler = SIG_IGN;
  sigaction(SIGXFSZ, &sa, nullptr);
}

// Says where an interruption stopped things; the exit status for it.
int interrupted(const std::string& where) {
  std::cerr << "\nflexure: interrupted " << where << "\n";
  return kExitInterrupted;
}

// A progress bar on stderr (when it is a terminal): done/total, rate and time left.
class ProgressBar {
 public:
  ProgressBar(bool enabled, std::string unit, std::string label = "")
      : enabled_(enabled && ::isatty(2)), unit_(std::move(unit)), label_(std::move(label)), t0_(Clock::now()) {}
  bool operator()(int done, int total) {
    if (interruptNoticed()) return false;
    if (!enabled_) return true;
    const auto now = Clock::now();
    if (done < total && now - last_ < std::chrono::milliseconds(100)) return true;
    last_ = now;
    const double secs = std::chrono::duration<double>(now - t0_).count();
    const double rate = secs > 0 ? done / secs : 0.0;
    const int width = 30, filled = total > 0 ? width * std::min(done, total) / total : width;
    char eta[32] = "";
    if (done < total && rate > 0) std::snprintf(eta, sizeof eta, "  ETA %.0f s", (total - done) / rate);
    std::fprintf(stderr, "\r%s[%.*s%*s] %d/%d %s  %.0f %s/s%s   ", label_.c_str(), filled,
                 "##############################", width - filled, "", done, total, unit_.c_str(), rate,
                 unit_.c_str(), eta);
    open_ = done < total;
    if (!open_) std::fputc('\n', stderr);
    return true;
  }
  // Ends an unfinished bar's line.
  void end() {
    if (enabled_ && open_) std::fputc('\n', stderr);
    open_ = false;
  }
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
  bool operator()(pipeline::Stage stage, int done, int total) {
    if (interruptNoticed()) return false;
    if (!bar_ || stage != stage_ || done < last_) {
      if (bar_) bar_->end();
      stage_ = stage;
      const bool tracking = stage == pipeline::Stage::Tracking;
      bar_.emplace(!quiet_ && (!tracking || total >= 50), stage == pipeline::Stage::Frames ? "frames" : "steps",
                   stage == pipeline::Stage::OtherPaths ? "other paths " : "");
    }
    last_ = done;
    return (*bar_)(done, total);
  }
  void end() {
    if (bar_) bar_->end();
  }

 private:
  bool quiet_;
  pipeline::Stage stage_ = pipeline::Stage::Tracking;
  int last_ = 0;
  std::optional<ProgressBar> bar_;
};

pipeline::StudyOptions studyOptions(const Args& a, StudyProgress& progress) {
  pipeline::StudyOptions o;
  o.projection_seed = a.seed;
  o.progress = [&progress](pipeline::Stage s, int d, int t) { return progress(s, d, t); };
  return o;
}

int trackStatus(const engine::DeformationPath& r) {
  if (g_interrupted)
    return interrupted("after " + std::to_string(r.summary.steps_done) + " of " +
                       std::to_string(r.summary.steps_requested) + " steps; what was computed is kept");
  return r.summary.status == engine::TrackStatus::Success ? kExitOk : kExitStopped;
}

int cmdTrack(const Args& a) {
  if (a.positional.size() != 1) usageError("track takes one SCENE");
  const std::string ext = present::extensionOf(a.output);
  if (!a.output.empty() && ext != "json" && ext != "csv")
    usageError("track writes .json or .csv, not '" + a.output + "'");
  const scenes::Scene scene = scenes::loadScene(a.positional[0], a.overrides);
  if (!a.output.empty()) present::checkWritable(a.output, {scene.path});
  StudyProgress progress(a.quiet);
  pipeline::Study study(scene, studyOptions(a, progress));
  const engine::DeformationPath& path = study.motion().path;
  progress.end();
  if (a.output.empty()) {
    rawOut() << present::jsonText(present::pathJson(scene, path), 1) << "\n";
    std::cerr << path.summary.briefReport() << "\n";
  } else {
    study.write({a.output, scenes::OutputKind::Path}, a.output, {});
    std::cout << path.summary.briefReport() << "\nwrote " << a.output << "\n";
  }
  return trackStatus(path);
}

// The file name a command writes by default: the scene's stem with `ext`.
std::string defaultOutput(const std::string& scene_path, const std::string& ext) {
  std::string stem = present::stemOf(scene_path);
  if (stem.rfind("catalog:", 0) == 0) stem = stem.substr(8);
  return stem + "." + ext;
}

// The renderer, made on first use, or exit 3 with the reason.
class LazyRenderer {
 public:
  render::Renderer& operator()() {
    if (!renderer_) {
      try {
        renderer_ = std::make_unique<render::Renderer>();
      } catch (const std::runtime_error& e) {
        throw present::OutputError(std::string("cannot render: ") + e.what());
      }
    }
    return *renderer_;
  }

 private:
  std::unique_ptr<render::Renderer> renderer_;
};

void reportStop(const engine::DeformationPath& r, int wanted) {
  if (static_cast<int>(r.samples.size()) <= wanted)
    std::cerr << "flexure: the path stopped at sample " << r.samples.size() - 1 << " (" << r.summary.reason << ")\n";
}

int cmdRender(const Args& a) {
  if (a.positional.size() != 1) usageError("render takes one SCENE");
  const std::string out = a.output.empty() ? defaultOutput(a.positional[0], "png") : a.output;
  if (present::extensionOf(out) != "png") usageError("render writes .png, not '" + out + "'");
  const scenes::Scene scene = scenes::loadScene(a.positional[0], a.overrides);
  present::checkWritable(out, {scene.path});
  const int want = std::max({a.sample, 0, scene.render.style.ghost});
  StudyProgress progress(a.quiet);
  pipeline::StudyOptions options = studyOptions(a, progress);
  options.steps = want;  // only as far as the frame needs
  pipeline::Study study(scene, options);
  int status = kExitOk;
  if (want > 0) {
    const engine::DeformationPath& path = study.motion().path;
    progress.end();
    if (static_cast<int>(path.samples.size()) <= want) {
      reportStop(path, want);
      std::cerr << "flexure: rendering sample " << path.samples.size() - 1 << " instead\n";
      status = g_interrupted ? kExitInterrupted : kExitStopped;
    }
  }
  LazyRenderer renderer;
  scenes::OutputSpec spec{out, scenes::OutputKind::Frame, a.sample, a.flex};
  const present::Written w = study.write(spec, out, std::ref(renderer));
  std::cout << "wrote " << out << " (" << w.summary << ", " << static_cast<int>(1e3 * w.seconds) << " ms)\n";
  return status;
}

int cmdAnimate(const Args& a) {
  if (a.positional.size() != 1) usageError("animate takes one SCENE");
  const std::string out = a.output.empty() ? defaultOutput(a.positional[0], "mp4") : a.output;
  const std::string ext = present::extensionOf(out);
  if (ext != "mp4" && ext != "gif") usageError("animate writes .mp4 or .gif, not '" + out + "'");
  const scenes::Scene scene = scenes::loadScene(a.positional[0], a.overrides);
  present::checkWritable(out, {scene.path});
  StudyProgress progress(a.quiet);
  pipeline::Study study(scene, studyOptions(a, progress));
  const engine::DeformationPath& path = study.motion().path;
  progress.end();
  if (g_interrupted) return interrupted("while tracking; nothing was written");
  std::cerr << path.summary.briefReport() << "\n";
  if (scene.render.animation.side_by_side) study.projectionPaths();
  LazyRenderer renderer;
  const present::Written w = study.write({out, scenes::OutputKind::Animation}, out, std::ref(renderer));
  progress.end();
  std::cout << "wrote " << out << " (" << w.summary << ")\n";
  return trackStatus(path);
}

int cmdProject(const Args& a) {
  if (a.positional.size() != 1) usageError("project takes one SCENE");
  const std::string out = a.output.empty() ? defaultOutput(a.positional[0], "png") : a.output;
  const std::string ext = present::extensionOf(out);
  if (ext != "png" && ext != "mp4" && ext != "gif")
    usageError("project writes .png (or .mp4/.gif: the animated projection), not '" + out + "'");
  if (!a.data.empty() && present::extensionOf(a.data) != "csv") usageError("--data writes .csv, not '" + a.data + "'");
  const scenes::Scene scene = scenes::loadScene(a.positional[0], a.overrides);
  present::checkWritable(out, {scene.path});
  if (!a.data.empty()) present::checkWritable(a.data, {scene.path, out});
  StudyProgress progress(a.quiet);
  pipeline::Study study(scene, studyOptions(a, progress));
  study.motion();
  const auto& paths = study.projectionPaths();
  progress.end();
  if (g_interrupted) return interrupted("while tracking; nothing was written");
  for (const auto& p : paths) std::cerr << p.label << ": " << p.status << "\n";
  LazyRenderer renderer;
  const present::Written w = study.write({out, scenes::OutputKind::Projection}, out, std::ref(renderer), a.data);
  progress.end();
  std::cout << "projection seed " << study.projectionSeed() << "\nwrote " << out << " (" << w.summary << ")\n";
  if (!a.data.empty()) std::cout << "wrote " << a.data << "\n";
  bool complete = true;
  for (const auto& p : paths) complete = complete && p.complete;
  return complete ? kExitOk : kExitStopped;
}

// Every output of `outputs` from one tracked motion; file names relative to `dir` (empty: as
// written). Returns the exit status.
int produceOutputs(const scenes::Scene& scene, const std::vector<scenes::OutputSpec>& outputs, const std::string& dir,
                   const Args& a) {
  if (outputs.empty()) {
    std::cerr << scene.path << ": the scene declares no [[output]] (add e.g. [[output]] file = \"motion.mp4\")\n";
    return kExitInput;
  }
  for (const auto& o : outputs) present::checkWritable(pipeline::placeIn(dir, o.file), {scene.path});
  StudyProgress progress(a.quiet);
  pipeline::Study study(scene, studyOptions(a, progress));
  const auto t0 = std::chrono::steady_clock::now();
  const engine::DeformationPath& path = study.motion().path;
  progress.end();
  if (g_interrupted) return interrupted("while tracking; nothing was written");
  std::cout << path.summary.briefReport() << " ("
            << static_cast<int>(1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count())
            << " ms)\n";
  for (const auto& o : outputs)
    if (o.kind == scenes::OutputKind::Frame) reportStop(path, o.sample);
  LazyRenderer renderer;
  const pipeline::Study::RunResult r = study.run(outputs, dir, std::ref(renderer), [&](const present::Written& w) {
    progress.end();
    std::cout << "wrote " << w.file << " (" << w.summary << ")\n";
  });
  if (!r.stopped_before.empty())
    return interrupted("before " + r.stopped_before + "; the outputs listed above were written");
  return trackStatus(path);
}

// Throws OutputError when `path` would be written outside `dir` through a symbolic link: the
// deepest folder of it that exists must resolve to `dir` or below.
void confineTo(const std::string& dir, const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path base = fs::weakly_canonical(dir, ec);
  fs::path existing = fs::path(path).parent_path();
  while (!existing.empty() && !fs::exists(existing, ec)) existing = existing.parent_path();
  const fs::path real = fs::weakly_canonical(existing.empty() ? fs::path(".") : existing, ec);
  if (std::mismatch(base.begin(), base.end(), real.begin(), real.end()).first != base.end())
    throw present::OutputError("cannot write " + path + ": it leads out of " + dir + " (through " +
                               existing.string() + " -> " + real.string() + ")");
}

int cmdRun(const Args& a) {
  if (a.positional.size() != 1) usageError("run takes one SCENE");
  if (!a.output.empty()) usageError("run writes the scene's [[output]] files; -o does not apply");
  const scenes::Scene scene = scenes::loadScene(a.positional[0], a.overrides);
  // The scene's files go to its own folder (the scene language admits no absolute path and no
  // '..'); a folder inside it that is a link out of it is refused too.
  const std::string dir = !a.output_dir.empty() ? a.output_dir : present::directoryOf(scene.path);
  if (!a.output_dir.empty()) present::makeDirectories(dir);
  for (const auto& o : scene.outputs) confineTo(dir, pipeline::placeIn(dir, o.file));
  return produceOutputs(scene, scene.outputs, dir == "." ? "" : dir, a);
}

int cmdCatalog(const Args& a) {
  if (!a.positional.empty()) usageError("catalog takes no arguments");
  for (const auto& e : scenes::catalog()) {
    const scenes::Scene s = scenes::loadSceneFromString(e.text, "catalog:" + e.name);
    const auto& sys = s.model->system();
    std::printf("%-38s %-10s %dD %3d vertices  %s\n", e.name.c_str(), s.type.c_str(),
                sys.dimension(), sys.numVertices(), s.title.c_str());
  }
  return kExitOk;
}

int cmdKeys(const Args& a) {
  if (!a.positional.empty()) usageError("keys takes no arguments");
  std::cout << scenes::keyReferenceMarkdown();
  return kExitOk;
}

int cmdDemo(const Args& a) {
  if (a.positional.size() > 1) usageError("demo takes at most one DIR");
  const std::string dir = a.positional.empty() ? "flexure-demo" : a.positional[0];
  const scenes::CatalogEntry* entry = scenes::findCatalogEntry("double_watt");
  const scenes::Scene scene = scenes::loadSceneFromString(entry->text, "catalog:double_watt", a.overrides);
  const engine::RigidityReport rep = pipeline::analyze(scene);
  present::makeDirectories(dir);
  const std::string scene_file = dir + "/double_watt.toml";
  const std::string report_file = dir + "/double_watt_analysis.json";
  present::writeFileAtomically(scene_file, entry->text);
  present::writeFileAtomically(report_file, present::jsonText(present::analysisJson(scene, rep), 2) + "\n");
  std::cout << present::analysisText(scene, rep);
  std::cout << "wrote " << scene_file << "\nwrote " << report_file << "\n";
  // The path, a picture, both animations and the projection.
  using K = scenes::OutputKind;
  const std::vector<scenes::OutputSpec> outputs = {{"double_watt_path.json", K::Path},
                                                   {"double_watt.png", K::Frame},
                                                   {"double_watt.mp4", K::Animation},
                                                   {"double_watt.gif", K::Animation},
                                                   {"double_watt_projection.png", K::Projection}};
  return produceOutputs(scene, outputs, dir, a);
}

int cmdView(const Args& a) {
  if (a.positional.size() != 1) usageError("view takes one SCENE");
  if (!a.output.empty()) usageError("view writes nothing but what you save from the page; -o does not apply");
  viewer::SessionOptions so;
  so.overrides = a.overrides;
  if (!a.quiet) so.log = [](const std::string& line) { std::cerr << "flexure view: " << line << "\n"; };
  viewer::Session session(a.positional[0], so);
  viewer::Server server(session, {});
  constexpr int kDefaultPort = 8765;
  int port = -1;
  if (a.port) {
    port = server.bind(*a.port);
    if (port < 0) {
      std::cerr << "flexure: cannot listen on 127.0.0.1:" << *a.port << " (in use?); --port 0 takes any free port\n";
      return kExitInput;
    }
  } else {
    for (int p = kDefaultPort; p < kDefaultPort + 20 && port < 0; ++p) port = server.bind(p);
    if (port < 0) port = server.bind(0);
    if (port < 0) {
      std::cerr << "flexure: cannot listen on 127.0.0.1\n";
      return kExitOutput;
    }
  }
  std::cout << "flexure view: http://127.0.0.1:" << port << "/  (" << a.positional[0]
            << "; Ctrl-C stops)" << std::endl;
  // From here the server looks at the flag every 50 ms: an interruption is always noticed, and
  // stopping may wait for open connections to time out (2 s) without being cut short.
  g_noticed = 1;
  server.run(&g_interrupted);
  std::cerr << "flexure view: stopped\n";
  // The viewer has nothing left to write (saves are complete files): it does not wait for a
  // computation in progress in the session to finish.
  ::_exit(finish(kExitOk));
}

int dispatch(const Args& args);

}  // namespace

int main(int argc, char** argv) {
  static SafeStreams streams;  // static: std::exit() (usage errors) flushes it too
  installSignalHandlers();
  return finish(dispatch(parseArgs(argc, argv)));
}

namespace {

int dispatch(const Args& args) {
  try {
    if (args.command == "analyze") return cmdAnalyze(args);
    if (args.command == "catalog") return cmdCatalog(args);
    if (args.command == "keys") return cmdKeys(args);
    if (args.command == "track") return cmdTrack(args);
    if (args.command == "render") return cmdRender(args);
    if (args.command == "animate") return cmdAnimate(args);
    if (args.command == "project") return cmdProject(args);
    if (args.command == "run") return cmdRun(args);
    if (args.command == "demo") return cmdDemo(args);
    return cmdView(args);  // CLI11 admits no other command
  } catch (const scenes::SceneError& e) {
    std::cerr << e.what() << "\n";
    return kExitInput;
  } catch (const present::OutputError& e) {
    std::cerr << "flexure: " << e.what() << "\n";
    return kExitOutput;
  } catch (const render::VideoInterrupted& e) {
    std::cerr << "\nflexure: interrupted (" << e.what() << "); nothing was written under the output's name\n";
    return kExitInterrupted;
  } catch (const std::invalid_argument& e) {
    std::cerr << "flexure: " << e.what() << "\n";
    return kExitInput;
  } catch (const std::runtime_error& e) {
    std::cerr << "flexure: " << e.what() << "\n";
    return kExitOutput;
  } catch (const std::bad_alloc&) {
    std::cerr << "flexure: out of memory\n";
    return kExitInput;
  }
}

}  // namespace
