// The commands that draw: render, animate, project, run, demo, view (flexure-draw only).
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <functional>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "cli/cli.h"
#include "present/output_file.h"
#include "present/report.h"
#include "present/text.h"
#include "render/renderer.h"
#include "render/video.h"
#include "scenes/catalog.h"
#include "scenes/scene.h"
#include "viewer/server.h"
#include "viewer/session.h"

namespace flexure::cli {

namespace {

using namespace flexure;


// The file name a command writes by default, in the current directory: the scene's stem, a
// suffix that keeps the commands' defaults apart (render: STEM.png, animate: STEM.mp4, project:
// STEM_projection.png), and `ext`.
std::string defaultOutput(const std::string& scene_path, const std::string& ext, const std::string& suffix = "") {
  std::string stem = present::stemOf(scene_path);
  if (stem.rfind("catalog:", 0) == 0) stem = stem.substr(8);
  return stem + suffix + "." + ext;
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
  if (!scenes::isImageExtension(present::extensionOf(out)) && !scenes::isSolidExtension(present::extensionOf(out)))
    usageError("render writes .png, .svg, .pdf, .tex (TikZ), or .obj/.stl (a solid), not '" + out + "'");
  if (!a.frame_samples.empty() && scenes::isSolidExtension(present::extensionOf(out)))
    usageError("a solid (.obj, .stl) is one configuration: --sample K, not --samples");
  const scenes::Scene scene = scenes::loadScene(a.positional[0], a.overrides);
  present::checkWritable(out, {scene.path});
  int want = std::max({a.sample, 0, scene.render.style.ghost});
  for (int k : a.frame_samples) want = std::max(want, k);
  StudyProgress progress(a.quiet);
  // The whole path is tracked, as far as [motion] steps (or further, for a sample beyond):
  // its one view (alignment and camera fitted over every sample) is the animation's, so that
  // sample K here is frame K there.
  pipeline::StudyOptions options = studyOptions(a, progress);
  // A solid (.obj, .stl) is drawn in the scene's coordinates, in no view: only as far as K.
  const bool solid = scenes::isSolidExtension(present::extensionOf(out));
  options.steps = scene.motion.steps > 0 && !solid ? std::max(want, scene.motion.steps) : want;
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
  scenes::OutputSpec spec{out, scenes::OutputKind::Frame, a.sample, a.flex, a.frame_samples};
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
  std::cerr << path.summary.briefReport() << "\n" << eventLines(path);
  if (scene.render.animation.side_by_side) study.projectionPaths();
  LazyRenderer renderer;
  const present::Written w = study.write({out, scenes::OutputKind::Animation}, out, std::ref(renderer));
  progress.end();
  std::cout << "wrote " << out << " (" << w.summary << ")\n";
  return trackStatus(path);
}

int cmdProject(const Args& a) {
  if (a.positional.size() != 1) usageError("project takes one SCENE");
  // Not SCENE-STEM.png: that is render's (as in the demo: double_watt.png, double_watt_projection.png).
  const std::string out = a.output.empty() ? defaultOutput(a.positional[0], "png", "_projection") : a.output;
  const std::string ext = present::extensionOf(out);
  if (!scenes::isImageExtension(ext) && ext != "mp4" && ext != "gif")
    usageError("project writes .png, .svg, .pdf, .tex (or .mp4/.gif: the animated projection), not '" + out + "'");
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
            << " ms)\n"
            << eventLines(path);
  for (const auto& o : outputs)
    if (o.kind == scenes::OutputKind::Frame)
      reportStop(path, o.samples.empty() ? o.sample : *std::max_element(o.samples.begin(), o.samples.end()));
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

}  // namespace

int drawingCommand(const Args& args) {
  try {
    if (args.command == "render") return cmdRender(args);
    if (args.command == "animate") return cmdAnimate(args);
    if (args.command == "project") return cmdProject(args);
    if (args.command == "run") return cmdRun(args);
    if (args.command == "demo") return cmdDemo(args);
    return cmdView(args);
  } catch (const render::VideoInterrupted& e) {
    std::cerr << "\nflexure: interrupted (" << e.what() << "); nothing was written under the output's name\n";
    return kExitInterrupted;
  }
}

}  // namespace flexure::cli
