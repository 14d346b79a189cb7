#define GL_GLEXT_PROTOTYPES 1
#include "render/renderer.h"

#include <GL/gl.h>
#include <GL/glext.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <stdexcept>
#include <vector>

#include "render/camera.h"
#include "render/gl_context.h"
#include "render/text.h"

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

struct ShapeVertex {
  float pos[3];
  float ends[4];
  float params[4];
  float fill[4];
  float stroke[4];
  float extra[4];
  float depths[3];
};

struct FlatVertex {
  float pos[3];
  float rgba[4];
  float uv[2];
};

void copyColor(float* out, const Color& c) {
  out[0] = c.r, out[1] = c.g, out[2] = c.b, out[3] = c.a;
}

// Ear clipping of a simple polygon given in 2D (indices into pts); returns triangles.
std::vector<int> triangulate(const std::vector<std::array<double, 2>>& pts) {
  const int n = static_cast<int>(pts.size());
  std::vector<int> out, idx(n);
  if (n < 3) return out;
  double area = 0;
  for (int i = 0; i < n; ++i) {
    const auto& p = pts[i];
    const auto& q = pts[(i + 1) % n];
    area += p[0] * q[1] - q[0] * p[1];
  }
  for (int i = 0; i < n; ++i) idx[i] = area >= 0 ? i : n - 1 - i;
  auto cross = [&](int a, int b, int c) {
    return (pts[b][0] - pts[a][0]) * (pts[c][1] - pts[a][1]) - (pts[b][1] - pts[a][1]) * (pts[c][0] - pts[a][0]);
  };
  int guard = 0;
  while (idx.size() > 3 && guard++ < 4 * n * n) {
    bool clipped = false;
    const int m = static_cast<int>(idx.size());
    for (int i = 0; i < m; ++i) {
      const int a = idx[(i + m - 1) % m], b = idx[i], c = idx[(i + 1) % m];
      if (cross(a, b, c) <= 0) continue;
      bool inside = false;
      for (int j : idx) {
        if (j == a || j == b || j == c) continue;
        if (cross(a, b, j) >= 0 && cross(b, c, j) >= 0 && cross(c, a, j) >= 0) {
          inside = true;
          break;
        }
      }
      if (inside) continue;
      out.insert(out.end(), {a, b, c});
      idx.erase(idx.begin() + i);
      clipped = true;
      break;
    }
    if (!clipped) break;  // degenerate: fan the rest
  }
  for (size_t i = 1; i + 1 < idx.size(); ++i) out.insert(out.end(), {idx[0], idx[i], idx[i + 1]});
  return out;
}

}  // namespace

struct Renderer::Impl {
  std::unique_ptr<GlContext> context;
  std::string font_path, regular_font_path;
  GLuint shape_program = 0, flat_program = 0;
  GLuint vao_shapes = 0, vbo_shapes = 0, vao_flat = 0, vbo_flat = 0;
  GLuint fbo = 0, color_rb = 0, depth_rb = 0;
  int fb_width = 0, fb_height = 0;
  std::vector<std::uint8_t> readback;  // bottom-up rows from glReadPixels, kept between frames
  std::map<int, std::unique_ptr<GlyphAtlas>> atlases;
  std::map<int, GLuint> atlas_textures;

  void ensureFramebuffer(int w, int h) {
    if (fbo && w == fb_width && h == fb_height) return;
    if (!fbo) {
      glGenFramebuffers(1, &fbo);
      glGenRenderbuffers(1, &color_rb);
      glGenRenderbuffers(1, &depth_rb);
    }
    glBindRenderbuffer(GL_RENDERBUFFER, color_rb);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, w, h);
    glBindRenderbuffer(GL_RENDERBUFFER, depth_rb);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, w, h);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color_rb);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_rb);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw std::runtime_error("the offscreen framebuffer of " + std::to_string(w) + "x" + std::to_string(h) +
                               " is not complete");
    fb_width = w, fb_height = h;
  }

  // Atlases are keyed by 2 * size + (regular weight).
  const GlyphAtlas& atlas(int key) {
    auto it = atlases.find(key);
    if (it != atlases.end()) return *it->second;
    auto a = std::make_unique<GlyphAtlas>(key % 2 ? regular_font_path : font_path, key / 2);
    GLuint tex = 0;
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D, tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_R8, a->width(), a->height(), 0, GL_RED, GL_UNSIGNED_BYTE, a->pixels().data());
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    atlas_textures[key] = tex;
    return *(atlases[key] = std::move(a));
  }

  static void setupAttributes(const std::vector<std::pair<int, size_t>>& layout, size_t stride) {
    for (size_t i = 0; i < layout.size(); ++i) {
      glEnableVertexAttribArray(static_cast<GLuint>(i));
      glVertexAttribPointer(static_cast<GLuint>(i), layout[i].first, GL_FLOAT, GL_FALSE, static_cast<GLsizei>(stride),
                            reinterpret_cast<const void*>(layout[i].second));
    }
  }
};

