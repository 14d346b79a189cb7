// Rigid origami (engine/systems/origami.h).
#include "engine/systems/origami.h"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <algorithm>
#include <map>
#include <numeric>
#include <string>

#include "engine/corrector.h"
#include "engine/factorization.h"

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
      panel_of_face_(std::move(p.panel_of_face)),
      base_(base) {
  // Each side's far vertex: on the face's side of the crease, farthest from its line.
  const auto farthest = [&](int face, int from, int to) {
    const Eigen::Vector3d n = newellNormal(points, faces_[static_cast<size_t>(face)]);
    const Eigen::Vector3d a = points.col(from).head<3>(), e = points.col(to).head<3>() - a;
    int best = -1;
    double most = 0;
    for (int v : faces_[static_cast<size_t>(face)]) {
      const double side = e.cross(points.col(v).head<3>() - a).dot(n);
      if (side > most) most = side, best = v;
    }
    return best;
  };
  wings_.reserve(edges_.size());
  for (size_t e = 0; e < edges_.size(); ++e) {
    const Crease& c = edges_[e];
    const bool two = c.left >= 0 && c.right >= 0;
    wings_.push_back(two ? std::array<int, 2>{farthest(c.left, c.a, c.b), farthest(c.right, c.b, c.a)}
                         : std::array<int, 2>{-1, -1});
    if (two && panel_of_face_[static_cast<size_t>(c.left)] != panel_of_face_[static_cast<size_t>(c.right)])
      hinges_.push_back(static_cast<int>(e));
  }
} catch (const ModelError& e) {
  // A panel's problem, told at its first face.
  if (e.key != "bodies" || e.item < 0) throw;
  int face = 0;
  while (face < static_cast<int>(p.panel_of_face.size()) && p.panel_of_face[static_cast<size_t>(face)] != e.item) ++face;
  std::string message = e.what();
  if (message.rfind("body ", 0) == 0) message = "the panel of face " + std::to_string(face + base) + message.substr(message.find(' ', 5));
  throw ModelError("faces", face, message);
}

