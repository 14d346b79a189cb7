#include "engine/exact/exact_generators.h"

#include <stdexcept>

namespace flexure::engine::exact {

namespace {

// A linear map on R^d as its nonzero entries (row, column, value): velocity L p.
struct Entry {
  int row, column, value;
};
using Linear = std::vector<Entry>;

std::vector<Linear> rotations(int d) {
  std::vector<Linear> out;
  for (int a = 0; a < d; ++a)
    for (int b = a + 1; b < d; ++b) out.push_back({{b, a, 1}, {a, b, -1}});  // p_a e_b - p_b e_a
  return out;
}

}  // namespace

RationalMatrix symmetryGenerators(const SymmetryGroup& group, const RationalMatrix& positions) {
  const int d = positions.rows, blocks = positions.cols;
  using F = SymmetryGroup::Family;
  std::vector<Linear> linear = rotations(d);
  int directions = 0;
  switch (group.family) {
    case F::Euclidean: directions = group.num_directions; break;
    case F::Similarity: {
      Linear identity;
      for (int a = 0; a < d; ++a) identity.push_back({a, a, 1});
      linear.push_back(identity);
      break;
    }
    case F::EquiAffine:
      linear.clear();
      for (int a = 0; a < d; ++a)
        for (int b = 0; b < d; ++b)
          if (a != b) linear.push_back({{a, b, 1}});
      for (int a = 0; a + 1 < d; ++a) linear.push_back({{a, a, 1}, {a + 1, a + 1, -1}});
      break;
    case F::Moebius: {
      if (d != 3) throw std::invalid_argument("Moebius generators act on caps in 3D");
      RationalMatrix g(blocks * d, 6);
      for (int i = 0; i < group.num_points; ++i) {
        int j = 0;
        for (const Linear& w : linear) {
          for (const Entry& e : w) g(i * d + e.row, j) += e.value * positions(e.column, i);
          ++j;
        }
        for (int k = 0; k < 3; ++k) {
          for (int c = 0; c < 3; ++c) g(i * d + c, 3 + k) = -positions(k, i) * positions(c, i);
          g(i * d + k, 3 + k) += 1;
        }
      }
      return g;
    }
  }
  const int t = d;  // translations first
  RationalMatrix g(blocks * d, t + static_cast<int>(linear.size()));
  for (int i = 0; i < group.num_points + directions && i < blocks; ++i) {
    const bool point = i < group.num_points;
    if (point)
      for (int k = 0; k < t; ++k) g(i * d + k, k) = 1;
    for (size_t j = 0; j < linear.size(); ++j)
      for (const Entry& e : linear[j]) g(i * d + e.row, t + static_cast<int>(j)) += e.value * positions(e.column, i);
  }
  return g;
}

}  // namespace flexure::engine::exact
