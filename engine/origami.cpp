#include "engine/origami.h"

#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <numeric>
#include <string>

#include "engine/corrector.h"

namespace flexure::engine {

Eigen::Vector3d newellNormal(const Matrix& p, const std::vector<int>& polygon) {
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  const size_t k = polygon.size();
  for (size_t i = 0; i < k; ++i) {
    const Eigen::Vector3d a = p.col(polygon[i]).head<3>(), b = p.col(polygon[(i + 1) % k]).head<3>();
    n += Eigen::Vector3d((a.y() - b.y()) * (a.z() + b.z()), (a.z() - b.z()) * (a.x() + b.x()),
                         (a.x() - b.x()) * (a.y() + b.y()));
  }
  const double len = n.norm();
  return len > 0 ? Eigen::Vector3d(n / len) : n;
}

struct Origami::Panels {
  std::vector<std::vector<int>> faces;
  std::vector<Crease> edges;
  std::vector<std::vector<int>> bodies;
  std::vector<int> panel_of_face;
};

namespace {

std::string sideText(int u, int v, int base) {
  return "[" + std::to_string(u + base) + ", " + std::to_string(v + base) + "]";
}

Origami::Panels makePanels(const Matrix& points, std::vector<std::vector<int>> faces, std::vector<Crease> edges,
                           int base) {
  const int n = static_cast<int>(points.cols());
  if (points.rows() != 3) throw ModelError("vertices", -1, "origami lives in 3D (a crease pattern has z = 0)");
  if (faces.empty()) throw ModelError("faces", -1, "the sheet has no faces");
  std::map<std::pair<int, int>, int> edge_of;  // undirected: (min, max) -> edge
  for (size_t e = 0; e < edges.size(); ++e) {
    Crease& c = edges[e];
    const int item = static_cast<int>(e);
    if (c.a < 0 || c.b < 0 || c.a >= n || c.b >= n) throw ModelError("creases", item, "the edge names a vertex out of range");
    if (c.a == c.b) throw ModelError("creases", item, "the edge " + sideText(c.a, c.b, base) + " joins a vertex to itself");
    if (!edge_of.emplace(std::minmax(c.a, c.b), item).second)
      throw ModelError("creases", item, "the edge " + sideText(c.a, c.b, base) + " is listed twice");
    c.left = c.right = -1;
  }
  for (size_t f = 0; f < faces.size(); ++f) {
    const auto& face = faces[f];
    const int item = static_cast<int>(f);
    if (face.size() < 3) throw ModelError("faces", item, "a face needs at least 3 vertices");
    for (size_t i = 0; i < face.size(); ++i) {
      const int u = face[i], v = face[(i + 1) % face.size()];
      const auto it = edge_of.find(std::minmax(u, v));
      if (it == edge_of.end())
        throw ModelError("faces", item, "the face's side " + sideText(u, v, base) + " is no crease or boundary edge");
      Crease& c = edges[static_cast<size_t>(it->second)];
      int& slot = c.a == u ? c.left : c.right;
      if (slot >= 0)
        throw ModelError("faces", item,
                         "the face runs its side " + sideText(u, v, base) + " the same way as face " +
                             std::to_string(slot + base) + ": faces must all be counterclockwise from one side" +
                             (slot == item ? "" : " (or a third face meets the edge)"));
      slot = item;
    }
  }
  // Panels: faces joined across flat (F) and join (J) creases.
  std::vector<int> root(faces.size());
  std::iota(root.begin(), root.end(), 0);
  const auto find = [&](int f) {
    while (root[static_cast<size_t>(f)] != f) f = root[static_cast<size_t>(f)] = root[static_cast<size_t>(root[static_cast<size_t>(f)])];
    return f;
  };
  for (size_t e = 0; e < edges.size(); ++e) {
    const Crease& c = edges[e];
    const bool two = c.left >= 0 && c.right >= 0;
    if (c.assignment == 'B' && two)
      throw ModelError("creases", static_cast<int>(e),
                       "the edge " + sideText(c.a, c.b, base) + " is a boundary (B), but faces " +
                           std::to_string(c.left + base) + " and " + std::to_string(c.right + base) + " meet there");
    if (two && (c.assignment == 'F' || c.assignment == 'J')) root[static_cast<size_t>(find(c.left))] = find(c.right);
  }
  Origami::Panels out;
  std::map<int, int> panel_of_root;
  out.panel_of_face.resize(faces.size());
  for (size_t f = 0; f < faces.size(); ++f) {
    const auto [it, fresh] = panel_of_root.emplace(find(static_cast<int>(f)), static_cast<int>(out.bodies.size()));
    if (fresh) out.bodies.emplace_back();
    auto& body = out.bodies[static_cast<size_t>(it->second)];
    for (int v : faces[f])
      if (std::find(body.begin(), body.end(), v) == body.end()) body.push_back(v);
    out.panel_of_face[f] = it->second;
  }
  out.faces = std::move(faces);
  out.edges = std::move(edges);
  return out;
}

}  // namespace

Origami::Origami(const Matrix& points, std::vector<std::vector<int>> faces, std::vector<Crease> edges,
                 const std::vector<int>& pinned, int base)
    : Origami(points, makePanels(points, std::move(faces), std::move(edges), base), pinned, base) {}

Origami::Origami(const Matrix& points, Panels&& p, const std::vector<int>& pinned, int base) try
    : BodyFramework("origami", points, p.bodies, {}, pinned, base),
      faces_(std::move(p.faces)),
      edges_(std::move(p.edges)),
      panel_of_face_(std::move(p.panel_of_face)) {
} catch (const ModelError& e) {
  // A panel's problem, told at its first face.
  if (e.key != "bodies" || e.item < 0) throw;
  int face = 0;
  while (face < static_cast<int>(p.panel_of_face.size()) && p.panel_of_face[static_cast<size_t>(face)] != e.item) ++face;
  std::string message = e.what();
  if (message.rfind("body ", 0) == 0) message = "the panel of face " + std::to_string(face + base) + message.substr(message.find(' ', 5));
  throw ModelError("faces", face, message);
}

std::vector<double> Origami::foldAngles(const Matrix& positions) const {
  std::vector<double> out(edges_.size(), 0.0);
  std::vector<Eigen::Vector3d> normals;  // each face's once (a face has several creases)
  normals.reserve(faces_.size());
  for (const auto& f : faces_) normals.push_back(newellNormal(positions, f));
  for (size_t e = 0; e < edges_.size(); ++e) {
    const Crease& c = edges_[e];
    if (c.left < 0 || c.right < 0) continue;
    const Eigen::Vector3d& nl = normals[static_cast<size_t>(c.left)];
    const Eigen::Vector3d& nr = normals[static_cast<size_t>(c.right)];
    const Eigen::Vector3d dir = (positions.col(c.b) - positions.col(c.a)).head<3>().normalized();
    // Valley: the faces turn towards their normals' side, and (n_left x n_right) points
    // against the left face's direction of the crease.
    out[e] = -std::atan2(nl.cross(nr).dot(dir), nl.dot(nr));
  }
  return out;
}

std::optional<Vector> Origami::assignedFoldPoint(const Vector& x, double distance, const Matrix& flexes) const {
  const std::vector<double> folds = foldAngles(system().vertexPositions(x));
  std::vector<size_t> assigned;  // the M/V creases between two faces
  for (size_t e = 0; e < edges_.size(); ++e) {
    const Crease& c = edges_[e];
    if (c.left < 0 || c.right < 0 || (c.assignment != 'M' && c.assignment != 'V')) continue;
    if (std::abs(folds[e]) > 1e-6) return std::nullopt;  // folded already
    assigned.push_back(e);
  }
  if (assigned.empty() || flexes.cols() == 0 || !(distance > 0)) return std::nullopt;
  // The fold rates of the nontrivial flexes (central differences: the signed fold angle is
  // smooth through the flat state), and the flex whose rates best match the assignment's signs
  // (+1 valley, -1 mountain) in least squares. At a single flat-foldable degree-4 vertex this
  // is the tangent of the branch with that assignment exactly (the branches' rate vectors are
  // orthogonal there).
  const Eigen::Index k = flexes.cols(), m = static_cast<Eigen::Index>(assigned.size());
  Matrix rates(m, k);
  Vector target(m);
  for (Eigen::Index i = 0; i < m; ++i) target(i) = edges_[assigned[static_cast<size_t>(i)]].assignment == 'V' ? 1.0 : -1.0;
  for (Eigen::Index j = 0; j < k; ++j) {
    const Vector u = flexes.col(j).normalized();
    const double h = 1e-6 * std::max(distance, 1e-300);
    const std::vector<double> plus = foldAngles(system().vertexPositions(x + h * u));
    const std::vector<double> minus = foldAngles(system().vertexPositions(x - h * u));
    for (Eigen::Index i = 0; i < m; ++i) {
      const size_t e = assigned[static_cast<size_t>(i)];
      rates(i, j) = (plus[e] - minus[e]) / (2 * h);
    }
  }
  Matrix unit = flexes;
  for (Eigen::Index j = 0; j < k; ++j) unit.col(j).normalize();
  const Vector c = rates.colPivHouseholderQr().solve(target);
  const Vector v = unit * c;
  if (!(v.norm() > 0) || !((rates * c).norm() > 1e-9 * target.norm())) return std::nullopt;
  Sphere sphere;
  sphere.center = x;
  sphere.radius = distance;
  CorrectorOptions options;
  options.max_iterations = 60;
  const CorrectorResult r = correct(system(), x + distance / v.norm() * v, options, {}, nullptr, &sphere);
  if (r.status != CorrectorStatus::Converged) return std::nullopt;
  return r.x;
}

int Origami::creaseAgainstAssignment(const Vector& x, double tolerance) const {
  const std::vector<double> folds = foldAngles(system().vertexPositions(x));
  for (size_t e = 0; e < edges_.size(); ++e) {
    const Crease& c = edges_[e];
    if (c.left < 0 || c.right < 0) continue;
    if ((c.assignment == 'M' && folds[e] > tolerance) || (c.assignment == 'V' && folds[e] < -tolerance))
      return static_cast<int>(e);
  }
  return -1;
}

Geometry Origami::geometry() const {
  Geometry g = BodyFramework::geometry();
  g.bars.clear();
  g.bar_kinds.clear();
  for (const Crease& c : edges_) {
    g.bars.push_back({c.a, c.b});
    const bool crease = c.left >= 0 && c.right >= 0;
    g.bar_kinds.push_back(!crease ? 'B' : c.assignment);
  }
  g.facets = faces_;
  return g;
}

}  // namespace flexure::engine
