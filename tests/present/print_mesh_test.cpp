// Solids for 3D printing: every part (a bar's tube, a joint's sphere, a packing's ball) is a
// closed, outward-oriented triangle mesh whose volume is the shape's; the files (OBJ, binary
// STL) hold every part.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <map>
#include <utility>

#include "pipeline/pipeline.h"
#include "present/print_mesh.h"
#include "../scenes/scene_test_common.h"

using namespace flexure;

namespace {

using V3 = std::array<double, 3>;

// Signed volume of triangles [from, to) (divergence theorem), and whether every edge is used
// once in each direction (closed and consistently oriented).
std::pair<double, bool> shell(const present::PrintMesh& m, int from, int to) {
  double volume = 0;
  std::map<std::pair<int, int>, int> edges;
  for (int t = from; t < to; ++t) {
    const auto& tri = m.triangles[static_cast<size_t>(t)];
    const V3& a = m.vertices[static_cast<size_t>(tri[0])];
    const V3& b = m.vertices[static_cast<size_t>(tri[1])];
    const V3& c = m.vertices[static_cast<size_t>(tri[2])];
    volume += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0])) / 6;
    for (int k = 0; k < 3; ++k) ++edges[{tri[k], tri[(k + 1) % 3]}];
  }
  bool closed = true;
  for (const auto& [e, n] : edges) closed = closed && n == 1 && edges.count({e.second, e.first}) == 1;
  return {volume, closed};
}

}  // namespace

TEST_CASE("print mesh: closed outward tubes and spheres of the right volume, named by part", "[outputs][print]") {
  const scenes::Scene scene = test::example("bricard_octahedron", {"motion.steps=10"});
  const engine::Geometry g = scene.model->geometry();
  const engine::Matrix p = scene.model->startPositions().leftCols(g.points);
  const present::PrintMesh m = present::printMesh(g, p, 0.05, 0.12, 1);
  REQUIRE(m.parts.size() == g.bars.edges.size() + static_cast<size_t>(g.points));  // 12 tubes, 6 joints
  CHECK(m.parts.front().name == "bar " + std::to_string(g.bars.edges[0][0] + 1) + "-" + std::to_string(g.bars.edges[0][1] + 1));
  CHECK(m.parts.back().name == "joint 6");
  std::vector<double> lengths;
  for (const auto& b : g.bars.edges) lengths.push_back((p.col(b[0]) - p.col(b[1])).norm());
  std::nth_element(lengths.begin(), lengths.begin() + 6, lengths.end());
  const double L = lengths[6], r = 0.05 * L, R = 0.12 * L;
  for (size_t k = 0; k < m.parts.size(); ++k) {
    INFO(m.parts[k].name);
    const int to = k + 1 < m.parts.size() ? m.parts[k + 1].first_triangle : static_cast<int>(m.triangles.size());
    const auto [volume, closed] = shell(m, m.parts[k].first_triangle, to);
    CHECK(closed);
    if (k < g.bars.edges.size()) {
      const double len = (p.col(g.bars.edges[k][0]) - p.col(g.bars.edges[k][1])).norm();
      CHECK(volume == Approx(8 * std::sin(2 * M_PI / 16) * r * r * len).epsilon(1e-9));  // the 16-gon prism
    } else {
      CHECK(volume == Approx(4.0 / 3 * M_PI * R * R * R).epsilon(0.05));  // a polyhedral sphere, within 5 %
      CHECK(volume < 4.0 / 3 * M_PI * R * R * R);                         // inscribed
    }
  }
}

TEST_CASE("print mesh: balls at their radii, 2D in the plane z = 0, OBJ and binary STL files", "[outputs][print]") {
  const scenes::Scene packing = test::example("sphere_packing");
  const engine::Geometry g = packing.model->geometry();
  const present::PrintMesh balls =
      present::printMesh(g, packing.model->startPositions().leftCols(g.points), 0.05, 0.12, packing.index_base);
  int named_balls = 0;
  for (const auto& part : balls.parts) named_balls += part.name.rfind("ball ", 0) == 0;
  CHECK(named_balls == g.points);
  const scenes::Scene dw = test::example("double_watt");
  const engine::Geometry g2 = dw.model->geometry();
  const present::PrintMesh flat = present::printMesh(g2, dw.model->startPositions().leftCols(g2.points), 0.05, 0.12, 1);
  double zmax = 0;
  for (const auto& v : flat.vertices) zmax = std::max(zmax, std::abs(v[2]));
  const engine::Matrix q = dw.model->startPositions();
  std::vector<double> lengths;
  for (const auto& b : g2.bars.edges) lengths.push_back((q.col(b[0]) - q.col(b[1])).norm());
  std::nth_element(lengths.begin(), lengths.begin() + 7, lengths.end());  // 15 bars: the 8th is the median
  CHECK(zmax == Approx(0.12 * lengths[7]).epsilon(1e-9));  // only the joints' spheres leave the plane z = 0
  const std::string obj = present::printMeshFile(flat, "obj", "t");
  size_t objects = 0, faces = 0;
  for (size_t at = obj.find("\no "); at != std::string::npos; at = obj.find("\no ", at + 1)) ++objects;
  for (size_t at = obj.find("\nf "); at != std::string::npos; at = obj.find("\nf ", at + 1)) ++faces;
  CHECK(objects == flat.parts.size());
  CHECK(faces == flat.triangles.size());
  const std::string stl = present::printMeshFile(flat, "stl", "solid name");
  REQUIRE(stl.size() == 84 + 50 * flat.triangles.size());
  CHECK(stl.rfind("solid", 0) != 0);  // a binary STL must not look like an ASCII one
  std::uint32_t count = 0;
  std::memcpy(&count, stl.data() + 80, 4);
  CHECK(count == flat.triangles.size());
  float normal[3];
  std::memcpy(normal, stl.data() + 84, 12);
  CHECK(std::sqrt(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]) == Approx(1).epsilon(1e-5));
}
