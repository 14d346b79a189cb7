// A model is a domain object (a framework, later polytopes, packings, ...) turned into a
// constraint system, with its start configuration and its symmetry group. Every system type
// of the paper's appendix B derives from it.
#pragma once

#include <memory>
#include <string>

#include "engine/constraint_system.h"
#include "engine/geometry.h"

namespace flexure::engine {

class Model {
 public:
  virtual ~Model() = default;
  virtual std::string typeName() const = 0;
  // Infinitesimal generators of the symmetry group acting on configurations, evaluated at
  // `positions` (d x numBlocks). Column j is the velocity of every block coordinate
  // (block-major, d per block) under generator j; pins are not taken into account here.
  virtual Matrix symmetryGenerators(const Matrix& positions) const = 0;
  // True when every constraint is a quadratic polynomial, so that the second-order theory of
  // the paper (section 2.1: stresses, prestress stability, second-order rigidity) applies.
  virtual bool quadraticConstraints() const { return true; }
  // The drawable structure (bars, facets, pins); positions come from system().positions(x).
  virtual Geometry geometry() const;

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

// Velocity fields of the Euclidean motions (translations, then rotations about the centroid of
// the first `num_points` blocks) on the first `num_points` blocks; other blocks get zero.
// Each column is normalised to unit length (zero columns stay zero).
Matrix euclideanGenerators(const Matrix& positions, int num_points);

}  // namespace flexure::engine
