#include "present/print_mesh.h"

#include "render/utf8.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>

namespace flexure::present {

namespace {

using V3 = std::array<double, 3>;

V3 add(const V3& a, const V3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
V3 sub(const V3& a, const V3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
V3 scale(const V3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
V3 cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double norm(const V3& a) { return std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]); }

constexpr int kSides = 16;             // around a tube
constexpr int kStacks = 10, kSlices = 20;  // a sphere

V3 point(const engine::Matrix& p, int i) {
  V3 q{0, 0, 0};
  for (int k = 0; k < std::min<int>(3, static_cast<int>(p.rows())); ++k) q[k] = p(k, i);
  return q;
}

// A closed cylinder from a to b of radius r: kSides quads and two fans.
void tube(PrintMesh& m, const V3& a, const V3& b, double r) {
  const V3 axis = sub(b, a);
  const double len = norm(axis);
  if (!(len > 0)) return;
  const V3 w = scale(axis, 1 / len);
  const V3 t = std::abs(w[0]) < 0.9 ? V3{1, 0, 0} : V3{0, 1, 0};
  V3 u = cross(w, t);
  u = scale(u, 1 / norm(u));
  const V3 v = cross(w, u);
  const int base = static_cast<int>(m.vertices.size());
  for (int end = 0; end < 2; ++end)
    for (int k = 0; k < kSides; ++k) {
      const double phi = 2 * M_PI * k / kSides;
      m.vertices.push_back(add(end ? b : a, add(scale(u, r * std::cos(phi)), scale(v, r * std::sin(phi)))));
    }
  const int ca = static_cast<int>(m.vertices.size());
  m.vertices.push_back(a);
  m.vertices.push_back(b);
  for (int k = 0; k < kSides; ++k) {
    const int k1 = (k + 1) % kSides;
    const int a0 = base + k, a1 = base + k1, b0 = base + kSides + k, b1 = base + kSides + k1;
    m.triangles.push_back({a0, a1, b1});  // u, v, w right-handed: outward
    m.triangles.push_back({a0, b1, b0});
    m.triangles.push_back({ca, a1, a0});      // the cap at a faces -w
    m.triangles.push_back({ca + 1, b0, b1});  // the cap at b faces +w
  }
}

// A UV sphere of radius r about c.
void sphere(PrintMesh& m, const V3& c, double r) {
  const int base = static_cast<int>(m.vertices.size());
  m.vertices.push_back(add(c, {0, 0, r}));   // north pole
  for (int i = 1; i < kStacks; ++i) {
    const double theta = M_PI * i / kStacks;
    for (int j = 0; j < kSlices; ++j) {
      const double phi = 2 * M_PI * j / kSlices;
      m.vertices.push_back(add(c, {r * std::sin(theta) * std::cos(phi), r * std::sin(theta) * std::sin(phi),
                                   r * std::cos(theta)}));
    }
  }
  m.vertices.push_back(add(c, {0, 0, -r}));  // south pole
  const int south = static_cast<int>(m.vertices.size()) - 1;
  const auto ring = [&](int i, int j) { return base + 1 + (i - 1) * kSlices + (j % kSlices); };
  for (int j = 0; j < kSlices; ++j) {
    m.triangles.push_back({base, ring(1, j), ring(1, j + 1)});
    for (int i = 1; i + 1 < kStacks; ++i) {
      m.triangles.push_back({ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)});
      m.triangles.push_back({ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)});
    }
    m.triangles.push_back({south, ring(kStacks - 1, j + 1), ring(kStacks - 1, j)});
  }
}

V3 normalOf(const PrintMesh& m, const std::array<int, 3>& t) {
  const V3 n = cross(sub(m.vertices[static_cast<size_t>(t[1])], m.vertices[static_cast<size_t>(t[0])]),
                     sub(m.vertices[static_cast<size_t>(t[2])], m.vertices[static_cast<size_t>(t[0])]));
  const double l = norm(n);
  return l > 0 ? scale(n, 1 / l) : V3{0, 0, 0};
}

}  // namespace

