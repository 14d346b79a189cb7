// flexure: continuous motions of geometric constraint systems. The command line (SPEC section 1).
#include <unistd.h>

#include <algorithm>
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
    "  flexure render SCENE [-o OUT.png] [--sample K] [--flex]\n"
    "                                   one frame: the start, or sample K of the path;\n"
    "                                   --flex draws the selected infinitesimal flex\n"
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
    "animate, project, run and view are not in this version yet.\n";

struct Args {
  std::string command;
  std::vector<std::string> positional;
  std::vector<std::string> overrides;
  std::string output;
  bool json = false;
  bool quiet = false;
  int sample = 0;     // render: which sample
  bool flex = false;  // render: draw the flex arrows
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

// The scene's motion: direction from [motion] flex, the tracker with the scene's options.
// Returns false (after printing FILE:LINE:COL) when the flex has the wrong number of
// coefficients.
struct Motion {
  engine::RigidityReport rep;
  std::vector<double> coefficients;
  std::string note;
  engine::TrackResult result;
};

bool trackScene(const scenes::Scene& scene, int steps, bool quiet, Motion& m) {
  m.rep = analyze(scene);
  engine::Vector direction;
  try {
    direction = initialDirection(scene, m.rep, m.coefficients, m.note);
  } catch (const scenes::SceneError&) {
    std::cerr << scene.motion.flex_where << ": flex has " << scene.motion.flex->size()
              << " coefficient(s), but the start configuration has " << m.rep.nontrivial
              << " nontrivial infinitesimal flex(es)\n";
    return false;
  }
  engine::TrackerOptions opt;
  opt.steps = steps;
  opt.step_size = scene.motion.step_size;
  opt.seed = scene.motion.seed;
  opt.factorization.rank_tolerance = scene.analysis.rank_tolerance;
  opt.corrector.factorization = opt.factorization;
  ProgressBar bar(!quiet && opt.steps >= 50);
  if (m.rep.nontrivial == 0) {
    m.result = engine::trackMotion(*scene.model, scene.model->startCoordinates(),
                                   engine::Vector::Zero(m.rep.variables), opt);
  } else {
    m.result = engine::trackMotion(*scene.model, scene.model->startCoordinates(), direction, opt,
                                   [&](int d, int t) { return bar(d, t); });
  }
  if (m.result.summary.status != engine::TrackStatus::Success) bar.end();
  return true;
}

int cmdTrack(const Args& a) {
  if (a.positional.size() != 1) usageError("track takes one SCENE");
  const std::string ext = lowerExtension(a.output);
  if (!a.output.empty() && ext != "json" && ext != "csv")
    usageError("track writes .json or .csv, not '" + a.output + "'");
  const scenes::Scene scene = scenes::loadScene(a.positional[0], a.overrides);
  Motion m;
  if (!trackScene(scene, scene.motion.steps, a.quiet, m)) return kExitInput;
  const engine::TrackResult& result = m.result;
  const auto json = scenes::pathJson(scene, result, m.coefficients, m.note);
  if (a.output.empty()) {
    std::cout << json.dump(1) << "\n";
    std::cerr << result.summary.briefReport() << "\n";
  } else {
    scenes::writeFileAtomically(a.output, ext == "csv" ? scenes::pathCsv(scene, result) : json.dump(1) + "\n");
    std::cout << result.summary.briefReport() << "\nwrote " << a.output << "\n";
  }
  return result.summary.status == engine::TrackStatus::Success ? kExitOk : kExitStopped;
}

// The file name a command writes by default: the scene's stem with `ext`.
std::string defaultOutput(const std::string& scene_path, const std::string& ext) {
  std::string stem = scene_path.substr(scene_path.find_last_of('/') + 1);
  if (stem.rfind("catalog:", 0) == 0) stem = stem.substr(8);
  const auto dot = stem.rfind('.');
  if (dot != std::string::npos && dot > 0) stem = stem.substr(0, dot);
  return stem + "." + ext;
}

int cmdRender(const Args& a) {
  if (a.positional.size() != 1) usageError("render takes one SCENE");
  const std::string out = a.output.empty() ? defaultOutput(a.positional[0], "png") : a.output;
  if (lowerExtension(out) != "png") usageError("render writes .png, not '" + out + "'");
  const scenes::Scene scene = scenes::loadScene(a.positional[0], a.overrides);
  scenes::FigureStyle style = scene.render.style;
  style.width = scene.render.width;
  style.height = scene.render.height;
  const engine::Model& model = *scene.model;
  const engine::ConstraintSystem& sys = model.system();
  const int want = std::max({a.sample, 0, style.trace ? a.sample : 0, style.ghost});
  int status = kExitOk;
  std::vector<engine::Vector> samples{model.startCoordinates()};
  std::string note;
  Motion m;
  if (want > 0) {
    if (!trackScene(scene, want, a.quiet, m)) return kExitInput;
    samples = m.result.samples;
    if (static_cast<int>(samples.size()) <= want) {
      std::cerr << "flexure: the path stopped at sample " << samples.size() - 1 << " ("
                << m.result.summary.reason << "); rendering that sample\n";
      status = kExitStopped;
    }
  }
  const int shown = std::min<int>(std::max(a.sample, 0), static_cast<int>(samples.size()) - 1);
  const engine::Matrix positions = sys.positions(samples[shown]);
  scenes::FigureExtras extras;
  if (a.flex) {
    // The selected flex at the configuration shown: the scene's coefficients in its
    // nontrivial-flex basis (or its auto flex when their number does not fit there).
    engine::RigidityOptions ro;
    ro.rank_tolerance = scene.analysis.rank_tolerance;
    const engine::RigidityReport rep = engine::analyzeRigidity(model, samples[shown], ro);
    if (rep.nontrivial > 0) {
      engine::Vector c = rep.auto_flex;
      if (scene.motion.flex && static_cast<int>(scene.motion.flex->size()) == rep.nontrivial)
        c = Eigen::Map<const engine::Vector>(scene.motion.flex->data(), rep.nontrivial);
      extras.flex = sys.velocityField(rep.flex_basis * c);
    } else {
      std::cerr << "flexure: no nontrivial infinitesimal flex at sample " << shown << " (no arrows drawn)\n";
    }
  }
  if (style.trace)
    for (int k = 0; k <= shown; ++k) extras.trace.push_back(sys.positions(samples[k]));
  if (style.ghost >= 0 && style.ghost < static_cast<int>(samples.size()))
    extras.ghost = sys.positions(samples[style.ghost]);
  const engine::Geometry geometry = model.geometry();
  std::vector<engine::Matrix> frames{positions};
  if (extras.ghost) frames.push_back(*extras.ghost);
  if (extras.flex.size() > 0) frames.push_back(scenes::flexTips(positions, extras.flex, style));
  for (const auto& t : extras.trace) frames.push_back(t);
  const render::View view = scenes::fitView(geometry, frames, style);
  const auto t0 = std::chrono::steady_clock::now();
  render::Image image;
  try {
    render::Renderer renderer;
    image = renderer.render(scenes::figure(geometry, positions, style, extras), view);
  } catch (const std::runtime_error& e) {
    std::cerr << "flexure: cannot render: " << e.what() << "\n";
    return kExitOutput;
  }
  const auto png = render::encodePng(image);
  scenes::writeFileAtomically(out, std::string(png.begin(), png.end()));
  const double ms = 1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::cout << "wrote " << out << " (" << image.width << "x" << image.height << ", sample " << shown << ", "
            << static_cast<int>(ms) << " ms)\n";
  return status;
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
    if (args.command == "render") return cmdRender(args);
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
