// flexure: continuous motions of geometric constraint systems. The command line (SPEC section 1).
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "engine/motion_tracker.h"
#include "engine/rigidity.h"
#include "scenes/catalog.h"
#include "scenes/output_file.h"
#include "scenes/path_output.h"
#include "scenes/report.h"
#include "scenes/scene.h"

namespace {

using namespace flexure;

constexpr int kExitOk = 0;
constexpr int kExitInput = 1;
constexpr int kExitStopped = 2;
constexpr int kExitOutput = 3;

const char* kUsage =
    "flexure " FLEXURE_VERSION " - continuous motions of geometric constraint systems\n"
    "\n"
    "usage:\n"
    "  flexure analyze SCENE [--json]   rigidity report of the start configuration\n"
    "  flexure track SCENE [-o PATH.json|PATH.csv]\n"
    "                                   the deformation path (JSON on stdout without -o)\n"
    "  flexure catalog                  the built-in named systems\n"
    "  flexure demo [DIR]               the default scene (double Watt mechanism) and its\n"
    "                                   rigidity report, into DIR (default flexure-demo)\n"
    "\n"
    "options:\n"
    "  --set KEY=VALUE   override a scene key, e.g. --set motion.steps=50 (repeatable)\n"
    "  --json            machine-readable output (analyze)\n"
    "  --quiet           no progress on stderr\n"
    "  --help, --version\n"
    "\n"
    "exit status: 0 success, 1 wrong input, 2 computation stopped early, 3 output not written.\n"
    "render, animate, project, run and view are not in this version yet.\n";

struct Args {
  std::string command;
  std::vector<std::string> positional;
  std::vector<std::string> overrides;
  std::string output;
  bool json = false;
  bool quiet = false;
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

engine::RigidityReport analyze(const scenes::Scene& scene) {
  engine::RigidityOptions opt;
  opt.rank_tolerance = scene.analysis.rank_tolerance;
  return engine::analyzeRigidity(*scene.model, scene.model->startCoordinates(), opt);
}

int cmdAnalyze(const Args& a) {
  if (a.positional.size() != 1) usageError("analyze takes one SCENE");
  const scenes::Scene scene = scenes::loadScene(a.positional[0], a.overrides);
  const engine::RigidityReport rep = analyze(scene);
  if (a.json) std::cout << scenes::analysisJson(scene, rep).dump(2) << "\n";
  else std::cout << scenes::analysisText(scene, rep);
  return kExitOk;
}

// The initial direction: the scene's flex coefficients in the canonical nontrivial-flex basis.
engine::Vector initialDirection(const scenes::Scene& scene, const engine::RigidityReport& rep,
                                std::vector<double>& coefficients, std::string& note) {
  const int k = rep.nontrivial;
  if (scene.motion.flex) {
    coefficients = *scene.motion.flex;
    if (static_cast<int>(coefficients.size()) != k)
      throw scenes::SceneError(scene.motion.flex_where, 0, 0, "");
    note = "given";
  } else {
    coefficients.assign(rep.auto_flex.data(), rep.auto_flex.data() + rep.auto_flex.size());
    note = "auto: " + rep.auto_flex_note;
  }
  engine::Vector c(k);
  for (int i = 0; i < k; ++i) c[i] = coefficients[i];
  return rep.flex_basis * c;
}

class ProgressBar {
 public:
  explicit ProgressBar(bool enabled) : enabled_(enabled && ::isatty(2)), t0_(Clock::now()) {}
  bool operator()(int done, int total) {
    if (!enabled_) return true;
    const auto now = Clock::now();
    if (done < total && now - last_ < std::chrono::milliseconds(100)) return true;
    last_ = now;
    const double secs = std::chrono::duration<double>(now - t0_).count();
    const int width = 30, filled = total > 0 ? width * done / total : width;
    std::fprintf(stderr, "\r[%.*s%*s] %d/%d steps  %.0f steps/s", filled,
                 "##############################", width - filled, "", done, total,
                 secs > 0 ? done / secs : 0.0);
    if (done == total) std::fputc('\n', stderr);
    return true;
  }
  void end() {
    if (enabled_) std::fputc('\n', stderr);
  }

