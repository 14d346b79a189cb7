#include <catch2/catch.hpp>
#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "engine/rigidity.h"
#include "engine/second_order.h"
#include "engine/systems/framework.h"
#include "../test_common.h"

using namespace flexure;
using engine::BlockedFlexResult;
using engine::Matrix;
using engine::Vector;
using Outcome = engine::BlockedFlexResult::Outcome;

namespace {

using test::makeFramework;

Matrix sym(std::initializer_list<std::initializer_list<double>> rows) {
  Matrix m(static_cast<Eigen::Index>(rows.size()), static_cast<Eigen::Index>(rows.size()));
  int i = 0;
  for (const auto& r : rows) {
    int j = 0;
    for (double v : r) m(i, j++) = v;
    ++i;
  }
  REQUIRE((m - m.transpose()).norm() == 0);
  return m;
}

Matrix randomSymmetric(std::mt19937& rng, int k) {
  const Matrix a = Eigen::Map<const Matrix>(test::randomVector(rng, k * k).data(), k, k);
  return 0.5 * (a + a.transpose());
}

double maxForm(const std::vector<Matrix>& forms, const Vector& l) {
  double r = 0;
  for (const Matrix& m : forms) r = std::max(r, std::abs(l.dot(m * l)));
  return r;
}

void requireUnblocked(const std::vector<Matrix>& forms, const BlockedFlexResult& r) {
  INFO(r.note);
  REQUIRE(r.outcome == Outcome::Unblocked);
  CHECK(r.flex.norm() == Approx(1.0).epsilon(1e-12));
  CHECK(maxForm(forms, r.flex) <= 1e-10);
  CHECK(r.residual == Approx(maxForm(forms, r.flex)).margin(1e-300));
}

}  // namespace

TEST_CASE("second order: the stress-energy forms are second differences of the constraints", "[engine]") {
  // The double Watt at its cusp: two flexes, one stress.
  const engine::Framework f =
      makeFramework({{0, 0}, {1, 0}, {2, 1}, {1, 2}, {3, 2}, {4, 2}, {5, 2}, {7, 2}, {6, 1}, {7, 0}, {8, 0}},
                    {{1, 2}, {2, 3}, {2, 4}, {3, 9}, {3, 4}, {3, 5}, {4, 5}, {5, 6}, {6, 7}, {7, 8}, {7, 9},
                     {8, 9}, {8, 10}, {9, 10}, {10, 11}},
                    {1, 6, 11});
  const Vector x = f.startCoordinates();
  const engine::RigidityReport rep = engine::analyzeRigidity(f, x);
  REQUIRE(rep.nontrivial == 2);
  REQUIRE(rep.stresses == 1);
  double scale = 0;
  const std::vector<Matrix> M = engine::stressEnergyForms(f.system(), x, rep.flex_basis, rep.stress_basis, &scale);
  REQUIRE(M.size() == 1);
  REQUIRE(scale > 0);
  const double h = 1e-4;
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b) {
      // w^T (F(x + h(u+v)) - F(x + h(u-v)) - F(x - h(u-v)) + F(x - h(u+v))) / (4 h^2) = w^T H(u, v)
      const Vector u = rep.flex_basis.col(a), v = rep.flex_basis.col(b);
      const Vector d = f.system().residuals(x + h * (u + v)) - f.system().residuals(x + h * (u - v)) -
                       f.system().residuals(x - h * (u - v)) + f.system().residuals(x - h * (u + v));
      CHECK(rep.stress_basis.col(0).dot(d) / (4 * h * h) / scale == Approx(M[0](a, b)).margin(1e-7));
    }
}

TEST_CASE("second order: prestress stability searches combinations of the stresses", "[engine]") {
  SECTION("each basis stress alone is indefinite; their sum is definite") {
    // The reference package tests basis stresses one at a time and says "not prestress stable".
    const std::vector<Matrix> forms{sym({{1, 0}, {0, -0.5}}), sym({{-0.5, 0}, {0, 1}})};
    const engine::PrestressResult r = engine::maximizeStressMargin(forms);
    REQUIRE(r.stable);
    CHECK(r.coefficients.norm() == Approx(1.0));
    // The best unit combination is (1, 1) / sqrt 2 with smallest eigenvalue 0.5 / sqrt 2.
    CHECK(r.margin == Approx(0.5 / std::sqrt(2.0)).epsilon(1e-3));
    const Matrix C = r.coefficients[0] * forms[0] + r.coefficients[1] * forms[1];
    CHECK(Eigen::SelfAdjointEigenSolver<Matrix>(C).eigenvalues().minCoeff() == Approx(r.margin));
  }
  SECTION("a traceless pair has no definite combination") {
    const std::vector<Matrix> forms{sym({{1, 0}, {0, -1}}), sym({{0, 1}, {1, 0}})};
    const engine::PrestressResult r = engine::maximizeStressMargin(forms);
    CHECK_FALSE(r.stable);
    CHECK(r.upper_bound <= 1e-8);
  }
  SECTION("a negative definite stress is as good as a positive one") {
    const std::vector<Matrix> forms{sym({{-2, 0.1}, {0.1, -1}}), sym({{0, 1}, {1, 0}})};
    const engine::PrestressResult r = engine::maximizeStressMargin(forms);
    REQUIRE(r.stable);
    CHECK(r.coefficients[0] < 0);
  }
}

