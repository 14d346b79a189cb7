// Angular frameworks (paper appendix B): angles (i, j, k) at j kept. A Model: its constraint
// terms, its symmetry group (the similarities) and what to draw.
// Constructors throw ModelError pointing at the offending item; messages number vertices
// from `index_base`.
#pragma once

#include <array>
#include <vector>

#include "engine/active_set.h"
#include "engine/model.h"

namespace flexure::engine {

// Angles (i, j, k) at j (AngleTerm). Symmetries: similarities.
class AngularFramework final : public Model, public Inequalities {
 public:
  using Angle = std::array<int, 3>;
  AngularFramework(const Matrix& points, std::vector<Angle> angles, const std::vector<int>& pinned,
                   int index_base = 1);
  std::string typeName() const override { return "angular_framework"; }
  std::optional<SymmetryGroup> symmetryGroup() const override;
  // The pairwise distances divided by their mean (similarities keep ratios).
  Vector congruenceInvariants(const Matrix& positions) const override;
  Geometry geometry() const override;
  // 2D: the first angle at x turned by more than 90 degrees from its start (-1: none). The 2D
  // equation |u||w| sin(theta0 - theta) = 0 also holds at theta0 + 180 degrees, reached when a
  // vertex passes through the angle's apex (an arm of length zero): a motion of the angles ends
  // before that.
  int turnedAngle(const Vector& x) const;
  // In 2D, the angles' orientations (no angle turned by 90 degrees or more from its start): Stop.
  const Inequalities* inequalities() const override { return system().dimension() == 2 ? this : nullptr; }
  Rule rule() const override { return Rule::Stop; }
  std::function<bool(const Vector&)> admissibleFrom(const Vector& start) const override;
  std::string outsideReason(const Vector& y, int index_base) const override;

 private:
  std::vector<Angle> angles_;
  std::vector<std::array<double, 2>> start_cos_sin_;  // per angle
};

}  // namespace flexure::engine