 private:
  using Clock = std::chrono::steady_clock;
  bool enabled_;
  Clock::time_point t0_, last_{};
};

std::string lowerExtension(const std::string& path) {
  const auto dot = path.rfind('.');
  std::string ext = dot == std::string::npos ? "" : path.substr(dot + 1);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

int cmdTrack(const Args& a) {
  if (a.positional.size() != 1) usageError("track takes one SCENE");
  const std::string ext = lowerExtension(a.output);
  if (!a.output.empty() && ext != "json" && ext != "csv")
    usageError("track writes .json or .csv, not '" + a.output + "'");
  const scenes::Scene scene = scenes::loadScene(a.positional[0], a.overrides);
  const engine::RigidityReport rep = analyze(scene);
  std::vector<double> coefficients;
  std::string note;
  engine::Vector direction;
  try {
    direction = initialDirection(scene, rep, coefficients, note);
  } catch (const scenes::SceneError&) {
    std::cerr << scene.motion.flex_where << ": flex has " << scene.motion.flex->size()
              << " coefficient(s), but the start configuration has " << rep.nontrivial
              << " nontrivial infinitesimal flex(es)\n";
    return kExitInput;
  }
  engine::TrackerOptions opt;
  opt.steps = scene.motion.steps;
  opt.step_size = scene.motion.step_size;
  opt.seed = scene.motion.seed;
  opt.factorization.rank_tolerance = scene.analysis.rank_tolerance;
  opt.corrector.factorization = opt.factorization;
  ProgressBar bar(!a.quiet && opt.steps >= 50);
  engine::TrackResult result;
  if (rep.nontrivial == 0) {
    result = engine::trackMotion(*scene.model, scene.model->startCoordinates(),
                                 engine::Vector::Zero(rep.variables), opt);
  } else {
    result = engine::trackMotion(*scene.model, scene.model->startCoordinates(), direction, opt,
                                 [&](int d, int t) { return bar(d, t); });
  }
  if (result.summary.status != engine::TrackStatus::Success) bar.end();
  const auto json = scenes::pathJson(scene, result, coefficients, note);
  if (a.output.empty()) {
    std::cout << json.dump(1) << "\n";
    std::cerr << result.summary.briefReport() << "\n";
  } else {
    scenes::writeFileAtomically(a.output, ext == "csv" ? scenes::pathCsv(scene, result) : json.dump(1) + "\n");
    std::cout << result.summary.briefReport() << "\nwrote " << a.output << "\n";
  }
  return result.summary.status == engine::TrackStatus::Success ? kExitOk : kExitStopped;
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
  const engine::RigidityReport rep = analyze(scene);
  scenes::makeDirectories(dir);
  const std::string scene_file = dir + "/double_watt.toml";
  const std::string report_file = dir + "/double_watt_analysis.json";
  scenes::writeFileAtomically(scene_file, entry->text);
  scenes::writeFileAtomically(report_file, scenes::analysisJson(scene, rep).dump(2) + "\n");
  std::cout << scenes::analysisText(scene, rep);
  std::cout << "wrote " << scene_file << "\nwrote " << report_file << "\n";
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  const Args args = parseArgs(argc, argv);
  try {
    if (args.command == "analyze") return cmdAnalyze(args);
    if (args.command == "catalog") return cmdCatalog(args);
    if (args.command == "track") return cmdTrack(args);
    if (args.command == "demo") return cmdDemo(args);
    usageError("unknown command '" + args.command + "'");
  } catch (const scenes::SceneError& e) {
    std::cerr << e.what() << "\n";
    return kExitInput;
  } catch (const scenes::OutputError& e) {
    std::cerr << "flexure: " << e.what() << "\n";
    return kExitOutput;
  } catch (const std::bad_alloc&) {
    std::cerr << "flexure: out of memory\n";
    return kExitInput;
  }
}
