// A scene: one geometric constraint system, how to move it and how to show it (SPEC section 2).
#pragma once

#include "scenes/catalog.h"

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/deformation_path.h"
#include "engine/model.h"
#include "engine/motion_tracker.h"
#include "engine/rigidity.h"
#include "scenes/importers.h"
#include "scenes/caption.h"
#include "scenes/style.h"

namespace flexure::engine {
struct RationalMatrix;  // engine/exact/rational.h
}

namespace flexure::scenes {

// The most samples a path may have after its start ([motion] steps, an edge contraction's
// steps, a frame's sample or ghost).
constexpr int kMaxSteps = 10'000'000;
// The most coordinates a path may hold: samples times variables (2 GB of doubles).
constexpr double kMaxPathValues = 2.5e8;

// Coordinates stay within +-kMaxCoordinate and configurations span at least kMinExtent, so
// that squared lengths, volumes and their derivatives neither overflow nor underflow.
constexpr double kMaxCoordinate = 1e50;
constexpr double kMinExtent = 1e-50;

// A scene-file problem, reported as "FILE:LINE:COLUMN: message".
class SceneError : public std::runtime_error {
 public:
  SceneError(std::string file, int line, int column, const std::string& message, long item = -1)
      : std::runtime_error(file + ":" + std::to_string(line) + ":" + std::to_string(column) + ": " + message),
        file(std::move(file)), line(line), column(column), message(message), item(item) {}
  std::string file;
  int line;
  int column;
  std::string message;
  long item;  // the row of an array given as numbers (SceneArray, an .npz) that is wrong, else -1
};

// A [system] array given as numbers instead of text (Python passes its numpy arrays so): `rows`
// rows of `cols` values (cols = 0: a flat array of `rows` values), row-major. The scene's text
// holds `KEY = []` for it in [system]; errors in it are at that place, with the item.
struct SceneArray {
  std::string key;
  std::vector<double> values;
  size_t rows = 0, cols = 0;
  bool integer = false;  // the values are integers (vertex numbers), not floats
};

struct MotionSettings {
  int steps = 100;                           // samples to compute after the start
  double step_size = 0.01;                   // predictor step length
  std::optional<std::vector<double>> flex;   // coefficients in the nontrivial-flex basis; unset = "auto"
  bool steps_given = false;                  // steps was set (edge contraction: a cap on the samples)
  std::uint64_t seed = 1;                    // every random choice derives from it
  bool certify = false;                      // certify every sample and step (engine/interval/krawczyk.h)
  // Edge contraction (paper B.2): the edge's length goes from its current value to
  // target_length in steps of step_size, instead of following a flex.
  std::optional<std::array<int, 2>> contract_edge;  // 0-based
  double target_length = 0;
  // Origami driven instead (engine/continuation.h): one crease (an index into the sheet's edges)
  // to fold_angle (radians, + valley), or every mountain and valley crease toward fold_percent
  // of its full fold; in `steps` equal steps of the driven quantity.
  std::optional<int> fold_crease;
  double fold_angle = 0;
  std::optional<double> fold_percent;
  // Where the flex key is, for messages (the scene file, line 1, column 1 when it is not given).
  std::string flex_file;
  int flex_line = 1, flex_column = 1;
  // From sample branch[0] on, along direction branch[1] of the tangent cone there (both from 0;
  // pipeline::branchesAt); where the key is, for messages.
  std::optional<std::array<int, 2>> branch;
  std::string branch_file;
  int branch_line = 1, branch_column = 1;
};

struct AnalysisSettings {
  double rank_tolerance = 1e-9;  // singular values <= rank_tolerance * sigma_max count as zero
  std::uint64_t seed = 1;        // the blocked-flex homotopy and the motion check
  int max_homotopy_flexes = 6;   // the blocked-flex homotopy (3^k paths) runs up to this many flexes
  int motion_check_steps = 8;    // a short tracked path proves "flexible" (0: no check)
  bool exact = false;            // also the exact analysis in rational arithmetic (engine/exact/)
  double exact_budget = 60;      // CPU seconds the exact analysis may take (estimated before it starts)
  bool certify = false;          // also the interval certificate of the start (engine/interval/)
};

// Animations ([render] keys too).
struct AnimationSettings {
  int frame_step = 1;                               // every k-th sample (the last one always)
  std::optional<std::vector<int>> fixed_vertices;   // 0-based; unset: the default; empty: none
  std::vector<double> fixed_direction;              // where fixed_vertices[1] goes (empty: e_x)
  bool rotate = false;                              // 3D: the camera turns about z
  int rotation_frames = 240;                        // frames per turn
  int gif_size = 480;                               // GIF frames: the longer side, px (at most)
  int crf = 20;                                     // MP4 quality (x264 CRF, lower is better)
  bool side_by_side = false;                        // the projection plot next to the mechanism
  bool mark_events = true;                          // caption singular points as they pass
  // Volume hypergraphs: every frame is moved by the equi-affine map (translation and det-1
  // linear map) taking this simplex to one reference simplex: a at the origin, b - a to
  // (target_stretch, 0[, 0]), c - a to (tip_value, h[, 0]) (3D: d - a to (tip, tip, h')), the
  // heights set by its constant volume. That removes every trivial motion. 0-based; unset: the
  // first simplex when nothing is pinned; empty: none.
  std::optional<std::vector<int>> fixed_simplex;
  double target_stretch = 1, tip_value = 0.5;
};

struct RenderSettings {
  int width = 1000;   // px (a figure sized in lengths: the length at dpi)
  int height = 1000;
  bool physical = false;  // width and height were given as lengths: sizes are in points
  int dpi = 300;          // px per inch of a figure sized in lengths
  int fps = 25;
  FigureStyle style;  // the look: colours, sizes, toggles, camera (its width/height unused)
  AnimationSettings animation;
  bool filmstrip_overlay = false;  // filmstrips: the samples in one picture, earlier ones fading
  int columns = 0;                 // filmstrips: panels per row (0: one row)
  // Filmstrips: each panel's caption (scenes/caption.h; Distance's vertices from 0).
  std::vector<CaptionPiece> caption = {{CaptionPiece::Text, "sample ", 0, 0}, {CaptionPiece::Sample, "", 0, 0}};
  // Projection plots' title and subtitle; unset: the defaults, "": none.
  std::optional<std::string> title, subtitle;
  // OBJ/STL solids: tube and joint radii as fractions of the median bar length.
  double print_tube = 0.05, print_joint = 0.12;
};

// [projection]: random projections of the deformation path (paper figures 8 and 9).
struct ProjectionSettings {
  std::optional<std::uint64_t> seed;          // unset: the [motion] seed
  std::vector<std::vector<double>> flexes;    // one path per coefficient list (empty: [motion] flex)
  bool both_directions = false;               // also follow -flex, drawn as one curve through the start
  bool flex_arrows = false;                   // the projected initial flex(es) as arrows
  std::vector<render::Color> colors;          // per path (default: gray35 for one, a palette for more)
  double line_width = 8, marker_size = 45;    // px of a 1000-pixel image
};

enum class OutputKind { Frame, Animation, Path, Projection };
const char* toString(OutputKind k);  // "frame", "animation", "path", "projection"
std::optional<OutputKind> parseOutputKind(const std::string& text);
// png, svg, pdf, tex: the extensions a picture (a frame, a filmstrip, a projection plot) is
// written in.
bool isImageExtension(const std::string& ext);
// obj, stl: a configuration as a solid for 3D printing (a frame output).
bool isSolidExtension(const std::string& ext);
// The kind a file name's (lower-case) extension implies: png/svg/pdf/tex frame, gif/mp4
// animation, json/csv path; none for others.
std::optional<OutputKind> outputKindOfExtension(const std::string& ext);
// Whether an output of `kind` can be written as a file with extension `ext` (lower case).
bool canWrite(OutputKind kind, const std::string& ext);

struct OutputSpec {
  std::string file;
  OutputKind kind = OutputKind::Frame;
  int sample = 0;    // frame: which sample
  bool flex = false; // frame: draw the flex arrows
  std::vector<int> samples{};  // frame: several samples in one figure (a filmstrip) instead of `sample`
};

// A path given as SCENE (a path JSON written by `track`): its samples in the scene's free
// coordinates (checked against its constraints when read), events and how it was tracked.
// Commands draw and write it instead of tracking.
struct GivenPath {
  engine::DeformationPath path;  // no segments: the pipeline starts it on the scene's model
};

struct Scene {
  std::string path;        // the file it came from (or "catalog:NAME")
  std::string title;
  std::string type;        // the [system] type after resolving "catalog"
  int index_base = 1;      // vertex numbers in the file count from this
  std::unique_ptr<engine::Model> model;
  MotionSettings motion;
  AnalysisSettings analysis;
  RenderSettings render;
  ProjectionSettings projection;
  std::vector<OutputSpec> outputs;
  // The scene as one TOML text that loads it again on its own: the file with its overrides,
  // `[system] from = FILE` replaced by the system it read, without [[output]] and [sweep]. The
  // path JSON carries it. Written when asked for (empty function: not available).
  std::function<std::string()> document;
  std::shared_ptr<const GivenPath> given;  // a path JSON given as SCENE
  // The exact mode ([analysis] exact): the vertices' coordinates as the file writes them, as
  // rationals (d x vertices); null when the system did not come from `vertices` in the file
  // (an import, a catalog entry): then the exact mode takes the shortest decimals of the doubles.
  std::shared_ptr<const engine::RationalMatrix> exact_vertices;
};

// Loads and validates a scene file. `overrides` are "KEY=VALUE" strings (the CLI's --set),
// applied before validation; VALUE is a TOML value (a bare word is taken as a string).
// A catalog name (`k24`, or `catalog:k24`) where no such file exists loads that entry.
// Throws SceneError for every problem with the input, including an unreadable file.
Scene loadScene(const std::string& path, const std::vector<std::string>& overrides = {});
// The text of a scene file; SceneError (line 1, column 1) when it cannot be opened or read.
std::string readSceneFile(const std::string& path);
// The catalog entry a command-line scene argument names: `NAME` or `catalog:NAME` when no file
// or directory of that name exists; nullptr otherwise.
const CatalogEntry* catalogArgument(const std::string& argument);
Scene loadSceneFromString(const std::string& text, const std::string& source_name,
                          const std::vector<std::string>& overrides = {});
// The same with [system] arrays given as numbers (each `KEY = []` in the text).
Scene loadSceneFromString(const std::string& text, const std::string& source_name, std::vector<SceneArray> arrays);
// The scene text a file given as SCENE stands for, as loadScene reads it: a scene file's own
// text; a path JSON's "scene"; for a graph or mesh file, `[system] from` the file itself (found
// next to itself). What the viewer edits and watches.
std::string sceneTextOfFile(const std::string& path, const std::string& text);

// The scene of a graph at its seeded random realization in dimension 2 or 3: what
// `[system] from = FILE` with `graph`, `dimension` and `seed` loads (vertices numbered from 1).
Scene loadGraphScene(const ImportedGraph& g, int dimension, std::uint64_t seed, const std::string& source_name,
                     const std::string& title, const std::vector<std::string>& overrides = {});

// The scene's [analysis] settings as engine options.
engine::RigidityOptions rigidityOptions(const Scene& scene);
// The scene's [motion] settings as tracker options, for `steps` steps.
engine::TrackerOptions trackerOptions(const Scene& scene, int steps);

}  // namespace flexure::scenes