std::vector<double> Origami::sampleQuantityValues(const Matrix& positions) const {
  constexpr double kDegrees = 180.0 / M_PI;
  std::vector<double> a = foldAngles(positions.leftCols(system().numVertices()));
  for (double& v : a) v *= kDegrees;
  return a;
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

std::optional<Vector> Origami::assignedFoldDirection(const Vector& x, const Matrix& flexes, const std::vector<int>& held,
                                                     int driven, double driven_sign) const {
  const std::vector<double> folds = foldAngles(system().vertexPositions(x));
  std::vector<std::pair<int, double>> asked;  // crease, the sign of its rate (0: held)
  for (size_t e = 0; e < edges_.size(); ++e) {
    const Crease& c = edges_[e];
    if (c.left < 0 || c.right < 0 || (c.assignment != 'M' && c.assignment != 'V')) continue;
    if (std::abs(folds[e]) > 1e-6) return std::nullopt;  // folded already
    const int i = static_cast<int>(e);
    if (i == driven || std::find(held.begin(), held.end(), i) != held.end()) continue;
    asked.emplace_back(i, c.assignment == 'V' ? 1.0 : -1.0);
  }
  for (int e : held) asked.emplace_back(e, 0.0);
  if (driven >= 0) asked.emplace_back(driven, driven_sign);
  if (asked.empty() || flexes.cols() == 0) return std::nullopt;
  // The fold rates of the nontrivial flexes (the signed fold angle is smooth through the flat
  // state), and the flex whose rates best match the assignment's signs (+1 valley, -1 mountain)
  // in least squares. At a single flat-foldable degree-4 vertex this is the tangent of the
  // branch with that assignment exactly (the branches' rate vectors are orthogonal there).
  const Eigen::Index k = flexes.cols(), m = static_cast<Eigen::Index>(asked.size());
  Matrix unit = flexes;
  for (Eigen::Index j = 0; j < k; ++j) unit.col(j).normalize();
  std::vector<int> creases;
  for (const auto& a : asked) creases.push_back(a.first);
  const Matrix gradients = foldAngleGradients(x, creases);
  Matrix rates(m, k);
  Vector target(m);
  for (Eigen::Index i = 0; i < m; ++i) {
    target(i) = asked[static_cast<size_t>(i)].second;
    rates.row(i) = gradients.row(i) * unit;
  }
  const Vector c = rates.colPivHouseholderQr().solve(target);
  const Vector v = unit * c;
  if (!(v.norm() > 0) || !((rates * c).norm() > 1e-9 * target.norm())) return std::nullopt;
  return Vector(v.normalized());
}

std::vector<int> Origami::stillCreases(const Vector& x, int e) const {
  // The first-order motions: the kernel K of J (rigid motions included, which fold nothing),
  // and the fold rates on it of e (r_e) and of the other creases between two panels (A).
  const JacobianFactorization fac(system().jacobian(x), FactorizationOptions{});
  const Matrix K = fac.kernel();
  std::vector<int> others;
  for (int c : hinges_)
    if (c != e) others.push_back(c);
  const Vector re = K.transpose() * foldAngleGradient(x, e);
  // No other crease between two panels (a strip of two): nothing to hold still. (An SVD of the
  // empty matrix A crashed in Eigen.)
  if (!(re.norm() > 0) || K.cols() == 0 || others.empty()) return {};
  const Matrix A = foldAngleGradients(x, others) * K;
  // The motion a that folds e at rate 1 and the others least (sum of their squared rates).
  Eigen::JacobiSVD<Matrix> svd(A, Eigen::ComputeFullV);
  const Vector& sv = svd.singularValues();
  const double top = sv.size() ? sv[0] : 0.0;
  Vector a = Vector::Zero(K.cols());
  double re_a = 0;
  // A's null space: motions that fold none of the others. If one folds e, it is the answer.
  Matrix N = svd.matrixV().rightCols(K.cols() - std::count_if(sv.data(), sv.data() + sv.size(), [&](double v) { return v > 1e-9 * top; }));
  const Vector ne = N.transpose() * re;
  if (ne.norm() > 1e-9 * re.norm()) {
    a = N * ne;
  } else {
    // Otherwise (A^T A)^+ r_e.
    for (Eigen::Index k = 0; k < sv.size(); ++k)
      if (sv[k] > 1e-9 * top) a += svd.matrixV().col(k) * (svd.matrixV().col(k).dot(re) / (sv[k] * sv[k]));
  }
  re_a = re.dot(a);
  if (!(std::abs(re_a) > 0)) return {};
  const Vector rates = A * a / re_a;  // the others' rates per unit rate of e
  std::vector<int> still;
  for (size_t i = 0; i < others.size(); ++i)
    if (std::abs(rates[static_cast<Eigen::Index>(i)]) <= 1e-6) still.push_back(others[i]);
  return still;
}

std::optional<Vector> Origami::assignedFoldPoint(const Vector& x, double distance, const Matrix& flexes) const {
  if (!(distance > 0)) return std::nullopt;
  const std::optional<Vector> v = assignedFoldDirection(x, flexes);
  if (!v) return std::nullopt;
  Sphere sphere;
  sphere.center = x;
  sphere.radius = distance;
  CorrectorOptions options;
  options.max_iterations = 60;
  const CorrectorResult r = correct(system(), x + distance * *v, options, {}, nullptr, &sphere);
  if (r.status != CorrectorStatus::Converged) return std::nullopt;
  return r.x;
}

namespace {

// The four points of a crease's dihedral angle: c on the left face, the crease a -> b, d on the
// right face. With e = b - a, u = e x (c - a) and w = (d - a) x e (the faces' normals),
// rho = -atan2((u x w) . e / |e|, u . w), as foldAngles. (Origami::HingePoints.)
struct Hinge {
  explicit Hinge(const std::array<Eigen::Vector3d, 4>& q) : a(q[0]), b(q[1]), c(q[2]), d(q[3]) {}
  const Eigen::Vector3d &a, &b, &c, &d;
};

double hingeAngle(const Hinge& h) {
  const Eigen::Vector3d e = h.b - h.a, u = e.cross(h.c - h.a), w = (h.d - h.a).cross(e);
  return -std::atan2(u.cross(w).dot(e) / e.norm(), u.dot(w));
}

// Its gradient with respect to c, a, b, d (Blondel and Karplus, J. Comput. Chem. 17 (1996)
// 1132, for the torsion c-a-b-d, which is pi - rho).
std::array<Eigen::Vector3d, 4> hingeGradient(const Hinge& h) {
  const Eigen::Vector3d F = h.c - h.a, G = h.a - h.b, H = h.d - h.b;
  const Eigen::Vector3d A = F.cross(G), B = H.cross(G);
  const double g = G.norm(), aa = A.squaredNorm(), bb = B.squaredNorm();
  const Eigen::Vector3d di = -g / aa * A, dl = g / bb * B;
  const Eigen::Vector3d mix = F.dot(G) / (aa * g) * A - H.dot(G) / (bb * g) * B;
  return {-di, di - mix, dl + mix, -dl};
}

}  // namespace

Origami::HingePoints Origami::hingePoints(const Matrix& p, int e) const {
  const Crease& c = edges_.at(static_cast<size_t>(e));
  const auto& wing = wings_[static_cast<size_t>(e)];
  if (wing[0] < 0 || wing[1] < 0) throw std::invalid_argument("the edge is no crease between two faces");
  return {{p.col(c.a).head<3>(), p.col(c.b).head<3>(), p.col(wing[0]).head<3>(), p.col(wing[1]).head<3>()},
          {wing[0], c.a, c.b, wing[1]}};
}

double Origami::foldAngleAt(const Matrix& p, int e) const { return hingeAngle(Hinge(hingePoints(p, e).points)); }

template <class Add>
void Origami::addFoldAngleGradient(const Matrix& p, int e, Add add) const {
  const HingePoints h = hingePoints(p, e);
  const auto g = hingeGradient(Hinge(h.points));
  for (size_t i = 0; i < 4; ++i)
    for (int k = 0; k < 3; ++k)
      if (const int v = system().variableIndex(h.vertices[i], k); v >= 0) add(v, g[i][k]);
}

double Origami::foldAngle(const Vector& x, int e) const { return foldAngleAt(system().vertexPositions(x), e); }

Vector Origami::foldAngleGradient(const Vector& x, int e) const {
  Vector out = Vector::Zero(system().numVariables());
  addFoldAngleGradient(system().vertexPositions(x), e, [&](int v, double g) { out[v] += g; });
  return out;
}

Matrix Origami::foldAngleGradients(const Vector& x, const std::vector<int>& creases) const {
  const Matrix p = system().vertexPositions(x);
  Matrix out = Matrix::Zero(static_cast<Eigen::Index>(creases.size()), system().numVariables());
  for (size_t i = 0; i < creases.size(); ++i)
    addFoldAngleGradient(p, creases[i], [&](int v, double g) { out(static_cast<Eigen::Index>(i), v) += g; });
  return out;
}

namespace {

std::string degreesText(double radians) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g degrees", radians * 180 / M_PI);
  return buf;
}

}  // namespace

