// Closed intervals of doubles with outward rounding: each operation is computed in the default
// rounding (to nearest, error at most half an ulp) and its bounds moved one ulp outward, so the
// result encloses every real result of the operation on the operands' points. The arithmetic of
// the certificates (engine/interval/certify.h): the term formulas (residual<T>) and their jets
// evaluated in it enclose the exact values at every point of a box.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>

namespace flexure::engine {

struct Interval {
  double lo = 0, hi = 0;

  Interval() = default;
  Interval(double x) : lo(x), hi(x) {}  // NOLINT: a point, implicit on purpose (term formulas write T(2))
  Interval(int x) : lo(x), hi(x) {}     // NOLINT
  Interval(double a, double b) : lo(a), hi(b) {}

  // The next double above x (std::nextafter toward +inf, inline: the library call was 60 % of a
  // certified track's time). Zeros go to the smallest subnormal; +inf and NaN stay.
  static double up(double x) {
    if (x == 0) return std::numeric_limits<double>::denorm_min();
    if (!(x < std::numeric_limits<double>::infinity())) return x;
    std::uint64_t bits;
    std::memcpy(&bits, &x, sizeof bits);
    bits = x > 0 ? bits + 1 : bits - 1;
    std::memcpy(&x, &bits, sizeof bits);
    return x;
  }
  static double down(double x) { return -up(-x); }

  double mid() const { return lo + 0.5 * (hi - lo); }
  double rad() const { return up(std::max(hi - mid(), mid() - lo)); }
  double mag() const { return std::max(std::abs(lo), std::abs(hi)); }
  bool contains(double x) const { return lo <= x && x <= hi; }
  bool finite() const { return std::isfinite(lo) && std::isfinite(hi); }

  Interval& operator+=(const Interval& o) { return *this = *this + o; }
  Interval& operator-=(const Interval& o) { return *this = *this - o; }
  Interval& operator*=(const Interval& o) { return *this = *this * o; }
  Interval& operator/=(const Interval& o) { return *this = *this / o; }

  friend Interval operator+(const Interval& a, const Interval& b) { return {down(a.lo + b.lo), up(a.hi + b.hi)}; }
  friend Interval operator-(const Interval& a, const Interval& b) { return {down(a.lo - b.hi), up(a.hi - b.lo)}; }
  friend Interval operator-(const Interval& a) { return {-a.hi, -a.lo}; }
  friend Interval operator*(const Interval& a, const Interval& b) {
    // A point times a point: one product.
    if (a.lo == a.hi && b.lo == b.hi) {
      const double p = a.lo * b.lo;
      return {down(p), up(p)};
    }
    // By the signs (two products where a bound's sign is known), else the extremes of the four.
    if (a.lo >= 0) {
      if (b.lo >= 0) return {down(a.lo * b.lo), up(a.hi * b.hi)};
      if (b.hi <= 0) return {down(a.hi * b.lo), up(a.lo * b.hi)};
      return {down(a.hi * b.lo), up(a.hi * b.hi)};
    }
    if (a.hi <= 0) {
      if (b.lo >= 0) return {down(a.lo * b.hi), up(a.hi * b.lo)};
      if (b.hi <= 0) return {down(a.hi * b.hi), up(a.lo * b.lo)};
      return {down(a.lo * b.hi), up(a.lo * b.lo)};
    }
    if (b.lo >= 0) return {down(a.lo * b.hi), up(a.hi * b.hi)};
    if (b.hi <= 0) return {down(a.hi * b.lo), up(a.lo * b.lo)};
    const double p1 = a.lo * b.lo, p2 = a.lo * b.hi, p3 = a.hi * b.lo, p4 = a.hi * b.hi;
    return {down(std::min(std::min(p1, p2), std::min(p3, p4))), up(std::max(std::max(p1, p2), std::max(p3, p4)))};
  }
  // Division by an interval holding 0 has no finite enclosure: std::domain_error (a certificate
  // then fails with that reason).
  friend Interval operator/(const Interval& a, const Interval& b) {
    if (b.lo <= 0 && b.hi >= 0) throw std::domain_error("an interval division by a range that holds 0");
    const double p1 = a.lo / b.lo, p2 = a.lo / b.hi, p3 = a.hi / b.lo, p4 = a.hi / b.hi;
    return {down(std::min(std::min(p1, p2), std::min(p3, p4))), up(std::max(std::max(p1, p2), std::max(p3, p4)))};
  }
  friend Interval sqrt(const Interval& a) {
    if (a.lo < 0) throw std::domain_error("an interval square root of a range below 0");
    return {std::max(0.0, down(std::sqrt(a.lo))), up(std::sqrt(a.hi))};
  }
  // The convex hull.
  friend Interval hull(const Interval& a, const Interval& b) { return {std::min(a.lo, b.lo), std::max(a.hi, b.hi)}; }
};

}  // namespace flexure::engine
