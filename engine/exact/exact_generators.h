// The shared symmetry groups' infinitesimal generators (engine/model.h: SymmetryGroup) in
// exact rationals, in the layout of Model::symmetryGenerators: column j is the velocity of
// every block coordinate (block-major, d per block) under generator j. Unnormalised and about
// the origin rather than the centroid: the same span as the double generators (the groups hold
// the translations, which absorb the difference), which is all the exact mode uses.
#pragma once

#include "engine/exact/rational.h"
#include "engine/model.h"

namespace flexure::engine::exact {

// positions: d x numBlocks.
RationalMatrix symmetryGenerators(const SymmetryGroup& group, const RationalMatrix& positions);

}  // namespace flexure::engine::exact