void Origami::setRates(DrivenQuantity& q, const std::vector<double>& proportions) const {
  q.proportions = Eigen::Map<const Vector>(proportions.data(), static_cast<Eigen::Index>(proportions.size()));
  q.rates = [this](const Vector& x) { return foldAngleGradients(x, hinges_); };
}

DrivenQuantity Origami::creaseAngleQuantity(int e, double near, std::vector<int> held) const {
  if (e < 0 || e >= static_cast<int>(edges_.size()) || wings_[static_cast<size_t>(e)][0] < 0 ||
      wings_[static_cast<size_t>(e)][1] < 0)
    throw std::invalid_argument("only a crease between two faces can be driven");
  const Crease& c = edges_[static_cast<size_t>(e)];
  DrivenQuantity q;
  q.name = "fold angle of crease [" + std::to_string(c.a + base_) + ", " + std::to_string(c.b + base_) + "]";
  q.value = [this, e, near](const Vector& x) { return near + std::remainder(foldAngle(x, e) - near, 2 * M_PI); };
  q.gradient = [this, e](const Vector& x) { return foldAngleGradient(x, e); };
  // A displacement delta turns a crease by about delta / h (h a panel's width): residualScale()
  // (a squared length) times an angle is about L delta, as the bars' residuals are.
  q.units = system().residualScale();
  q.valueText = degreesText;
  // The other creases change as little as the sheet allows: the rates closest to e's alone.
  std::vector<double> proportions;
  for (int i : hinges_) proportions.push_back(i == e ? 1.0 : 0.0);
  setRates(q, proportions);
  if (!held.empty()) {
    // Each held angle taken near its start value (continuous through +-180 degrees there).
    const Vector x0 = startCoordinates();
    std::vector<double> centre;
    for (int c : held) centre.push_back(foldAngle(x0, c));
    q.held = [this, held, centre](const Vector& x) {
      const Matrix p = system().vertexPositions(x);
      Vector v(static_cast<Eigen::Index>(held.size()));
      for (size_t i = 0; i < held.size(); ++i)
        v[static_cast<Eigen::Index>(i)] = centre[i] + std::remainder(foldAngleAt(p, held[i]) - centre[i], 2 * M_PI);
      return v;
    };
    q.held_gradients = [this, held](const Vector& x) { return foldAngleGradients(x, held); };
  }
  return q;
}