TEST_CASE("second order: a traceless pair in two variables blocks every flex (sum-of-squares certificate)",
          "[engine]") {
  // (l1^2 - l2^2)^2 + (2 l1 l2)^2 = |l|^4: second-order rigid, not prestress stable.
  const std::vector<Matrix> forms{sym({{1, 0}, {0, -1}}), sym({{0, 1}, {1, 0}})};
  const BlockedFlexResult r = engine::findUnblockedFlex(forms, Vector::Ones(2));
  INFO(r.note);
  REQUIRE(r.outcome == Outcome::AllBlocked);
  CHECK(r.lower_bound > 0.1);
  CHECK(r.paths == 0);
}

TEST_CASE("second order: a zero where the sum of squares vanishes to fourth order is found", "[engine]") {
  // Q1 = l1^2 - l2^2, Q2 = 2 l1 l2: the only real zeros on the sphere are +-e3, where
  // sum Q^2 = (l1^2 + l2^2)^2 vanishes to fourth order and the sum-of-squares bound is 0.
  const std::vector<Matrix> forms{sym({{1, 0, 0}, {0, -1, 0}, {0, 0, 0}}), sym({{0, 1, 0}, {1, 0, 0}, {0, 0, 0}})};
  const BlockedFlexResult r = engine::findUnblockedFlex(forms, Vector::Ones(3));
  requireUnblocked(forms, r);
  CHECK(std::abs(r.flex[2]) == Approx(1.0).epsilon(1e-8));
  CHECK(r.flex[2] > 0);  // the sign closest to the target
  CHECK(r.paths > 0);
}

TEST_CASE("second order: for two forms in three or more variables, a common real zero exists iff no "
          "combination is definite (Calabi)",
          "[engine]") {
  std::mt19937 rng(11);
  int definite = 0, unblocked = 0;
  for (int trial = 0; trial < 24; ++trial) {
    const int k = 3 + trial % 2;
    std::vector<Matrix> forms{randomSymmetric(rng, k), randomSymmetric(rng, k)};
    // Shift half of them towards definiteness so that both answers occur.
    if (trial % 3 == 0) forms[0] += 2.5 * Matrix::Identity(k, k);
    const engine::PrestressResult ps = engine::maximizeStressMargin(forms);
    const BlockedFlexResult r = engine::findUnblockedFlex(forms, Vector::Ones(k));
    INFO("trial " << trial << ": " << r.note);
    REQUIRE(r.outcome != Outcome::Undecided);
    CHECK((r.outcome == Outcome::AllBlocked) == ps.stable);
    if (r.outcome == Outcome::Unblocked) requireUnblocked(forms, r), ++unblocked;
    definite += ps.stable;
  }
  CHECK(definite >= 4);
  CHECK(unblocked >= 4);
}

TEST_CASE("second order: planted real zeros are found, with as many forms as flexes", "[engine]") {
  std::mt19937 rng(5);
  for (int k = 3; k <= 5; ++k)
    for (int s : {k - 1, k}) {
      Vector l0 = test::randomVector(rng, k).normalized();
      std::vector<Matrix> forms;
      for (int i = 0; i < s; ++i) {
        Matrix m = randomSymmetric(rng, k);
        m -= l0.dot(m * l0) * l0 * l0.transpose();  // now l0^T m l0 = 0
        forms.push_back(m);
      }
      INFO("k = " << k << ", s = " << s);
      const BlockedFlexResult r = engine::findUnblockedFlex(forms, Vector::Ones(k));
      requireUnblocked(forms, r);
      if (s == k) CHECK(std::abs(r.flex.dot(l0)) == Approx(1.0).epsilon(1e-8));  // the only real zero
    }
}

TEST_CASE("second order: more random forms than flexes leave no real zero", "[engine]") {
  // Decided by the sum-of-squares certificate, and again by the homotopy alone.
  for (const int sos : {8, 0}) {
    std::mt19937 rng(3);
    engine::BlockedFlexOptions opt;
    opt.max_sos_flexes = sos;
    for (int trial = 0; trial < 6; ++trial) {
      const int k = 2 + trial % 3;
      std::vector<Matrix> forms;
      for (int i = 0; i <= k; ++i) forms.push_back(randomSymmetric(rng, k));
      const BlockedFlexResult r = engine::findUnblockedFlex(forms, Vector::Ones(k), opt);
      INFO("k = " << k << ", sos up to " << sos << ": " << r.note);
      CHECK(r.outcome == Outcome::AllBlocked);
      CHECK(r.lower_bound > 0);
      CHECK((r.paths > 0) == (sos == 0));
      CHECK(r.failed_paths == 0);
    }
  }
}

TEST_CASE("second order: the blocked-flex search is deterministic and seeded", "[engine]") {
  const std::vector<Matrix> forms{sym({{1, 0, 0}, {0, -1, 0}, {0, 0, 0.5}}), sym({{0, 1, 0}, {1, 0, 0.3}, {0, 0.3, -1}})};
  const BlockedFlexResult a = engine::findUnblockedFlex(forms, Vector::Ones(3));
  const BlockedFlexResult b = engine::findUnblockedFlex(forms, Vector::Ones(3));
  requireUnblocked(forms, a);
  CHECK(a.flex == b.flex);
  CHECK(a.paths == b.paths);
}
