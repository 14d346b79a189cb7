#include "render/renderer.h"

#include <map>

#include "render/batches.h"
#include "render/draw_backend.h"
#include "render/text.h"

namespace flexure::render {

struct Renderer::Impl {
  std::unique_ptr<DrawBackend> backend;
  std::string font;
  std::map<int, std::unique_ptr<GlyphAtlas>> atlases;  // key: 2 * size + (regular weight)

  GlyphAtlas& atlas(int key) {
    auto& a = atlases[key];
    if (!a) a = std::make_unique<GlyphAtlas>(font, key % 2 == 0, key / 2);
    return *a;
  }
};

Renderer::Renderer(const std::string& font) : Renderer(createOpenGlBackend(), font) {}

Renderer::Renderer(std::unique_ptr<DrawBackend> backend, const std::string& font) : impl_(std::make_unique<Impl>()) {
  impl_->font = font.empty() ? defaultFont() : font;
  impl_->backend = std::move(backend);
}

Renderer::~Renderer() = default;

std::string Renderer::contextDescription() const { return impl_->backend->description(); }

DrawBackend& Renderer::backend() { return *impl_->backend; }

Image Renderer::render(const DrawList& list, const View& view) {
  Image image;
  render(list, view, image);
  return image;
}

void Renderer::render(const DrawList& list, const View& view, Image& image) {
  Impl& m = *impl_;
  const FrameBatches f = buildFrame(list, view, [&m](int key) -> GlyphAtlas& { return m.atlas(key); });
  DrawBackend& b = *m.backend;
  // Setup, then the opaque pass: polygons, then (2D) the translucent polygons under the shapes.
  b.begin(f.width, f.height, f.background, f.depth, f.fog);
  b.drawPolygons(f.opaque_polygons, true);
  if (!f.depth) b.drawPolygons(f.translucent_polygons, true);
  // Shapes: opaque, then translucent ones (3D: back to front, no depth writes).
  b.drawShapes(f.shapes, f.opaque_shape_vertices);
  // 3D: translucent facets over the opaque scene, depth-tested, not written.
  if (f.depth) b.drawPolygons(f.translucent_polygons, false);
  // Overlays: text on top of everything.
  for (const TextBatch& t : f.text) b.drawText(t, m.atlas(t.atlas_key));
  b.finish(image);
}

}  // namespace flexure::render
