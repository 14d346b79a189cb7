// The rank decision does not depend on the order of the equations (edges, facets, contacts) or
// of the coordinates (vertices): every catalog scene's Jacobian at its start, with its rows and
// columns permuted at random, gets the same rank, dense or sparse.
#include <catch2/catch.hpp>

#include <algorithm>
#include <random>

#include <toml++/toml.h>

#include "engine/factorization.h"
#include "scenes/catalog.h"
#include "scenes/scene.h"
#include "../test_common.h"

using namespace flexure;

TEST_CASE("order: every catalog scene gets one rank in every order of its equations and coordinates",
          "[scenes][engine]") {
  std::mt19937 rng(3);
  int compared = 0;
  for (const scenes::CatalogEntry& e : scenes::catalog()) {
    INFO(e.name);
    const scenes::Scene scene = scenes::loadSceneFromString(e.text, "catalog:" + std::string(e.name));
    const engine::ConstraintSystem& sys = scene.model->system();
    const engine::SparseMatrix J = sys.jacobian(scene.model->startCoordinates());
    engine::FactorizationOptions o;
    o.rank_tolerance = scene.analysis.rank_tolerance;
    const int rank = engine::JacobianFactorization(J, o).rank();
    for (int trial = 0; trial < 3; ++trial) {
      const engine::SparseMatrix P = test::permuted(J, rng);
      CHECK(engine::JacobianFactorization(P, o).rank() == rank);
      // Sparse too, whatever the size.
      engine::FactorizationOptions sparse = o;
      sparse.dense_limit = 0;
      if (J.rows() > 0 && J.cols() > 0) CHECK(engine::JacobianFactorization(P, sparse).rank() == rank);
    }
    ++compared;
  }
  CHECK(compared >= 44);
}
