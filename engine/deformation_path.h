// The deformation path: what every way of tracking produces (the smooth tracker, edge
// contraction, sticky packings), as one engine result. Samples in free coordinates, typed
// events, a summary of how tracking went, and the model in force along each stretch of the
// path: a sticky packing gains a contact, and so a new model, at every contact event.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "engine/geometry.h"
#include "engine/model.h"

namespace flexure::engine {

enum class TrackStatus { Success, StoppedEarly, StoppedByCallback, LeftAdmissibleSet };
// The status as the path JSON writes it: "success" or "stopped_early" (the three ways of
// stopping early are told apart by the reason).
const char* toString(TrackStatus s);

enum class EventKind {
  Singularity,  // a singular point passed (or where the path starts against the flex)
  Contact,      // two balls of a sticky packing came into contact; `vertices` is the pair
  Intersection, // two faces of an origami sheet began to pass through each other; `faces`
};
const char* toString(EventKind k);  // "singularity", "contact", "intersection"

// The branches that meet at a sample: the tangent cone of the constraint set there (modulo
// trivial motions, engine::tangentCone), one unit direction per half-branch.
struct BranchDirections {
  bool computed = false;           // false: not looked for (too large, piecewise): `note` says why
  int flexes = 0;                  // nontrivial flexes there, at the cone's loose tolerance
  int stresses = 0;
  std::string note;                // how the directions were found
  // Where they were computed: the sample, or at a singular event the singular point the path
  // passed next to it (engine::locateSingularPoint), from which a branch leaves.
  Vector point;
  std::vector<Vector> directions;  // unit, free coordinates at `point`
  // Per direction: "path" (the path leaves the sample so), "back" (the way it came), "other".
  std::vector<std::string> kinds;
};

struct TrackEvent {
  int sample = 0;             // index into the samples
  EventKind kind = EventKind::Singularity;
  std::string detail;         // how it was detected or passed
  std::vector<int> vertices;  // the vertices concerned (0-based), e.g. the pair of a contact
  std::vector<int> faces;     // the faces concerned (0-based): an intersection's pair
  // A singularity's branches (pipeline::addBranchDirections), where they were looked for.
  std::optional<BranchDirections> branches;
};

struct TrackSummary {
  TrackStatus status = TrackStatus::StoppedEarly;
  std::string reason = "the path was not tracked";
  int steps_requested = 0;
  int steps_done = 0;
  int rejected_steps = 0;    // predictor-corrector attempts thrown away (no convergence, jumps)
  double max_residual = 0;   // max over samples of ||F||_inf
  std::uint64_t seed = 0;
  std::string briefReport() const;
};

// What interval arithmetic proves about a path (engine/interval/krawczyk.h; track --certify):
// per sample a radius r (exactly one point of the real solution set, in the slice across the
// tangent and the trivial motions, lies within r of the sample, max norm over the free
// coordinates) or NaN; per step whether both samples lie on one smooth arc.
struct PathCertificate {
  std::vector<double> radii;
  std::vector<char> steps;
  std::string reason;  // one line: what was certified, or where and why not (every failure's reason)
  // The same for a person (the command line's report): the counts and the first few failures'
  // reasons, bounded however many there are; empty: `reason` is short enough.
  std::string summary;
  // Proved flexible: a chain of certified samples and steps from the start reaches a point that
  // no trivial motion of the start reaches (a distance between two vertices changed by more than
  // the radii allow). Unset: not proved this way.
  std::optional<bool> flexible;
  bool certified() const;
};

class DeformationPath {
 public:
  std::vector<Vector> samples;  // free coordinates; samples[0] is the start
  std::vector<TrackEvent> events;
  TrackSummary summary;
  Vector outside;  // LeftAdmissibleSet: the corrected sample that was not admissible

  // How the direction was chosen, as the caller described it (recorded with the path): the
  // coefficients in the start's canonical nontrivial-flex basis and a note ("given",
  // "auto: ...", "edge contraction of ...").
  std::vector<double> flex;
  std::string flex_choice;

  // The model in force from sample `first_sample` on. The first segment is the model the path
  // started on, which the path does not own: keep it alive while the path is used.
  struct Segment {
    int first_sample = 0;
    std::shared_ptr<const Model> model;
  };
  std::vector<Segment> segments;
  // track --certify: the certificate (unset: not asked for).
  std::optional<PathCertificate> certificate;

  // The model whose constraints hold at sample k (the start's model without segments).
  const Model& modelAt(int k) const;
  // What is drawn at sample k: the start model's geometry plus the bars of the contacts made
  // up to k, in the order they were made.
  Geometry geometryAt(int k) const;
  // The singular points passed (sample indices, ascending).
  std::vector<int> singularSamples() const;
  // A path that starts on `model` (one segment, not owned).
  void startOn(const Model& model);
};

// Called after every accepted sample with (steps done, steps requested); return false to stop.
using StepCallback = std::function<bool(int, int)>;

}  // namespace flexure::engine
