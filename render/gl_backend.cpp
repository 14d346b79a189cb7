#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>

#include <cstddef>
#include <cstring>
#include <map>
#include <stdexcept>

#include "render/draw_backend.h"
#include "render/gl_context.h"

namespace flexure::render {

namespace {

// Every program takes vertices in pixels (origin bottom left) and a depth in [-1, 1].
const char* kShapeVertex = R"(#version 330 core
layout(location = 0) in vec3 pos;
layout(location = 1) in vec4 ends;     // a.xy, b.xy in px
layout(location = 2) in vec4 params;   // kind, radius, outline, depth radius
layout(location = 3) in vec4 fill;
layout(location = 4) in vec4 stroke;
layout(location = 5) in vec4 extra;    // pointing.xy (triangle) or dash, gap (segment)
layout(location = 6) in vec3 depths;   // depth at a, depth at b, shaded
uniform vec2 viewport;
out vec2 v_pos;
flat out vec4 v_ends;
flat out vec4 v_params;
flat out vec4 v_fill;
flat out vec4 v_stroke;
flat out vec4 v_extra;
flat out vec3 v_depths;
void main() {
  v_pos = pos.xy;
  v_ends = ends; v_params = params; v_fill = fill; v_stroke = stroke; v_extra = extra; v_depths = depths;
  gl_Position = vec4(pos.xy / viewport * 2.0 - 1.0, pos.z, 1.0);
}
)";

const char* kShapeFragment = R"(#version 330 core
in vec2 v_pos;
flat in vec4 v_ends;
flat in vec4 v_params;
flat in vec4 v_fill;
flat in vec4 v_stroke;
flat in vec4 v_extra;
flat in vec3 v_depths;
uniform int use_depth;
uniform float fog;       // render::fogged: toward fog_color by depth
uniform vec3 fog_color;
out vec4 color;
const vec3 light = normalize(vec3(-0.35, 0.45, 0.82));
float triangle(vec2 p, float r) {  // equilateral, half side r, centroid at 0, tip up
  const float k = sqrt(3.0);
  p.x = abs(p.x) - r;
  p.y = p.y + r / k;
  if (p.x + k * p.y > 0.0) p = vec2(p.x - k * p.y, -k * p.x - p.y) / 2.0;
  p.x -= clamp(p.x, -2.0 * r, 0.0);
  return -length(p) * sign(p.y);
}
float pentagon(vec2 p, float r) {  // regular, inradius r, centre at 0, tip up
  const vec3 k = vec3(0.809016994, 0.587785252, 0.726542528);
  p.y = -p.y;
  p.x = abs(p.x);
  p -= 2.0 * min(dot(vec2(-k.x, k.y), p), 0.0) * vec2(-k.x, k.y);
  p -= 2.0 * min(dot(vec2(k.x, k.y), p), 0.0) * vec2(k.x, k.y);
  p -= vec2(clamp(p.x, -r * k.z, r * k.z), r);
  return length(p) * sign(p.y);
}
void main() {
  float kind = v_params.x, r = v_params.y, w = v_params.z;
  vec2 a = v_ends.xy, b = v_ends.zw;
  float d;
  float z = v_depths.x;
  vec3 n = vec3(0.0, 0.0, 1.0);
  if (kind < 0.5) {
    vec2 ab = b - a;
    float len = length(ab);
    vec2 dir = len > 0.0 ? ab / len : vec2(1.0, 0.0);
    float t = len > 0.0 ? clamp(dot(v_pos - a, dir), 0.0, len) : 0.0;
    vec2 off = v_pos - (a + t * dir);
    d = length(off) - r;
    z = mix(v_depths.x, v_depths.y, len > 0.0 ? t / len : 0.0);
    if (v_extra.x > 0.0) {  // dashes with square ends
      float along = dot(v_pos - a, dir);
      float period = v_extra.x + v_extra.y;
      float m = mod(along, period);
      float da = m < v_extra.x ? max(-m, m - v_extra.x) : min(m - v_extra.x, period - m);
      d = max(abs(dot(v_pos - a, vec2(-dir.y, dir.x))) - r, da);
      if (along < -0.5 || along > len + 0.5) d = max(d, 1.0);
    }
    float s = clamp(dot(off, vec2(-dir.y, dir.x)) / max(r, 1e-6), -1.0, 1.0);
    n = vec3(vec2(-dir.y, dir.x) * s, sqrt(max(0.0, 1.0 - s * s)));
  } else if (kind < 1.5) {
    vec2 off = v_pos - a;
    d = length(off) - r;
    vec2 q = off / max(r, 1e-6);
    float h = sqrt(max(0.0, 1.0 - dot(q, q)));
    n = vec3(q, h);
    z = v_depths.x - v_params.w * h;
  } else {
    vec2 dir = normalize(v_extra.xy);
    vec2 u = v_pos - a;
    vec2 q = vec2(dot(u, vec2(dir.y, -dir.x)), dot(u, dir));
    d = kind < 2.5 ? triangle(q, r * 0.8660254) : pentagon(q, r * 0.809017);
  }
  float coverage = clamp(0.5 - d, 0.0, 1.0);
  if (coverage <= 0.0) discard;
  vec4 c = v_fill;
  if (w > 0.0) c = mix(v_fill, v_stroke, clamp(d + w + 0.5, 0.0, 1.0));
  if (v_depths.z > 0.5) {
    float diffuse = max(dot(n, light), 0.0);
    float spec = pow(max(dot(reflect(-light, n), vec3(0.0, 0.0, 1.0)), 0.0), 24.0);
    c.rgb = c.rgb * (0.45 + 0.6 * diffuse) + vec3(0.25 * spec);
  }
  if (fog > 0.0) c.rgb = mix(c.rgb, fog_color, fog * clamp((z + 0.8) / 1.6, 0.0, 1.0));
  color = vec4(c.rgb, c.a * coverage);
  gl_FragDepth = use_depth != 0 ? z * 0.5 + 0.5 : 0.5;
}
)";

