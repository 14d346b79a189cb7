// Rigid origami: a sheet of planar panels joined by creases. The panels are rigid bodies (the
// faces, merged across flat and join creases), each held as BodyFramework holds a body whatever
// its shape, and the creases are hinges: neighbouring panels share the crease's two vertices.
// Fold angles follow the FOLD convention: radians in [-pi, pi], positive for a valley (the two
// faces turn towards the side their counterclockwise order faces), negative for a mountain.
#pragma once

#include <array>
#include <optional>
#include <vector>

#include "engine/active_set.h"
#include "engine/continuation.h"
#include "engine/systems/body_framework.h"

namespace flexure::engine {

struct Crease {
  int a = 0, b = 0;      // the edge's vertices
  char assignment = 'U'; // B boundary, M mountain, V valley, F flat, U unassigned, J join
  int left = -1;         // the face whose counterclockwise order runs a -> b (-1: none)
  int right = -1;        // the face running b -> a (-1: none)
};

class Origami final : public BodyFramework, public Inequalities {
 public:
  // `points`: 3 x n (a crease pattern has z = 0). `faces`: counterclockwise vertex cycles.
  // `edges` with their assignments; the faces on either side are found here. Throws ModelError
  // ("faces", i) or ("edges", i) naming the face or edge at fault.
  Origami(const Matrix& points, std::vector<std::vector<int>> faces, std::vector<Crease> edges,
          const std::vector<int>& pinned, int index_base = 1);
  const std::vector<std::vector<int>>& faces() const { return faces_; }
  const std::vector<Crease>& edges() const { return edges_; }
  // The panel (body) of each face.
  const std::vector<int>& panelOfFace() const { return panel_of_face_; }
  // Every edge's fold angle at `positions` (3 x n), radians; 0 for edges with fewer than two
  // faces.
  std::vector<double> foldAngles(const Matrix& positions) const;
  Geometry geometry() const override;
  std::string rigidPartName(int) const override { return "a panel"; }
  int numFaces() const override { return static_cast<int>(faces_.size()); }
  // Every edge's fold angle in degrees, as "fold_angles" in a path's JSON and "fold1, ..." in
  // its CSV.
  SampleQuantities sampleQuantities() const override { return {"fold_angles", "fold"}; }
  std::vector<double> sampleQuantityValues(const Matrix& positions) const override;
  // The first mountain or valley crease (between two faces) folded the other way at x, beyond
  // `tolerance` radians (fully folded, +-180 degrees, counts either way); -1 when every one keeps
  // its assignment.
  int creaseAgainstAssignment(const Vector& x, double tolerance = 1e-7) const;
  // At a flat state (every mountain and valley crease unfolded), the first point of the fold
  // the mountain/valley assignment asks for, `distance` from x (free coordinates): along the
  // combination of `flexes` (nontrivial infinitesimal flexes at x, columns) whose fold rates
  // best match the assignment's signs, corrected onto the constraints on the sphere of radius
  // `distance` about x (so the corrector cannot fall back to the flat state). None away from a
  // flat state, without M/V creases, or when the correction fails.
  std::optional<Vector> assignedFoldPoint(const Vector& x, double distance, const Matrix& flexes) const;
  // The direction of that fold: the combination of `flexes` (unit length), or none. With
  // `held` creases (their rates asked to be 0) and a `driven` crease (its rate asked to have the
  // sign `driven_sign`, whatever its assignment): the start of a driven fold.
  std::optional<Vector> assignedFoldDirection(const Vector& x, const Matrix& flexes, const std::vector<int>& held = {},
                                              int driven = -1, double driven_sign = 0) const;
  // For driving crease e from x: the other creases (between two panels) that stay put while e
  // folds with the least change of the others (their rates on the first-order motions that fold
  // e and the others least are 0). x should be folded: at a flat state first order allows more
  // than the sheet can do.
  std::vector<int> stillCreases(const Vector& x, int e) const;

