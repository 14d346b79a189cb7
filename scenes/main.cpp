// flexure: continuous motions of geometric constraint systems. The command line (SPEC section 1).
#include <cstdio>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "engine/rigidity.h"
#include "scenes/catalog.h"
#include "scenes/output_file.h"
#include "scenes/report.h"
#include "scenes/scene.h"

namespace {

using namespace flexure;

constexpr int kExitOk = 0;
constexpr int kExitInput = 1;
constexpr int kExitOutput = 3;

const char* kUsage =
    "flexure " FLEXURE_VERSION " - continuous motions of geometric constraint systems\n"
    "\n"
    "usage:\n"
    "  flexure analyze SCENE [--json]   rigidity report of the start configuration\n"
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
    "track, render, animate, project, run and view are not in this version yet.\n";

struct Args {
  std::string command;
  std::vector<std::string> positional;
  std::vector<std::string> overrides;
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