const char* kFlatVertex = R"(#version 330 core
layout(location = 0) in vec3 pos;
layout(location = 1) in vec4 rgba;
layout(location = 2) in vec2 uv;
uniform vec2 viewport;
out vec4 v_color;
out vec2 v_uv;
void main() {
  v_color = rgba;
  v_uv = uv;
  gl_Position = vec4(pos.xy / viewport * 2.0 - 1.0, pos.z, 1.0);
}
)";

const char* kFlatFragment = R"(#version 330 core
in vec4 v_color;
in vec2 v_uv;
uniform int textured;
uniform sampler2D atlas;
out vec4 color;
void main() {
  float a = textured != 0 ? texture(atlas, v_uv).r : 1.0;
  color = vec4(v_color.rgb, v_color.a * a);
}
)";

GLuint compile(GLenum type, const char* source) {
  const GLuint s = glCreateShader(type);
  glShaderSource(s, 1, &source, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048];
    glGetShaderInfoLog(s, sizeof log, nullptr, log);
    throw std::runtime_error(std::string("shader compilation failed: ") + log);
  }
  return s;
}

GLuint link(const char* vs, const char* fs) {
  const GLuint p = glCreateProgram();
  const GLuint v = compile(GL_VERTEX_SHADER, vs), f = compile(GL_FRAGMENT_SHADER, fs);
  glAttachShader(p, v);
  glAttachShader(p, f);
  glLinkProgram(p);
  glDeleteShader(v);
  glDeleteShader(f);
  GLint ok = 0;
  glGetProgramiv(p, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[2048];
    glGetProgramInfoLog(p, sizeof log, nullptr, log);
    throw std::runtime_error(std::string("shader link failed: ") + log);
  }
  return p;
}

void setupAttributes(const std::vector<std::pair<int, size_t>>& layout, size_t stride) {
  for (size_t i = 0; i < layout.size(); ++i) {
    glEnableVertexAttribArray(static_cast<GLuint>(i));
    glVertexAttribPointer(static_cast<GLuint>(i), layout[i].first, GL_FLOAT, GL_FALSE, static_cast<GLsizei>(stride),
                          reinterpret_cast<const void*>(layout[i].second));
  }
}

