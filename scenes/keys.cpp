#include "scenes/keys.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "scenes/scene.h"

namespace flexure::scenes {

namespace {

// Where a simple key's value lives in a Scene.
#define FIELD(expr) [](Scene & s) -> decltype(auto) { return (expr); }

using IntRef = int& (*)(Scene&);
using RealRef = double& (*)(Scene&);
using FlagRef = bool& (*)(Scene&);
using ColorRef = render::Color& (*)(Scene&);
using OptColorRef = std::optional<render::Color>& (*)(Scene&);
using SeedRef = std::uint64_t& (*)(Scene&);
using OptSeedRef = std::optional<std::uint64_t>& (*)(Scene&);

KeySpec custom(std::string table, std::string key, std::string type, std::string default_doc, std::string doc,
               std::string range_doc = "", std::string types = "") {
  KeySpec k;
  k.table = std::move(table), k.key = std::move(key), k.type = std::move(type);
  k.default_doc = std::move(default_doc), k.doc = std::move(doc), k.range_doc = std::move(range_doc);
  k.types = std::move(types);
  return k;
}

KeySpec system(std::string key, std::string type, std::string doc, std::string types = "",
               std::string default_doc = "required") {
  return custom("system", std::move(key), std::move(type), std::move(default_doc), std::move(doc), "",
                std::move(types));
}

KeySpec integer(std::string table, std::string key, double lo, double hi, std::string doc, IntRef f,
                std::string message = "") {
  KeySpec k = custom(std::move(table), std::move(key), "integer", "", std::move(doc));
  k.kind = KeyKind::Integer, k.lo = lo, k.hi = hi, k.field = f, k.range_message = std::move(message);
  return k;
}

KeySpec number(std::string table, std::string key, double lo, double hi, std::string doc, RealRef f,
               bool open_lo = false, bool open_hi = false, std::string message = "") {
  KeySpec k = custom(std::move(table), std::move(key), "number", "", std::move(doc));
  k.kind = KeyKind::Number, k.lo = lo, k.hi = hi, k.open_lo = open_lo, k.open_hi = open_hi, k.field = f;
  k.range_message = std::move(message);
  return k;
}

KeySpec flag(std::string table, std::string key, std::string doc, FlagRef f) {
  KeySpec k = custom(std::move(table), std::move(key), "boolean", "", std::move(doc));
  k.kind = KeyKind::Flag, k.field = f;
  return k;
}

KeySpec color(std::string key, std::string doc, ColorRef f) {
  KeySpec k = custom("render", std::move(key), "colour", "", std::move(doc));
  k.kind = KeyKind::Color, k.field = f;
  return k;
}

KeySpec optionalColor(std::string key, std::string doc, OptColorRef f, std::string default_doc) {
  KeySpec k = custom("render", std::move(key), "colour", std::move(default_doc), std::move(doc));
  k.kind = KeyKind::OptionalColor, k.field = f;
  return k;
}

KeySpec seed(std::string table, std::string doc, SeedRef f) {
  KeySpec k = custom(std::move(table), "seed", "integer", "", std::move(doc));
  k.kind = KeyKind::Seed, k.field = f;
  return k;
}

KeySpec optionalSeed(std::string table, std::string doc, OptSeedRef f, std::string default_doc) {
  KeySpec k = custom(std::move(table), "seed", "integer", std::move(default_doc), std::move(doc));
  k.kind = KeyKind::OptionalSeed, k.field = f;
  return k;
}

const char* kAllTypes = "";  // every type but catalog

// A key that takes a length too (KeySpec::lengths).
KeySpec length(KeySpec k) {
  k.lengths = true;
  return k;
}

std::string sizeDoc(const std::string& what) {
  return what + ": px of a 1000-pixel image (of an 11.3 cm one in a figure sized in lengths), or a length \"9pt\"";
}

// A key whose value holds vertex numbers.
KeySpec indices(KeySpec k) {
  k.vertex_indices = true;
  return k;
}

std::vector<KeySpec> makeKeys() {
  const std::string R = "render", M = "motion", A = "analysis", P = "projection", O = "output";
  return {
      // The top level.
      custom("", "title", "string", "\"\"", "shown in reports, plots and the viewer"),
      custom("", "index_base", "integer", "1", "vertex numbers in the file count from this (0 or 1)", "0 or 1"),
      custom("", "system", "table", "required", "the geometric constraint system ([system] below)"),
      custom("", "motion", "table", "", "how it moves ([motion])"),
      custom("", "analysis", "table", "", "the rigidity analysis ([analysis])"),
      custom("", "render", "table", "", "how it looks ([render])"),
      custom("", "projection", "table", "", "random projections of the path ([projection])"),
      custom("", "output", "array of tables", "", "what `flexure run` writes ([[output]])"),
      custom("", "sweep", "table", "",
             "keys and the values `flexure sweep` runs the scene with (e.g. motion.seed = 1..100); other "
             "commands ignore it"),
      // [system]: which keys a type takes.
      system("type", "string", "the system type (see the types below) or \"catalog\"", "", "required"),
      system("name", "string", "the catalog entry (`flexure catalog` lists them)", "catalog"),
      system("from", "file name",
             "the system of a file, relative to the scene: a graph (a framework) from graph6/sparse6 (.g6, .s6), "
             "an edge list (.edges, .edgelist) or networkx's node-link JSON (.json), realized at random unless "
             "its nodes have \"pos\"; an OFF/OBJ/STL mesh (a polytope); or a FOLD file (.fold: origami, frame 0 unless frame is given); type, "
             "vertices and the rest come from it. Or NumPy's arrays (.npz, from numpy.savez): each array is the [system] "
             "key of its name (vertices, edges, faces, ...; pinned, lengths, radii), beside `type` and the scene's other keys",
             "from", "-"),
      system("graph", "integer", "which graph of a graph6/sparse6 file, from 1", "from", "1"),
      system("frame", "integer", "which frame of a FOLD file: 0 the top level, k file_frames[k - 1] (inheriting "
             "as frame_inherit says)", "from", "0"),
      system("dimension", "integer", "a graph's random realization: 2 or 3", "from", "2"),
      system("seed", "integer", "a graph's random realization: uniform in the unit square or cube, from this seed",
             "from", "1"),
      system("vertices", "[[x, y(, z)], ...]", "the start configuration, one point per vertex (numbers or expressions)"),
      indices(system("edges", "[[i, j], ...]", "bars whose lengths are kept", "framework framework_on_surface")),
      indices(system("pinned", "[i, ...]", "vertices that do not move", kAllTypes, "[]")),
      indices(system("attached", "[[v, a, b(, c)], ...]",
                     "vertex v held in the frame of a, b (and c) where it is at the start: a coupler point, a "
                     "point of a ternary link; in 3D two frame vertices hold only points on their line. No degree "
                     "of freedom is added",
                     "framework", "[]")),
      system("lengths", "[number, ...]", "edge lengths the realization must satisfy (checked, with the residual)",
             "framework", "the realization's"),
      indices(system("facets", "[[i, j, k, ...], ...] or \"hull\"",
                     "cyclic vertex lists of planar facets, or the facets of the vertices' convex hull", "polytope")),
      indices(system("bodies", "[[i, j, ...], ...]", "rigid bodies (vertex lists; shared vertices are hinges)",
                     "body_hinge body_bar")),
      indices(system("bars", "[[i, j], ...]", "bars between bodies whose lengths are kept", "body_bar")),
      indices(system("faces", "[[i, j, k, ...], ...]",
                     "origami: the panels' faces, counterclockwise vertex cycles (faces joined by F or J creases "
                     "are one rigid panel)", "origami")),
      indices(system("creases", "[[i, j], ...]", "origami: every edge of the sheet, creases and boundary (each face's "
                     "sides must be among them)", "origami")),
      system("assignments", "string", "origami: one letter per crease, B boundary, M mountain, V valley, F flat, "
             "U unassigned, J join (FOLD's edges_assignment)", "origami", "all U"),
      indices(system("angles", "[[i, j, k], ...]", "the angle at j between ji and jk is kept", "angular_framework")),
      indices(system("simplices", "[[i, j, k(, l)], ...]", "d + 1 vertices each; their signed volumes are kept",
                     "volume_hypergraph")),
      indices(system("contacts", "[[i, j], ...]", "caps (3D points a with abs(a) > 1) whose inversive distance is kept",
                     "spherical_disk_packing")),
      system("radii", "[number, ...]", "one radius per disk or sphere", "sphere_packing", "required (or radius)"),
      system("radius", "number", "one radius for all", "sphere_packing", "(or radii)"),
      system("tolerance", "number", "pairs with abs(gap) <= tolerance * (r_i + r_j) touch; in (0, 0.1)",
             "sphere_packing", "1e-6"),
      system("surface", "expression in x, y, z", "every vertex stays on f(x, y, z) = 0 (3D)", "framework_on_surface"),
      system("project_start", "boolean", "correct the start onto the surface (keeping the bar lengths)",
             "framework_on_surface", "false"),
      // [motion]
      integer(M, "steps", 0, kMaxSteps, "samples to compute after the start (edge contraction: a cap)",
              FIELD(s.motion.steps)),
      number(M, "step_size", 0, INFINITY,
             "distance between consecutive samples (edge contraction: length step; a driven fold takes equal steps "
             "instead)",
             FIELD(s.motion.step_size), true, false, "step_size must be positive"),
      custom(M, "flex", "\"auto\" or [number, ...]", "\"auto\"",
             "the initial direction: coefficients in the canonical nontrivial-flex basis, or a flex no stress "
             "blocks closest to equal coefficients"),
      seed(M, "every random choice of the tracker derives from it", FIELD(s.motion.seed)),
      flag(M, "certify",
           "certify every sample (a radius holding exactly one point of the real motion, Krawczyk test) and every "
           "step (one smooth arc) in interval arithmetic (track --certify)",
           FIELD(s.motion.certify)),
      indices(custom(M, "contract_edge", "[i, j]", "",
                     "contract this edge instead of following a flex (with target_length)")),
      custom(M, "target_length", "number", "", "the length the contracted edge goes to", "> 0"),
      indices(custom(M, "fold_crease", "[i, j]", "",
                     "origami: fold this crease instead of following a flex (with fold_angle), in `steps` equal "
                     "steps of its angle")),
      custom(M, "fold_angle", "number", "", "origami: the angle fold_crease goes to, degrees (+ valley, - mountain)",
             "[-180, 180]"),
      custom(M, "fold_percent", "number", "",
             "origami: fold every mountain and valley crease toward this percentage of its full fold (+-180 degrees), "
             "in `steps` equal steps of the percentage", "[0, 100]"),
      custom(M, "branch", "[k, j]", "",
             "continue from sample k of the path along direction j of the tangent cone there (both from 0; the path "
             "JSON lists the directions at each singular sample; track --branch k:j)"),
      // [analysis]
      number(A, "rank_tolerance", 0, 1, "singular values <= rank_tolerance * sigma_max count as zero",
             FIELD(s.analysis.rank_tolerance), true, true, "rank_tolerance must be in (0, 1)"),
      seed(A, "the blocked-flex homotopy's random start and perturbation, and the motion check",
           FIELD(s.analysis.seed)),
      integer(A, "max_homotopy_flexes", 0, 9, "the blocked-flex homotopy (3^k paths) runs up to this many flexes",
              FIELD(s.analysis.max_homotopy_flexes),
              "max_homotopy_flexes must be between 0 and 9 (the homotopy has 3^k paths)"),
      integer(A, "motion_check_steps", 0, 1000, "a short tracked path that proves \"flexible\" (0: none)",
              FIELD(s.analysis.motion_check_steps)),
      flag(A, "exact",
           "also analyse in exact rational arithmetic (coordinates: integers, decimals, \"p/q\"): proved counts, "
           "inf_rigid and prestress stability (analyze --exact)",
           FIELD(s.analysis.exact)),
      number(A, "exact_budget", 0, 1e9,
             "CPU seconds the exact analysis may take: its time and memory are estimated from the matrix before "
             "it starts, and work beyond this or beyond the memory there is is refused with the estimate (exit 1)",
             FIELD(s.analysis.exact_budget), true, false, "exact_budget must be a number of seconds in (0, 1e9]"),
      flag(A, "certify",
           "also prove what interval arithmetic can about the start as given (analyze --certify): infinitesimal "
           "rigidity with a bound on the smallest singular value, or flexibility at a regular point",
           FIELD(s.analysis.certify)),
      // [render]: the picture.
      length(integer(R, "width", 16, 8192, "image width: px, or a length (\"8cm\", \"80mm\", \"3in\", \"230pt\") "
                     "that sizes the figure for print (raster at dpi; sizes in points)", FIELD(s.render.width))),
      length(integer(R, "height", 16, 8192, "image height: px, or a length (unset with a length width: the same)",
                     FIELD(s.render.height))),
      integer(R, "dpi", 36, 2400, "pixels per inch of a figure sized in lengths (its PNG says so)", FIELD(s.render.dpi)),
      integer(R, "fps", 1, 240, "animation frames per second (GIFs: at most 50)", FIELD(s.render.fps)),
      color("background", "background colour", FIELD(s.render.style.background)),
      color("edge_color", "bars and edges", FIELD(s.render.style.edge_color)),
      color("vertex_color", "vertices", FIELD(s.render.style.vertex_color)),
      color("label_color", "vertex labels", FIELD(s.render.style.label_color)),
      color("pin_color", "the triangles that mark pinned vertices", FIELD(s.render.style.pin_color)),
      color("flex_color", "flex arrows", FIELD(s.render.style.flex_color)),
      color("trace_color", "the vertices' trajectories (trace = true)", FIELD(s.render.style.trace_color)),
      color("ghost_color", "the ghost sample drawn underneath", FIELD(s.render.style.ghost_color)),
      color("facet_color", "polytope facets (translucent)", FIELD(s.render.style.facet_color)),
      length(number(R, "vertex_size", 0, 1000, sizeDoc("vertex disc diameter"), FIELD(s.render.style.vertex_size))),
      length(number(R, "line_width", 0, 1000, sizeDoc("bar width"), FIELD(s.render.style.line_width))),
      length(number(R, "font_size", 1, 1000, sizeDoc("label size"), FIELD(s.render.style.font_size))),
      length(number(R, "arrow_size", 0, 1000, sizeDoc("arrow head size"), FIELD(s.render.style.arrow_size))),
      flag(R, "labels", "draw vertex numbers", FIELD(s.render.style.labels)),
      flag(R, "pins", "mark pinned vertices", FIELD(s.render.style.pins)),
      number(R, "padding", 0, 1e12, "world units around the figure (unset: 0.15 times the power of ten nearest the median bar)", FIELD(s.render.style.padding)),
      custom(R, "view", "[[x, y(, z)], [x, y(, z)]]", "fitted over the whole path", "the box shown, fixed by hand: lower and upper corner (3D: the box the camera fits)"),
      number(R, "flex_scale", 0, 100, "the longest flex arrow as a fraction of the figure's extent",
             FIELD(s.render.style.flex_scale)),
      number(R, "azimuth", -1e3, 1e3, "3D camera azimuth, radians", FIELD(s.render.style.azimuth)),
      number(R, "elevation", -1e3, 1e3, "3D camera elevation, radians", FIELD(s.render.style.elevation)),
      color("panel_color", "origami: the panels (shaded in 3D)", FIELD(s.render.style.panel_color)),
      color("mountain_color", "origami: mountain creases (solid)", FIELD(s.render.style.mountain_color)),
      color("valley_color", "origami: valley creases (dashed)", FIELD(s.render.style.valley_color)),
      flag(R, "perspective", "3D: perspective instead of orthographic projection", FIELD(s.render.style.perspective)),
      number(R, "fog", 0, 1, "3D: how much colours fade toward the background at the far side of the figure (0: none)", FIELD(s.render.style.fog)),
      flag(R, "trace", "draw each moving vertex's trajectory up to the sample", FIELD(s.render.style.trace)),
      integer(R, "ghost", 0, kMaxSteps, "draw this sample underneath in ghost_color (default -1: none)",
              FIELD(s.render.style.ghost), "ghost must be a sample number 0..10000000 (0 is the start)"),
      // [render]: animations.
      integer(R, "frame_step", 1, 1'000'000, "animate every k-th sample (the last one always)",
              FIELD(s.render.animation.frame_step)),
      indices(custom(R, "fixed_vertices", "[i, j(, k)]", "the first 2 (3 in 3D) without pins; none with pins",
                     "the frame is moved so that i stays at the origin, j on the fixed direction (k in a half-plane)")),
      custom(R, "fixed_direction", "[x, y(, z)]", "e_x", "where fixed_vertices[1] is put"),
      flag(R, "rotate", "3D: the camera turns about z during the animation", FIELD(s.render.animation.rotate)),
      integer(R, "rotation_frames", 1, 1'000'000, "frames per turn with rotate",
              FIELD(s.render.animation.rotation_frames)),
      integer(R, "gif_size", 1, 4096, "GIF frames: the longer side at most, px", FIELD(s.render.animation.gif_size)),
      integer(R, "crf", 0, 51, "MP4 quality (x264 CRF; lower is better)", FIELD(s.render.animation.crf),
              "crf must be between 0 (lossless) and 51"),
      number(R, "print_tube", 0, 10, "OBJ/STL solids: the bars' tube radius as a fraction of the median bar length",
             FIELD(s.render.print_tube)),
      number(R, "print_joint", 0, 10, "OBJ/STL solids: the joints' sphere radius as a fraction of the median bar length",
             FIELD(s.render.print_joint)),
      custom(R, "title", "string", "the scene's title", "the title over projection plots; \"\" for none"),
      custom(R, "subtitle", "string", "how the plot was made (projection, seed)", "the subtitle of projection plots; \"\" for none"),
      indices(custom(R, "edge_styles", "[{edges = [[i, j], ...], color, width, dash, label}, ...]", "",
                     "bars in their own look: colour, width (size units or a length), dashed, a label at the middle")),
      indices(custom(R, "vertex_styles", "[{vertices = [i, ...], color, size, label}, ...]", "",
                     "vertices in their own look: colour, disc diameter, a label instead of the number")),
      integer(R, "stress", -1, 100000, "draw this equilibrium stress of the basis (0: the first; -1: none; render "
              "--stress K): tension red, compression blue, widths by magnitude (default -1: none)",
              FIELD(s.render.style.stress)),
      integer(R, "columns", 0, 64, "filmstrips: panels per row (0: all in one row)", FIELD(s.render.columns)),
      custom(R, "caption", "string", "\"sample {sample}\"",
             "filmstrips: each panel's caption, with {sample}, {arc_length} (from the start, coordinate space), "
             "{event} (the event at that sample) and {distance:I:J} (of vertices I and J) filled in; \"\" for none"),
      flag(R, "filmstrip_overlay", "filmstrips (render --samples): the samples overlaid in one picture, earlier ones "
           "fading, instead of side by side", FIELD(s.render.filmstrip_overlay)),
      flag(R, "side_by_side", "animations: the projection plot beside the mechanism, a marker following it",
           FIELD(s.render.animation.side_by_side)),
      flag(R, "mark_events", "caption singular points and new contacts as they pass",
           FIELD(s.render.animation.mark_events)),
      // [render]: per system type.
      optionalColor("ball_color", "sphere packings: disks and spheres", FIELD(s.render.style.ball_color),
                    "steelblue, alpha 0.1 (2D) or 0.25 (3D)"),
      optionalColor("contact_color", "sphere packings: the contact graph", FIELD(s.render.style.contact_color),
                    "grey80 (2D) or grey50 (3D)"),
      number(R, "ball_outline", 0, 1000, "disk outline width, px of a 1000-pixel image",
             FIELD(s.render.style.ball_outline)),
      number(R, "contact_width", 0, 1000, "contact graph line width, px of a 1000-pixel image",
             FIELD(s.render.style.contact_width)),
      color("angle_color", "angular frameworks: the constrained angles' sectors", FIELD(s.render.style.angle_color)),
      custom(R, "simplex_colors", "[colour, ...]", "#CD0000, #228B22, #4169E1, #00A5A8, #DAA520, #8B3A9B",
             "volume hypergraphs: simplex i is filled (alpha 0.25) and outlined with colour i mod the list's length"),
      color("cap_color", "spherical disk packings: the caps' circles", FIELD(s.render.style.cap_color)),
      color("sphere_color", "spherical disk packings: the unit sphere", FIELD(s.render.style.sphere_color)),
      color("apex_color", "spherical disk packings: the cones' apices", FIELD(s.render.style.apex_color)),
      color("surface_color", "frameworks on surfaces: the surface (translucent)", FIELD(s.render.style.surface_color)),
      integer(R, "surface_samples", 4, 400, "frameworks on surfaces: grid cells per axis of the surface mesh",
              FIELD(s.render.style.surface_samples)),
      indices(custom(R, "fixed_simplex", "[i, j, k(, l)]", "the first simplex without pins",
                     "volume hypergraphs: every frame is moved by the equi-affine map taking this simplex to a "
                     "fixed one")),
      number(R, "target_stretch", 0, INFINITY, "volume hypergraphs: the reference simplex's first edge length",
             FIELD(s.render.animation.target_stretch), true, false, "target_stretch must be positive"),
      number(R, "tip_value", -INFINITY, INFINITY, "volume hypergraphs: the reference simplex's tip offset",
             FIELD(s.render.animation.tip_value)),
      // [projection]
      optionalSeed(P, "the random projection", FIELD(s.projection.seed), "[motion] seed"),
      custom(P, "flexes", "[[number, ...], ...]", "[motion] flex",
             "one path per list of coefficients (at most 64)"),
      flag(P, "both_directions", "also follow -flex, drawn as one curve through the start",
           FIELD(s.projection.both_directions)),
      flag(P, "flex_arrows", "the projected initial flexes as arrows", FIELD(s.projection.flex_arrows)),
      custom(P, "colors", "[colour, ...]", "gray35 for one path, a palette for more", "one per path"),
      number(P, "line_width", 0, 1000, "curve width, px of a 1000-pixel image", FIELD(s.projection.line_width)),
      number(P, "marker_size", 0, 1000, "start and singular-point markers, px of a 1000-pixel image",
             FIELD(s.projection.marker_size)),
      // [[output]]
      custom(O, "file", "string", "required",
             "a path inside the scene's folder (no absolute path, no ..; run --output-dir moves it); its extension gives the kind: .png/.svg/.pdf/.tex frame (.obj/.stl: a solid of it), .gif/.mp4 animation, .json/.csv path"),
      custom(O, "kind", "string", "from the extension", "frame, animation, path or projection"),
      custom(O, "sample", "integer", "0", "frame: which sample (0 is the start)", ">= 0"),
      custom(O, "samples", "[integer, ...]", "", "frame: a filmstrip of these samples (side by side, or overlaid with [render] filmstrip_overlay) instead of `sample`", "1 to 64 sample numbers"),
      custom(O, "flex", "boolean", "false", "frame: draw the flex arrows"),
  };
}

std::string fmt(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

std::string colorText(const render::Color& c) {
  char buf[16];
  auto byte = [](float x) { return static_cast<unsigned>(std::lround(x * 255)); };
  std::snprintf(buf, sizeof buf, "#%02X%02X%02X%02X", byte(c.r), byte(c.g), byte(c.b), byte(c.a));
  return buf;
}

}  // namespace

const std::vector<KeySpec>& sceneKeys() {
  static const std::vector<KeySpec> keys = makeKeys();
  return keys;
}

std::vector<std::string> keysOf(const std::string& table, const std::string& type) {
  std::vector<std::string> out;
  for (const KeySpec& k : sceneKeys()) {
    if (k.table != table) continue;
    if (table == "system" && !type.empty() && k.key != "type") {
      const bool catalog = type == "catalog";
      if (k.types.empty() ? catalog : (" " + k.types + " ").find(" " + type + " ") == std::string::npos) continue;
    }
    out.push_back(k.key);
  }
  return out;
}

std::vector<std::string> indexKeysOf(const std::string& table, const std::string& type) {
  std::vector<std::string> out;
  for (const std::string& key : keysOf(table, type))
    for (const KeySpec& k : sceneKeys())
      if (k.table == table && k.key == key && k.vertex_indices) out.push_back(key);
  return out;
}

std::string rangeText(const KeySpec& k) {
  if (k.kind == KeyKind::Seed || k.kind == KeyKind::OptionalSeed) return ">= 0";
  if (k.kind != KeyKind::Integer && k.kind != KeyKind::Number) return k.range_doc;
  const bool lo = std::isfinite(k.lo), hi = std::isfinite(k.hi);
  if (lo && hi && (k.open_lo || k.open_hi))
    return std::string(k.open_lo ? "(" : "[") + fmt(k.lo) + ", " + fmt(k.hi) + (k.open_hi ? ")" : "]");
  if (lo && hi) return fmt(k.lo) + " to " + fmt(k.hi);
  if (lo) return (k.open_lo ? "> " : ">= ") + fmt(k.lo);
  if (hi) return (k.open_hi ? "< " : "<= ") + fmt(k.hi);
  return "any";
}

std::string defaultText(const KeySpec& k) {
  Scene s;
  struct Visitor {
    Scene& s;
    const KeySpec& k;
    std::string operator()(std::monostate) const { return k.default_doc; }
    std::string operator()(int& (*f)(Scene&)) const { return std::to_string(f(s)); }
    std::string operator()(double& (*f)(Scene&)) const { return fmt(f(s)); }
    std::string operator()(bool& (*f)(Scene&)) const { return f(s) ? "true" : "false"; }
    std::string operator()(render::Color& (*f)(Scene&)) const { return "\"" + colorText(f(s)) + "\""; }
    std::string operator()(std::optional<render::Color>& (*f)(Scene&)) const {
      return f(s) ? "\"" + colorText(*f(s)) + "\"" : k.default_doc;
    }
    std::string operator()(std::uint64_t& (*f)(Scene&)) const { return std::to_string(f(s)); }
    std::string operator()(std::optional<std::uint64_t>& (*f)(Scene&)) const {
      return f(s) ? std::to_string(*f(s)) : k.default_doc;
    }
  };
  return std::visit(Visitor{s, k}, k.field);
}

std::string keyReferenceMarkdown() {
  static const std::vector<std::pair<std::string, std::string>> tables = {
      {"", "The top level"}, {"system", "[system]"}, {"motion", "[motion]"}, {"analysis", "[analysis]"},
      {"render", "[render]"}, {"projection", "[projection]"}, {"output", "[[output]]"}};
  auto cell = [](std::string t) {
    std::string out;
    for (char c : t) out += c == '|' ? std::string("\\|") : std::string(1, c);
    return out;
  };
  std::ostringstream o;
  for (const auto& [table, title] : tables) {
    o << "#### " << title << "\n\n";
    const bool sys = table == "system";
    o << (sys ? "| key | type | types that take it | default | what it is |\n|---|---|---|---|---|\n"
              : "| key | type | range | default | what it is |\n|---|---|---|---|---|\n");
    for (const KeySpec& k : sceneKeys()) {
      if (k.table != table) continue;
      const std::string third = sys ? (k.key == "type" ? "all" : k.types.empty() ? "all but catalog" : k.types)
                                    : rangeText(k);
      const std::string def = defaultText(k);
      o << "| `" << k.key << "` | " << cell(k.type) << " | " << cell(third.empty() ? "-" : third) << " | " << cell(def.empty() ? "-" : def)
        << " | " << cell(k.doc) << " |\n";
    }
    o << "\n";
  }
  return o.str();
}

// Levenshtein distance: the "did you mean" of unknown keys and fields.
int editDistance(const std::string& a, const std::string& b) {
  std::vector<int> prev(b.size() + 1), cur(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) prev[j] = static_cast<int>(j);
  for (size_t i = 1; i <= a.size(); ++i) {
    cur[0] = static_cast<int>(i);
    for (size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] != b[j - 1])});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

}  // namespace flexure::scenes
