// Everything a scene can produce from its tracked motion: frames (PNG), animations (MP4, GIF),
// random projections of the deformation path (PNG plot, animated, CSV data) and the path itself.
// The CLI's render, animate, project, run and demo commands are thin wrappers around these.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "engine/motion_tracker.h"
#include "engine/rigidity.h"
#include "render/plot.h"
#include "render/renderer.h"
#include "render/video.h"
#include "scenes/scene.h"

namespace flexure::scenes {

// A tracked motion and how its direction was chosen.
struct Motion {
  engine::RigidityReport rep;          // at the start
  std::vector<double> coefficients;    // in the canonical nontrivial-flex basis
  std::string note;                    // "given" or "auto: ..."
  engine::TrackResult result;
};

// The scene's [analysis] settings as engine options.
engine::RigidityOptions rigidityOptions(const Scene& scene);
engine::RigidityReport analyzeScene(const Scene& scene);

// Follows the scene's motion for `steps` steps along its [motion] flex (or `coefficients`).
// Throws SceneError, at the flex key, when the number of coefficients does not match the
// number of nontrivial flexes. A rigid start gives a path of one sample, stopped early.
Motion trackScene(const Scene& scene, int steps, const engine::StepCallback& on_step = {},
                  const std::vector<double>* coefficients = nullptr);

// The geometry drawn at `sample` of a path: the model's, plus the sticky contacts its events
// made up to there.
engine::Geometry geometryAt(engine::Geometry g, const std::vector<engine::TrackEvent>& events, int sample);

// The samples an animation shows: 0, k, 2k, ... and always the last one.
std::vector<int> frameSamples(int sample_count, int step);

// [render] fixed_vertices, resolved: as given; else none when something is pinned (the pins fix
// the picture), else vertices 1, 2 (and 3 in 3D, when not collinear with them).
std::vector<int> fixedVertices(const Scene& scene);

// Moves every configuration (d x n) by a proper rigid motion so that fixed[0] is at the origin,
// fixed[1] on the ray along `direction` (empty: e_x) and, in 3D, fixed[2] in the half-plane
// spanned by `direction` and the axis of e_y (e_z if direction is along e_y) orthogonal to it.
// Degenerate frames (the vertices coincide or are collinear) keep the previous frame's motion.
void alignConfigurations(std::vector<engine::Matrix>& frames, const std::vector<int>& fixed,
                         const std::vector<double>& direction);

// Moves every configuration (d x n) by the equi-affine map taking simplex (a, b, c[, d]) to the
// reference simplex of AnimationSettings::fixed_simplex (orientation and volume kept). Frames
// where the simplex is degenerate are left as they are.
void normalizeEquiAffine(std::vector<engine::Matrix>& frames, const std::vector<int>& simplex, double target_stretch,
                         double tip_value);

// The simplex the animation of `scene` normalises on: as given, else the first simplex of an
// unpinned volume hypergraph, else none.
std::vector<int> fixedSimplex(const Scene& scene);

// A random n x k matrix with orthonormal columns (the Q factor of a seeded Gaussian matrix).
engine::Matrix randomProjection(int n, int k, std::uint64_t seed);

// One curve of a projection plot, in free coordinates, in order along the curve.
struct ProjectionPath {
  std::string label;
  std::vector<engine::Vector> samples;
  std::vector<int> sample_numbers;  // per sample: its index on the tracked path (negative: along -flex)
  int start = 0;                    // where the start configuration is in `samples`
  std::vector<int> singular;        // indices (into samples) of singular points passed
  engine::Vector flex;              // the initial direction, free coordinates, unit length
  std::string status;               // the tracker's brief report(s)
  bool complete = true;             // every tracked piece reached its steps
};

// The curves [projection] asks for: one per `flexes` entry (default: `main`, the scene's motion),
// each continued along -flex too with both_directions.
std::vector<ProjectionPath> projectionPaths(const Scene& scene, const Motion& main,
                                            const engine::StepCallback& on_step = {});

struct Projection {
  std::uint64_t seed = 1;
  engine::Matrix q;                               // n x 2, orthonormal columns
  std::vector<std::vector<render::Point2>> curves;  // per path
  std::vector<int> starts;                          // per path: the start's index in its curve
  render::Plot plot;
};
Projection projectPaths(const Scene& scene, const std::vector<ProjectionPath>& paths, std::uint64_t seed);
// path,sample,p1,p2 (sample: the index on the tracked path; negative along -flex).
std::string projectionCsv(const std::vector<ProjectionPath>& paths, const Projection& projection);
render::PlotStyle projectionStyle(const Scene& scene, int width, int height);

// What the viewer changes per frame; unset keeps the scene's [render] choice.
struct FrameOptions {
  std::optional<bool> labels, trace;
  bool flex = false;                         // arrows: the path's velocity at the sample shown
  std::optional<double> azimuth, elevation;  // 3D camera, radians
  double zoom = 1;
};

// The frames of an animation: aligned configurations, one camera for all, optional rotation,
// event captions and the projection plot beside it.
class Animation {
 public:
  // `projection`: drawn beside the mechanism with side_by_side; its first path must be the
  // scene's motion (a cursor follows it).
  Animation(const Scene& scene, const Motion& motion, int width, int height,
            const Projection* projection = nullptr);
  int frameCount() const { return static_cast<int>(samples_.size()); }
  int width() const { return width_; }
  int height() const { return height_; }
  int sampleCount() const { return static_cast<int>(positions_.size()); }
  // Draws frame i into `out` (reusing its memory).
  void frame(int i, render::Renderer& renderer, render::Image& out) const;
  // Draws sample k of the path (any sample, not only the animation's frames) as the viewer
  // asks for it; no turntable, no side-by-side plot.
  void sample(int k, const FrameOptions& options, render::Renderer& renderer, render::Image& out) const;