Renderer::Renderer(const std::string& font_path) : impl_(std::make_unique<Impl>()) {
  impl_->font_path = font_path.empty() ? defaultFontPath() : font_path;
  impl_->regular_font_path = font_path.empty() ? regularFontPath(impl_->font_path) : font_path;
  impl_->context = createOffscreenContext();
  impl_->shape_program = link(kShapeVertex, kShapeFragment);
  impl_->flat_program = link(kFlatVertex, kFlatFragment);
  glGenVertexArrays(1, &impl_->vao_shapes);
  glGenBuffers(1, &impl_->vbo_shapes);
  glBindVertexArray(impl_->vao_shapes);
  glBindBuffer(GL_ARRAY_BUFFER, impl_->vbo_shapes);
  Impl::setupAttributes({{3, offsetof(ShapeVertex, pos)},
                         {4, offsetof(ShapeVertex, ends)},
                         {4, offsetof(ShapeVertex, params)},
                         {4, offsetof(ShapeVertex, fill)},
                         {4, offsetof(ShapeVertex, stroke)},
                         {4, offsetof(ShapeVertex, extra)},
                         {3, offsetof(ShapeVertex, depths)}},
                        sizeof(ShapeVertex));
  glGenVertexArrays(1, &impl_->vao_flat);
  glGenBuffers(1, &impl_->vbo_flat);
  glBindVertexArray(impl_->vao_flat);
  glBindBuffer(GL_ARRAY_BUFFER, impl_->vbo_flat);
  Impl::setupAttributes({{3, offsetof(FlatVertex, pos)}, {4, offsetof(FlatVertex, rgba)}, {2, offsetof(FlatVertex, uv)}},
                        sizeof(FlatVertex));
  glBindVertexArray(0);
}

Renderer::~Renderer() {
  if (!impl_ || !impl_->context) return;
  for (auto& [size, tex] : impl_->atlas_textures) glDeleteTextures(1, &tex);
  glDeleteBuffers(1, &impl_->vbo_shapes);
  glDeleteBuffers(1, &impl_->vbo_flat);
  glDeleteVertexArrays(1, &impl_->vao_shapes);
  glDeleteVertexArrays(1, &impl_->vao_flat);
  if (impl_->fbo) {
    glDeleteFramebuffers(1, &impl_->fbo);
    glDeleteRenderbuffers(1, &impl_->color_rb);
    glDeleteRenderbuffers(1, &impl_->depth_rb);
  }
  glDeleteProgram(impl_->shape_program);
  glDeleteProgram(impl_->flat_program);
}

std::string Renderer::contextDescription() const { return impl_->context->description(); }

Image Renderer::render(const DrawList& list, const View& view) {
  Image image;
  render(list, view, image);
  return image;
}