DrivenQuantity Origami::foldPercentQuantity() const {
  std::vector<std::pair<int, double>> terms;  // crease, s_i * 100 / (pi m)
  for (size_t e = 0; e < edges_.size(); ++e)
    if (wings_[e][0] >= 0 && wings_[e][1] >= 0 && (edges_[e].assignment == 'M' || edges_[e].assignment == 'V'))
      terms.emplace_back(static_cast<int>(e), edges_[e].assignment == 'V' ? 1.0 : -1.0);
  if (terms.empty()) throw std::invalid_argument("a fold percentage needs mountain (M) or valley (V) creases");
  const double m = static_cast<double>(terms.size());
  for (auto& t : terms) t.second *= 100.0 / (M_PI * m);
  DrivenQuantity q;
  q.name = "fold percentage";
  q.value = [this, terms](const Vector& x) {
    const Matrix p = system().vertexPositions(x);
    double v = 0;
    for (const auto& [e, w] : terms) {
      const double near = w > 0 ? M_PI / 2 : -M_PI / 2;
      v += w * (near + std::remainder(foldAngleAt(p, e) - near, 2 * M_PI));
    }
    return v;
  };
  q.gradient = [this, terms](const Vector& x) {
    const Matrix p = system().vertexPositions(x);
    Vector g = Vector::Zero(system().numVariables());
    for (const auto& [e, w] : terms) addFoldAngleGradient(p, e, [&, w = w](int v, double d) { g[v] += w * d; });
    return g;
  };
  // One percentage point is pi m / 100 radians of fold summed over the creases.
  q.units = system().residualScale() * M_PI * m / 100.0;
  // Every crease between two panels toward its full fold at once: the rates of the mountains
  // and valleys in proportion to their targets (-pi, +pi), the others' 0.
  std::vector<double> proportions;
  for (int e : hinges_) {
    const char a = edges_[static_cast<size_t>(e)].assignment;
    proportions.push_back(a == 'V' ? 1.0 : a == 'M' ? -1.0 : 0.0);
  }
  setRates(q, proportions);
  q.valueText = [](double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g %%", v);
    return std::string(buf);
  };
  return q;
}

std::function<bool(const Vector&)> Origami::admissibleFrom(const Vector& start) const {
  if (creaseAgainstAssignment(start) >= 0) return {};
  return [this](const Vector& y) { return creaseAgainstAssignment(y) < 0; };
}

std::string Origami::outsideReason(const Vector& y, int index_base) const {
  const int e = creaseAgainstAssignment(y);
  if (e < 0) return {};
  const Crease& c = edges_[static_cast<size_t>(e)];
  return "crease [" + std::to_string(c.a + index_base) + ", " + std::to_string(c.b + index_base) + "] (" +
         std::string(1, c.assignment) + ") would turn " + (c.assignment == 'M' ? "valley" : "mountain") +
         " next: the sheet is fully folded or flat there, and its mountain/valley assignment holds";
}

