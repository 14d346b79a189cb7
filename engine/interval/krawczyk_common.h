// What the certified tracks' two tests share (engine/interval/krawczyk.h): the constraints and
// their Jacobian enclosed over a box, boxes around points, the second derivative along a line.
// The dense Krawczyk test (krawczyk.cpp) and the sparse norm test for large systems
// (krawczyk_sparse.cpp) both stand on them.
#pragma once

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "engine/deformation_path.h"
#include "engine/evaluate_in.h"
#include "engine/interval/interval.h"
#include "engine/model.h"

namespace flexure::engine::certify::detail {

constexpr double kContraction = 7.0 / 8.0;
// The largest radius a certified sample gets, relative to the configuration's size.
constexpr double kMaxRelativeRadius = 1e-8;
const double kNaN = std::numeric_limits<double>::quiet_NaN();

using IVec = std::vector<Interval>;

// The constraints' enclosures over a box of free coordinates (pinned blocks at their points),
// with the term parameters from the model's start.
struct Enclosure {
  IVec F;
  std::vector<JacobianEntry<Interval>> J;
};
Enclosure enclose(const Model& model, const IVec& free);
// The constraints' enclosures alone (no Jacobian).
IVec encloseResiduals(const Model& model, const IVec& free);
// The constraints' enclosures and, in `slope`, those of F'(x) direction: one pass of a
// directional jet per term.
IVec encloseAlong(const Model& model, const IVec& free, const Vector& direction, IVec& slope);
// The Jacobian at x in double from the same formulas (m x N; no row weights, as the enclosures).
Matrix jacobianAt(const Model& model, const Vector& x);

// x + r [-1, 1] per coordinate (a point box when r = 0).
IVec pointBox(const Vector& x, double r = 0);

// The configuration's size: the largest extent of its vertices along an axis.
double configurationScale(const ConstraintSystem& sys, const Vector& x);

// Enclosures of d^T H_i d over a box for every equation i (H_i its Hessian): the second-order
// term of F along a line, through the terms' jets.
IVec secondDerivativeAlong(const Model& model, const IVec& free, const Vector& direction);

// The sparse test (systems beyond the dense test's size; one degree of freedom, pins fixing the
// trivial motions). A sample's radius in the slice x_j = x~_j, j the largest coordinate of
// `direction` (the path's direction there); NaN with `why` when not certified.
// `estimate`: the smallest eigenvalue of A^T A last seen (the shifts of the proof start there).
double certifySampleSparse(const Model& model, const Vector& x, const Vector& direction, std::string& why,
                           double* estimate = nullptr);
// A step: one smooth arc through the points the samples certify (radii ra, rb). `pieces` as in
// the dense test: the count to begin with, and the count that passed.
// `keep_going` (optional) is asked before each piece (a large system's step may take seconds).
bool certifyStepSparse(const Model& model, const Vector& a, const Vector& b, double ra, double rb, std::string& why,
                       int& pieces, double* estimate = nullptr, const std::function<bool()>* keep_going = nullptr);

// Quadratic systems of min_variables to max_variables free coordinates, one degree of freedom,
// pins fixing the trivial motions: one anchor per step (a factorization at the step's midpoint on the curve, with the
// tangent and the curvature there; krawczyk_sparse.cpp) certifies the step and the samples not
// yet certified, for the whole step at once. Fills `radii` (NaN: not certified) and `steps`;
// what it leaves is for certifySampleSparse and certifyStepSparse, which give the reasons.
// `stop` is asked before each step.
void certifyQuadraticPath(const DeformationPath& path, int min_variables, int max_variables,
                          std::vector<double>& radii, std::vector<char>& steps, double* estimate,
                          const std::function<bool()>& stop);

}  // namespace flexure::engine::certify::detail
