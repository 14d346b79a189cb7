#include "pipeline/pipeline.h"

#include <Eigen/Core>
#include <Eigen/QR>
#include <algorithm>
#include <cstdio>

#include "engine/active_set.h"
#include "engine/drag.h"
#include "engine/exact/exact_rigidity.h"
#include "engine/interval/certify.h"
#include "engine/interval/krawczyk.h"
#include "engine/track.h"
#include "present/output_file.h"
#include "present/report.h"

namespace flexure::pipeline {

namespace {

std::string shortText(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// The flex with coefficients c in the analysis's basis; zero without nontrivial flexes, and
// empty when c does not have one coefficient per flex (a driven motion has none).
engine::Vector flexDirection(const engine::RigidityReport& rep, const std::vector<double>& c) {
  if (rep.nontrivial == 0) return engine::Vector::Zero(rep.variables);
  if (static_cast<int>(c.size()) != rep.nontrivial || rep.flex_basis.cols() != rep.nontrivial) return {};
  engine::Vector w = Eigen::Map<const engine::Vector>(c.data(), rep.nontrivial);
  // Only the direction counts (the tracker takes its unit vector): coefficients such as
  // [1e200, 1e200] are scaled first, or the flex's norm overflows and the motion reads as none.
  const double size = w.cwiseAbs().maxCoeff();
  if (size > 1e100 || (size > 0 && size < 1e-100)) w /= size;
  return rep.flex_basis * w;
}

}  // namespace

engine::RigidityReport analyze(const Scene& scene, bool counts_only) {
  engine::RigidityOptions options = scenes::rigidityOptions(scene);
  options.counts_only = counts_only && !scene.analysis.certify && !scene.analysis.exact;
  engine::RigidityReport rep = engine::analyzeRigidity(*scene.model, scene.model->startCoordinates(), options);
  if (scene.analysis.certify && !scene.analysis.exact) {
    // The exact mode proves more where it applies; certify alone: interval arithmetic.
    engine::certify::CertifyOptions options;
    options.index_base = scene.index_base;
    engine::certify::applyCertificate(
        rep, engine::certify::certifyStart(*scene.model, scene.model->startCoordinates(), rep, options));
  }
  if (scene.analysis.exact) {
    engine::exact::ExactOptions options;
    options.index_base = scene.index_base;
    options.budget_seconds = scene.analysis.exact_budget;
    try {
      const engine::RationalMatrix points =
          scene.exact_vertices ? *scene.exact_vertices : engine::exact::pointsFromDoubles(*scene.model);
      engine::exact::applyExact(rep, engine::exact::analyzeExact(*scene.model, points, &rep, options));
    } catch (const engine::exact::Refusal& e) {
      throw std::invalid_argument(scene.path + ": the exact mode cannot take this scene: " + e.what());
    }
  }
  return rep;
}

namespace {

// The certificate stops when the caller's step callback says so (Ctrl-C: the path is kept, with
// what was certified).
engine::certify::PathCertifyOptions certifyOptions(const engine::DeformationPath& path,
                                                   const engine::StepCallback& on_step) {
  engine::certify::PathCertifyOptions o;
  if (on_step) {
    const int done = path.summary.steps_done, requested = path.summary.steps_requested;
    o.keep_going = [on_step, done, requested] { return on_step(done, requested); };
  }
  return o;
}

}  // namespace

namespace {

// The scene's motion for `steps` steps, without its branch: along `coefficients` or the scene's
// own flex, contraction or fold drive; certified when `certify`.
Motion trackAlong(const Scene& scene, int steps, const engine::StepCallback& on_step,
                  const std::vector<double>* coefficients, const engine::RigidityReport* start, bool certify) {
  const double values = (static_cast<double>(steps) + 1) * scene.model->system().numVariables();
  if (values > scenes::kMaxPathValues)
    throw std::invalid_argument(std::to_string(steps) + " steps of " +
                                std::to_string(scene.model->system().numVariables()) + " coordinates would hold " +
                                shortText(values) + " numbers; a path holds at most " +
                                shortText(scenes::kMaxPathValues) + " (2 GB): fewer steps");
  Motion m;
  m.rep = start ? *start : analyze(scene);
  if (scene.given) {
    // A path read from a file: its samples (up to `steps`), not tracked again.
    m.path = scene.given->path;
    m.path.startOn(*scene.model);
    const int keep = std::clamp(steps, 0, static_cast<int>(m.path.samples.size()) - 1);
    m.path.samples.resize(static_cast<size_t>(keep) + 1);
    m.path.events.erase(std::remove_if(m.path.events.begin(), m.path.events.end(),
                                       [&](const engine::TrackEvent& e) { return e.sample > keep; }),
                        m.path.events.end());
    m.path.summary.steps_done = keep;
    if (certify) m.path.certificate = engine::certify::certifyPath(m.path, certifyOptions(m.path, on_step));
    return m;
  }
  const int k = m.rep.nontrivial;
  engine::MotionSpec spec;
  const std::vector<double>* given = coefficients ? coefficients : scene.motion.flex ? &*scene.motion.flex : nullptr;
  if (given) {
    spec.coefficients = *given;
    if (static_cast<int>(spec.coefficients.size()) != k && k > 0)
      throw scenes::SceneError(scene.motion.flex_file, scene.motion.flex_line, scene.motion.flex_column,
                               "flex has " + std::to_string(spec.coefficients.size()) +
                                   " coefficient(s), but the start configuration has " + std::to_string(k) +
                                   " nontrivial infinitesimal flex(es)");
    spec.note = "given";
  } else {
    spec.coefficients.assign(m.rep.auto_flex.data(), m.rep.auto_flex.data() + m.rep.auto_flex.size());
    spec.note = "auto: " + m.rep.auto_flex_note;
  }
  // Coefficients passed in (the projection's other paths) ask for a motion along that flex: the
  // scene's edge contraction or fold drive is its own motion only.
  const bool along_given = coefficients != nullptr;
  // A quantity of the model's own driven to a target (origami: a crease's fold angle, or the
  // sheet's fold percentage), in `steps` equal steps.
  std::optional<engine::DrivenQuantity> drive_quantity;
  if (!along_given && (scene.motion.fold_crease || scene.motion.fold_percent)) {
    const int item = scene.motion.fold_crease ? *scene.motion.fold_crease : -1;
    const double target = scene.motion.fold_crease ? scene.motion.fold_angle : *scene.motion.fold_percent;
    drive_quantity = scene.model->drivenQuantity(item, target, scene.model->startCoordinates(), m.rep.flex_basis,
                                                 scene.motion.step_size);
  }
  const bool driven = drive_quantity.has_value();
  const bool contracted = !along_given && scene.motion.contract_edge;
  if (contracted) {
    const auto [a, b] = *scene.motion.contract_edge;
    engine::EdgeContraction c;
    c.row = engine::distanceEquation(scene.model->system(), a, b);
    c.target_length = scene.motion.target_length;
    c.options.step = scene.motion.step_size;
    c.options.max_steps = scene.motion.steps_given || steps != scene.motion.steps ? steps : -1;
    c.options.corrector.factorization.rank_tolerance = scene.analysis.rank_tolerance;
    spec.contraction = c;
    spec.coefficients.clear();
    spec.note = "edge contraction of [" + std::to_string(a + scene.index_base) + ", " +
                std::to_string(b + scene.index_base) + "] to length " + shortText(scene.motion.target_length);
  } else if (!driven) {
    spec.direction = flexDirection(m.rep, spec.coefficients);
  }
  engine::TrackerOptions options = scenes::trackerOptions(scene, steps);
  // The model's inequalities (origami's mountain/valley assignment, 2D angles' orientation):
  // the motion ends before a sample that would break them.
  const engine::Inequalities* inequalities = scene.model->inequalities();
  if (inequalities && inequalities->rule() == engine::Inequalities::Rule::Stop)
    options.admissible = inequalities->admissibleFrom(scene.model->startCoordinates());
  if (driven) {
    // A driven fold: one crease's angle, or the sheet's fold percentage, in `steps` equal steps.
    engine::QuantityDrive drive;
    drive.quantity = std::move(*drive_quantity);
    drive.target = scene.motion.fold_crease ? scene.motion.fold_angle : *scene.motion.fold_percent;
    drive.options.steps = steps;
    drive.options.corrector.factorization.rank_tolerance = scene.analysis.rank_tolerance;
    drive.options.admissible = options.admissible;
    spec.note = scene.motion.fold_crease ? drive.quantity.name + " to " + drive.quantity.valueText(drive.target)
                                         : "fold percentage to " + drive.quantity.valueText(drive.target);
    spec.drive = std::move(drive);
    spec.coefficients.clear();
  }
  // Origami at its flat state: the mountain/valley assignment picks the branch and gives the
  // first sample, not the auto flex (which may go straight through the flat state, or fold
  // another way).
  if (!given && !contracted && !driven && steps > 0) {
    const engine::Vector start = scene.model->startCoordinates();
    if (auto first = scene.model->preferredFirstSample(start, scene.motion.step_size, m.rep.flex_basis)) {
      spec.direction = *first - start;
      if (m.rep.nontrivial > 0) {  // its coefficients in the flex basis, for the record
        const engine::Vector c = m.rep.flex_basis.colPivHouseholderQr().solve(spec.direction);
        spec.coefficients.assign(c.data(), c.data() + c.size());
      }
      spec.note = "the mountain/valley assignment, from the flat state";
      options.first_point = *first;
    }
  }
  m.path = engine::track(*scene.model, scene.model->startCoordinates(), spec, options, on_step);
  scene.model->markEvents(m.path, scene.index_base);
  if (options.admissible && m.path.summary.status == engine::TrackStatus::LeftAdmissibleSet &&
      m.path.outside.size() > 0) {
    m.path.summary.status = engine::TrackStatus::Success;
    m.path.summary.reason = "the motion ends at sample " + std::to_string(m.path.samples.size() - 1) + ": " +
                            inequalities->outsideReason(m.path.outside, scene.index_base);
  }
  if (certify) m.path.certificate = engine::certify::certifyPath(m.path, certifyOptions(m.path, on_step));
  return m;
}

// The path from `sample` on along `direction` (free coordinates there), up to `steps` steps in
// all: tracking is deterministic, so the samples up to `sample` are those of the whole path.
void continueAlong(const Scene& scene, engine::DeformationPath& path, int steps, int sample,
                   const engine::Vector& direction, const std::string& note, const engine::StepCallback& on_step) {
  const engine::Model& model = path.modelAt(sample);
  if (engine::piecewise(model) || scene.motion.contract_edge || scene.motion.fold_crease || scene.motion.fold_percent)
    throw std::invalid_argument("branches are followed on smooth motions along a flex only");
  engine::TrackerOptions to = scenes::trackerOptions(scene, steps - sample);
  to.sample_offset = sample;
  // The first sample on the chosen branch, a step away on a sphere about the start: from a
  // singular point, a plain step's corrector may land on another branch.
  to.first_point = engine::branchStep(model.system(), path.samples.back(), direction.normalized(),
                                      scene.motion.step_size, to.corrector);
  const engine::DeformationPath rest = engine::trackMotion(
      model, path.samples.back(), direction, to,
      [&](int done, int total) { return !on_step || on_step(sample + done, sample + total); });
  path.samples.insert(path.samples.end(), rest.samples.begin() + 1, rest.samples.end());
  for (engine::TrackEvent e : rest.events) {
    e.sample += sample;
    bool seen = false;
    for (const auto& f : path.events) seen = seen || (f.sample == e.sample && f.kind == e.kind);
    if (!seen) path.events.push_back(e);
  }
  path.summary.status = rest.summary.status;
  path.summary.reason = rest.summary.reason;
  path.summary.steps_requested = steps;
  path.summary.steps_done = sample + rest.summary.steps_done;
  path.summary.rejected_steps += rest.summary.rejected_steps;
  path.summary.max_residual = std::max(path.summary.max_residual, rest.summary.max_residual);
  path.flex_choice += "; from sample " + std::to_string(sample) + " along " + (note.empty() ? "a branch" : note);
  // The model's own events (an origami sheet's faces passing through each other), over the
  // whole path again.
  scene.model->markEvents(path, scene.index_base);
}

}  // namespace

engine::BranchDirections branchesAt(const engine::DeformationPath& path, int sample, std::uint64_t seed) {
  engine::BranchDirections b;
  const int last = static_cast<int>(path.samples.size()) - 1;
  if (sample < 0 || sample > last) throw std::invalid_argument("sample " + std::to_string(sample) + " is not on the path");
  const engine::Model& model = path.modelAt(sample);
  if (engine::piecewise(model)) {
    b.note = "not computed: the model changes along the path (contacts, inequalities)";
    return b;
  }
  engine::TangentConeOptions o;
  o.seed = seed;
  o.dense_limit = kMaxBranchCoordinates;
  // At a singular event the samples straddle the singular point: the cone is that point's.
  const bool event = std::any_of(path.events.begin(), path.events.end(), [&](const engine::TrackEvent& e) {
    return e.sample == sample && e.kind == engine::EventKind::Singularity;
  });
  const auto at = [&](int k) -> const engine::Vector& { return path.samples[static_cast<size_t>(k)]; };
  const engine::Vector x = event && sample > 0 && sample < last && model.system().numVariables() <= kMaxBranchCoordinates &&
                                   &path.modelAt(sample - 1) == &model && &path.modelAt(sample + 1) == &model
                               ? engine::locateSingularPoint(model, at(sample - 1), at(sample), at(sample + 1))
                               : at(sample);
  b.point = x;
  engine::TangentCone cone = engine::tangentCone(model, x, o);
  b.computed = cone.computed;
  b.flexes = cone.kernel_dimension;
  b.stresses = cone.stresses;
  b.note = cone.note;
  for (const engine::Vector& landing : cone.landings) {
    const engine::Vector d = (landing - x).normalized();
    const auto towards = [&](int k) {  // the cosine with the secant to sample k
      if (k < 0 || k > last || k == sample) return -1.0;
      const engine::Vector s = path.samples[static_cast<size_t>(k)] - x;
      return s.norm() > 0 ? d.dot(s) / s.norm() : -1.0;
    };
    const double next = towards(sample + 1), previous = towards(sample - 1);
    b.kinds.push_back(std::max(next, previous) < 0.9 ? "other" : next >= previous ? "path" : "back");
  }
  b.directions = std::move(cone.directions);
  return b;
}

void addBranchDirections(engine::DeformationPath& path, std::uint64_t seed) {
  int looked = 0;
  for (size_t i = 0; i < path.events.size(); ++i) {
    engine::TrackEvent& e = path.events[i];
    if (e.kind != engine::EventKind::Singularity || e.branches) continue;
    const bool again = std::any_of(path.events.begin(), path.events.begin() + static_cast<long>(i),
                                   [&](const engine::TrackEvent& f) { return f.sample == e.sample && f.branches; });
    if (again || e.sample >= static_cast<int>(path.samples.size())) continue;
    if (looked == kMaxBranchPoints) {
      e.branches = engine::BranchDirections{};
      e.branches->note = "not computed: the first " + std::to_string(kMaxBranchPoints) + " singular samples only";
      continue;
    }
    ++looked;
    e.branches = branchesAt(path, e.sample, seed);
  }
}

Motion track(const Scene& scene, int steps, const engine::StepCallback& on_step, const std::vector<double>* coefficients,
             const engine::RigidityReport* start) {
  // The projection's other paths (coefficients given) follow no branch and get no branch
  // directions; a path read from a file follows none (its samples are given) and gets them.
  if (coefficients) return trackAlong(scene, steps, on_step, coefficients, start, false);
  if (scene.given) {
    Motion m = trackAlong(scene, steps, on_step, nullptr, start, scene.motion.certify);
    addBranchDirections(m.path, scene.motion.seed);
    return m;
  }
  if (!scene.motion.branch) {
    Motion m = trackAlong(scene, steps, on_step, nullptr, start, false);
    addBranchDirections(m.path, scene.motion.seed);
    if (scene.motion.certify) m.path.certificate = engine::certify::certifyPath(m.path, certifyOptions(m.path, on_step));
    return m;
  }
  // [motion] branch = [k, j]: the path up to sample k, then along direction j of the tangent
  // cone there (the directions the path JSON lists at that sample, in that order).
  const int k = (*scene.motion.branch)[0], j = (*scene.motion.branch)[1];
  const scenes::MotionSettings& ms = scene.motion;
  // One sample past k: a singular point at k is told by both its neighbours (and located
  // between them), as on the whole path.
  Motion m = trackAlong(scene, std::min(k + 1, steps), [&](int done, int) { return !on_step || on_step(done, steps); },
                        nullptr, start, false);
  if (static_cast<int>(m.path.samples.size()) > k) {
    const engine::BranchDirections b = branchesAt(m.path, k, ms.seed);
    m.path.samples.resize(static_cast<size_t>(k) + 1);
    m.path.events.erase(std::remove_if(m.path.events.begin(), m.path.events.end(),
                                       [&](const engine::TrackEvent& e) { return e.sample > k; }),
                        m.path.events.end());
    m.path.summary.steps_done = k;
    const auto fail = [&](const std::string& why) {
      throw scenes::SceneError(ms.branch_file, ms.branch_line, ms.branch_column, why);
    };
    if (!b.computed) fail("branch: no directions at sample " + std::to_string(k) + ": " + b.note);
    const int n = static_cast<int>(b.directions.size());
    if (j >= n)
      fail("branch: sample " + std::to_string(k) + " has " + std::to_string(n) + " branch direction(s)" +
           (n ? " (0.." + std::to_string(n - 1) + ")" : "") + "; there is no direction " + std::to_string(j));
    // The branch leaves from the singular point itself (within a step of sample k).
    m.path.samples.back() = b.point;
    if (k < steps)
      continueAlong(scene, m.path, steps, k, b.directions[static_cast<size_t>(j)],
                    "branch direction " + std::to_string(j) + " (" + b.kinds[static_cast<size_t>(j)] + ")", on_step);
  }
  addBranchDirections(m.path, ms.seed);
  if (ms.certify) m.path.certificate = engine::certify::certifyPath(m.path, certifyOptions(m.path, on_step));
  return m;
}

std::vector<present::ProjectionPath> projectionPaths(const Scene& scene, const Motion& main,
                                                     const engine::StepCallback& on_step) {
  const scenes::ProjectionSettings& ps = scene.projection;
  std::vector<std::vector<double>> flexes = ps.flexes;
  const bool use_main = flexes.empty();
  if (use_main) flexes.push_back(main.path.flex);
  std::vector<present::ProjectionPath> out;
  for (const auto& c : flexes) {
    // Every path starts where the scene's motion does: its analysis is reused.
    const Motion forward = use_main ? main : track(scene, scene.motion.steps, on_step, &c, &main.rep);
    present::ProjectionPath path;
    const auto& fs = forward.path.samples;
    // A motion along a flex, or a driven one (an edge contraction, a fold drive: no flex
    // coefficients; its direction is its first step, and it has no backward path).
    const engine::Vector along = flexDirection(forward.rep, forward.path.flex);
    const bool along_flex = forward.rep.nontrivial > 0 && along.size() > 0;
    path.label = along_flex || forward.path.flex_choice.empty() ? "flex " + present::coefficientsText(forward.path.flex)
                                                                : forward.path.flex_choice;
    path.complete = forward.path.summary.status == engine::TrackStatus::Success;
    path.status = forward.path.summary.briefReport();
    if (along_flex && along.norm() > 0) path.flex = along.normalized();
    else if (fs.size() > 1 && (fs[1] - fs[0]).norm() > 0) path.flex = (fs[1] - fs[0]).normalized();
    if (ps.both_directions && along_flex) {
      std::vector<double> minus = forward.path.flex;
      for (double& x : minus) x = -x;
      const Motion backward = track(scene, scene.motion.steps, on_step, &minus, &main.rep);
      const auto& bs = backward.path.samples;
      for (size_t i = bs.size(); i-- > 1;) {
        path.samples.push_back(bs[i]);
        path.sample_numbers.push_back(-static_cast<int>(i));
      }
      for (int s : backward.path.singularSamples())
        if (s > 0) path.singular.push_back(static_cast<int>(bs.size()) - 1 - s);
      path.complete = path.complete && backward.path.summary.status == engine::TrackStatus::Success;
      path.status += "; backwards: " + backward.path.summary.briefReport();
    }
    path.start = static_cast<int>(path.samples.size());
    for (size_t i = 0; i < fs.size(); ++i) {
      path.samples.push_back(fs[i]);
      path.sample_numbers.push_back(static_cast<int>(i));
    }
    for (int s : forward.path.singularSamples()) path.singular.push_back(path.start + s);
    std::sort(path.singular.begin(), path.singular.end());
    path.singular.erase(std::unique(path.singular.begin(), path.singular.end()), path.singular.end());
    out.push_back(std::move(path));
  }
  return out;
}

// ---------------------------------------------------------------------------------------------

Study::Study(const Scene& scene, StudyOptions options)
    : scene_(scene),
      options_(std::move(options)),
      steps_(options_.steps.value_or(scene.motion.steps)),
      projection_seed_(options_.projection_seed.value_or(scene.projection.seed.value_or(scene.motion.seed))) {}

engine::StepCallback Study::stepCallback(Stage stage) {
  return [this, stage](int done, int total) {
    if (cancelled_) return false;
    if (options_.progress && !options_.progress(stage, done, total)) cancelled_ = true;
    return !cancelled_;
  };
}

const engine::RigidityReport& Study::analysis() {
  if (!analysis_) analysis_ = analyze(scene_);
  return *analysis_;
}

const Motion& Study::motion() {
  if (motion_) return *motion_;
  if (!options_.branch) {
    motion_ = track(scene_, steps_, stepCallback(Stage::Tracking), nullptr, &analysis());
    return *motion_;
  }
  // The path up to the branch's sample (tracking is deterministic: the same samples as the
  // whole path has there), then the rest of the steps along the branch.
  const StudyOptions::Branch& b = *options_.branch;
  if (b.sample < 0 || b.sample > steps_) throw std::invalid_argument("the branch's sample is not on the path");
  Motion m = trackAlong(scene_, b.sample, stepCallback(Stage::Tracking), nullptr, &analysis(), false);
  if (static_cast<int>(m.path.samples.size()) == b.sample + 1) {  // else stopped before it
    if (b.point.size() == m.path.samples.back().size()) m.path.samples.back() = b.point;
    continueAlong(scene_, m.path, steps_, b.sample, b.direction, b.note, stepCallback(Stage::Tracking));
  }
  addBranchDirections(m.path, scene_.motion.seed);
  motion_ = std::move(m);
  return *motion_;
}

const std::vector<present::ProjectionPath>& Study::projectionPaths() {
  if (!paths_) paths_ = pipeline::projectionPaths(scene_, motion(), stepCallback(Stage::OtherPaths));
  return *paths_;
}

std::string placeIn(const std::string& dir, const std::string& file) {
  return dir.empty() || (!file.empty() && file[0] == '/') ? file : dir + "/" + file;
}

}  // namespace flexure::pipeline
