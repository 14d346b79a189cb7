// Sticky disk and sphere packings (paper appendix B.3, notes 3.6): balls of given radii in 2D or
// 3D; touching pairs keep touching (one squared-distance constraint per contact), and a pair
// that comes into contact during the motion sticks from then on: its gaps are inequalities with
// the Stick rule (engine/active_set.h), tracked piecewise (engine/piecewise_tracking.h).
#pragma once

#include <array>
#include <vector>

#include "engine/active_set.h"
#include "engine/model.h"

namespace flexure::engine {

class SpherePacking final : public Model, public Inequalities {
 public:
  using Contact = std::array<int, 2>;
  // points: d x n (d = 2 disks, d = 3 spheres); radii: one per point, > 0. A pair touches when
  // its gap |p_i - p_j| - r_i - r_j is within tolerance * (r_i + r_j) of 0; the start is then
  // corrected onto exact contact (moving it by at most about that much). `sticky` pairs are
  // contacts whatever their gap (earlier events). A pair closer than that is an overlap:
  // ModelError naming it. Messages number vertices from index_base. `contacts_at_start`: each
  // contact keeps the squared distance it has in `points`, computed in the arithmetic the
  // equations are evaluated in (SquaredDistanceTerm::atStart), not (r_i + r_j)^2 in double: for a
  // caller that has checked that every contact holds exactly (the exact mode, whose rationals
  // must satisfy the equations exactly); the start is then not corrected.
  SpherePacking(const Matrix& points, std::vector<double> radii, const std::vector<int>& pinned,
                double tolerance = 1e-6, int index_base = 1, const std::vector<Contact>& sticky = {},
                bool contacts_at_start = false);

  std::string typeName() const override { return "sphere_packing"; }
  std::optional<SymmetryGroup> symmetryGroup() const override;
  Geometry geometry() const override;
  // The gaps of the pairs (pair i < j: Id i * n + j), the contacts active: Stick.
  const Inequalities* inequalities() const override { return this; }

  const std::vector<Contact>& contacts() const { return contacts_; }
  const std::vector<double>& radii() const { return radii_; }
  double tolerance() const override { return tolerance_; }
  int indexBase() const { return index_base_; }
  const std::vector<int>& pinned() const { return pinned_; }
  bool isContact(int i, int j) const;
  // The smallest relative gap (|p_i - p_j| - r_i - r_j) / (r_i + r_j) over the pairs that are
  // not contacts (+infinity if there are none), and that pair.
  double smallestGap(const Matrix& positions, Contact* pair = nullptr) const;
  // "disks" or "spheres".
  const char* ballsName() const { return system().dimension() == 2 ? "disks" : "spheres"; }

  // Inequalities (Stick): the slack is smallestGap's relative gap; the rebuilt packing keeps the
  // contacts and adds the pairs touching within tolerance at `at`.
  Rule rule() const override { return Rule::Stick; }
  double smallestSlack(const Matrix& positions, Id* which = nullptr) const override;
  std::vector<Id> active() const override;
  bool isActive(Id i) const override;
  std::vector<int> vertices(Id i) const override;
  std::string name(Id i) const override;
  std::shared_ptr<const Model> withActive(const Matrix& at) const override;

 private:
  struct Built;
  explicit SpherePacking(Built&& b);
  std::vector<double> radii_;
  std::vector<Contact> contacts_;
  std::vector<long long> contact_keys_;  // i * n + j (i < j) of the contacts, sorted
  std::vector<int> pinned_;
  double tolerance_;
  int index_base_;
};

}  // namespace flexure::engine
