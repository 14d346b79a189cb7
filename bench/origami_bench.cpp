// Rigid origami: an n x n Miura-ori (Schenk and Guest's, sides 1, angle 60 degrees) tracked
// for 200 steps of 0.05, from part-folded (theta = 45 degrees: one degree of freedom) and from
// flat (the branch its mountain/valley assignment picks, the first sample found by
// Origami::assignedFoldPoint); then driven (engine/continuation.h). CPU time: the analysis once,
// the tracking best of 3; the target is under 1 s for 10 x 10.
#include <cmath>
#include <cstdio>
#include <ctime>
#include <map>

#include "engine/continuation.h"
#include "engine/motion_tracker.h"
#include "engine/rigidity.h"
#include "engine/systems/origami.h"

using namespace flexure;

namespace {

engine::Origami miura(int n, double theta, const std::vector<char>* assignment) {
  const double g = M_PI / 3, c = std::cos(theta), t = std::tan(g), q = std::sqrt(1 + c * c * t * t);
  const double H = std::sin(theta) * std::sin(g), S = c * t / q, L = std::sqrt(1 - std::pow(std::sin(theta) * std::sin(g), 2)),
               V = 1 / q;
  const auto index = [n](int i, int j) { return i * (n + 1) + j; };
  engine::Matrix p(3, (n + 1) * (n + 1));
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) p.col(index(i, j)) << i * S, j * L + V * (i % 2), H * (j % 2);
  std::vector<std::vector<int>> faces;
  std::vector<engine::Crease> edges;
  std::map<std::pair<int, int>, int> seen;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      faces.push_back({index(i, j), index(i + 1, j), index(i + 1, j + 1), index(i, j + 1)});
      const auto& f = faces.back();
      for (int k = 0; k < 4; ++k) {
        const auto e = std::minmax(f[k], f[(k + 1) % 4]);
        if (seen.emplace(e, static_cast<int>(edges.size())).second) {
          engine::Crease cr;
          cr.a = e.first, cr.b = e.second;
          edges.push_back(cr);
        }
      }
    }
  for (size_t e = 0; e < edges.size(); ++e) edges[e].assignment = assignment ? (*assignment)[e] : 'U';
  return engine::Origami(p, faces, edges, {}, 0);
}

double cpu() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

void run(int n, bool flat) {
  // The assignment: the signs of the part-folded sheet's fold angles.
  const engine::Origami folded = miura(n, M_PI / 4, nullptr);
  const std::vector<double> r = folded.foldAngles(folded.system().vertexPositions(folded.startCoordinates()));
  std::vector<char> letters;
  for (size_t e = 0; e < r.size(); ++e) {
    const auto& c = folded.edges()[e];
    letters.push_back(c.left < 0 || c.right < 0 ? 'B' : r[e] > 0 ? 'V' : 'M');
  }
  const engine::Origami o = miura(n, flat ? 0.0 : M_PI / 4, &letters);
  const engine::Vector x0 = o.startCoordinates();
  double t0 = cpu();
  const engine::RigidityReport rep = engine::analyzeRigidity(o, x0);
  const double analysis = cpu() - t0;
  double best = 1e300;
  engine::DeformationPath path;
  for (int k = 0; k < 3; ++k) {
    t0 = cpu();
    engine::TrackerOptions opt;
    opt.steps = 200;
    opt.step_size = 0.05;
    engine::Vector direction = rep.flex_basis * rep.auto_flex;
    if (flat) {
      opt.first_point = o.assignedFoldPoint(x0, opt.step_size, rep.flex_basis);
      if (opt.first_point) direction = *opt.first_point - x0;
      opt.admissible = [&o](const engine::Vector& y) { return o.creaseAgainstAssignment(y) < 0; };
    }
    path = engine::trackMotion(o, x0, direction, opt);
    best = std::min(best, cpu() - t0);
  }
  std::printf("Miura-ori %2dx%-2d from %-11s %4d vars  analysis %6.3f s  tracking %3d/200 steps %6.3f s CPU  %6.2f ms/step  (%s)\n",
              n, n, flat ? "flat" : "theta = 45", static_cast<int>(x0.size()), analysis, path.summary.steps_done, best,
              1e3 * best / std::max(1, path.summary.steps_done), path.summary.briefReport().c_str());
}

// Driving the part-folded sheet (theta = 45 degrees) for 200 equal steps: the fold percentage
// to 90, and its first mountain crease to -170 degrees.
void drive(int n) {
  const engine::Origami folded = miura(n, M_PI / 4, nullptr);
  const std::vector<double> r = folded.foldAngles(folded.system().vertexPositions(folded.startCoordinates()));
  std::vector<char> letters;
  int crease = -1;
  for (size_t e = 0; e < r.size(); ++e) {
    const auto& c = folded.edges()[e];
    letters.push_back(c.left < 0 || c.right < 0 ? 'B' : r[e] > 0 ? 'V' : 'M');
    if (crease < 0 && letters.back() == 'M') crease = static_cast<int>(e);
  }
  const engine::Origami o = miura(n, M_PI / 4, &letters);
  const engine::Vector x0 = o.startCoordinates();
  for (const bool percent : {true, false}) {
    double best = 1e300;
    engine::DeformationPath path;
    for (int k = 0; k < 3; ++k) {
      const double t0 = cpu();
      const double target = percent ? 90.0 : -170 * M_PI / 180;
      const engine::DrivenQuantity q = percent ? o.foldPercentQuantity()
                                               : o.creaseAngleQuantity(crease, 0.5 * (o.foldAngle(x0, crease) + target),
                                                                       o.stillCreases(x0, crease));
      engine::DriveOptions opt;
      opt.steps = 200;
      opt.admissible = [&o](const engine::Vector& y) { return o.creaseAgainstAssignment(y) < 0; };
      path = engine::driveQuantity(o, x0, q, target, opt);
      best = std::min(best, cpu() - t0);
    }
    std::printf("Miura-ori %2dx%-2d driven: %-26s %4d vars  %3d/200 steps %6.3f s CPU  %6.2f ms/step  (%s)\n", n, n,
                percent ? "fold percentage to 90" : "one crease to -170 degrees", static_cast<int>(x0.size()),
                path.summary.steps_done, best, 1e3 * best / std::max(1, path.summary.steps_done),
                path.summary.briefReport().c_str());
  }
}

}  // namespace

int main() {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  for (int n : {4, 10}) {
    run(n, false);
    run(n, true);
    drive(n);
  }
  return 0;
}