class OpenGlBackend final : public DrawBackend {
 public:
  OpenGlBackend() : context_(createOffscreenContext()) {
    shape_program_ = link(kShapeVertex, kShapeFragment);
    flat_program_ = link(kFlatVertex, kFlatFragment);
    glGenVertexArrays(1, &vao_shapes_);
    glGenBuffers(1, &vbo_shapes_);
    glBindVertexArray(vao_shapes_);
    glBindBuffer(GL_ARRAY_BUFFER, vbo_shapes_);
    setupAttributes({{3, offsetof(ShapeVertex, pos)},
                     {4, offsetof(ShapeVertex, ends)},
                     {4, offsetof(ShapeVertex, params)},
                     {4, offsetof(ShapeVertex, fill)},
                     {4, offsetof(ShapeVertex, stroke)},
                     {4, offsetof(ShapeVertex, extra)},
                     {3, offsetof(ShapeVertex, depths)}},
                    sizeof(ShapeVertex));
    glGenVertexArrays(1, &vao_flat_);
    glGenBuffers(1, &vbo_flat_);
    glBindVertexArray(vao_flat_);
    glBindBuffer(GL_ARRAY_BUFFER, vbo_flat_);
    setupAttributes({{3, offsetof(FlatVertex, pos)}, {4, offsetof(FlatVertex, rgba)}, {2, offsetof(FlatVertex, uv)}},
                    sizeof(FlatVertex));
    glBindVertexArray(0);
  }

  ~OpenGlBackend() override {
    for (auto& [key, tex] : atlas_textures_) glDeleteTextures(1, &tex.first);
    glDeleteBuffers(1, &vbo_shapes_);
    glDeleteBuffers(1, &vbo_flat_);
    glDeleteVertexArrays(1, &vao_shapes_);
    glDeleteVertexArrays(1, &vao_flat_);
    if (fbo_) {
      glDeleteFramebuffers(1, &fbo_);
      glDeleteRenderbuffers(1, &color_rb_);
      glDeleteRenderbuffers(1, &depth_rb_);
    }
    glDeleteProgram(shape_program_);
    glDeleteProgram(flat_program_);
  }

  std::string description() const override { return context_->description(); }

