// The OSMesa backend: a 3.3 core-profile context on a 1x1 user buffer (everything is drawn
// into framebuffer objects). Link libOSMesa only: libGL next to it breaks dispatch.
#define GL_GLEXT_PROTOTYPES 1
#include <GL/osmesa.h>
#include <GL/gl.h>

#include <stdexcept>
#include <vector>

#include "render/gl_context.h"

namespace flexure::render {

namespace {

class OsMesaContext final : public GlContext {
 public:
  OsMesaContext() : buffer_(4, 0) {
    const int attributes[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 24, OSMESA_STENCIL_BITS, 0,
                              OSMESA_PROFILE, OSMESA_CORE_PROFILE, OSMESA_CONTEXT_MAJOR_VERSION, 3,
                              OSMESA_CONTEXT_MINOR_VERSION, 3, 0};
    ctx_ = OSMesaCreateContextAttribs(attributes, nullptr);
    if (!ctx_) throw std::runtime_error("OSMesa could not create a 3.3 core-profile context");
    makeCurrent();
    const char* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
    const char* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    if (!version) throw std::runtime_error("OSMesa context has no GL version (is libGL linked next to libOSMesa?)");
    description_ = std::string("OSMesa: ") + version + ", " + (renderer ? renderer : "?");
  }
  ~OsMesaContext() override { OSMesaDestroyContext(ctx_); }
  void makeCurrent() override {
    if (!OSMesaMakeCurrent(ctx_, buffer_.data(), GL_UNSIGNED_BYTE, 1, 1))
      throw std::runtime_error("OSMesaMakeCurrent failed");
  }
  std::string description() const override { return description_; }

 private:
  OSMesaContext ctx_ = nullptr;
  std::vector<unsigned char> buffer_;
  std::string description_;
};

}  // namespace

std::unique_ptr<GlContext> createOffscreenContext() { return std::make_unique<OsMesaContext>(); }

}  // namespace flexure::render
