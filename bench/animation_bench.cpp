// The demo's pipeline, stage by stage: tracking, rendering alone, encoding alone (frames
// rendered beforehand, kept in memory) and rendering + encoding together as `flexure animate`
// runs them (encoder on its own thread). Target: together <= 1.5x encoding alone.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "scenes/catalog.h"
#include "pipeline/pipeline.h"
#include "present/animation.h"
#include "scenes/scene.h"

using namespace flexure;
using Clock = std::chrono::steady_clock;

namespace {

double seconds(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

void run(render::Renderer& r, const char* name, const std::vector<std::string>& overrides, bool gif) {
  const scenes::Scene scene = scenes::loadSceneFromString(scenes::findCatalogEntry(name)->text, name, overrides);
  auto t0 = Clock::now();
  const pipeline::Motion m = pipeline::track(scene, scene.motion.steps);
  const double track = seconds(t0);
  const int w = scene.render.width, h = scene.render.height;
  int fw = w, fh = h;
  if (gif) {
    const double s = std::min(1.0, scene.render.animation.gif_size / static_cast<double>(std::max(w, h)));
    fw = static_cast<int>(std::lround(w * s)), fh = static_cast<int>(std::lround(h * s));
  }
  const present::Animation anim(scene, m.path, fw, fh);
  const int n = anim.frameCount();
  render::Image scratch;
  anim.frame(0, r, scratch);  // warm up
  t0 = Clock::now();
  for (int i = 0; i < n; ++i) anim.frame(i, r, scratch);
  const double render_only = seconds(t0);
  std::vector<render::Image> frames(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) anim.frame(i, r, frames[static_cast<size_t>(i)]);
  const std::string out = (std::filesystem::temp_directory_path() / (std::string("flexure_bench.") + (gif ? "gif" : "mp4"))).string();
  render::VideoOptions o;
  o.format = gif ? render::VideoFormat::Gif : render::VideoFormat::Mp4;
  o.width = fw, o.height = fh, o.fps = scene.render.fps;
  // Best of two for each (the first run of a process also pays for fresh memory pages).
  double encode_only = 1e300, together = 1e300;
  render::VideoStats stats;
  for (int rep = 0; rep < 2; ++rep) {
    t0 = Clock::now();
    render::writeVideo(out, o, n, [&](int i, render::Image& image) { image = frames[static_cast<size_t>(i)]; });
    encode_only = std::min(encode_only, seconds(t0));
    t0 = Clock::now();
    stats = render::writeVideo(out, o, n, [&](int i, render::Image& image) { anim.frame(i, r, image); });
    together = std::min(together, seconds(t0));
  }
  std::filesystem::remove(out);
  std::printf("%-14s %s %4dx%-4d %4d frames | track %5.2f s | render alone %5.2f s (%5.1f fps) | encode alone %5.2f s "
              "(%5.1f fps) | together %5.2f s = %.2fx encode%s\n",
              name, gif ? "GIF" : "MP4", fw, fh, n, track, render_only, n / render_only, encode_only, n / encode_only,
              together, together / encode_only, stats.rendered_twice ? " (rendered twice)" : "");
}

}  // namespace

int main() {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  render::Renderer r;
  run(r, "double_watt", {}, false);
  run(r, "double_watt", {}, true);
  run(r, "coned_cube", {"render.width=1920", "render.height=1080", "motion.steps=200"}, false);
  return 0;
}
