// The offscreen renderer: draws a DrawList into an RGBA image in stages: the batches are built
// without GL (render/batches.h), then a DrawBackend rasterizes them pass by pass: OpenGL (core
// profile, shaders in gl_backend.cpp) through the GlContext, or the null backend in tests.
// Shapes are anti-aliased analytically (signed distances in pixels), so no multisampling is
// needed. One thread owns a Renderer.
#pragma once

#include <memory>
#include <string>

#include "render/draw_list.h"
#include "render/image.h"

namespace flexure::render {

class DrawBackend;

class Renderer {
 public:
  // Creates the GL context; throws std::runtime_error when it or the font cannot be had.
  // `font`: a font file or a fontconfig pattern (render/text.h); empty: defaultFont().
  explicit Renderer(const std::string& font = "");
  // Draws through `backend` (e.g. a NullBackend in tests).
  explicit Renderer(std::unique_ptr<DrawBackend> backend, const std::string& font = "");
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  Image render(const DrawList& list, const View& view);
  // The same into `out`, reusing its memory when it already has the size (animations render
  // hundreds of frames: fresh 4 MB buffers each time cost more in page faults than drawing).
  void render(const DrawList& list, const View& view, Image& out);
  std::string contextDescription() const;
  DrawBackend& backend();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace flexure::render
