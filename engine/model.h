// A model is a domain object (a framework, later polytopes, packings, ...) turned into a
// constraint system, with its start configuration and its symmetry group. Every system type
// of the paper's appendix B derives from it.
#pragma once

#include <functional>
#include <memory>
#include <stdexcept>
#include <optional>
#include <string>

#include "engine/constraint_system.h"
#include "engine/geometry.h"

namespace flexure::engine {

class Inequalities;     // engine/active_set.h
class DeformationPath;  // engine/deformation_path.h
struct DrivenQuantity;  // engine/continuation.h

// Bad input found while building a model, pointing at the offending item of a scene key
// (e.g. key "facets", item 3: the fourth facet), so that a scene loader can show its position.
class ModelError : public std::invalid_argument {
 public:
  ModelError(std::string key, int item, const std::string& message)
      : std::invalid_argument(message), key(std::move(key)), item(item) {}
  std::string key;  // a [system] key
  int item;         // 0-based index into that key's array, or -1 for the key itself
};

// The symmetry groups that models share: their generators come from the functions below in
// double and from engine/exact/exact_generators.h in exact rationals, so one description serves
// both arithmetics.
struct SymmetryGroup {
  enum class Family { Euclidean, Similarity, EquiAffine, Moebius };
  Family family = Family::Euclidean;
  int num_points = 0;      // the first blocks: points
  int num_directions = 0;  // then directions (facet normals; Euclidean only): rotated, not translated
};

class Model {
 public:
  virtual ~Model() = default;
  virtual std::string typeName() const = 0;
  // Infinitesimal generators of the symmetry group acting on configurations, evaluated at
  // `positions` (d x numBlocks). Column j is the velocity of every block coordinate
  // (block-major, d per block) under generator j; pins are not taken into account here.
  // Default: the generators of symmetryGroup(), which a model without one must override.
  virtual Matrix symmetryGenerators(const Matrix& positions) const;
  // The model's symmetry group when it is one of the shared families; none (the default): the
  // model computes its generators itself (numerically), and the exact mode refuses it.
  virtual std::optional<SymmetryGroup> symmetryGroup() const { return std::nullopt; }
  // True when every active constraint is a polynomial of degree at most 2 (the terms' own
  // degree(): the 3D angle, the inversive distance and a surface that is not a quadric are not),
  // so that the second-order theory of the paper (section 2.1: stresses, prestress stability,
  // second-order rigidity) applies.
  bool quadraticConstraints() const;
  // The drawable structure (bars, facets, pins); positions come from system().positions(x).
  virtual Geometry geometry() const;
  // Numbers that the symmetry group keeps (positions: d x numBlocks): two configurations with
  // different invariants are not congruent. Default: the distances between all pairs of
  // points, kept by Euclidean motions and every subgroup of them.
  virtual Vector congruenceInvariants(const Matrix& positions) const;
  // The inequalities that the equations do not hold, with the rule a motion keeps them by
  // (engine/active_set.h: a sticky packing's contacts, origami's mountain/valley assignment, the
  // orientation of 2D angles); null (the default): none. Owned by the model.
  virtual const Inequalities* inequalities() const { return nullptr; }
  // A first sample about `distance` from x that the model's own data single out when no flex
  // is given (origami at its flat state: the fold its mountain/valley assignment asks for),
  // given the nontrivial flexes at x (columns); none by default: the auto flex decides.
  virtual std::optional<Vector> preferredFirstSample(const Vector& x, double distance, const Matrix& flexes) const {
    (void)x, (void)distance, (void)flexes;
    return std::nullopt;
  }

  // A quantity of the model's own to drive from x (origami: crease `item`'s fold angle to
  // `target`, or with item -1 the fold percentage to `target`), given the nontrivial flexes at x
  // (columns) and the first step's length; none by default.
  virtual std::optional<DrivenQuantity> drivenQuantity(int item, double target, const Vector& x, const Matrix& flexes,
                                                       double step) const;
  // Marks the model's own events along `path` (origami: two faces beginning to pass through each
  // other), replacing those it marked before, in order with the path's other events (vertices
  // and faces numbered from index_base in their texts); none by default.
  virtual void markEvents(DeformationPath& path, int index_base) const {
    (void)path, (void)index_base;
  }

