// Where batches are rasterized. The renderer calls a backend stage by stage: setup (the frame's
// size, background, depth test), the opaque pass (polygons, then shapes), the translucent pass
// (shapes, then polygons in 3D; in 2D translucent polygons go under the shapes, in order), the
// text overlay, and the readback. OpenGL (through a GlContext: OSMesa) draws; the null backend
// records the calls and returns a frame of the background colour, so that everything above
// it is tested without a GL library.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "render/batches.h"
#include "render/image.h"
#include "render/text.h"

namespace flexure::render {

class DrawBackend {
 public:
  virtual ~DrawBackend() = default;
  virtual std::string description() const = 0;
  // Setup: a cleared frame of width x height, depth-tested when `depth`; shapes fade toward the
  // background with depth by `fog` (render::fogged).
  virtual void begin(int width, int height, const Color& background, bool depth, float fog) = 0;
  // Flat triangles; with depth_write false they are depth-tested but do not hide what is
  // drawn after them (translucent facets in 3D).
  virtual void drawPolygons(const std::vector<FlatVertex>& triangles, bool depth_write) = 0;
  // Shape quads: [0, opaque) opaque, then the rest translucent (no depth writes in 3D).
  virtual void drawShapes(const std::vector<ShapeVertex>& vertices, size_t opaque) = 0;
  // Glyph quads over everything, textured by `atlas`.
  virtual void drawText(const TextBatch& batch, const GlyphAtlas& atlas) = 0;
  // The frame, top row first.
  virtual void finish(Image& out) = 0;
};

// OpenGL 3.3 core through an offscreen context; throws std::runtime_error when it cannot be had.
std::unique_ptr<DrawBackend> createOpenGlBackend();

// Records each call (one line each, e.g. "shapes 12 opaque 6") and draws nothing.
class NullBackend final : public DrawBackend {
 public:
  std::string description() const override { return "null backend (records the calls, draws nothing)"; }
  void begin(int width, int height, const Color& background, bool depth, float fog) override;
  void drawPolygons(const std::vector<FlatVertex>& triangles, bool depth_write) override;
  void drawShapes(const std::vector<ShapeVertex>& vertices, size_t opaque) override;
  void drawText(const TextBatch& batch, const GlyphAtlas& atlas) override;
  void finish(Image& out) override;

  std::vector<std::string> calls;  // this frame's, from begin on

 private:
  int width_ = 0, height_ = 0;
  Color background_;
};

}  // namespace flexure::render
