// Rendering speed: frames per second of figure building + drawing + readback (what an
// animation pays per frame), and of PNG encoding separately.
#include <chrono>
#include <cstdio>

#include "render/renderer.h"
#include "scenes/catalog.h"
#include "present/figure.h"
#include "scenes/scene.h"

using namespace flexure;
using Clock = std::chrono::steady_clock;

namespace {

double seconds(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

void run(render::Renderer& r, const char* name, int w, int h, int frames) {
  const scenes::Scene scene = scenes::loadSceneFromString(scenes::findCatalogEntry(name)->text, name);
  scenes::FigureStyle style = scene.render.style;
  style.width = w, style.height = h;
  const engine::Geometry g = scene.model->geometry();
  const engine::Matrix p = scene.model->startPositions();
  const render::View view = present::fitView(g, {p}, style);
  const std::vector<render::Polygon> surface = present::surfaceMesh(g, view, style);  // once, as animations do
  present::FigureExtras extras;
  extras.surface = &surface;
  r.render(present::figure(g, p, style, extras), view);  // warm up: shader JIT, glyph atlas
  auto t0 = Clock::now();
  render::Image im;
  for (int i = 0; i < frames; ++i) {
    style.azimuth += 0.01;  // a moving camera, so nothing is cached
    render::View v = view;
    v.azimuth = style.azimuth;
    r.render(present::figure(g, p, style, extras), v, im);
  }
  const double t = seconds(t0);
  t0 = Clock::now();
  for (int i = 0; i < 5; ++i) render::encodePng(im);
  const double png = seconds(t0) / 5;
  std::printf("%-22s %dD %4dx%-4d  %6.1f frames/s  (%.1f ms/frame)   PNG encode %.1f ms\n", name,
              scene.model->system().dimension(), w, h, frames / t, 1e3 * t / frames, 1e3 * png);
}

}  // namespace

int main() {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  render::Renderer r;
  std::printf("%s\n", r.contextDescription().c_str());
  run(r, "double_watt", 1000, 1000, 60);
  run(r, "coned_cube", 1920, 1080, 60);
  run(r, "bricard_octahedron", 1920, 1080, 60);
  run(r, "cuboctahedron", 1920, 1080, 60);          // 3D polytopes: translucent facets sorted per frame
  run(r, "truncated_icosahedron", 1920, 1080, 60);
  run(r, "sphere_packing", 1920, 1080, 60);         // translucent shaded spheres
  run(r, "spherical_bricard", 1920, 1080, 60);      // caps: 390 circle pieces
  run(r, "square_on_hyperboloid", 1920, 1080, 30);  // a meshed surface: ~19,000 translucent triangles
  return 0;
}