 private:
  const Scene& scene_;
  engine::Geometry geometry_;
  std::vector<int> samples_;               // sample index per frame
  std::vector<engine::Matrix> positions_;  // aligned, per sample of the path
  std::optional<engine::Matrix> ghost_;
  std::vector<render::Polygon> surface_;  // a framework's surface, meshed once for the view
  FigureStyle style_;
  render::DrawList figureAt(int k, const FigureStyle& style, bool flex) const;
  render::View view_;
  int width_, height_, panel_width_;
  std::vector<engine::TrackEvent> events_;  // singular points and new contacts
  std::optional<render::PlotCanvas> plot_;
  std::vector<render::Point2> cursor_path_;  // the projected motion, from its start
  mutable render::Image left_, right_;       // the two panels side by side
};

// What an output took.
struct Written {
  std::string file;
  std::string summary;  // e.g. "501 frames, 1000x1000, 25 fps, 20.04 s"
  double seconds = 0;
  render::VideoStats video;
};

// One PNG of sample `sample` of `motion` (the start when motion is null), with flex arrows.
Written writeFrame(const Scene& scene, const Motion* motion, int sample, bool flex, const std::string& file,
                   render::Renderer& renderer);
// An MP4 or GIF (by extension) of the whole motion.
Written writeAnimation(const Scene& scene, const Motion& motion, const std::string& file, render::Renderer& renderer,
                       const std::vector<ProjectionPath>* paths, std::uint64_t projection_seed,
                       const render::FrameProgress& progress = {});
// The projection plot (PNG), or its animation with a moving marker (GIF/MP4).
Written writeProjection(const Scene& scene, const std::vector<ProjectionPath>& paths, std::uint64_t seed,
                        const std::string& file, const std::string& data_file, render::Renderer& renderer,
                        const render::FrameProgress& progress = {});
// The path as JSON or CSV (SPEC section 3).
Written writePath(const Scene& scene, const Motion& motion, const std::string& file);

// The lower-case extension of a file name ("" without one).
std::string extensionOf(const std::string& path);

}  // namespace flexure::scenes
