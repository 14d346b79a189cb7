#include "engine/exact/rational.h"

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

bool parseDecimal(std::string_view s, Rational& out) {
  size_t i = 0;
  bool negative = false;
  if (i < s.size() && (s[i] == '+' || s[i] == '-')) negative = s[i++] == '-';
  std::string whole, fraction, exponent;
  if (!readDigits(s, i, whole)) return false;
  if (i < s.size() && s[i] == '.') {
    ++i;
    if (!readDigits(s, i, fraction)) return false;
  }
  bool exp_negative = false;
  if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
    ++i;
    if (i < s.size() && (s[i] == '+' || s[i] == '-')) exp_negative = s[i++] == '-';
    if (!readDigits(s, i, exponent)) return false;
  }
  if (i != s.size()) return false;
  // Exponents beyond what a scene can mean are not numbers here (10^100000 digits).
  if (exponent.size() > 5) return false;
  const long e = (exponent.empty() ? 0 : std::stol(exponent)) * (exp_negative ? -1 : 1) -
                 static_cast<long>(fraction.size());
  if (std::labs(e) > 100000) return false;
  mpz_class digits(whole + fraction, 10);
  Rational q = e >= 0 ? Rational(digits * powerOfTen(static_cast<unsigned long>(e)))
                      : Rational(digits, powerOfTen(static_cast<unsigned long>(-e)));
  q.canonicalize();
  out = negative ? Rational(-q) : q;
  return true;
}

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

std::string toString(const Rational& q) { return q.get_str(); }

}  // namespace flexure::engine