PrintMesh printMesh(const engine::Geometry& g, const engine::Matrix& p, double tube_fraction, double joint_fraction,
                    int index_base) {
  std::vector<double> lengths;
  for (const auto& b : g.bars.edges) lengths.push_back(norm(sub(point(p, b[0]), point(p, b[1]))));
  double L = 0;
  if (!lengths.empty()) {
    std::nth_element(lengths.begin(), lengths.begin() + static_cast<long>(lengths.size() / 2), lengths.end());
    L = lengths[lengths.size() / 2];
  }
  if (!(L > 0)) {  // no bars: the extent
    for (int i = 0; i < g.points; ++i)
      for (int j = i + 1; j < g.points; ++j) L = std::max(L, norm(sub(point(p, i), point(p, j))));
    if (!(L > 0)) L = 1;
  }
  PrintMesh m;
  const auto part = [&](std::string name) { m.parts.push_back({std::move(name), static_cast<int>(m.triangles.size())}); };
  for (const auto& b : g.bars.edges) {
    part("bar " + std::to_string(b[0] + index_base) + "-" + std::to_string(b[1] + index_base));
    tube(m, point(p, b[0]), point(p, b[1]), tube_fraction * L);
  }
  for (int i = 0; i < g.points; ++i) {
    const bool ball = !g.balls.empty();
    part((ball ? "ball " : "joint ") + std::to_string(i + index_base));
    sphere(m, point(p, i), ball ? g.balls.radii[static_cast<size_t>(i)] : joint_fraction * L);
  }
  return m;
}

std::string printMeshFile(const PrintMesh& m, const std::string& format, const std::string& title) {
  std::string out;
  if (format == "obj") {
    // The title and part names as text on their lines (a newline in a title would start an
    // OBJ statement).
    out = "# " + render::cleanText(title) + "\n# written by flexure: bars as tubes, joints as spheres, in the scene's units\n";
    char buf[96];
    for (const auto& v : m.vertices) {
      std::snprintf(buf, sizeof buf, "v %.9g %.9g %.9g\n", v[0], v[1], v[2]);
      out += buf;
    }
    for (size_t k = 0; k < m.parts.size(); ++k) {
      std::string name = render::cleanText(m.parts[k].name);
      std::replace(name.begin(), name.end(), ' ', '_');
      out += "o " + name + "\n";
      const size_t end = k + 1 < m.parts.size() ? static_cast<size_t>(m.parts[k + 1].first_triangle) : m.triangles.size();
      for (size_t t = static_cast<size_t>(m.parts[k].first_triangle); t < end; ++t) {
        std::snprintf(buf, sizeof buf, "f %d %d %d\n", m.triangles[t][0] + 1, m.triangles[t][1] + 1, m.triangles[t][2] + 1);
        out += buf;
      }
    }
    return out;
  }
  // Binary STL: an 80-byte header, the count, then per triangle the normal, three corners and
  // two zero bytes (little-endian floats).
  std::string header = "flexure: " + render::cleanText(title);
  header.resize(80, ' ');
  if (header.rfind("solid", 0) == 0) header[0] = 'S';  // never "solid": readers would take it for ASCII
  out = header;
  const auto put32 = [&](std::uint32_t v) {
    for (int k = 0; k < 4; ++k) out += static_cast<char>((v >> (8 * k)) & 0xFF);
  };
  const auto putFloat = [&](double d) {
    const float f = static_cast<float>(d);
    std::uint32_t bits;
    std::memcpy(&bits, &f, 4);
    put32(bits);
  };
  put32(static_cast<std::uint32_t>(m.triangles.size()));
  for (const auto& t : m.triangles) {
    for (double c : normalOf(m, t)) putFloat(c);
    for (int v : t)
      for (double c : m.vertices[static_cast<size_t>(v)]) putFloat(c);
    out += std::string(2, '\0');
  }
  return out;
}

}  // namespace flexure::present
