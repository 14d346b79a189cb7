// Every constraint term's Jacobian and exact second derivative against finite differences, in
// every dimension the term is used in. The list of terms below is checked against the classes
// that engine/terms.h declares, so that a new term cannot be left out.
#include <catch2/catch.hpp>

#include <fstream>
#include <functional>
#include <regex>
#include <set>
#include <sstream>

#include "engine/terms.h"
#include "../test_common.h"

using namespace flexure;
using engine::ConstraintTerm;
using engine::Matrix;
using engine::Vector;

namespace {

// A quadric with exact derivatives: x^2 + 2 y^2 - z^2 + x y - 1.
class Quadric final : public engine::ScalarField {
 public:
  double value(const double* x) const override {
    return x[0] * x[0] + 2 * x[1] * x[1] - x[2] * x[2] + x[0] * x[1] - 1;
  }
  void evaluate(const double* x, double* f, double* g, double* h) const override {
    if (f) *f = value(x);
    if (g) g[0] = 2 * x[0] + x[1], g[1] = 4 * x[1] + x[0], g[2] = -2 * x[2];
    if (h) {
      const double H[9] = {2, 1, 0, 1, 4, 0, 0, 0, -2};
      std::copy(H, H + 9, h);
    }
  }
  std::string text() const override { return "x^2 + 2*y^2 - z^2 + x*y - 1"; }
};

struct TermCase {
  std::string name;          // the class in engine/terms.h
  std::vector<int> dimensions;
  int blocks;                // how many blocks the term takes (d + 1 for a simplex: -1)
  std::function<std::unique_ptr<ConstraintTerm>(int d)> make;
};

const std::vector<TermCase>& termCases() {
  static const std::vector<TermCase> cases = {
      {"SquaredDistanceTerm", {2, 3}, 2,
       [](int) { return std::make_unique<engine::SquaredDistanceTerm>(0, 1, 2.5); }},
      {"FacetPlaneTerm", {2, 3}, 3,
       [](int) { return std::make_unique<engine::FacetPlaneTerm>(0, 1, 2, 0, 1.7); }},
      {"UnitNormTerm", {2, 3}, 1, [](int) { return std::make_unique<engine::UnitNormTerm>(0, 0, 1.3); }},
      {"SimplexVolumeTerm", {2, 3}, -1,
       [](int d) {
         std::vector<int> blocks(static_cast<size_t>(d) + 1);
         for (int i = 0; i <= d; ++i) blocks[static_cast<size_t>(i)] = i;
         return std::make_unique<engine::SimplexVolumeTerm>(blocks, 0.3, 1.2, 0.7);
       }},
      {"AffineCombinationTerm", {2, 3}, 4,
       [](int d) { return std::make_unique<engine::AffineCombinationTerm>(d, std::vector<int>{0, 1, 2, 3}, std::vector<double>{0.3, 1.1, -0.4}, 1.7, "body 1"); }},
      {"FramePointTerm", {2, 3}, 3,
       [](int d) {
         return std::make_unique<engine::FramePointTerm>(d, std::vector<int>{0, 1, 2},
                                                         std::array<double, 3>{0.4, d == 2 ? -0.7 : 0.0, 0.0}, 1.3);
       }},
      {"FramePointTerm", {2, 3}, 4,
       [](int d) {
         return std::make_unique<engine::FramePointTerm>(d, std::vector<int>{0, 1, 2, 3},
                                                         std::array<double, 3>{0.4, -0.7, 0.9}, 1.3);
       }},
      {"AngleTerm", {2, 3}, 3,
       [](int) { return std::make_unique<engine::AngleTerm>(0, 1, 2, std::cos(1.1), std::sin(1.1), 0.8); }},
      {"InversiveDistanceTerm", {3}, 2, [](int) { return std::make_unique<engine::InversiveDistanceTerm>(0, 1, 0.4); }},
      {"SurfaceTerm", {3}, 1,
       [](int) { return std::make_unique<engine::SurfaceTerm>(0, std::make_shared<Quadric>(), 1.3, 0.6); }},
  };
  return cases;
}

}  // namespace

TEST_CASE("terms: every term's derivatives match finite differences in 2D and 3D", "[engine]") {
  std::mt19937 rng(2026);
  int checked = 0;
  for (const TermCase& c : termCases())
    for (int d : c.dimensions) {
      const int blocks = c.blocks < 0 ? d + 1 : c.blocks;
      engine::ConstraintSystem sys(d, blocks, blocks);
      sys.addTerm(c.make(d));
      Matrix p(d, blocks);
      for (int b = 0; b < blocks; ++b) p.col(b) = test::randomVector(rng, d, 1.0) + Vector::Constant(d, 1.5);
      sys.finalize(p);
      for (int trial = 0; trial < 5; ++trial) {
        // Points spread around (1.5, 1.5, 1.5): away from the origin, where caps and angles
        // are singular.
        Vector x = sys.freeCoordinates(p) + test::randomVector(rng, sys.numVariables(), 0.3);
        INFO(c.name << " in " << d << "D, trial " << trial);
        test::requireJacobianMatchesFiniteDifferences(sys, x);
        test::requireSecondDerivativeMatchesFiniteDifferences(
            sys, x, test::randomVector(rng, sys.numVariables()), test::randomVector(rng, sys.numVariables()));
        ++checked;
      }
    }
  CHECK(checked == 5 * 18);
}

TEST_CASE("terms: the finite-difference list names every term engine/terms.h declares", "[engine]") {
  const std::string source = test::readProjectFile(FLEXURE_SOURCE_DIR, "engine/terms.h");
  const std::regex declaration(R"(class\s+(\w+)\s+(?:final\s+)?:\s+public\s+ConstraintTerm)");
  std::set<std::string> declared, listed;
  for (std::sregex_iterator it(source.begin(), source.end(), declaration), end; it != end; ++it)
    declared.insert((*it)[1]);
  for (const TermCase& c : termCases()) listed.insert(c.name);
  CHECK(declared.size() >= 8);
  CHECK(declared == listed);
}
