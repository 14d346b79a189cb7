// The one way of computing that every front end (the CLI, the viewer, later Python and sweeps)
// calls: a Study of one scene analyses its start once, tracks its motion once, tracks the
// projection's paths once, and writes any output the scene language can name. Progress and
// cancellation go through one callback; nothing here prints.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "engine/deformation_path.h"
#include "engine/rigidity.h"
#include "present/projection.h"
#include "present/writers.h"
#include "render/renderer.h"
#include "scenes/scene.h"

namespace flexure::pipeline {

using scenes::Scene;

// A tracked motion and the analysis of the start it was chosen from.
struct Motion {
  engine::RigidityReport rep;   // at the start
  engine::DeformationPath path;  // path.flex: the coefficients in rep's flex basis
};

// What a study is doing when it reports progress.
enum class Stage {
  Tracking,    // the scene's motion
  OtherPaths,  // the projection's other paths (other flexes, the backward direction)
  Frames,      // frames of an animation being written
};
// (stage, done, total); return false to stop at the next step or frame.
using Progress = std::function<bool(Stage, int, int)>;

struct StudyOptions {
  // Track this many steps instead of [motion] steps.
  std::optional<int> steps;
  // The projection's seed, instead of the scene's rule ([projection] seed, else [motion] seed).
  std::optional<std::uint64_t> projection_seed;
  Progress progress;
  // Leave the scene's motion at `sample` along `direction` (free coordinates at that sample: a
  // tangent-cone direction of a singular point, engine::tangentCone), and track the rest of
  // the steps from there: the viewer's "continue along this branch".
  struct Branch {
    int sample = 0;
    engine::Vector direction;
    std::string note;
    engine::Vector point;  // where the branch leaves (engine::BranchDirections::point); empty: the sample
  };
  std::optional<Branch> branch;
};

// The analysis of the scene's start (its [analysis] settings).
// counts_only: the counts alone (RigidityOptions::counts_only), unless the scene asks for a
// certificate or the exact mode.
engine::RigidityReport analyze(const Scene& scene, bool counts_only = false);

// The scene's motion for `steps` steps, along `coefficients` (default: [motion] flex, else the
// auto flex) in the start's nontrivial-flex basis, or its edge contraction. `start` is the
// start's analysis when the caller has it. Throws SceneError, at the flex key, when the number
// of coefficients does not match the number of nontrivial flexes. A rigid start gives a path of
// one sample, stopped early.
Motion track(const Scene& scene, int steps, const engine::StepCallback& on_step = {},
             const std::vector<double>* coefficients = nullptr, const engine::RigidityReport* start = nullptr);

// The curves [projection] asks for: one per `flexes` entry (default: the scene's motion), each
// continued along -flex too with both_directions.
std::vector<present::ProjectionPath> projectionPaths(const Scene& scene, const Motion& main,
                                                     const engine::StepCallback& on_step = {});

// Branch directions are looked for at the first kMaxBranchPoints singular samples of a path, in
// systems of at most kMaxBranchCoordinates free coordinates (a dense SVD and a search on the
// kernel: tens of milliseconds each).
constexpr int kMaxBranchPoints = 10;
constexpr int kMaxBranchCoordinates = 400;
// The branches that meet at sample `sample` of the path (engine::tangentCone with `seed`): the
// directions [motion] branch = [sample, j] chooses from, each with its kind.
engine::BranchDirections branchesAt(const engine::DeformationPath& path, int sample, std::uint64_t seed);
// Fills `branches` on the path's singularity events (the first event at each sample).
void addBranchDirections(engine::DeformationPath& path, std::uint64_t seed);

class Study {
 public:
  explicit Study(const Scene& scene, StudyOptions options = {});
  const Scene& scene() const { return scene_; }

  // Each computed once, on first use.
  const engine::RigidityReport& analysis();
  const Motion& motion();
  const std::vector<present::ProjectionPath>& projectionPaths();
  const present::Projection& projection();

  std::uint64_t projectionSeed() const { return projection_seed_; }
  int steps() const { return steps_; }
  // True once the progress callback has asked to stop.
  bool cancelled() const { return cancelled_; }

  // Writes one output to `file` (its kind from `spec`; spec.file is not used), tracking what
  // it needs first; `renderer` is asked for only by the outputs that draw. `data`: the
  // projection's coordinates as CSV too (projection only).
  using RendererSource = std::function<render::Renderer&()>;
  present::Written write(const scenes::OutputSpec& spec, const std::string& file, const RendererSource& renderer,
                         const std::string& data = "");

  // A frame (spec.sample, spec.flex) or the projection plot as an image, not a file: what
  // the Python module returns as an array. Other kinds throw std::invalid_argument.
  render::Image image(const scenes::OutputSpec& spec, const RendererSource& renderer);
  // The animation's frames as images, one call of `frame` each (the image's memory is reused
  // between calls): what an MP4 or GIF of the scene's motion shows, at the scene's size.
  void animationFrames(const RendererSource& renderer, const std::function<void(int, const render::Image&)>& frame);

  // The scene's outputs, one after the other, with file names relative to `dir` (empty: as
  // written); `on_written` after each. Stops before the next output once cancelled and says
  // which one in the result.
  struct RunResult {
    std::vector<present::Written> written;
    std::string stopped_before;  // the output that was not written because of a stop ("": none)
  };
  RunResult run(const std::vector<scenes::OutputSpec>& outputs, const std::string& dir, const RendererSource& renderer,
                const std::function<void(const present::Written&)>& on_written = {});

 private:
  engine::StepCallback stepCallback(Stage stage);
  const Scene& scene_;
  StudyOptions options_;
  int steps_;
  std::uint64_t projection_seed_;
  bool cancelled_ = false;
  std::optional<engine::RigidityReport> analysis_;
  std::optional<Motion> motion_;
  std::optional<std::vector<present::ProjectionPath>> paths_;
  std::optional<present::Projection> projection_;
};

// A file name placed in `dir` (unchanged when dir is empty or the name is absolute).
std::string placeIn(const std::string& dir, const std::string& file);

}  // namespace flexure::pipeline
