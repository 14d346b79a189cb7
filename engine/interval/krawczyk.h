// Certified tracks (issue 44, SPEC section 5: track --certify): the Krawczyk test in interval
// arithmetic (engine/interval/interval.h) on the term formulas (engine/evaluate_in.h).
//
// A sample x~: the square system G(x) = [F(x); Z^T (x - x~)], F the constraints and Z an
// orthonormal basis of ker F'(x~) (the tangent and the trivial motions: slices across them).
// With A ~ G'(x~)^-1 and the box x~ + r [-1, 1]^N, if every entry of
//   K = -A G(x~) / r + (I - A G'(x~ + r [-1, 1]^N)) [-1, 1]^N
// lies in [-7/8, 7/8], the box holds exactly one zero of G (Krawczyk, Moore): one point of the
// real solution set in that slice, within r (max norm) of the sample. A sample is certified
// only as accurate: r at most 1e-8 of the configuration's size.
// A step: with c the midpoint of two samples, t the unit chord, W an orthonormal basis of its
// complement, x = c + s t + W y; if the test holds on the y-box for all s in [-h, h] at once, the
// solution set in the slab is the graph of one smooth function y(s): one arc, which holds the
// points the two samples certify. Steps are certified where the path is a curve modulo its
// trivial motions and no constraint is redundant: pins fix the trivial motions, or (an unpinned
// system of the Euclidean group) a gauge slice does: both samples are moved by rigid motions
// onto their midpoint p (Kabsch), which puts them in the slice T(p)^T (x - p) = 0, and the
// test above runs in that slice (its g rows join the square system).
#pragma once

#include <functional>
#include <string>

#include "engine/deformation_path.h"

namespace flexure::engine::certify {

struct PathCertifyOptions {
  // Up to this many free coordinates the dense Krawczyk test; beyond, the sparse norm test
  // (engine/interval/krawczyk_sparse.cpp: pins fixing the trivial motions, one degree of freedom).
  int dense_variables = 300;
  // Quadratic systems of at least this many free coordinates: one anchor per step (a sparse
  // factorization at the step's midpoint on the curve, the tangent and the curvature there)
  // certifies the step and its samples at once (krawczyk_sparse.cpp); what it leaves goes to the
  // dense or the sparse test. Below it the dense test is faster (the double Watt's 16
  // coordinates); at 196 (a ladder of 49 cells) the anchors take 1 % of its time.
  int anchored_variables = 64;
  // Off: the dense and sparse tests alone (the tests compare both).
  bool quadratic_anchors = true;
  // Larger systems are not certified, with the reason.
  int max_variables = 2000000;
  // Asked before each sample and step; false stops the certificate there (the rest is not
  // certified, "stopped on request"). Unset: never stops.
  std::function<bool()> keep_going;
};

// The certificate of every sample and step of `path` (what the path JSON's "certificate" holds).
PathCertificate certifyPath(const DeformationPath& path, const PathCertifyOptions& options = {});

}  // namespace flexure::engine::certify