std::optional<DrivenQuantity> Origami::drivenQuantity(int item, double target, const Vector& x, const Matrix& flexes,
                                                      double step) const {
  DrivenQuantity q;
  if (item >= 0) {
    // The other creases change as little as the sheet allows, and those that need not change
    // stay exactly: chosen where the sheet is folded (from a flat state, one step along the
    // fold its assignment asks for).
    const int e = item;
    const std::optional<Vector> probe = assignedFoldPoint(x, step, flexes);
    const std::vector<int> held = stillCreases(probe ? *probe : x, e);
    q = creaseAngleQuantity(e, 0.5 * (foldAngle(x, e) + target), held);
    // From the flat state, the first step folds the way the assignment asks, the held creases
    // not at all.
    if (auto v = assignedFoldDirection(x, flexes, held, e, target >= 0 ? 1 : -1)) q.first_direction = *v;
  } else {
    q = foldPercentQuantity();
    // From the flat state, the first step folds the way the mountain/valley assignment asks.
    if (auto v = assignedFoldDirection(x, flexes)) q.first_direction = *v;
  }
  return q;
}

void Origami::markEvents(DeformationPath& path, int index_base) const {
  path.events.erase(std::remove_if(path.events.begin(), path.events.end(),
                                   [](const TrackEvent& e) { return e.kind == EventKind::Intersection; }),
                    path.events.end());
  std::vector<std::array<int, 2>> before;
  bool added = false;
  for (size_t k = 0; k < path.samples.size(); ++k) {
    const std::vector<std::array<int, 2>> now = crossingFaces(system().vertexPositions(path.samples[k]));
    for (const auto& pair : now) {
      if (std::binary_search(before.begin(), before.end(), pair)) continue;
      TrackEvent e;
      e.sample = static_cast<int>(k);
      e.kind = EventKind::Intersection;
      e.faces = {pair[0], pair[1]};
      e.detail = "faces " + std::to_string(pair[0] + index_base) + " and " + std::to_string(pair[1] + index_base) +
                 " pass through each other";
      path.events.push_back(std::move(e));
      added = true;
    }
    before = now;
  }
  if (added)
    std::stable_sort(path.events.begin(), path.events.end(),
                     [](const TrackEvent& a, const TrackEvent& b) { return a.sample < b.sample; });
}

int Origami::creaseAgainstAssignment(const Vector& x, double tolerance) const {
  const std::vector<double> folds = foldAngles(system().vertexPositions(x));
  for (size_t e = 0; e < edges_.size(); ++e) {
    const Crease& c = edges_[e];
    if (c.left < 0 || c.right < 0) continue;
    // Fully folded (+-180 degrees, where the sign of the angle is rounding's) is either way.
    if (std::abs(folds[e]) >= M_PI - tolerance) continue;
    if ((c.assignment == 'M' && folds[e] > tolerance) || (c.assignment == 'V' && folds[e] < -tolerance))
      return static_cast<int>(e);
  }
  return -1;
}

namespace {

using Triangle = std::array<Eigen::Vector3d, 3>;

// Where triangle t meets the plane (n, o), as an interval along the line direction `line`:
// false unless t has corners strictly on both sides (beyond eps, a length).
bool planeCut(const Triangle& t, const Eigen::Vector3d& n, const Eigen::Vector3d& o, const Eigen::Vector3d& line,
              double eps, double& lo, double& hi) {
  std::array<double, 3> d{};
  bool above = false, below = false;
  for (size_t i = 0; i < 3; ++i) {
    d[i] = n.dot(t[i] - o);
    above = above || d[i] > eps;
    below = below || d[i] < -eps;
  }
  if (!(above && below)) return false;
  lo = INFINITY, hi = -INFINITY;
  const auto take = [&](const Eigen::Vector3d& p) {
    const double s = line.dot(p);
    lo = std::min(lo, s), hi = std::max(hi, s);
  };
  for (size_t i = 0; i < 3; ++i) {
    const size_t j = (i + 1) % 3;
    if (std::abs(d[i]) <= eps) take(t[i]);
    if ((d[i] > eps && d[j] < -eps) || (d[i] < -eps && d[j] > eps)) take(t[i] + (t[j] - t[i]) * (d[i] / (d[i] - d[j])));
  }
  return true;
}

// Whether two triangles pass through each other: each has corners strictly on both sides of
// the other's plane, and the two cuts overlap along the planes' common line by more than eps.
// Triangles that only touch (a corner or a side on the other), or lie in one plane, do not.
bool trianglesCross(const Triangle& a, const Triangle& b, double eps) {
  Eigen::Vector3d na = (a[1] - a[0]).cross(a[2] - a[0]), nb = (b[1] - b[0]).cross(b[2] - b[0]);
  if (!(na.norm() > 0 && nb.norm() > 0)) return false;
  na.normalize(), nb.normalize();
  Eigen::Vector3d line = na.cross(nb);
  if (!(line.norm() > 1e-12)) return false;  // parallel planes
  line.normalize();
  double alo, ahi, blo, bhi;
  if (!planeCut(a, nb, b[0], line, eps, alo, ahi) || !planeCut(b, na, a[0], line, eps, blo, bhi)) return false;
  return std::min(ahi, bhi) - std::max(alo, blo) > eps;
}

}  // namespace

