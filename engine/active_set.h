// Inequalities g_i(x) >= 0 that a model's equations do not hold, and the rule by which a motion
// keeps them: one active set. A model that has some returns them from Model::inequalities()
// (null: none), and implements them in its own room (engine/systems/<type>.cpp); the engine
// asks only this interface, never the concrete model.
//
// A new inequality rule goes here: a Rule value, the members it needs, and its case in
// engine::track (engine/track.cpp).
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "engine/model.h"

namespace flexure::engine {

class Inequalities {
 public:
  enum class Rule {
    // A tight inequality joins the equations and stays there (a contact of a sticky packing):
    // the motion is tracked piecewise (engine/piecewise_tracking.h), one model per segment.
    Stick,
    // The path ends before a sample that breaks one (origami's mountain/valley assignment, the
    // orientation of 2D angles): admissibleFrom and outsideReason.
    Stop,
    // Declared for the future: a tight inequality held as an equation leaves the equations where
    // the motion would break it the other way (a tensegrity cable going slack where its stress
    // would change sign). No model implements it yet; engine::track refuses it
    // (std::logic_error) rather than ignoring it.
    Release,
  };
  // An inequality of the set, numbered by the model (a packing: pair i < j is i * n + j).
  using Id = long long;

  virtual ~Inequalities() = default;
  virtual Rule rule() const = 0;

  // ---- Stop
  // The test a motion from `start` keeps (true: the sample keeps every inequality), or empty
  // where none applies from there (the default).
  virtual std::function<bool(const Vector&)> admissibleFrom(const Vector& start) const;
  // What a point outside the set would break, for the path's reason (vertices numbered from
  // index_base); empty where nothing is (the default).
  virtual std::string outsideReason(const Vector& y, int index_base) const;

  // ---- Stick (the defaults throw std::logic_error: a set of another rule has none of these)
  // The relative slack within which an inequality is tight; a sample whose smallest slack is
  // below -tolerance() is outside.
  virtual double tolerance() const;
  // The smallest slack at `positions` (d x blocks) over the inequalities that are not active
  // (+infinity if there are none), and which one (`which`, when given).
  virtual double smallestSlack(const Matrix& positions, Id* which = nullptr) const;
  // The active inequalities (equations of the model), in the model's order.
  virtual std::vector<Id> active() const;
  virtual bool isActive(Id i) const;
  // Inequality i's vertices (an event's `vertices`) and its name in messages ("disks 1 and 2",
  // numbered from the model's index base).
  virtual std::vector<int> vertices(Id i) const;
  virtual std::string name(Id i) const;
  // The model rebuilt at `at` (d x blocks): the active inequalities stay active, and those tight
  // there (within tolerance) become active. Throws (ModelError, ...) when it cannot be built.
  virtual std::shared_ptr<const Model> withActive(const Matrix& at) const;
};

// True when the motion of `model` is tracked piecewise: its active set changes along the path
// (a Stick or Release set), so that one constraint set does not hold along the whole path.
bool piecewise(const Model& model);

}  // namespace flexure::engine
