// The command line (SPEC section 1): parsing, signals, progress, and the commands that draw
// nothing (analyze, track, catalog, keys); the commands that draw go to drawingCommand().
#include "cli/cli.h"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "engine/resources.h"
#include "engine/rigidity.h"
#include "present/output_file.h"
#include "present/path_output.h"
#include "present/report.h"
#include "present/text.h"
#include "render/provenance.h"
#include "render/reproducible.h"
#include "scenes/catalog.h"
#include "scenes/keys.h"
#include "scenes/scene.h"

namespace flexure::cli {

char** g_argv = nullptr;

namespace {

const char* kDescription = "flexure " FLEXURE_VERSION " - continuous motions of geometric constraint systems";
const char* kFooter =
    "Exit status: 0 success, 1 wrong input, 2 computation stopped early, 3 output not written,\n"
    "130 interrupted (Ctrl-C). 'flexure COMMAND --help' shows a command's options.";


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

}  // namespace

// What the program prints goes through terminal filters (present::TerminalFilter): a scene's
// title or expression cannot send escape sequences to the terminal. JSON, already escaped,
// goes to the raw standard output.
std::ostream& rawOut() {
  static std::ostream raw(std::cout.rdbuf());
  return raw;
}


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

namespace {

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
  std::string sample_text, samples_text, stress_text, seed_text, port_text;
  auto scene = [&](CLI::App* c, const char* what = "SCENE") {
    c->add_option(what, a.positional, std::string(what) == "DIR" ? "where to write (default flexure-demo)"
                                                                  : "the scene: a TOML scene file, a path JSON (its scene), a catalog "
                                                                    "name (flexure catalog), or a file to import: .fold, graph6/sparse6 "
                                                                    "(.g6, .s6), an edge list (.edges), node-link .json, .off, .obj, .stl")
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
  analyze->add_flag("--exact", a.exact,
                    "also in exact rational arithmetic: proved counts, inf_rigid and prestress stability "
                    "(rational coordinates; [analysis] exact)");
  analyze->add_flag("--certify", a.certify,
                    "also prove in interval arithmetic what can be proved about the start as given: infinitesimal "
                    "rigidity or flexibility at a regular point ([analysis] certify)");
  CLI::App* track = scene(app.add_subcommand("track", "the deformation path (JSON on stdout without -o)"));
  output(track, "PATH.json, PATH.csv or (origami) PATH.fold");
  track->add_flag("--certify", a.certify,
                  "certify every sample and step in interval arithmetic (Krawczyk; [motion] certify): the path "
                  "JSON's \"certified\" and \"certificate\"");
  CLI::App* render = scene(app.add_subcommand("render", "one frame (the start, or sample K of the path) or a filmstrip"));
  output(render, "OUT.png, .svg, .pdf, .tex (TikZ), or .obj/.stl: a solid for 3D printing (default: the scene's name .png)");
  render->add_option("--sample", sample_text, "the sample to draw (0: the start)")->type_name("K");
  render->add_option("--samples", samples_text, "a filmstrip: these samples in one figure, side by side "
                     "([render] filmstrip_overlay: overlaid)")->type_name("K,K,...");
  render->add_flag("--flex", a.flex, "draw the selected infinitesimal flex as arrows");
  render->add_option("--stress", stress_text, "draw equilibrium stress K of the basis (0: the first; [render] stress): "
                     "tension red, compression blue, widths by magnitude")->type_name("K");
  CLI::App* animate = scene(app.add_subcommand("animate", "animation of the deformation path"));
  output(animate, "OUT.mp4 or OUT.gif (default: the scene's name .mp4)");
  seed(animate);
  CLI::App* project = scene(app.add_subcommand("project", "random 2D projection of the deformation path"));
  output(project, "OUT.png, or OUT.mp4/OUT.gif for the animated projection (default: the scene's name _projection.png)");
  seed(project);
  project->add_option("--data", a.data, "the projected coordinates as CSV")->type_name("OUT.csv");
  std::string branch_text;
  for (CLI::App* c : {track, render, animate, project})
    c->add_option("--branch", branch_text,
                  "from sample K on, follow direction J of the tangent cone there (both from 0: the path JSON lists "
                  "the directions at each singular sample; [motion] branch)")
        ->type_name("K:J");
  CLI::App* run = scene(app.add_subcommand("run", "every [[output]] the scene declares, in the scene's folder"));
  seed(run);
  run->add_option("--output-dir", a.output_dir, "write the [[output]] files under DIR instead of the scene's folder")
      ->type_name("DIR");
  CLI::App* demo = scene(app.add_subcommand("demo", "the default scene (double Watt mechanism): report, path, PNG, "
                                                    "MP4, GIF, projection, into DIR (default flexure-demo)"),
                         "DIR");
  seed(demo);
  CLI::App* sweep = app.add_subcommand(
      "sweep", "one job over a family of systems, as JSON Lines: sweep analyze|track INPUT, sweep merge SHARD...|DIR");
  sweep->add_option("WORDS", a.positional, "analyze, track or merge, then INPUT (a graph6/sparse6 file or - for "
                                             "geng's output, a directory or list of scenes, a scene with [sweep]) "
                                             "or the shards to merge")
      ->type_name("");
  sweep->add_option("-o,--output", a.output, "OUT.jsonl (default: standard output); an existing OUT is continued")
      ->type_name("FILE");
  sweep->add_option("--dimension", a.dimension, "graph input: realize in 2 or 3 dimensions (default 2)")->type_name("D");
  sweep->add_option("--seed", a.sweep_seed, "graph input: the seed every realization's seed derives from (default 1)")
      ->type_name("S");
  sweep->add_option("--realizations", a.realizations, "graph input: random realizations per graph (default 1)")
      ->type_name("K");
  sweep->add_option("--slice", a.slice, "run only the items whose id is k modulo N (k from 0)")->type_name("k/N");
  sweep->add_option("--threads", a.threads, "worker threads (default: every core)")->type_name("T");
  sweep->add_option("--where", a.where, "keep the results of the items this holds for, e.g. "
                                         "\"nontrivial_inf_flexes > 0 and stress_dim > 0\"")
      ->type_name("EXPR");
  sweep->add_option("--fields", a.fields,
                    "keep only these result fields on each line, e.g. rigidity_rank,stress_dim (with the item's id, "
                    "input, status); when they and --where's are counts, analyze computes the counts alone")
      ->type_name("LIST");
  sweep->add_flag("--samples", a.samples, "track: the path's samples on each line");
  sweep->add_flag("--certify", a.certify,
                  "analyze: prove each verdict in interval arithmetic; track: certify each path (Krawczyk); the "
                  "lines' \"certified\" and \"certificate\", e.g. --where certified");
  sweep->add_flag("--slurm", a.slurm, "submit the sweep as a Slurm job array and a merge job");
  sweep->add_flag("--dry-run", a.dry_run, "with --slurm: print the scripts and commands, submit nothing");
  sweep->add_option("--tasks", a.tasks, "with --slurm: array tasks, one slice each (default 4); with merge DIR: the shards of N")->type_name("N");
  sweep->add_option("--max-running", a.max_running, "with --slurm: at most M tasks at once")->type_name("M");
  sweep->add_option("--cpus-per-task", a.cpus, "with --slurm: threads per task (default 1)")->type_name("C");
  sweep->add_option("--partition", a.partition, "with --slurm: the partition")->type_name("P");
  sweep->add_option("--time", a.time_limit, "with --slurm: each task's time limit (Slurm's format, e.g. 2:00:00)")
      ->type_name("T");
  sweep->add_option("--account", a.account, "with --slurm: the account to charge")->type_name("A");
  app.add_subcommand("catalog", "the built-in named systems; catalog NAME prints that entry's scene")
      ->add_option("NAME", a.positional, "an entry's name: its scene file is printed")
      ->type_name("");
  app.add_subcommand("keys", "every scene key: table, type, range, default, what it is (Markdown)")
      ->add_flag("--types", a.types, "the table of system types instead (Markdown)");
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
  if (render->count("--stress"))  // as --set render.stress=K (checked here, with the option's name)
    a.overrides.push_back("render.stress=" + std::to_string(parseCount("--stress", stress_text, 100000, "a stress number 0..100000")));
  if (render->count("--samples")) {
    if (render->count("--sample")) usageError("render takes --sample K or --samples K,K,..., not both");
    size_t from = 0;
    while (from <= samples_text.size()) {
      const size_t comma = std::min(samples_text.find(',', from), samples_text.size());
      a.frame_samples.push_back(static_cast<int>(
          parseCount("--samples", samples_text.substr(from, comma - from), scenes::kMaxSteps,
                     "sample numbers 0..10000000 separated by commas, e.g. 0,60,120")));
      from = comma + 1;
    }
    if (a.frame_samples.size() > 64) usageError("--samples: at most 64 samples in one figure");
  }
  for (CLI::App* c : {track, render, animate, project})
    if (c->count("--branch")) {
      const size_t colon = branch_text.find(':');
      const std::string needs = "K:J, a sample and a direction, both from 0 (e.g. 40:1)";
      if (colon == std::string::npos) usageError("--branch needs " + needs + ", not '" + branch_text + "'");
      const auto k = parseCount("--branch", branch_text.substr(0, colon), scenes::kMaxSteps, needs);
      const auto j = parseCount("--branch", branch_text.substr(colon + 1), 1000, needs);
      a.overrides.push_back("motion.branch=[" + std::to_string(k) + "," + std::to_string(j) + "]");
    }
  for (CLI::App* c : {animate, project, run, demo})
    if (c->count("--seed")) a.seed = parseCount("--seed", seed_text, ~0ull, "a nonnegative integer");
  if (view->count("--port")) a.port = static_cast<int>(parseCount("--port", port_text, 65535, "a port number 0..65535"));
  return a;
}

int cmdAnalyze(const Args& a) {
  if (a.positional.size() != 1) usageError("analyze takes one SCENE");
  std::vector<std::string> overrides = a.overrides;
  if (a.exact) overrides.push_back("analysis.exact=true");
  if (a.certify) overrides.push_back("analysis.certify=true");
  const scenes::Scene scene = scenes::loadScene(a.positional[0], overrides);
  const engine::RigidityReport rep = pipeline::analyze(scene);
  // Interrupted while the analysis finished within the second it is given: the user asked to
  // stop, so no report (a large polytope's hull and analysis ended with exit 0 before).
  if (g_interrupted) return interrupted("during the analysis; nothing was written");
  if (a.json) rawOut() << present::jsonText(present::analysisJson(scene, rep), 2) << "\n";
  else std::cout << present::analysisText(scene, rep);
  return kExitOk;
}

}  // namespace

// Ctrl-C and SIGTERM. The first asks a computation to stop at its next step or frame and keep
// what it has; a stage that has not noticed within a second (a scene read from a FIFO, one
// long factorization) is cut short, and so is everything at a second signal. Cutting short
// removes any temporary name first (outputs in progress are unnamed files: nothing is left).
volatile std::sig_atomic_t g_interrupted = 0;
volatile std::sig_atomic_t g_noticed = 0;

namespace {

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

}  // namespace

// True once interrupted; the interruption counts as noticed (no cut after a second).
bool interruptNoticed() {
  if (!g_interrupted) return false;
  g_noticed = 1;
  return true;
}

namespace {

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
  // A reader that goes away (`flexure keys | head -1`) makes a write fail with EPIPE, which
  // finish() reports as exit 3, instead of killing the process with SIGPIPE (exit 141).
  sigaction(SIGPIPE, &sa, nullptr);
}

}  // namespace

