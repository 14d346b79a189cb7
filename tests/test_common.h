// Helpers shared by the test executables.
#pragma once

#include <catch2/catch.hpp>
#include <unistd.h>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include "engine/constraint_system.h"
#include "engine/systems/framework.h"

namespace flexure::test {

using engine::Matrix;
using engine::Vector;

// A folder of this process in the temporary directory: PREFIX-PID (made on first use).
inline std::filesystem::path scratchFolder(const std::string& prefix) {
  auto p = std::filesystem::temp_directory_path() / (prefix + "-" + std::to_string(::getpid()));
  std::filesystem::create_directories(p);
  return p;
}

// `text` written (bytes as they are) to NAME in the folder; its path.
inline std::string writeScratch(const std::filesystem::path& folder, const std::string& name, const std::string& text) {
  const auto p = folder / name;
  std::ofstream(p, std::ios::binary) << text;
  return p.string();
}

// A framework from points given row by row (one vertex per row), 1-based edges and pins as in
// the notes.
inline engine::Framework makeFramework(std::initializer_list<std::initializer_list<double>> rows,
                                       std::initializer_list<std::array<int, 2>> edges1,
                                       std::initializer_list<int> pins1 = {}) {
  const int n = static_cast<int>(rows.size());
  const int d = static_cast<int>(rows.begin()->size());
  Matrix p(d, n);
  int i = 0;
  for (const auto& r : rows) {
    int k = 0;
    for (double v : r) p(k++, i) = v;
    ++i;
  }
  std::vector<engine::Framework::Edge> edges;
  for (const auto& e : edges1) edges.push_back({e[0] - 1, e[1] - 1});
  std::vector<int> pins;
  for (int v : pins1) pins.push_back(v - 1);
  return engine::Framework(p, edges, pins);
}

inline Vector randomVector(std::mt19937& rng, int n, double scale = 1.0) {
  std::normal_distribution<double> g(0.0, scale);
  Vector v(n);
  for (int i = 0; i < n; ++i) v[i] = g(rng);
  return v;
}

// Central differences of the residuals against the analytic Jacobian, column by column.
inline void requireJacobianMatchesFiniteDifferences(const engine::ConstraintSystem& sys,
                                                    const Vector& x) {
  const Matrix J(sys.jacobian(x));
  const double h = 1e-6;
  for (int c = 0; c < sys.numVariables(); ++c) {
    Vector xp = x, xm = x;
    xp[c] += h;
    xm[c] -= h;
    const Vector fd = (sys.residuals(xp) - sys.residuals(xm)) / (2 * h);
    const double scale = std::max(1.0, J.col(c).cwiseAbs().maxCoeff());
    INFO("column " << c);
    REQUIRE((fd - J.col(c)).cwiseAbs().maxCoeff() <= 1e-6 * scale);
  }
}

// u^T H_i w against central differences of J(x + t w) u.
inline void requireSecondDerivativeMatchesFiniteDifferences(const engine::ConstraintSystem& sys,
                                                            const Vector& x, const Vector& u,
                                                            const Vector& w) {
  const double h = 1e-5;
  const Vector fd = (sys.jacobian(x + h * w) * u - sys.jacobian(x - h * w) * u) / (2 * h);
  const Vector an = sys.secondDerivative(x, u, w);
  const double scale = std::max(1.0, an.cwiseAbs().maxCoeff());
  REQUIRE((fd - an).cwiseAbs().maxCoeff() <= 1e-6 * scale);
}

// The text of a file of the project, by its path from the project root (FLEXURE_SOURCE_DIR).
inline std::string readProjectFile(const std::string& source_dir, const std::string& path) {
  std::ifstream in(source_dir + "/" + path);
  REQUIRE(in.good());
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// P_r A P_c for random permutations of the rows and columns (equations and coordinates
// reordered): the rank decision must not depend on the order.
inline engine::SparseMatrix permuted(const engine::SparseMatrix& A, std::mt19937& rng) {
  std::vector<int> rows(static_cast<size_t>(A.rows())), cols(static_cast<size_t>(A.cols()));
  for (size_t i = 0; i < rows.size(); ++i) rows[i] = static_cast<int>(i);
  for (size_t i = 0; i < cols.size(); ++i) cols[i] = static_cast<int>(i);
  std::shuffle(rows.begin(), rows.end(), rng);
  std::shuffle(cols.begin(), cols.end(), rng);
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> R(Eigen::Map<Eigen::VectorXi>(rows.data(), A.rows()));
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> C(Eigen::Map<Eigen::VectorXi>(cols.data(), A.cols()));
  return engine::SparseMatrix(R * A * C);
}

}  // namespace flexure::test
