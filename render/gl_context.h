// The OpenGL context behind a small interface: one thread creates it, makes it current and
// owns it. Drawing goes into framebuffer objects, so a backend only has to provide a current
// core-profile context. OSMesa now (Mesa 25.1 dropped it upstream); an EGL-surfaceless backend
// is a second implementation of this class and touches no drawing code.
#pragma once

#include <memory>
#include <string>

namespace flexure::render {

class GlContext {
 public:
  virtual ~GlContext() = default;
  virtual void makeCurrent() = 0;
  virtual std::string description() const = 0;  // "OSMesa: 4.5 (Core Profile) Mesa 22.3.6, llvmpipe"
};

// Throws std::runtime_error with what went wrong.
std::unique_ptr<GlContext> createOffscreenContext();

}  // namespace flexure::render
