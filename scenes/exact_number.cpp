#include "scenes/exact_number.h"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "scenes/expression.h"

namespace flexure::scenes::detail {

namespace {

class RationalParser {
 public:
  explicit RationalParser(std::string_view s) : s_(s) {}

  engine::Rational parse() {
    engine::Rational v = sum();
    skip();
    if (i_ != s_.size()) fail("unexpected '" + std::string(1, s_[i_]) + "'");
    return v;
  }

 private:
  [[noreturn]] void fail(const std::string& m, size_t at) const { throw ExpressionError(m, static_cast<int>(at)); }
  [[noreturn]] void fail(const std::string& m) const { fail(m, i_); }
  void skip() {
    while (i_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[i_]))) ++i_;
  }
  bool eat(char c) {
    skip();
    if (i_ < s_.size() && s_[i_] == c) {
      ++i_;
      return true;
    }
    return false;
  }
  engine::Rational sum() {
    engine::Rational v = product();
    for (;;) {
      if (eat('+')) v += product();
      else if (eat('-')) v -= product();
      else return v;
    }
  }
  engine::Rational product() {
    engine::Rational v = unary();
    for (;;) {
      if (eat('*')) {
        v *= unary();
      } else if (eat('/')) {
        skip();
        const size_t at = i_;
        const engine::Rational w = unary();
        if (w == 0) fail("division by zero", at);
        v /= w;
      } else {
        return v;
      }
    }
  }
  // Unary minus binds looser than ^ (-2^2 = -4), as in the double expressions.
  engine::Rational unary() {
    if (eat('-')) return -unary();
    if (eat('+')) return unary();
    return power();
  }
  engine::Rational power() {
    engine::Rational base = atom();
    if (!eat('^')) return base;
    skip();
    const size_t at = i_;
    const engine::Rational e = unary();
    if (e.get_den() != 1 || abs(e.get_num()) > 10000)
      fail("the exponent " + e.get_str() + " is not an integer of at most 10000 in size: the power is not rational", at);
    const long k = e.get_num().get_si();
    if (base == 0 && k < 0) fail("division by zero", at);
    engine::Rational out;
    mpz_pow_ui(out.get_num_mpz_t(), base.get_num_mpz_t(), static_cast<unsigned long>(std::labs(k)));
    mpz_pow_ui(out.get_den_mpz_t(), base.get_den_mpz_t(), static_cast<unsigned long>(std::labs(k)));
    out.canonicalize();
    return k < 0 ? engine::Rational(1 / out) : out;
  }
  engine::Rational atom() {
    skip();
    if (eat('(')) {
      engine::Rational v = sum();
      if (!eat(')')) fail("missing ')'");
      return v;
    }
    const size_t from = i_;
    if (i_ < s_.size() && std::isalpha(static_cast<unsigned char>(s_[i_]))) {
      while (i_ < s_.size() && (std::isalnum(static_cast<unsigned char>(s_[i_])) || s_[i_] == '_')) ++i_;
      fail("'" + std::string(s_.substr(from, i_ - from)) +
               "' is not rational arithmetic: the exact mode takes + - * / ^ of rational numbers",
           from);
    }
    while (i_ < s_.size() && (std::isdigit(static_cast<unsigned char>(s_[i_])) || s_[i_] == '.' || s_[i_] == '_' ||
                              ((s_[i_] == 'e' || s_[i_] == 'E') && i_ > from) ||
                              ((s_[i_] == '+' || s_[i_] == '-') && i_ > from && (s_[i_ - 1] == 'e' || s_[i_ - 1] == 'E'))))
      ++i_;
    engine::Rational v;
    if (i_ == from || !engine::parseDecimal(s_.substr(from, i_ - from), v)) fail("expected a number", from);
    return v;
  }

  std::string_view s_;
  size_t i_ = 0;
};

// The numeral of a float node in the file's text, when it can be found there and reads back
// as the node's value.
bool numeralInText(const Reader& r, const toml::node& n, engine::Rational& out) {
  const toml::source_region& src = n.source();
  const std::string_view text = r.lineOfText(src);
  if (text.empty() || src.begin.column < 1 || static_cast<size_t>(src.begin.column) > text.size()) return false;
  size_t i = static_cast<size_t>(src.begin.column) - 1, j = i;
  while (j < text.size() && (std::isdigit(static_cast<unsigned char>(text[j])) || std::strchr("+-._eE", text[j]))) ++j;
  const std::string numeral(text.substr(i, j - i));
  engine::Rational q;
  if (!engine::parseDecimal(numeral, q)) return false;
  std::string plain;
  for (char c : numeral)
    if (c != '_') plain += c;
  if (std::strtod(plain.c_str(), nullptr) != n.as_floating_point()->get()) return false;
  out = q;
  return true;
}

}  // namespace

engine::Rational evaluateRational(std::string_view text) { return RationalParser(text).parse(); }

engine::Rational exactNumber(const Reader& r, const toml::node& n, const std::string& what) {
  if (auto i = n.as_integer()) return engine::Rational(mpz_class(std::to_string(i->get())));
  if (auto f = n.as_floating_point()) {
    engine::Rational q;
    if (numeralInText(r, n, q)) return q;
    if (!std::isfinite(f->get())) r.fail(n, what + " is not finite");
    return engine::shortestDecimal(f->get());
  }
  if (auto s = n.as_string()) {
    try {
      return evaluateRational(s->get());
    } catch (const ExpressionError& e) {
      r.fail(n.source(), what + " in exact mode: " + e.what() + " in \"" + s->get() + "\"", e.offset + 1);
    }
  }
  r.fail(n, what + " must be a number or an expression string, not " + typeName(n));
}

}  // namespace flexure::scenes::detail
