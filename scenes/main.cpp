// flexure: continuous motions of geometric constraint systems. The command line (SPEC section 1).
#include <unistd.h>

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

#include "engine/motion_tracker.h"
#include "engine/rigidity.h"
#include "render/renderer.h"
#include "scenes/catalog.h"
#include "scenes/output_file.h"
#include "scenes/outputs.h"
#include "scenes/path_output.h"
#include "scenes/report.h"
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

const char* kUsage =
    "flexure " FLEXURE_VERSION " - continuous motions of geometric constraint systems\n"
    "\n"
    "usage:\n"
    "  flexure analyze SCENE [--json]   rigidity report of the start configuration\n"
    "  flexure track SCENE [-o PATH.json|PATH.csv]\n"
    "                                   the deformation path (JSON on stdout without -o)\n"
    "  flexure render SCENE [-o OUT.png] [--sample K] [--flex]\n"
    "                                   one frame: the start, or sample K of the path;\n"
    "                                   --flex draws the selected infinitesimal flex\n"
    "  flexure animate SCENE [-o OUT.mp4|OUT.gif]\n"
    "                                   animation of the deformation path\n"
    "  flexure project SCENE [-o OUT.png|OUT.mp4|OUT.gif] [--seed S] [--data OUT.csv]\n"
    "                                   random 2D projection of the deformation path\n"
    "  flexure run SCENE                every [[output]] the scene declares\n"
    "  flexure catalog                  the built-in named systems\n"
    "  flexure demo [DIR]               the default scene (double Watt mechanism): report,\n"
    "                                   path, PNG, MP4, GIF, projection, into DIR (default\n"
    "                                   flexure-demo)\n"
    "  flexure view SCENE [--port P]    interactive viewer in the browser, on 127.0.0.1 only\n"
    "                                   (port 8765 or the next free one); follows the scene\n"
    "                                   file as it is edited\n"
    "\n"
    "options:\n"
    "  --set KEY=VALUE   override a scene key, e.g. --set motion.steps=50 (repeatable)\n"
    "  --json            machine-readable output (analyze)\n"
    "  --seed S          the projection's seed (project, and side-by-side animations)\n"
    "  --data OUT.csv    the projected coordinates (project)\n"
    "  --port P          the viewer's port (view; 0: any free port)\n"
    "  --quiet           no progress on stderr\n"
    "  --help, --version\n"
    "\n"
    "exit status: 0 success, 1 wrong input, 2 computation stopped early, 3 output not written,\n"
    "130 interrupted (Ctrl-C).\n";

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
};

[[noreturn]] void usageError(const std::string& message) {
  std::cerr << "flexure: " << message << "\n\n" << kUsage;
  std::exit(kExitInput);
}

Args parseArgs(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string s = argv[i];
    if (s == "--help" || s == "-h") {
      std::cout << kUsage;
      std::exit(kExitOk);
    } else if (s == "--version") {
      std::cout << "flexure " FLEXURE_VERSION "\n";
      std::exit(kExitOk);
    } else if (s == "--json") {
      a.json = true;
    } else if (s == "--quiet" || s == "-q") {
      a.quiet = true;
    } else if (s == "--set") {
      if (i + 1 >= argc) usageError("--set needs KEY=VALUE");
      a.overrides.push_back(argv[++i]);
    } else if (s == "--flex") {
      a.flex = true;
    } else if (s == "--sample") {
      if (i + 1 >= argc) usageError("--sample needs a sample number");
      char* end = nullptr;
      const long v = std::strtol(argv[++i], &end, 10);
      if (*end != '\0' || v < 0 || v > 100000000) usageError("--sample needs a sample number >= 0, not '" + std::string(argv[i]) + "'");
      a.sample = static_cast<int>(v);
    } else if (s == "--seed") {
      if (i + 1 >= argc) usageError("--seed needs a number");
      char* end = nullptr;
      const unsigned long long v = std::strtoull(argv[++i], &end, 10);
      if (*end != '\0' || argv[i][0] == '-' || argv[i][0] == '\0') usageError("--seed needs a nonnegative integer, not '" + std::string(argv[i]) + "'");
      a.seed = v;
    } else if (s == "--port") {
      if (i + 1 >= argc) usageError("--port needs a port number");
      char* end = nullptr;
      const long v = std::strtol(argv[++i], &end, 10);
      if (*end != '\0' || argv[i][0] == '\0' || v < 0 || v > 65535)
        usageError("--port needs a port number 0..65535, not '" + std::string(argv[i]) + "'");
      a.port = static_cast<int>(v);
    } else if (s == "--data") {
      if (i + 1 >= argc) usageError("--data needs a file name");
      a.data = argv[++i];
    } else if (s == "-o" || s == "--output") {
      if (i + 1 >= argc) usageError(s + " needs a file name");
      a.output = argv[++i];
    } else if (s.rfind("--set=", 0) == 0) {
      a.overrides.push_back(s.substr(6));
    } else if (!s.empty() && s[0] == '-') {
      usageError("unknown option '" + s + "'");
    } else if (a.command.empty()) {
      a.command = s;
    } else {
      a.positional.push_back(s);
    }
  }
  if (a.command.empty()) usageError("no command given");
  return a;
}

