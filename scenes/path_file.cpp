#include "scenes/path_file.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

#include <Eigen/SparseQR>

#include "engine/constraint_system.h"
#include "engine/contraction.h"
#include "scenes/json_text.h"

namespace flexure::scenes {

bool looksLikePathJson(const std::string& text) {
  const size_t first = text.find_first_not_of(" \t\r\n");
  if (first == std::string::npos || text[first] != '{') return false;
  // track writes "scene" after "samples"; a node-link file has "nodes" and "links" instead.
  return text.find("\"samples\"") != std::string::npos && text.find("\"scene\"") != std::string::npos;
}

bool isPathJson(const nlohmann::json& j) {
  return j.is_object() && j.contains("samples") && j.contains("scene") && !j.contains("nodes");
}

Scene loadPathJson(const std::string& file, const std::string& text, const std::vector<std::string>& overrides) {
  return loadPathJson(file, parseJsonText(text, file), overrides);
}

Scene loadPathJson(const std::string& file, const nlohmann::json& j, const std::vector<std::string>& overrides) {
  const auto fail = [&](const std::string& where, const std::string& m) -> void {
    throw SceneError(file, 1, 1, where + ": " + m);
  };
  if (!j.is_object()) fail("the file", "a path JSON is an object (as `flexure track -o PATH.json` writes it)");
  if (!j.contains("scene") || !j["scene"].is_string())
    fail("scene", "missing, or not a string: the scene's TOML text, as `flexure track` writes it");
  Scene scene = loadSceneFromString(j["scene"].get<std::string>(), file + " (its \"scene\")", overrides);
  scene.path = file;
  const engine::Model& model = *scene.model;
  const engine::ConstraintSystem& sys = model.system();
  const int d = sys.dimension(), n = sys.numVertices(), base = scene.index_base;
  if (!j.contains("samples") || !j["samples"].is_array() || j["samples"].empty())
    fail("samples", "missing, empty or not an array: one configuration per sample");
  const nlohmann::json& samples = j["samples"];
  if (static_cast<double>(samples.size()) * std::max(1, sys.numVariables()) > kMaxPathValues)
    fail("samples", "more than " + std::to_string(static_cast<long long>(kMaxPathValues)) + " numbers");
  auto given = std::make_shared<GivenPath>();
  engine::DeformationPath& path = given->path;
  // The equation of a contracted edge follows its length along the path; the others vanish.
  // Only its distance equation: a polytope's facet-plane equation of the same two vertices
  // (n . (x_b - x_a) = 0) holds all along, and taking it for a moving one left the normals
  // underdetermined (a contracted tetrahedron's path was refused).
  std::vector<int> moving_rows;
  if (scene.motion.contract_edge) {
    const int row = engine::distanceEquation(sys, (*scene.motion.contract_edge)[0], (*scene.motion.contract_edge)[1]);
    if (row >= 0) moving_rows.push_back(row);
  }
  const double scale = sys.residualScale(), tolerance = 1e-7 * scale;
  double extent = 0;
  for (int v = 0; v < n; ++v) extent = std::max(extent, model.startPositions().col(v).cwiseAbs().maxCoeff());
  engine::Matrix blocks = model.startPositions();  // auxiliary blocks (facet normals, ...) carried along
  std::vector<int> aux;  // their free coordinates
  for (int b = n; b < sys.numBlocks(); ++b)
    for (int c = 0; c < d; ++c)
      if (sys.variableIndex(b, c) >= 0) aux.push_back(sys.variableIndex(b, c));
  double max_residual = 0;
  for (size_t k = 0; k < samples.size(); ++k) {
    const std::string at = "samples[" + std::to_string(k) + "]";
    const nlohmann::json& conf = samples[k];
    if (!conf.is_array() || static_cast<int>(conf.size()) != n)
      fail(at, "not a list of " + std::to_string(n) + " points (the scene has " + std::to_string(n) + " vertices)");
    for (int v = 0; v < n; ++v) {
      const nlohmann::json& p = conf[static_cast<size_t>(v)];
      if (!p.is_array() || static_cast<int>(p.size()) != d)
        fail(at + "[" + std::to_string(v) + "]", "not a point of " + std::to_string(d) + " coordinates");
      for (int c = 0; c < d; ++c) {
        if (!p[static_cast<size_t>(c)].is_number() || !std::isfinite(p[static_cast<size_t>(c)].get<double>()))
          fail(at + "[" + std::to_string(v) + "][" + std::to_string(c) + "]", "not a finite number");
        blocks(c, v) = p[static_cast<size_t>(c)].get<double>();
      }
      if (sys.isPinned(v) && (blocks.col(v) - model.startPositions().col(v)).cwiseAbs().maxCoeff() > 1e-9 * (1 + extent))
        fail(at + "[" + std::to_string(v) + "]", "vertex " + std::to_string(v + base) +
                                                      " is pinned, but it is not where the scene pins it");
    }
    engine::Vector x = sys.freeCoordinates(blocks);
    engine::Vector F = sys.residuals(x);
    if (!aux.empty() && F.size() > 0) {
      // The auxiliary coordinates (facet normals, ...; not in the file) by Gauss-Newton on them
      // alone, from the previous sample's: the vertices stay exactly as read.
      // A step that does not lower the largest residual is halved (up to 30 times): from the
      // previous sample's normals, far off where the vertices moved much (a contracted hull
      // polytope's nearly flat facets turn fast), the full step can overshoot.
      auto largest = [&](engine::Vector& G) {
        for (int row : moving_rows) G[row] = 0;
        return G.cwiseAbs().maxCoeff();
      };
      double now = largest(F);
      for (int iteration = 0; iteration < 60; ++iteration) {
        if (now <= 1e-13 * scale) break;  // converged
        const engine::SparseMatrix J = sys.jacobian(x);
        std::vector<Eigen::Triplet<double>> t;
        for (size_t c = 0; c < aux.size(); ++c)
          for (engine::SparseMatrix::InnerIterator it(J, aux[c]); it; ++it)
            if (std::find(moving_rows.begin(), moving_rows.end(), static_cast<int>(it.row())) == moving_rows.end())
              t.emplace_back(static_cast<int>(it.row()), static_cast<int>(c), it.value());
        engine::SparseMatrix Ja(J.rows(), static_cast<Eigen::Index>(aux.size()));
        Ja.setFromTriplets(t.begin(), t.end());
        Ja.makeCompressed();
        Eigen::SparseQR<engine::SparseMatrix, Eigen::COLAMDOrdering<int>> qr(Ja);
        if (qr.info() != Eigen::Success) break;
        const engine::Vector step = qr.solve(engine::Vector(-F));
        if (qr.info() != Eigen::Success || !step.allFinite()) break;
        bool lowered = false;
        for (double alpha = 1.0; alpha > 1e-9 && !lowered; alpha *= 0.5) {
          engine::Vector trial = x;
          for (size_t c = 0; c < aux.size(); ++c) trial[aux[c]] += alpha * step[static_cast<Eigen::Index>(c)];
          engine::Vector G = sys.residuals(trial);
          const double after = largest(G);
          if (after < now) x = std::move(trial), F = std::move(G), now = after, lowered = true;
        }
        if (!lowered) break;  // at the rounding floor
      }
      F = sys.residuals(x);
      blocks = sys.positions(x);
    }
    for (int row : moving_rows) F[row] = 0;
    Eigen::Index worst = 0;
    const double r = F.size() > 0 ? F.cwiseAbs().maxCoeff(&worst) : 0.0;
    if (!(r <= tolerance))
      fail(at, "the scene's constraints do not hold there (residual " + std::to_string(r) + " at " +
                   sys.equationLabel(static_cast<int>(worst), base) + "): not a path of this scene");
    max_residual = std::max(max_residual, r);
    path.samples.push_back(std::move(x));
  }
  // Continuity: a tracked path's samples lie about a step apart (equal steps in the
  // configuration; shorter ones near singular points, a longer first one where a drive starts).
  // A sample moved away, even by a motion that keeps every constraint (a translation of an
  // unpinned framework), is a jump that no path makes: refused where the vertices move by more
  // than 50 times the median step and by more than a quarter of the configuration's size. (An
  // edge contraction's steps are equal in its length, not in the configuration: the
  // dodecahedron's largest is 16 times its median, 2 % of its size.)
  if (path.samples.size() >= 3) {
    const auto vertices = [&](const engine::Vector& x) {
      const engine::Matrix P = sys.positions(x).leftCols(n);
      return engine::Vector(Eigen::Map<const engine::Vector>(P.data(), P.size()));
    };
    const engine::Matrix start = model.startPositions().leftCols(n);
    const double size = (start.rowwise().maxCoeff() - start.rowwise().minCoeff()).norm();
    std::vector<double> steps;
    engine::Vector before = vertices(path.samples[0]);
    for (size_t k = 1; k < path.samples.size(); ++k) {
      engine::Vector now = vertices(path.samples[k]);
      steps.push_back((now - before).norm());
      before = std::move(now);
    }
    std::vector<double> sorted = steps;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2), sorted.end());
    const double median = sorted[sorted.size() / 2];
    for (size_t k = 0; k < steps.size(); ++k)
      if (steps[k] > 50 * median && steps[k] > 0.25 * size)
        fail("samples[" + std::to_string(k + 1) + "]",
             "a jump: the vertices move by " + std::to_string(steps[k]) + " from the sample before, where the path's "
             "median step is " + std::to_string(median) + " and the configuration's size " + std::to_string(size) +
             " (not a continuous path)");
  }
  const int last = static_cast<int>(samples.size()) - 1;
  if (j.contains("events")) {
    if (!j["events"].is_array()) fail("events", "not an array");
    for (size_t i = 0; i < j["events"].size(); ++i) {
      const nlohmann::json& e = j["events"][i];
      const std::string at = "events[" + std::to_string(i) + "]";
      if (!e.is_object() || !e.contains("sample") || !e["sample"].is_number_integer())
        fail(at, "an event is {\"sample\": K, \"kind\": ...}");
      engine::TrackEvent ev;
      const long long s = e["sample"].get<long long>();
      if (s < 0 || s > last) fail(at + ".sample", "not a sample of the path (0.." + std::to_string(last) + ")");
      ev.sample = static_cast<int>(s);
      if (e.contains("kind") && !e["kind"].is_string()) fail(at + ".kind", "a string");
      const std::string kind = e.value("kind", std::string());
      if (kind == "singularity") {
        ev.kind = engine::EventKind::Singularity;
      } else if (kind == "contact" || kind == "intersection") {
        // A contact names its two vertices ("pair"), an intersection its two faces ("faces").
        const bool contact = kind == "contact";
        ev.kind = contact ? engine::EventKind::Contact : engine::EventKind::Intersection;
        const char* key = contact ? "pair" : "faces";
        const long long count = contact ? n : model.numFaces();
        if (!e.contains(key) || !e[key].is_array() || e[key].size() != 2 || !e[key][0].is_number_integer() ||
            !e[key][1].is_number_integer())
          fail(at + "." + key, contact ? "a contact names its two vertices" : "an intersection names its two faces");
        for (int q = 0; q < 2; ++q) {
          const long long v = e[key][static_cast<size_t>(q)].get<long long>() - base;
          if (v < 0 || v >= count) fail(at + "." + key, contact ? "vertex out of range" : "face out of range");
          (contact ? ev.vertices : ev.faces).push_back(static_cast<int>(v));
        }
      } else {
        fail(at + ".kind", "\"singularity\", \"contact\" or \"intersection\", not '" + kind + "'");
      }
      if (e.contains("detail") && e["detail"].is_string()) ev.detail = e["detail"].get<std::string>();
      path.events.push_back(std::move(ev));
    }
  }
  engine::TrackSummary& sum = path.summary;
  if (j.contains("status") && !j["status"].is_string()) fail("status", "a string (\"success\" or what stopped the path)");
  sum.status = j.value("status", std::string("success")) == "success" ? engine::TrackStatus::Success
                                                                       : engine::TrackStatus::StoppedEarly;
  sum.reason = j.contains("reason") && j["reason"].is_string() ? j["reason"].get<std::string>() : "";
  // Counts as track writes them: integers of an int (a forged 10^18 would wrap to a negative).
  const auto count = [&](const char* key, int otherwise) {
    if (!j.contains(key)) return otherwise;
    const nlohmann::json& v = j[key];
    if (!v.is_number_integer() || v.get<long long>() < 0 || v.get<long long>() > 2147483647LL)
      fail(key, "not a count of steps (an integer 0..2147483647)");
    return static_cast<int>(v.get<long long>());
  };
  sum.steps_requested = count("steps_requested", last);
  sum.steps_done = last;
  sum.rejected_steps = count("rejected_steps", 0);
  sum.seed = j.contains("seed") && j["seed"].is_number_unsigned() ? j["seed"].get<std::uint64_t>() : scene.motion.seed;
  sum.max_residual = max_residual;
  if (j.contains("flex") && j["flex"].is_array())
    for (const auto& c : j["flex"])
      if (c.is_number()) path.flex.push_back(c.get<double>());
  path.flex_choice = j.contains("flex_choice") && j["flex_choice"].is_string() ? j["flex_choice"].get<std::string>()
                                                                               : "as read from " + file;
  // The whole path, unless the scene says how many steps: an edge contraction's scene need not
  // (it stops at its target length), and the default 100 would cut the path short.
  if (!scene.motion.steps_given) scene.motion.steps = last;
  scene.given = std::move(given);
  return scene;
}

}  // namespace flexure::scenes