  // The fold angle of crease e (between two faces) at x, free coordinates: the dihedral angle of
  // four points, the crease's ends and, on either side, the face's vertex farthest from the
  // crease at the start (on the constraints, the angle foldAngles gives), and its gradient.
  double foldAngle(const Vector& x, int e) const;
  Vector foldAngleGradient(const Vector& x, int e) const;
  // The gradients of several creases' angles at x, one row each.
  Matrix foldAngleGradients(const Vector& x, const std::vector<int>& creases) const;
  // A crease's angle, or the fold percentage of the whole sheet, as a quantity to drive
  // (engine/continuation.h).
  // - The crease's angle is taken in (near - pi, near + pi], continuous through +-180 degrees
  //   (near: halfway between the start's angle and the target); the `held` creases
  //   (stillCreases) keep their start angles.
  // - The fold percentage is 100 sum_i s_i rho_i / (pi m) over the m mountain and valley
  //   creases, s_i = +1 valley and -1 mountain (each rho_i taken in (s_i pi / 2 - pi,
  //   s_i pi / 2 + pi]): 100 when every one is fully folded (+-180 degrees) and 0 flat. Each step
  //   folds every crease toward its full fold at once: the creases' rates as close to
  //   proportional to their targets (+-pi; 0 for the unassigned) as the sheet allows.
  // Names use the vertex numbering from index_base. Throws std::invalid_argument for a crease
  // without two faces, or a percentage of a sheet without mountains or valleys.
  DrivenQuantity creaseAngleQuantity(int e, double near = 0, std::vector<int> held = {}) const;
  DrivenQuantity foldPercentQuantity() const;
  // A start that keeps its mountain/valley assignment keeps it along the motion: the motion
  // ends where a crease would turn the other way (the sheet fully folded, or flat again): Stop.
  const Inequalities* inequalities() const override { return this; }
  Rule rule() const override { return Rule::Stop; }
  std::function<bool(const Vector&)> admissibleFrom(const Vector& start) const override;
  std::string outsideReason(const Vector& y, int index_base) const override;
  std::optional<Vector> preferredFirstSample(const Vector& x, double distance, const Matrix& flexes) const override {
    return assignedFoldPoint(x, distance, flexes);
  }
  // Crease `item`'s angle to `target` (radians, + valley; the other creases held as stillCreases
  // finds them from one step along the assigned fold), or with item -1 the fold percentage to
  // `target`; from a flat state the first step folds the way the assignment asks.
  std::optional<DrivenQuantity> drivenQuantity(int item, double target, const Vector& x, const Matrix& flexes,
                                               double step) const override;
  // An Intersection event at every sample where two faces begin to pass through each other (the
  // first sample of each pair's crossing: crossingFaces), replacing the path's earlier ones.
  void markEvents(DeformationPath& path, int index_base) const override;

  // The pairs of faces (ascending, 0-based) that pass through each other at `positions` (3 x n):
  // faces of different panels with no vertex in common that cut through each other along a
  // segment longer than 1e-9 of the sheet's size, each with corners strictly on both sides of the
  // other. Faces that only touch, and layers that lie on each other as in a flat-folded state,
  // do not count: the sheet has no thickness.
  std::vector<std::array<int, 2>> crossingFaces(const Matrix& positions) const;

  struct Panels;  // the faces grouped into panels (origami.cpp)

 private:
  Origami(const Matrix& points, Panels&& p, const std::vector<int>& pinned, int base);
  std::vector<std::vector<int>> faces_;
  std::vector<Crease> edges_;
  std::vector<int> panel_of_face_;
  // A crease's four points at vertex positions p (3 x n): the hinge and its vertices c, a, b, d.
  struct HingePoints {
    std::array<Eigen::Vector3d, 4> points;  // a, b, c, d
    std::array<int, 4> vertices;            // c, a, b, d: the order of hingeGradient
  };
  HingePoints hingePoints(const Matrix& p, int e) const;
  double foldAngleAt(const Matrix& p, int e) const;
  // add(variable, value) for each entry of crease e's angle gradient at positions p.
  template <class Add>
  void addFoldAngleGradient(const Matrix& p, int e, Add add) const;
  // q.rates: the hinges' angles (rows), to keep in these proportions (one per hinge).
  void setRates(DrivenQuantity& q, const std::vector<double>& proportions) const;
  std::vector<std::array<int, 2>> wings_;  // per crease: the left and right face's far vertex (-1: none)
  std::vector<int> hinges_;                // the creases between two panels: the ones that fold
  int base_ = 1;
};

// The unit normal of a planar polygon from its vertices' order (Newell's method): counter-
// clockwise seen from the side it points to.
Eigen::Vector3d newellNormal(const Matrix& positions, const std::vector<int>& polygon);

}  // namespace flexure::engine