int cmdAnalyze(const Args& a) {
  if (a.positional.size() != 1) usageError("analyze takes one SCENE");
  const scenes::Scene scene = scenes::loadScene(a.positional[0], a.overrides);
  const engine::RigidityReport rep = scenes::analyzeScene(scene);
  if (a.json) std::cout << scenes::analysisJson(scene, rep).dump(2) << "\n";
  else std::cout << scenes::analysisText(scene, rep);
  return kExitOk;
}

// Ctrl-C: long computations stop at the next step or frame and say so.
volatile std::sig_atomic_t g_interrupted = 0;
// A second Ctrl-C does not wait for the first one to be noticed (a computation that checks
// only between its steps, the viewer finishing a long analysis).
extern "C" void onInterrupt(int) {
  if (g_interrupted) ::_exit(kExitInterrupted);
  g_interrupted = 1;
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
    if (g_interrupted) return false;
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

std::string lowerExtension(const std::string& path) { return scenes::extensionOf(path); }

// The scene's motion with a progress bar; reports an interruption.
scenes::Motion track(const scenes::Scene& scene, int steps, bool quiet,
                     const std::vector<double>* coefficients = nullptr) {
  ProgressBar bar(!quiet && steps >= 50, "steps");
  scenes::Motion m = scenes::trackScene(scene, steps, [&](int d, int t) { return bar(d, t); }, coefficients);
  bar.end();
  return m;
}

int trackStatus(const engine::TrackResult& r) {
  if (g_interrupted)
    return interrupted("after " + std::to_string(r.summary.steps_done) + " of " +
                       std::to_string(r.summary.steps_requested) + " steps; what was computed is kept");
  return r.summary.status == engine::TrackStatus::Success ? kExitOk : kExitStopped;
}

int cmdTrack(const Args& a) {
  if (a.positional.size() != 1) usageError("track takes one SCENE");
  const std::string ext = lowerExtension(a.output);
  if (!a.output.empty() && ext != "json" && ext != "csv")
    usageError("track writes .json or .csv, not '" + a.output + "'");
  const scenes::Scene scene = scenes::loadScene(a.positional[0], a.overrides);
  const scenes::Motion m = track(scene, scene.motion.steps, a.quiet);
  const engine::TrackResult& result = m.result;
  if (a.output.empty()) {
    std::cout << scenes::pathJson(scene, result, m.coefficients, m.note).dump(1) << "\n";
    std::cerr << result.summary.briefReport() << "\n";
  } else {
    scenes::writePath(scene, m, a.output);
    std::cout << result.summary.briefReport() << "\nwrote " << a.output << "\n";
  }
  return trackStatus(result);
}

// The file name a command writes by default: the scene's stem with `ext`.
std::string defaultOutput(const std::string& scene_path, const std::string& ext) {
  std::string stem = scenes::stemOf(scene_path);
  if (stem.rfind("catalog:", 0) == 0) stem = stem.substr(8);
  return stem + "." + ext;
}

// The renderer, or exit 3 with the reason.
std::unique_ptr<render::Renderer> makeRenderer() {
  try {
    return std::make_unique<render::Renderer>();
  } catch (const std::runtime_error& e) {
    throw scenes::OutputError(std::string("cannot render: ") + e.what());
  }
}

void reportStop(const engine::TrackResult& r, int wanted) {
  if (static_cast<int>(r.samples.size()) <= wanted)
    std::cerr << "flexure: the path stopped at sample " << r.samples.size() - 1 << " (" << r.summary.reason << ")\n";
}

int cmdRender(const Args& a) {
  if (a.positional.size() != 1) usageError("render takes one SCENE");
  const std::string out = a.output.empty() ? defaultOutput(a.positional[0], "png") : a.output;
  if (lowerExtension(out) != "png") usageError("render writes .png, not '" + out + "'");
  const scenes::Scene scene = scenes::loadScene(a.positional[0], a.overrides);
  const scenes::FigureStyle& style = scene.render.style;
  const int want = std::max({a.sample, 0, style.ghost});
  int status = kExitOk;
  std::optional<scenes::Motion> m;
  if (want > 0) {
    m = track(scene, want, a.quiet);
    if (static_cast<int>(m->result.samples.size()) <= want) {
      reportStop(m->result, want);
      std::cerr << "flexure: rendering sample " << m->result.samples.size() - 1 << " instead\n";
      status = g_interrupted ? kExitInterrupted : kExitStopped;
    }
  }
  auto renderer = makeRenderer();
  const scenes::Written w = scenes::writeFrame(scene, m ? &*m : nullptr, a.sample, a.flex, out, *renderer);
  std::cout << "wrote " << out << " (" << w.summary << ", " << static_cast<int>(1e3 * w.seconds) << " ms)\n";
  return status;
}

int cmdAnimate(const Args& a) {
  if (a.positional.size() != 1) usageError("animate takes one SCENE");
  const std::string out = a.output.empty() ? defaultOutput(a.positional[0], "mp4") : a.output;
  const std::string ext = lowerExtension(out);
  if (ext != "mp4" && ext != "gif") usageError("animate writes .mp4 or .gif, not '" + out + "'");
  const scenes::Scene scene = scenes::loadScene(a.positional[0], a.overrides);
  scenes::makeDirectories(scenes::directoryOf(out));
  const scenes::Motion m = track(scene, scene.motion.steps, a.quiet);
  if (g_interrupted) return interrupted("while tracking; nothing was written");
  std::cerr << m.result.summary.briefReport() << "\n";
  std::vector<scenes::ProjectionPath> paths;
  const std::uint64_t seed = a.seed ? *a.seed : scene.projection.seed.value_or(scene.motion.seed);
  if (scene.render.animation.side_by_side) paths = scenes::projectionPaths(scene, m);
  auto renderer = makeRenderer();
  ProgressBar bar(!a.quiet, "frames");
  const scenes::Written w = scenes::writeAnimation(scene, m, out, *renderer, &paths, seed,
                                                   [&](int d, int t) { return bar(d, t); });
  bar.end();
  std::cout << "wrote " << out << " (" << w.summary << ")\n";
  return trackStatus(m.result);
}

int cmdProject(const Args& a) {
  if (a.positional.size() != 1) usageError("project takes one SCENE");
  const std::string out = a.output.empty() ? defaultOutput(a.positional[0], "png") : a.output;
  const std::string ext = lowerExtension(out);
  if (ext != "png" && ext != "mp4" && ext != "gif")
    usageError("project writes .png (or .mp4/.gif: the animated projection), not '" + out + "'");
  if (!a.data.empty() && lowerExtension(a.data) != "csv") usageError("--data writes .csv, not '" + a.data + "'");
  const scenes::Scene scene = scenes::loadScene(a.positional[0], a.overrides);
  const std::uint64_t seed = a.seed ? *a.seed : scene.projection.seed.value_or(scene.motion.seed);
  const scenes::Motion m = track(scene, scene.motion.steps, a.quiet);
  ProgressBar steps(!a.quiet, "steps", "other paths ");
  const auto paths = scenes::projectionPaths(scene, m, [&](int d, int t) { return steps(d, t); });
  steps.end();
  if (g_interrupted) return interrupted("while tracking; nothing was written");
  for (const auto& p : paths) std::cerr << p.label << ": " << p.status << "\n";
  auto renderer = makeRenderer();
  ProgressBar bar(!a.quiet && ext != "png", "frames");
  const scenes::Written w =
      scenes::writeProjection(scene, paths, seed, out, a.data, *renderer, [&](int d, int t) { return bar(d, t); });
  bar.end();
  std::cout << "projection seed " << seed << "\nwrote " << out << " (" << w.summary << ")\n";
  if (!a.data.empty()) std::cout << "wrote " << a.data << "\n";
  bool complete = true;
  for (const auto& p : paths) complete = complete && p.complete;
  return complete ? kExitOk : kExitStopped;
}

// Every [[output]] of a scene, from one tracked motion; file names relative to `dir` (empty:
// as written). Returns the exit status.
int produceOutputs(const scenes::Scene& scene, const std::vector<scenes::OutputSpec>& outputs, const std::string& dir,
                   const Args& a) {
  if (outputs.empty()) {
    std::cerr << scene.path << ": the scene declares no [[output]] (add e.g. [[output]] file = \"motion.mp4\")\n";
    return kExitInput;
  }
  auto place = [&](const std::string& f) { return dir.empty() || (!f.empty() && f[0] == '/') ? f : dir + "/" + f; };
  for (const auto& o : outputs) scenes::makeDirectories(scenes::directoryOf(place(o.file)));
  const auto t0 = std::chrono::steady_clock::now();
  const scenes::Motion m = track(scene, scene.motion.steps, a.quiet);
  if (g_interrupted) return interrupted("while tracking; nothing was written");
  std::cout << m.result.summary.briefReport() << " ("
            << static_cast<int>(1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count())
            << " ms)\n";
  const std::uint64_t seed = a.seed ? *a.seed : scene.projection.seed.value_or(scene.motion.seed);
  std::optional<std::vector<scenes::ProjectionPath>> paths;
  auto projectionPaths = [&]() -> const std::vector<scenes::ProjectionPath>& {
    if (!paths) {
      ProgressBar steps(!a.quiet, "steps", "other paths ");
      paths = scenes::projectionPaths(scene, m, [&](int d, int t) { return steps(d, t); });
    }
    return *paths;
  };
  std::unique_ptr<render::Renderer> renderer;
  auto gl = [&]() -> render::Renderer& {
    if (!renderer) renderer = makeRenderer();
    return *renderer;
  };
  for (const auto& o : outputs) {
    if (g_interrupted) return interrupted("before " + place(o.file) + "; the outputs listed above were written");
    const std::string file = place(o.file);
    scenes::Written w;
    if (o.kind == "path") {
      w = scenes::writePath(scene, m, file);
    } else if (o.kind == "frame") {
      if (static_cast<int>(m.result.samples.size()) <= o.sample) reportStop(m.result, o.sample);
      w = scenes::writeFrame(scene, &m, o.sample, o.flex, file, gl());
    } else {
      ProgressBar bar(!a.quiet, "frames");
      auto progress = [&](int d, int t) { return bar(d, t); };
      if (o.kind == "animation")
        w = scenes::writeAnimation(scene, m, file, gl(),
                                   scene.render.animation.side_by_side ? &projectionPaths() : nullptr, seed, progress);
      else
        w = scenes::writeProjection(scene, projectionPaths(), seed, file, "", gl(), progress);
    }
    std::cout << "wrote " << file << " (" << w.summary << ")\n";
  }
  return trackStatus(m.result);
}

int cmdRun(const Args& a) {
  if (a.positional.size() != 1) usageError("run takes one SCENE");
  if (!a.output.empty()) usageError("run writes the scene's [[output]] files; -o does not apply");
  const scenes::Scene scene = scenes::loadScene(a.positional[0], a.overrides);
  return produceOutputs(scene, scene.outputs, "", a);
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

int cmdDemo(const Args& a) {
  if (a.positional.size() > 1) usageError("demo takes at most one DIR");
  const std::string dir = a.positional.empty() ? "flexure-demo" : a.positional[0];
  const scenes::CatalogEntry* entry = scenes::findCatalogEntry("double_watt");
  const scenes::Scene scene = scenes::loadSceneFromString(entry->text, "catalog:double_watt", a.overrides);
  const engine::RigidityReport rep = scenes::analyzeScene(scene);
  scenes::makeDirectories(dir);
  const std::string scene_file = dir + "/double_watt.toml";
  const std::string report_file = dir + "/double_watt_analysis.json";
  scenes::writeFileAtomically(scene_file, entry->text);
  scenes::writeFileAtomically(report_file, scenes::analysisJson(scene, rep).dump(2) + "\n");
  std::cout << scenes::analysisText(scene, rep);
  std::cout << "wrote " << scene_file << "\nwrote " << report_file << "\n";
  // The path, a picture, both animations and the projection.
  const std::vector<scenes::OutputSpec> outputs = {{"double_watt_path.json", "path"},
                                                   {"double_watt.png", "frame"},
                                                   {"double_watt.mp4", "animation"},
                                                   {"double_watt.gif", "animation"},
                                                   {"double_watt_projection.png", "projection"}};
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
  server.run(&g_interrupted);
  std::cerr << "flexure view: stopped\n";
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  const Args args = parseArgs(argc, argv);
  std::signal(SIGINT, onInterrupt);
  std::signal(SIGTERM, onInterrupt);
  // A file-size limit (ulimit -f) or a full disk must fail a write, not kill the process
  // with a half-written temporary file left behind.
  std::signal(SIGXFSZ, SIG_IGN);
  try {
    if (args.command == "analyze") return cmdAnalyze(args);
    if (args.command == "catalog") return cmdCatalog(args);
    if (args.command == "track") return cmdTrack(args);
    if (args.command == "render") return cmdRender(args);
    if (args.command == "animate") return cmdAnimate(args);
    if (args.command == "project") return cmdProject(args);
    if (args.command == "run") return cmdRun(args);
    if (args.command == "demo") return cmdDemo(args);
    if (args.command == "view") return cmdView(args);
    usageError("unknown command '" + args.command + "'");
  } catch (const scenes::SceneError& e) {
    std::cerr << e.what() << "\n";
    return kExitInput;
  } catch (const scenes::OutputError& e) {
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