void Renderer::render(const DrawList& list, const View& view, Image& image) {
  Impl& m = *impl_;
  const int W = view.width, H = view.height;
  m.ensureFramebuffer(W, H);
  glBindFramebuffer(GL_FRAMEBUFFER, m.fbo);
  glViewport(0, 0, W, H);
  glClearColor(view.background.r, view.background.g, view.background.b, 1.0f);
  glClearDepth(1.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glEnable(GL_BLEND);
  glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
  const bool depth = view.three_d;
  const Projector project(view);
  const float viewport[2] = {static_cast<float>(W), static_cast<float>(H)};

  // Polygons: opaque ones first; translucent ones back to front without depth writes.
  std::vector<FlatVertex> opaque_tris, clear_tris;
  std::vector<std::pair<double, size_t>> order;
  for (size_t i = 0; i < list.polygons.size(); ++i) {
    double zsum = 0;  // 2D: all zero, so the order given stays
    if (depth)
      for (const Point3& p : list.polygons[i].points) zsum += project(p)[2];
    order.push_back({-zsum / std::max<size_t>(1, list.polygons[i].points.size()), i});
  }
  std::stable_sort(order.begin(), order.end(), [](auto& a, auto& b) { return a.first < b.first; });
  for (const auto& [key, i] : order) {
    const Polygon& poly = list.polygons[i];
    const size_t n = poly.points.size();
    if (n < 3) continue;
    // Triangulate in the polygon's own plane (Newell normal), so edge-on views stay right.
    std::array<double, 3> normal{0, 0, 0}, c{0, 0, 0};
    for (size_t k = 0; k < n; ++k) {
      const Point3& p = poly.points[k];
      const Point3& q = poly.points[(k + 1) % n];
      normal[0] += (p[1] - q[1]) * (p[2] + q[2]);
      normal[1] += (p[2] - q[2]) * (p[0] + q[0]);
      normal[2] += (p[0] - q[0]) * (p[1] + q[1]);
      for (int j = 0; j < 3; ++j) c[j] += p[j] / static_cast<double>(n);
    }
    const double nn = std::sqrt(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]);
    std::array<double, 3> e1{1, 0, 0}, e2{0, 1, 0};
    if (nn > 0) {
      for (double& x : normal) x /= nn;
      const std::array<double, 3> t = std::abs(normal[0]) < 0.9 ? std::array<double, 3>{1, 0, 0}
                                                                 : std::array<double, 3>{0, 1, 0};
      e1 = {normal[1] * t[2] - normal[2] * t[1], normal[2] * t[0] - normal[0] * t[2], normal[0] * t[1] - normal[1] * t[0]};
      const double l = std::sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
      for (double& x : e1) x /= l;
      e2 = {normal[1] * e1[2] - normal[2] * e1[1], normal[2] * e1[0] - normal[0] * e1[2], normal[0] * e1[1] - normal[1] * e1[0]};
    }
    static const std::vector<int> kTriangle = {0, 1, 2};  // meshes: no triangulation needed
    std::vector<int> triangles;
    if (n > 3) {
      std::vector<std::array<double, 2>> flat(n);
      for (size_t k = 0; k < n; ++k) {
        double u = 0, v = 0;
        for (int j = 0; j < 3; ++j) {
          u += (poly.points[k][j] - c[j]) * e1[j];
          v += (poly.points[k][j] - c[j]) * e2[j];
        }
        flat[k] = {u, v};
      }
      triangles = triangulate(flat);
    }
    Color col = poly.fill;
    if (poly.shaded && depth && nn > 0) {
      const auto ne = project.toEye({normal[0], normal[1], normal[2]});
      const double lit = std::abs(-0.35 * ne[0] + 0.45 * ne[1] + 0.82 * ne[2]);
      const float f = static_cast<float>(0.55 + 0.45 * std::min(1.0, lit));
      col.r *= f, col.g *= f, col.b *= f;
    }
    std::vector<FlatVertex>& out = col.a >= 1.0f ? opaque_tris : clear_tris;
    for (int k : n > 3 ? triangles : kTriangle) {
      const auto q = project(poly.points[static_cast<size_t>(k)]);
      FlatVertex fv{};
      fv.pos[0] = static_cast<float>(q[0]), fv.pos[1] = static_cast<float>(q[1]), fv.pos[2] = static_cast<float>(q[2]);
      copyColor(fv.rgba, col);
      out.push_back(fv);
    }
  }
  auto drawFlat = [&](const std::vector<FlatVertex>& v, bool textured, GLuint tex) {
    if (v.empty()) return;
    glUseProgram(m.flat_program);
    glUniform2fv(glGetUniformLocation(m.flat_program, "viewport"), 1, viewport);
    glUniform1i(glGetUniformLocation(m.flat_program, "textured"), textured ? 1 : 0);
    glUniform1i(glGetUniformLocation(m.flat_program, "atlas"), 0);
    if (textured) {
      glActiveTexture(GL_TEXTURE0);
      glBindTexture(GL_TEXTURE_2D, tex);
    }
    glBindVertexArray(m.vao_flat);
    glBindBuffer(GL_ARRAY_BUFFER, m.vbo_flat);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(v.size() * sizeof(FlatVertex)), v.data(), GL_STREAM_DRAW);
    glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(v.size()));
  };

  // Shapes: one quad each, in pixels.
  std::vector<ShapeVertex> shapes;
  shapes.reserve(list.shapes.size() * 6);
  const double depth_per_px = depth ? project.depthPerUnit() / std::max(project.pixelsPerUnit(), 1e-300) : 0.0;
  // In 3D, translucent shapes go after the opaque ones, back to front (larger depth first).
  std::vector<size_t> shape_order(list.shapes.size());
  size_t opaque_shapes = list.shapes.size();  // 2D: all in order, depth plays no part
  for (size_t i = 0; i < shape_order.size(); ++i) shape_order[i] = i;
  if (depth) {
    std::vector<double> z(shape_order.size());
    for (size_t i = 0; i < shape_order.size(); ++i) z[i] = 0.5 * (project(list.shapes[i].a)[2] + project(list.shapes[i].b)[2]);
    auto clear = [&](size_t i) { return list.shapes[i].fill.a < 1.0f; };
    const auto mid = std::stable_partition(shape_order.begin(), shape_order.end(), [&](size_t i) { return !clear(i); });
    std::stable_sort(mid, shape_order.end(), [&](size_t i, size_t j) { return z[i] > z[j]; });
    opaque_shapes = static_cast<size_t>(mid - shape_order.begin());
  }
  size_t opaque_vertices = 0;  // shapes[0, opaque_vertices) are the opaque ones
  for (size_t pos = 0; pos < shape_order.size(); ++pos) {
    if (pos == opaque_shapes) opaque_vertices = shapes.size();
    Shape s = list.shapes[shape_order[pos]];
    if (s.kind == ShapeKind::Disc && s.world_radius > 0)
      s.radius = static_cast<float>(s.world_radius * project.pixelsPerUnitAt(s.a));
    auto pa = project(s.a), pb = project(s.b);
    float pointing[2] = {s.pointing[0], s.pointing[1]};
    if (s.kind == ShapeKind::Triangle && s.a != s.b) {  // an arrow head at b
      const double dx = pb[0] - pa[0], dy = pb[1] - pa[1], len = std::hypot(dx, dy);
      if (len < 1e-9) continue;
      pointing[0] = static_cast<float>(dx / len), pointing[1] = static_cast<float>(dy / len);
      pa = pb;
      pa[0] -= s.radius * dx / len, pa[1] -= s.radius * dy / len;
    }
    if (s.kind != ShapeKind::Segment) {
      pa[0] += s.offset[0], pa[1] += s.offset[1];
      pb = pa;
    } else if (s.inset > 0) {
      const double dx = pb[0] - pa[0], dy = pb[1] - pa[1], len = std::hypot(dx, dy);
      const double keep = std::max(0.0, len - s.inset) / std::max(len, 1e-300);
      pb[0] = pa[0] + keep * dx, pb[1] = pa[1] + keep * dy, pb[2] = pa[2] + keep * (pb[2] - pa[2]);
    }
    ShapeVertex base{};
    base.ends[0] = static_cast<float>(pa[0]), base.ends[1] = static_cast<float>(pa[1]);
    base.ends[2] = static_cast<float>(pb[0]), base.ends[3] = static_cast<float>(pb[1]);
    base.params[0] = static_cast<float>(s.kind == ShapeKind::Segment ? 0 : s.kind == ShapeKind::Disc ? 1
                                        : s.kind == ShapeKind::Triangle ? 2 : 3);
    base.params[1] = s.radius;
    base.params[2] = s.outline;
    base.params[3] = static_cast<float>(s.radius * depth_per_px);
    copyColor(base.fill, s.fill);
    copyColor(base.stroke, s.stroke);
    if (s.kind == ShapeKind::Segment) {
      base.extra[0] = s.dash, base.extra[1] = s.gap;
    } else {
      base.extra[0] = pointing[0], base.extra[1] = pointing[1];
    }
    base.depths[0] = static_cast<float>(pa[2]), base.depths[1] = static_cast<float>(pb[2]);
    base.depths[2] = s.shaded && depth ? 1.0f : 0.0f;
    // The covering quad.
    const double grow = s.radius + 1.5;
    double dx = pb[0] - pa[0], dy = pb[1] - pa[1];
    const double len = std::hypot(dx, dy);
    if (len > 0) dx /= len, dy /= len;
    else dx = 1, dy = 0;
    const double nx = -dy, ny = dx;
    const double corners[4][2] = {{pa[0] - grow * dx - grow * nx, pa[1] - grow * dy - grow * ny},
                                  {pb[0] + grow * dx - grow * nx, pb[1] + grow * dy - grow * ny},
                                  {pb[0] + grow * dx + grow * nx, pb[1] + grow * dy + grow * ny},
                                  {pa[0] - grow * dx + grow * nx, pa[1] - grow * dy + grow * ny}};
    const float zq = static_cast<float>(std::min(pa[2], pb[2]));
    for (int k : {0, 1, 2, 0, 2, 3}) {
      ShapeVertex v = base;
      v.pos[0] = static_cast<float>(corners[k][0]), v.pos[1] = static_cast<float>(corners[k][1]), v.pos[2] = zq;
      shapes.push_back(v);
    }
  }
  if (opaque_shapes >= shape_order.size()) opaque_vertices = shapes.size();

  if (depth) {
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LEQUAL);
    glDepthMask(GL_TRUE);
  } else {
    glDisable(GL_DEPTH_TEST);
  }
  drawFlat(opaque_tris, false, 0);
  if (!depth) drawFlat(clear_tris, false, 0);  // 2D: polygons under the shapes, in order
  if (!shapes.empty()) {
    glUseProgram(m.shape_program);
    glUniform2fv(glGetUniformLocation(m.shape_program, "viewport"), 1, viewport);
    glUniform1i(glGetUniformLocation(m.shape_program, "use_depth"), depth ? 1 : 0);
    glBindVertexArray(m.vao_shapes);
    glBindBuffer(GL_ARRAY_BUFFER, m.vbo_shapes);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(shapes.size() * sizeof(ShapeVertex)), shapes.data(),
                 GL_STREAM_DRAW);
    // Translucent shapes (3D, sorted last) test depth but do not write it: nothing behind them
    // is hidden, and among themselves the back-to-front order blends them.
    glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(opaque_vertices));
    if (depth) glDepthMask(GL_FALSE);
    glDrawArrays(GL_TRIANGLES, static_cast<GLint>(opaque_vertices),
                 static_cast<GLsizei>(shapes.size() - opaque_vertices));
    if (depth) glDepthMask(GL_TRUE);
  }
  if (depth) {  // translucent facets over the opaque scene, depth-tested, not written
    glDepthMask(GL_FALSE);
    drawFlat(clear_tris, false, 0);
    glDepthMask(GL_TRUE);
  }

  // Labels on top, centred on their anchors.
  glDisable(GL_DEPTH_TEST);
  std::map<int, std::vector<FlatVertex>> text;
  for (const Label& l : list.labels) {
    const int size = 2 * std::max(4, static_cast<int>(std::lround(l.size))) + (l.regular ? 1 : 0);
    const GlyphAtlas& atlas = m.atlas(size);
    const auto at = l.screen ? std::array<double, 3>{l.at[0], H - l.at[1], 0.0} : project(l.at);
    double width = 0, top = -1e9, bottom = 1e9, left = 1e9;
    double pen = 0;
    for (char ch : l.text) {
      const Glyph& g = atlas.glyph(ch);
      if (g.w > 0) {
        left = std::min(left, pen + g.left);
        top = std::max(top, static_cast<double>(g.top));
        bottom = std::min(bottom, static_cast<double>(g.top - g.h));
        width = pen + g.left + g.w;
      }
      pen += g.advance;
    }
    if (top < bottom) continue;
    const double ox = std::round(at[0] + l.offset[0] - 0.5 * (1 + l.align) * width + 0.5 * (l.align - 1) * left);
    const double oy = std::round(at[1] + l.offset[1] - 0.5 * (top + bottom));
    pen = 0;
    auto& out = text[size];
    for (char ch : l.text) {
      const Glyph& g = atlas.glyph(ch);
      if (g.w > 0) {
        const double x0 = ox + pen + g.left, y1 = oy + g.top, x1 = x0 + g.w, y0 = y1 - g.h;
        const float u0 = static_cast<float>(g.x) / atlas.width(), u1 = static_cast<float>(g.x + g.w) / atlas.width();
        const float v0 = static_cast<float>(g.y) / atlas.height(), v1 = static_cast<float>(g.y + g.h) / atlas.height();
        const double xs[4] = {x0, x1, x1, x0}, ys[4] = {y0, y0, y1, y1};
        const float us[4] = {u0, u1, u1, u0}, vs[4] = {v1, v1, v0, v0};
        for (int k : {0, 1, 2, 0, 2, 3}) {
          FlatVertex fv{};
          fv.pos[0] = static_cast<float>(xs[k]), fv.pos[1] = static_cast<float>(ys[k]), fv.pos[2] = 0;
          copyColor(fv.rgba, l.color);
          fv.uv[0] = us[k], fv.uv[1] = vs[k];
          out.push_back(fv);
        }
      }
      pen += g.advance;
    }
  }
  for (auto& [size, verts] : text) drawFlat(verts, true, m.atlas_textures.at(size));

  glFinish();
  image.width = W, image.height = H;
  image.rgba.resize(static_cast<size_t>(W) * H * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  m.readback.resize(static_cast<size_t>(W) * H * 4);
  glReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, m.readback.data());
  for (int y = 0; y < H; ++y)
    std::memcpy(&image.rgba[static_cast<size_t>(y) * W * 4], &m.readback[static_cast<size_t>(H - 1 - y) * W * 4],
                static_cast<size_t>(W) * 4);
  const GLenum err = glGetError();
  if (err != GL_NO_ERROR) throw std::runtime_error("OpenGL error " + std::to_string(err) + " while rendering");
}

}  // namespace flexure::render
