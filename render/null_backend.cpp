#include <cmath>

#include "render/draw_backend.h"

namespace flexure::render {

void NullBackend::begin(int width, int height, const Color& background, bool depth, float /*fog*/) {
  calls.clear();
  width_ = width, height_ = height, background_ = background;
  calls.push_back("begin " + std::to_string(width) + "x" + std::to_string(height) + (depth ? " depth" : ""));
}

void NullBackend::drawPolygons(const std::vector<FlatVertex>& triangles, bool depth_write) {
  if (triangles.empty()) return;
  calls.push_back("polygons " + std::to_string(triangles.size() / 3) + (depth_write ? "" : " no-depth-write"));
}

void NullBackend::drawShapes(const std::vector<ShapeVertex>& vertices, size_t opaque) {
  if (vertices.empty()) return;
  calls.push_back("shapes " + std::to_string(vertices.size() / 6) + " opaque " + std::to_string(opaque / 6));
}

void NullBackend::drawText(const TextBatch& batch, const GlyphAtlas& atlas) {
  calls.push_back("text " + std::to_string(batch.vertices.size() / 6) + " glyphs at " +
                  std::to_string(atlas.pixelSize()) + " px");
}

void NullBackend::finish(Image& out) {
  calls.push_back("finish");
  out.width = width_, out.height = height_;
  out.rgba.assign(static_cast<size_t>(width_) * height_ * 4, 0);
  const auto byte = [](float x) { return static_cast<std::uint8_t>(std::lround(255 * x)); };
  for (size_t i = 0; i < out.rgba.size(); i += 4) {
    out.rgba[i] = byte(background_.r), out.rgba[i + 1] = byte(background_.g), out.rgba[i + 2] = byte(background_.b);
    out.rgba[i + 3] = 255;
  }
}

}  // namespace flexure::render
