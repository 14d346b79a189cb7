#include "engine/exact/rational.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <stdexcept>

namespace flexure::engine {

namespace {

bool isDigit(char c) { return c >= '0' && c <= '9'; }

// Digits with single underscores between them (TOML); appends them to `out`.
bool readDigits(std::string_view s, size_t& i, std::string& out) {
  const size_t from = i;
  while (i < s.size() && (isDigit(s[i]) || (s[i] == '_' && i > from && i + 1 < s.size() && isDigit(s[i - 1]) && isDigit(s[i + 1])))) {
    if (s[i] != '_') out += s[i];
    ++i;
  }
  return !out.empty() && i > from;
}

mpz_class powerOfTen(unsigned long e) {
  mpz_class p;
  mpz_ui_pow_ui(p.get_mpz_t(), 10, e);
  return p;
}

}  // namespace

long rationalBits(const Rational& q) {
  return static_cast<long>(mpz_sizeinbase(q.get_num_mpz_t(), 2) + mpz_sizeinbase(q.get_den_mpz_t(), 2));
}

DecimalRead readDecimal(std::string_view s, Rational& out) {
  size_t i = 0;
  bool negative = false;
  if (i < s.size() && (s[i] == '+' || s[i] == '-')) negative = s[i++] == '-';
  std::string whole, fraction, exponent;
  if (!readDigits(s, i, whole)) return DecimalRead::not_numeral;
  if (i < s.size() && s[i] == '.') {
    ++i;
    if (!readDigits(s, i, fraction)) return DecimalRead::not_numeral;
  }
  bool exp_negative = false;
  if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
    ++i;
    if (i < s.size() && (s[i] == '+' || s[i] == '-')) exp_negative = s[i++] == '-';
    if (!readDigits(s, i, exponent)) return DecimalRead::not_numeral;
  }
  if (i != s.size()) return DecimalRead::not_numeral;
  // The value is digits * 10^e: leading zeros of the digits and of the exponent mean nothing,
  // trailing zeros of the digits go into the exponent, and zero is zero whatever the exponent.
  std::string digits = whole + fraction;
  const size_t first = digits.find_first_not_of('0');
  if (first == std::string::npos) {
    out = Rational(0);
    return DecimalRead::ok;
  }
  const size_t last = digits.find_last_not_of('0');
  const long trailing = static_cast<long>(digits.size() - 1 - last);
  digits = digits.substr(first, last + 1 - first);
  const size_t e_first = exponent.find_first_not_of('0');
  exponent = e_first == std::string::npos ? "" : exponent.substr(e_first);
  // Sizes before any arithmetic: a digit is log2(10) bits.
  constexpr double kBitsPerDigit = 3.321928094887362;
  const double limit = static_cast<double>(kMaxRationalBits);
  if (exponent.size() > 15 || (static_cast<double>(digits.size()) - 1) * kBitsPerDigit > limit) return DecimalRead::too_large;
  const long e = (exponent.empty() ? 0 : std::stol(exponent)) * (exp_negative ? -1 : 1) -
                 static_cast<long>(fraction.size()) + trailing;
  const mpz_class m(digits, 10);
  Rational q;
  if (e >= 0) {
    // At least (bits(m) - 1) + e log2(10) bits.
    if (static_cast<double>(mpz_sizeinbase(m.get_mpz_t(), 2)) - 1 + static_cast<double>(e) * kBitsPerDigit > limit)
      return DecimalRead::too_large;
    q = Rational(m * powerOfTen(static_cast<unsigned long>(e)));
  } else {
    // m / (2^k 5^k) in lowest terms without a gcd: the 2s and 5s that m shares with 10^k cancel.
    const unsigned long k = static_cast<unsigned long>(-e);
    mpz_class num = m;
    const mpz_class five(5);
    const unsigned long twos = std::min<unsigned long>(mpz_scan1(num.get_mpz_t(), 0), k);
    mpz_tdiv_q_2exp(num.get_mpz_t(), num.get_mpz_t(), twos);
    unsigned long fives = mpz_remove(num.get_mpz_t(), num.get_mpz_t(), five.get_mpz_t());
    if (fives > k) {  // more 5s than 10^k has: put the others back
      mpz_class back;
      mpz_ui_pow_ui(back.get_mpz_t(), 5, fives - k);
      num *= back;
      fives = k;
    }
    const double den_bits = static_cast<double>(k - twos) + static_cast<double>(k - fives) * 2.321928094887362;
    if (static_cast<double>(mpz_sizeinbase(num.get_mpz_t(), 2)) + den_bits > limit + 2) return DecimalRead::too_large;
    mpz_class den, p5;
    mpz_ui_pow_ui(p5.get_mpz_t(), 5, k - fives);
    mpz_mul_2exp(den.get_mpz_t(), p5.get_mpz_t(), k - twos);
    q = Rational(num, den);  // coprime by construction: already in lowest terms
  }
  if (rationalBits(q) > kMaxRationalBits) return DecimalRead::too_large;
  out = negative ? Rational(-q) : q;
  return DecimalRead::ok;
}

bool parseDecimal(std::string_view s, Rational& out) { return readDecimal(s, out) == DecimalRead::ok; }

Rational shortestDecimal(double v) {
  if (!std::isfinite(v)) throw std::invalid_argument("shortestDecimal: not a finite number");
  char buf[64];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  if (ec != std::errc()) throw std::invalid_argument("shortestDecimal: cannot format");
  Rational q;
  if (!parseDecimal(std::string_view(buf, static_cast<size_t>(end - buf)), q))
    throw std::invalid_argument("shortestDecimal: unexpected numeral " + std::string(buf, end));
  return q;
}

double nearestDouble(const Rational& q) {
  if (q == 0) return 0.0;
  const mpz_class num = abs(q.get_num());
  const mpz_class& den = q.get_den();
  // t = floor(|q| 2^s) with 61 or 62 bits, the remainder folded into its lowest bit (a sticky bit
  // below double's 53: the one rounding, to nearest, happens in the conversion to double).
  const long D = static_cast<long>(mpz_sizeinbase(num.get_mpz_t(), 2)) - static_cast<long>(mpz_sizeinbase(den.get_mpz_t(), 2));
  if (D > 1100) return q < 0 ? -HUGE_VAL : HUGE_VAL;
  if (D < -1200) return q < 0 ? -0.0 : 0.0;
  const long s = 61 - D;
  mpz_class a = num, b = den, t, rem;
  if (s >= 0) mpz_mul_2exp(a.get_mpz_t(), a.get_mpz_t(), static_cast<unsigned long>(s));
  else mpz_mul_2exp(b.get_mpz_t(), b.get_mpz_t(), static_cast<unsigned long>(-s));
  mpz_fdiv_qr(t.get_mpz_t(), rem.get_mpz_t(), a.get_mpz_t(), b.get_mpz_t());
  unsigned long long bits = mpz_get_ui(t.get_mpz_t());
  if (rem != 0) bits |= 1;
  const double v = std::ldexp(static_cast<double>(bits), static_cast<int>(-s));
  return q < 0 ? -v : v;
}

std::string toString(const Rational& q) { return q.get_str(); }

}  // namespace flexure::engine