  void begin(int width, int height, const Color& background, bool depth, float fog) override {
    ensureFramebuffer(width, height);
    depth_ = depth;
    fog_ = fog;
    background_[0] = background.r, background_[1] = background.g, background_[2] = background.b;
    viewport_[0] = static_cast<float>(width), viewport_[1] = static_cast<float>(height);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
    glViewport(0, 0, width, height);
    glClearColor(background.r, background.g, background.b, 1.0f);
    glClearDepth(1.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glEnable(GL_BLEND);
    glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    if (depth) {
      glEnable(GL_DEPTH_TEST);
      glDepthFunc(GL_LEQUAL);
      glDepthMask(GL_TRUE);
    } else {
      glDisable(GL_DEPTH_TEST);
    }
  }

  void drawPolygons(const std::vector<FlatVertex>& triangles, bool depth_write) override {
    if (!depth_write && depth_) glDepthMask(GL_FALSE);
    drawFlat(triangles, false, 0);
    if (!depth_write && depth_) glDepthMask(GL_TRUE);
  }

  void drawShapes(const std::vector<ShapeVertex>& shapes, size_t opaque) override {
    if (shapes.empty()) return;
    glUseProgram(shape_program_);
    glUniform2fv(glGetUniformLocation(shape_program_, "viewport"), 1, viewport_);
    glUniform1i(glGetUniformLocation(shape_program_, "use_depth"), depth_ ? 1 : 0);
    glUniform1f(glGetUniformLocation(shape_program_, "fog"), depth_ ? fog_ : 0.0f);
    glUniform3fv(glGetUniformLocation(shape_program_, "fog_color"), 1, background_);
    glBindVertexArray(vao_shapes_);
    glBindBuffer(GL_ARRAY_BUFFER, vbo_shapes_);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(shapes.size() * sizeof(ShapeVertex)), shapes.data(),
                 GL_STREAM_DRAW);
    // Translucent shapes (3D, sorted last) test depth but do not write it: nothing behind them
    // is hidden, and among themselves the back-to-front order blends them.
    glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(opaque));
    if (depth_) glDepthMask(GL_FALSE);
    glDrawArrays(GL_TRIANGLES, static_cast<GLint>(opaque), static_cast<GLsizei>(shapes.size() - opaque));
    if (depth_) glDepthMask(GL_TRUE);
  }

  void drawText(const TextBatch& batch, const GlyphAtlas& atlas) override {
    glDisable(GL_DEPTH_TEST);
    drawFlat(batch.vertices, true, texture(batch.atlas_key, atlas));
  }

  void finish(Image& image) override {
    const int W = fb_width_, H = fb_height_;
    glFinish();
    image.width = W, image.height = H;
    image.rgba.resize(static_cast<size_t>(W) * H * 4);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    readback_.resize(static_cast<size_t>(W) * H * 4);
    glReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, readback_.data());
    for (int y = 0; y < H; ++y)
      std::memcpy(&image.rgba[static_cast<size_t>(y) * W * 4], &readback_[static_cast<size_t>(H - 1 - y) * W * 4],
                  static_cast<size_t>(W) * 4);
    const GLenum err = glGetError();
    if (err != GL_NO_ERROR) throw std::runtime_error("OpenGL error " + std::to_string(err) + " while rendering");
  }

 private:
  void ensureFramebuffer(int w, int h) {
    if (fbo_ && w == fb_width_ && h == fb_height_) return;
    if (!fbo_) {
      glGenFramebuffers(1, &fbo_);
      glGenRenderbuffers(1, &color_rb_);
      glGenRenderbuffers(1, &depth_rb_);
    }
    glBindRenderbuffer(GL_RENDERBUFFER, color_rb_);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, w, h);
    glBindRenderbuffer(GL_RENDERBUFFER, depth_rb_);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, w, h);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color_rb_);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_rb_);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw std::runtime_error("the offscreen framebuffer of " + std::to_string(w) + "x" + std::to_string(h) +
                               " is not complete");
    fb_width_ = w, fb_height_ = h;
  }

  // The atlas's texture, uploaded on first use and again when the atlas has grown since.
  GLuint texture(int key, const GlyphAtlas& a) {
    auto& [tex, generation] = atlas_textures_[key];
    if (tex && generation == a.generation()) return tex;
    if (!tex) glGenTextures(1, &tex);
    generation = a.generation();
    glBindTexture(GL_TEXTURE_2D, tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_R8, a.width(), a.height(), 0, GL_RED, GL_UNSIGNED_BYTE, a.pixels().data());
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    return tex;
  }

  void drawFlat(const std::vector<FlatVertex>& v, bool textured, GLuint tex) {
    if (v.empty()) return;
    glUseProgram(flat_program_);
    glUniform2fv(glGetUniformLocation(flat_program_, "viewport"), 1, viewport_);
    glUniform1i(glGetUniformLocation(flat_program_, "textured"), textured ? 1 : 0);
    glUniform1i(glGetUniformLocation(flat_program_, "atlas"), 0);
    if (textured) {
      glActiveTexture(GL_TEXTURE0);
      glBindTexture(GL_TEXTURE_2D, tex);
    }
    glBindVertexArray(vao_flat_);
    glBindBuffer(GL_ARRAY_BUFFER, vbo_flat_);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(v.size() * sizeof(FlatVertex)), v.data(), GL_STREAM_DRAW);
    glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(v.size()));
  }

  std::unique_ptr<GlContext> context_;
  GLuint shape_program_ = 0, flat_program_ = 0;
  GLuint vao_shapes_ = 0, vbo_shapes_ = 0, vao_flat_ = 0, vbo_flat_ = 0;
  GLuint fbo_ = 0, color_rb_ = 0, depth_rb_ = 0;
  int fb_width_ = 0, fb_height_ = 0;
  bool depth_ = false;
  float fog_ = 0, background_[3] = {1, 1, 1};
  float viewport_[2] = {0, 0};
  std::vector<std::uint8_t> readback_;  // bottom-up rows from glReadPixels, kept between frames
  std::map<int, std::pair<GLuint, int>> atlas_textures_;  // key -> texture, atlas generation
};

}  // namespace

std::unique_ptr<DrawBackend> createOpenGlBackend() { return std::make_unique<OpenGlBackend>(); }

}  // namespace flexure::render