// Says where an interruption stopped things; the exit status for it.
int interrupted(const std::string& where) {
  std::cerr << "\nflexure: interrupted " << where << "\n";
  return kExitInterrupted;
}

ProgressBar::ProgressBar(bool enabled, std::string unit, std::string label)
    : enabled_(enabled && ::isatty(2)), unit_(std::move(unit)), label_(std::move(label)), t0_(Clock::now()) {}

bool ProgressBar::operator()(int done, int total) {
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

void ProgressBar::end() {
  if (enabled_ && open_) std::fputc('\n', stderr);
  open_ = false;
}

bool StudyProgress::operator()(pipeline::Stage stage, int done, int total) {
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

pipeline::StudyOptions studyOptions(const Args& a, StudyProgress& progress) {
  pipeline::StudyOptions o;
  o.projection_seed = a.seed;
  o.progress = [&progress](pipeline::Stage s, int d, int t) { return progress(s, d, t); };
  return o;
}

std::string eventLines(const engine::DeformationPath& r) {
  std::string out;
  for (const engine::TrackEvent& e : r.events)
    if (e.kind == engine::EventKind::Intersection) out += "sample " + std::to_string(e.sample) + ": " + e.detail + "\n";
  return out;
}

int trackStatus(const engine::DeformationPath& r) {
  if (g_interrupted)
    return interrupted("after " + std::to_string(r.summary.steps_done) + " of " +
                       std::to_string(r.summary.steps_requested) + " steps; what was computed is kept");
  return r.summary.status == engine::TrackStatus::Success ? kExitOk : kExitStopped;
}

namespace {

// track --certify: one line saying what is certified.
std::string certificateLine(const engine::DeformationPath& path) {
  if (!path.certificate) return "";
  const engine::PathCertificate& c = *path.certificate;  // the summary: bounded, the whole in the JSON
  return std::string(c.certified() ? "certified: " : "not certified: ") + (c.summary.empty() ? c.reason : c.summary) + "\n";
}

int cmdTrack(const Args& a) {
  if (a.positional.size() != 1) usageError("track takes one SCENE");
  std::vector<std::string> overrides = a.overrides;
  if (a.certify) overrides.push_back("motion.certify=true");
  const std::string ext = present::extensionOf(a.output);
  if (!a.output.empty() && ext != "json" && ext != "csv" && ext != "fold")
    usageError("track writes .json, .csv or (origami) .fold, not '" + a.output + "'");
  const scenes::Scene scene = scenes::loadScene(a.positional[0], overrides);
  if (ext == "fold" && !present::writesFold(scene))
    usageError("a .fold path is for origami scenes; " + a.positional[0] + " is a " + scene.type + " (write .json or .csv)");
  if (!a.output.empty()) present::checkWritable(a.output, {scene.path});
  StudyProgress progress(a.quiet);
  pipeline::Study study(scene, studyOptions(a, progress));
  const engine::DeformationPath& path = study.motion().path;
  progress.end();
  if (a.output.empty()) {
    rawOut() << present::jsonText(present::pathJson(scene, path), 1) << "\n";
    std::cerr << path.summary.briefReport() << "\n" << eventLines(path) << certificateLine(path);
  } else {
    present::writePath(scene, path, a.output);
    std::cout << path.summary.briefReport() << "\n" << eventLines(path) << certificateLine(path) << "wrote " << a.output
              << "\n";
  }
  return trackStatus(path);
}
// `catalog`: the entries, one line each; `catalog NAME`: the entry's scene, as a file to start
// from (`flexure catalog cube > my_cube.toml`).
int cmdCatalog(const Args& a) {
  if (a.positional.size() > 1) usageError("catalog takes at most one NAME");
  if (a.positional.size() == 1) {
    const std::string& name = a.positional[0];
    const scenes::CatalogEntry* e = scenes::findCatalogEntry(name.rfind("catalog:", 0) == 0 ? name.substr(8) : name);
    if (!e) usageError(scenes::unknownCatalogName(name));
    rawOut() << e->text;
    return kExitOk;
  }
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
  std::cout << (a.types ? scenes::systemTypesMarkdown() : scenes::keyReferenceMarkdown());
  return kExitOk;
}

int dispatch(const Args& args) {
  try {
    if (args.command == "analyze") return cmdAnalyze(args);
    if (args.command == "catalog") return cmdCatalog(args);
    if (args.command == "keys") return cmdKeys(args);
    if (args.command == "track") return cmdTrack(args);
    if (args.command == "sweep") return sweepCommand(args);
    return drawingCommand(args);  // render, animate, project, run, demo, view
  } catch (const scenes::SceneError& e) {
    std::cerr << e.what() << "\n";
    return kExitInput;
  } catch (const present::OutputError& e) {
    std::cerr << "flexure: " << e.what() << "\n";
    return kExitOutput;
  } catch (const std::invalid_argument& e) {
    std::cerr << "flexure: " << e.what() << "\n";
    return kExitInput;
  } catch (const engine::ResourceError& e) {  // the input asks for more memory than there is
    // Named by the input that asks for it (a sweep's items report theirs on their lines).
    const size_t input = args.command == "sweep" ? 1 : 0;
    std::cerr << "flexure: " << (args.positional.size() > input ? args.positional[input] + ": " : std::string())
              << e.what() << "\n";
    return kExitInput;
  } catch (const nlohmann::json::exception& e) {  // a JSON value of the wrong type, wherever read
    std::cerr << "flexure: " << e.what() << "\n";
    return kExitInput;
  } catch (const std::runtime_error& e) {
    std::cerr << "flexure: " << e.what() << "\n";
    return kExitOutput;
  } catch (const std::bad_alloc&) {
    std::cerr << "flexure: out of memory\n";
    return kExitInput;
  } catch (const std::exception& e) {  // anything else: said, never an abort
    std::cerr << "flexure: " << e.what() << "\n";
    return kExitInput;
  }
}

}  // namespace

int main(int argc, char** argv) {
  g_argv = argv;
  render::setCommandLine(std::vector<std::string>(argv, argv + argc));
  static SafeStreams streams;  // static: std::exit() (usage errors) flushes it too
  installSignalHandlers();
  try {
    render::sourceDateEpoch();  // a malformed value is refused before any work
  } catch (const std::invalid_argument& e) {
    std::cerr << "flexure: " << e.what() << "\n";
    return kExitInput;
  }
  return finish(dispatch(parseArgs(argc, argv)));
}

}  // namespace flexure::cli