std::vector<std::array<int, 2>> Origami::crossingFaces(const Matrix& positions) const {
  const size_t nf = faces_.size();
  // Bounding boxes, and the size of the sheet for the margins.
  std::vector<Eigen::Vector3d> lo(nf), hi(nf);
  Eigen::Vector3d all_lo = Eigen::Vector3d::Constant(INFINITY), all_hi = -all_lo;
  for (size_t f = 0; f < nf; ++f) {
    lo[f] = hi[f] = positions.col(faces_[f][0]).head<3>();
    for (int v : faces_[f]) {
      lo[f] = lo[f].cwiseMin(positions.col(v).head<3>());
      hi[f] = hi[f].cwiseMax(positions.col(v).head<3>());
    }
    all_lo = all_lo.cwiseMin(lo[f]);
    all_hi = all_hi.cwiseMax(hi[f]);
  }
  const double eps = 1e-9 * std::max((all_hi - all_lo).maxCoeff(), 1e-300);
  // Sweep along x: faces sorted by their boxes' low x.
  std::vector<size_t> order(nf);
  std::iota(order.begin(), order.end(), size_t{0});
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return lo[a].x() < lo[b].x(); });
  // The faces' fan triangles (from each face's first corner: exact for the convex faces of
  // crease patterns; a face that is not star-shaped from its first corner is covered only
  // approximately).
  std::vector<std::vector<Triangle>> fans(nf);
  for (size_t f = 0; f < nf; ++f) {
    const auto& face = faces_[f];
    for (size_t t = 1; t + 1 < face.size(); ++t)
      fans[f].push_back({positions.col(face[0]).head<3>(), positions.col(face[t]).head<3>(), positions.col(face[t + 1]).head<3>()});
  }
  const auto crosses = [&](size_t f, size_t g) {
    for (const Triangle& a : fans[f])
      for (const Triangle& b : fans[g])
        if (trianglesCross(a, b, eps)) return true;
    return false;
  };
  std::vector<std::array<int, 2>> out;
  for (size_t i = 0; i < nf; ++i) {
    const size_t f = order[i];
    for (size_t j = i + 1; j < nf && lo[order[j]].x() <= hi[f].x(); ++j) {
      const size_t g = order[j];
      if (!((lo[f].array() <= hi[g].array()).all() && (lo[g].array() <= hi[f].array()).all())) continue;
      if (panel_of_face_[f] == panel_of_face_[g]) continue;
      bool shared = false;
      for (int v : faces_[f]) shared = shared || std::find(faces_[g].begin(), faces_[g].end(), v) != faces_[g].end();
      if (shared || !crosses(f, g)) continue;
      out.push_back({static_cast<int>(std::min(f, g)), static_cast<int>(std::max(f, g))});
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

Geometry Origami::geometry() const {
  Geometry g = BodyFramework::geometry();
  g.bars.edges.clear();
  g.bars.kinds.clear();
  g.bars.role = Bars::Role::Crease;
  for (const Crease& c : edges_) {
    g.bars.edges.push_back({c.a, c.b});
    const bool crease = c.left >= 0 && c.right >= 0;
    g.bars.kinds.push_back(!crease ? 'B' : c.assignment);
  }
  g.facets.polygons = faces_;
  g.facets.panels = true;
  g.vertices.look = Vertices::Look::Dot;  // the sheet, not its vertices
  g.vertices.numbered = false;            // the sheet reads better without vertex numbers
  return g;
}

}  // namespace flexure::engine
