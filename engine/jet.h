// Derivatives of a formula written once, in any arithmetic: a hyper-dual number
//   v + a e1 + b e2 + ab e1 e2   (e1^2 = e2^2 = 0, e1 e2 = e2 e1 != 0)
// over a number type T (double, an interval, a rational). Evaluating f at x + u e1 + w e2 gives
// f(x), the directional derivatives f'(x)[u] and f'(x)[w], and u^T f''(x) w, exactly in T: no
// step, no truncation. A term's residual, written as a template on its number type
// (engine/terms.h), gets its Jacobian column j from u = e_j and its second derivative from
// (u, w), which is how the finite-difference tests, the exact and the interval evaluators all
// reach the same formula.
#pragma once

#include <cmath>
#include <stdexcept>
#include <type_traits>

namespace flexure::engine {

// sqrt where the arithmetic has one; an arithmetic without (exact rationals) throws
// std::domain_error: a term that needs a root is not polynomial (its degree() is -1), and the
// exact evaluator refuses it before it gets here.
template <class T, class = void>
struct HasSqrt : std::false_type {};
template <class T>
struct HasSqrt<T, std::void_t<decltype(sqrt(std::declval<const T&>()))>> : std::true_type {};

template <class T>
T root(const T& x) {
  if constexpr (std::is_floating_point_v<T>) {
    return std::sqrt(x);
  } else if constexpr (HasSqrt<T>::value) {
    return sqrt(x);
  } else {
    (void)x;
    throw std::domain_error("a square root, which this arithmetic does not have");
  }
}

template <class T>
struct HyperDual {
  T v{}, a{}, b{}, ab{};

  HyperDual() = default;
  // A constant (no derivative): integers and doubles convert to T where T allows it.
  HyperDual(const T& value) : v(value), a(T(0)), b(T(0)), ab(T(0)) {}  // NOLINT: implicit on purpose
  template <class S, class = std::enable_if_t<std::is_arithmetic_v<S> && !std::is_same_v<S, T>>>
  HyperDual(S value) : HyperDual(T(value)) {}  // NOLINT
  HyperDual(T value, T da, T db, T dab) : v(value), a(da), b(db), ab(dab) {}

  HyperDual& operator+=(const HyperDual& o) { v += o.v, a += o.a, b += o.b, ab += o.ab; return *this; }
  HyperDual& operator-=(const HyperDual& o) { v -= o.v, a -= o.a, b -= o.b, ab -= o.ab; return *this; }
  HyperDual& operator*=(const HyperDual& o) { return *this = *this * o; }
  HyperDual& operator/=(const HyperDual& o) { return *this = *this / o; }

  friend HyperDual operator+(HyperDual x, const HyperDual& y) { return x += y; }
  friend HyperDual operator-(HyperDual x, const HyperDual& y) { return x -= y; }
  friend HyperDual operator-(const HyperDual& x) { return HyperDual(-x.v, -x.a, -x.b, -x.ab); }
  friend HyperDual operator*(const HyperDual& x, const HyperDual& y) {
    return HyperDual(x.v * y.v, x.a * y.v + x.v * y.a, x.b * y.v + x.v * y.b,
                     x.ab * y.v + x.a * y.b + x.b * y.a + x.v * y.ab);
  }
  // The chain rule for g(x) with g(v), g'(v), g''(v) given.
  friend HyperDual chain(const HyperDual& x, const T& g0, const T& g1, const T& g2) {
    return HyperDual(g0, g1 * x.a, g1 * x.b, g1 * x.ab + g2 * x.a * x.b);
  }
  friend HyperDual operator/(const HyperDual& x, const HyperDual& y) {
    const T inv = T(1) / y.v;
    return x * chain(y, inv, -inv * inv, T(2) * inv * inv * inv);
  }
  friend HyperDual sqrt(const HyperDual& x) {
    const T s = root(x.v);
    const T g1 = T(1) / (T(2) * s);
    return chain(x, s, g1, -g1 / (T(2) * x.v));
  }
};

// First derivatives only: x = v + a e with e^2 = 0. A term's Jacobian is one evaluation per
// coordinate in Dual<T>, a third of the products of HyperDual<T> (whose second parts are zero
// there).
template <class T>
struct Dual {
  T v{}, a{};

  Dual() = default;
  Dual(const T& value) : v(value), a(T(0)) {}  // NOLINT: implicit on purpose
  template <class S, class = std::enable_if_t<std::is_arithmetic_v<S> && !std::is_same_v<S, T>>>
  Dual(S value) : Dual(T(value)) {}  // NOLINT
  Dual(T value, T da) : v(value), a(da) {}

  Dual& operator+=(const Dual& o) { v += o.v, a += o.a; return *this; }
  Dual& operator-=(const Dual& o) { v -= o.v, a -= o.a; return *this; }
  Dual& operator*=(const Dual& o) { return *this = *this * o; }
  Dual& operator/=(const Dual& o) { return *this = *this / o; }

  friend Dual operator+(Dual x, const Dual& y) { return x += y; }
  friend Dual operator-(Dual x, const Dual& y) { return x -= y; }
  friend Dual operator-(const Dual& x) { return Dual(-x.v, -x.a); }
  friend Dual operator*(const Dual& x, const Dual& y) { return Dual(x.v * y.v, x.a * y.v + x.v * y.a); }
  friend Dual operator/(const Dual& x, const Dual& y) {
    const T inv = T(1) / y.v;
    const T q = x.v * inv;
    return Dual(q, (x.a - q * y.a) * inv);
  }
  friend Dual sqrt(const Dual& x) {
    const T s = root(x.v);
    return Dual(s, x.a / (T(2) * s));
  }
};

// The value of a number with or without derivatives.
template <class T>
const T& valueOf(const HyperDual<T>& x) {
  return x.v;
}
template <class T>
const T& valueOf(const Dual<T>& x) {
  return x.v;
}
inline double valueOf(double x) { return x; }

}  // namespace flexure::engine