  // The rigid part (a body, a panel) that keeps the distance between vertices a and b, or -1
  // (a contraction cannot change that distance); and how a message names part k.
  virtual int rigidPartHolding(int a, int b) const {
    (void)a, (void)b;
    return -1;
  }
  virtual std::string rigidPartName(int k) const { return "body " + std::to_string(k + 1); }
  // The faces an Intersection event may name (origami's), 0 for a model without faces.
  virtual int numFaces() const { return 0; }
  // Quantities of a configuration that a path writes with every sample beside the coordinates,
  // one per item (origami: each crease's fold angle in degrees): their JSON key and CSV column
  // prefix (empty key: none), and their values at `positions` (d x numBlocks).
  struct SampleQuantities {
    std::string json_key, csv_prefix;
  };
  virtual SampleQuantities sampleQuantities() const { return {}; }
  virtual std::vector<double> sampleQuantityValues(const Matrix& positions) const {
    (void)positions;
    return {};
  }

  const ConstraintSystem& system() const { return system_; }
  const Matrix& startPositions() const { return start_; }
  Vector startCoordinates() const { return system_.freeCoordinates(start_); }

 protected:
  Model(ConstraintSystem system, Matrix start)
      : system_(std::move(system)), start_(std::move(start)) {}

 private:
  ConstraintSystem system_;
  Matrix start_;
};

// The diagonal of the points' (columns') bounding box: the length scale of tolerances and
// messages (0 for no points).
double extentOf(const Matrix& points);
// Distances between pairs of the points (columns): all pairs up to 400 points, else each point
// with the next 64.
Vector pairwiseDistances(const Matrix& points);
// A number in a message: 3 significant digits.
std::string shortNumber(double v);

// Infinitesimal generators of the symmetry groups, evaluated at `positions` (d x blocks), in
// the layout of Model::symmetryGenerators. Points are the first `num_points` blocks; blocks
// from `num_points` to `num_points + num_directions` are directions (facet normals), which
// rotate with the points but do not translate; other blocks get zero. Each column is
// normalised to unit length (zero columns stay zero).

// Euclidean motions: translations, then rotations about the points' centroid.
Matrix euclideanGenerators(const Matrix& positions, int num_points, int num_directions = 0);
// Similarities: the Euclidean motions and the scaling about the centroid (angles).
Matrix similarityGenerators(const Matrix& positions, int num_points);
// Equi-affine maps x -> A x + b with det A = 1: translations and the traceless linear maps
// about the centroid, d^2 - 1 + d of them (volumes).
Matrix equiAffineGenerators(const Matrix& positions, int num_points);
// Moebius transformations of the unit sphere acting on caps a (the plane a . y = 1), i.e. the
// Lorentz group on (a, 1) up to scale: rotations a' = W a and boosts a' = e_k - a_k a (6).
Matrix moebiusGenerators(const Matrix& positions, int num_points);

// The groups acting by finite maps (certified steps move a sample into a gauge slice by one): an
// element is a (d + 1) x (d + 1) matrix G on homogeneous coordinates, a point p going to
// pi(G (p, 1)) with pi dividing by the last coordinate (1 for the affine families; the Lorentz
// group on the caps' points for Moebius, d = 3) and a direction n to G's top-left block times n.
// The Lie algebra: matrices X whose velocities (groupVelocities) span the generators above.
std::vector<Matrix> lieAlgebra(const SymmetryGroup& group, int d);
// `positions` (d x blocks) moved by G (blocks past the points and directions unchanged).
Matrix applyGroupElement(const SymmetryGroup& group, const Matrix& G, const Matrix& positions);
// The velocity of every block under exp(t X) at t = 0 (d x blocks).
Matrix groupVelocities(const SymmetryGroup& group, const Matrix& X, const Matrix& positions);

}  // namespace flexure::engine
