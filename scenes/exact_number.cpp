#include "scenes/exact_number.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "scenes/expression.h"

namespace flexure::scenes::detail {

namespace {

// "N bits, beyond the exact mode's limit of ...": why a number is refused as too large.
// bits = 0: a number read as written, known only to be beyond the limit.
std::string beyondLimit(const std::string& what, double bits = 0) {
  const std::string limit = std::to_string(engine::kMaxRationalBits);
  if (bits <= 0)
    return what + " is beyond the exact mode's numbers: as an exact rational it needs more than " + limit +
           " bits (numerator and denominator together), the limit for a scene number";
  return what + " could have up to " +
         (bits < 1e15 ? std::to_string(static_cast<long long>(bits)) : std::string("more than 10^15")) +
         " bits (numerator and denominator together), beyond the exact mode's limit of " + limit +
         " bits for a scene number";
}

// Rational arithmetic with every result's size bounded before it is computed: size(x) =
// bits(numerator) + bits(denominator) (engine::rationalBits), size(x * y), size(x / y) <=
// size(x) + size(y), size(a/b +- c/d) <= max(bits(ad), bits(cb)) + 1 + bits(bd), and
// size(x^k) <= |k| size(x). A bound beyond engine::kMaxRationalBits is
// refused at the operator, so GMP never sees an operation whose result it cannot hold and no
// expression costs more than a few milliseconds per operator.
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
  static constexpr int kMaxDepth = 200;  // as the double expressions (scenes/expression.cpp)

  [[noreturn]] void fail(const std::string& m, size_t at) const { throw ExpressionError(m, static_cast<int>(at)); }
  [[noreturn]] void fail(const std::string& m) const { fail(m, i_); }
  struct DepthGuard {
    explicit DepthGuard(RationalParser& p) : p(p) {
      if (++p.depth_ > kMaxDepth) p.fail("expression nested too deeply");
    }
    ~DepthGuard() { --p.depth_; }
    RationalParser& p;
  };
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
  // Refuses the operation at `at` when its result's size bound is beyond the limit, or when the
  // expression's results together would be beyond kMaxWorkBits (a megabyte of "7^50000 + "
  // repeated is 10^5 powers of 140,000 bits each: minutes, though no single one is too large).
  static constexpr double kMaxWorkBits = 64.0 * engine::kMaxRationalBits;
  void bound(double bits, const char* what, size_t at) {
    if (bits > static_cast<double>(engine::kMaxRationalBits)) fail(beyondLimit(std::string("the result of this ") + what, bits), at);
    work_ += bits;
    if (work_ > kMaxWorkBits)
      fail("the expression's operations up to this " + std::string(what) + " produce more than " +
               std::to_string(static_cast<long long>(kMaxWorkBits)) +
               " bits in all, the limit for one scene number's arithmetic in exact mode",
           at);
  }
  // x * y = (a c)/(b d) and x / y = (a d)/(b c): at most size(x) + size(y).
  void boundProduct(const engine::Rational& x, const engine::Rational& y, const char* what, size_t at) {
    bound(static_cast<double>(engine::rationalBits(x)) + static_cast<double>(engine::rationalBits(y)), what, at);
  }
  // a/b +- c/d = (a d +- c b)/(b d): at most max(bits(a d), bits(c b)) + 1 + bits(b d), up to
  // twice size(x) + size(y) (1/B + 1/3 has about twice B's bits).
  void boundSum(const engine::Rational& x, const engine::Rational& y, const char* what, size_t at) {
    const auto bits = [](const mpz_class& z) { return static_cast<double>(mpz_sizeinbase(z.get_mpz_t(), 2)); };
    const double a = bits(x.get_num()), b = bits(x.get_den()), c = bits(y.get_num()), d = bits(y.get_den());
    bound(std::max(a + d, c + b) + 1 + b + d, what, at);
  }
  engine::Rational sum() {
    DepthGuard guard(*this);
    engine::Rational v = product();
    for (;;) {
      skip();
      const size_t at = i_;
      if (eat('+')) {
        const engine::Rational w = product();
        boundSum(v, w, "sum", at);
        v += w;
      } else if (eat('-')) {
        const engine::Rational w = product();
        boundSum(v, w, "difference", at);
        v -= w;
      } else {
        return v;
      }
    }
  }
  engine::Rational product() {
    engine::Rational v = unary();
    for (;;) {
      skip();
      const size_t op = i_;
      if (eat('*')) {
        const engine::Rational w = unary();
        boundProduct(v, w, "product", op);
        v *= w;
      } else if (eat('/')) {
        skip();
        const size_t at = i_;
        const engine::Rational w = unary();
        if (w == 0) fail("division by zero", at);
        boundProduct(v, w, "quotient", op);
        v /= w;
      } else {
        return v;
      }
    }
  }
  // Unary minus binds looser than ^ (-2^2 = -4), as in the double expressions.
  engine::Rational unary() {
    DepthGuard guard(*this);
    if (eat('-')) return -unary();
    if (eat('+')) return unary();
    return power();
  }
  engine::Rational power() {
    engine::Rational base = atom();
    skip();
    const size_t op = i_;
    if (!eat('^')) return base;
    skip();
    const size_t at = i_;
    const engine::Rational e = unary();
    if (e.get_den() != 1) fail("the exponent " + e.get_str() + " is not an integer: the power is not rational", at);
    const mpz_class& k = e.get_num();
    if (base == 0) {
      if (k < 0) fail("division by zero", at);
      return k == 0 ? engine::Rational(1) : engine::Rational(0);
    }
    if (abs(base) == 1) return base < 0 && mpz_odd_p(k.get_mpz_t()) ? engine::Rational(-1) : engine::Rational(1);
    // |k| size(base): beyond the limit for every |k| > kMaxRationalBits (size(base) >= 3 here).
    const mpz_class magnitude = abs(k);
    if (magnitude > engine::kMaxRationalBits) bound(magnitude.get_d() * static_cast<double>(engine::rationalBits(base)), "power", op);
    const unsigned long n = magnitude.get_ui();
    bound(static_cast<double>(n) * static_cast<double>(engine::rationalBits(base)), "power", op);
    engine::Rational out;
    mpz_pow_ui(out.get_num_mpz_t(), base.get_num_mpz_t(), n);
    mpz_pow_ui(out.get_den_mpz_t(), base.get_den_mpz_t(), n);
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
    const engine::DecimalRead got = i_ == from ? engine::DecimalRead::not_numeral : engine::readDecimal(s_.substr(from, i_ - from), v);
    if (got == engine::DecimalRead::too_large) fail(beyondLimit("the number " + std::string(s_.substr(from, std::min<size_t>(i_ - from, 40)))), from);
    if (got != engine::DecimalRead::ok) fail("expected a number", from);
    return v;
  }

  std::string_view s_;
  size_t i_ = 0;
  int depth_ = 0;
  double work_ = 0;  // the size bounds of the results so far
};

// The line of text a node was parsed from: the file's (Reader::lineOfText), or a --set value's
// ("--set KEY=VALUE" is parsed as "v = VALUE", and that is its node's source path); empty when
// there is none (an import, a catalog entry, an array given as numbers).
std::string sourceLine(const Reader& r, const toml::node& n) {
  const toml::source_region& src = n.source();
  if (const std::string_view line = r.lineOfText(src); !line.empty()) return std::string(line);
  if (!src.path || src.begin.line < 1) return {};
  const std::string& path = *src.path;
  if (path.rfind("--set ", 0) != 0) return {};
  const size_t eq = path.find('=', 6);
  if (eq == std::string::npos) return {};
  const std::string text = "v = " + path.substr(eq + 1);
  size_t from = 0;
  for (toml::source_index l = 1; l < src.begin.line; ++l) {
    from = text.find('\n', from);
    if (from == std::string::npos) return {};
    ++from;
  }
  return text.substr(from, text.find('\n', from) == std::string::npos ? std::string::npos : text.find('\n', from) - from);
}

enum class Numeral { none, found, too_large, unreadable };

// The numeral of a float node in the text it was parsed from, read exactly: none when the node
// has no text, unreadable when the text there is not a numeral of its value.
Numeral numeralInText(const Reader& r, const toml::node& n, engine::Rational& out, std::string& numeral) {
  const toml::source_region& src = n.source();
  const std::string text = sourceLine(r, n);
  if (text.empty() || src.begin.column < 1) return Numeral::none;
  // toml++ counts columns in code points.
  size_t i = 0;
  for (toml::source_index c = 1; c < src.begin.column && i < text.size(); ++c) {
    ++i;
    while (i < text.size() && (static_cast<unsigned char>(text[i]) & 0xC0) == 0x80) ++i;
  }
  size_t j = i;
  while (j < text.size() && (std::isdigit(static_cast<unsigned char>(text[j])) || std::strchr("+-._eE", text[j]))) ++j;
  numeral = text.substr(i, j - i);
  engine::Rational q;
  const engine::DecimalRead got = engine::readDecimal(numeral, q);
  if (got == engine::DecimalRead::too_large) return Numeral::too_large;
  if (got != engine::DecimalRead::ok) return Numeral::unreadable;
  std::string plain;
  for (char c : numeral)
    if (c != '_') plain += c;
  if (std::strtod(plain.c_str(), nullptr) != n.as_floating_point()->get()) return Numeral::unreadable;
  out = q;
  return Numeral::found;
}

}  // namespace

engine::Rational evaluateRational(std::string_view text) { return RationalParser(text).parse(); }

engine::Rational exactNumber(const Reader& r, const toml::node& n, const std::string& what) {
  if (auto i = n.as_integer()) return engine::Rational(mpz_class(std::to_string(i->get())));
  if (auto f = n.as_floating_point()) {
    if (!std::isfinite(f->get())) r.fail(n, what + " is not finite");
    engine::Rational q;
    std::string numeral;
    switch (numeralInText(r, n, q, numeral)) {
      case Numeral::found: return q;
      case Numeral::too_large: r.fail(n, beyondLimit(what + " " + numeral.substr(0, 40) + (numeral.size() > 40 ? "..." : "")));
      case Numeral::unreadable:
        r.fail(n, what + ": the numeral '" + numeral + "' at this place does not read as its value " + fmt(f->get()) +
                      ", so it cannot be taken exactly");
      case Numeral::none: break;
    }
    // No text (an import, a catalog entry): the shortest decimal that reads back as the double,
    // which is the numeral itself for one of at most 15 significant digits.
    return engine::shortestDecimal(f->get());
  }
  if (auto s = n.as_string()) {
    try {
      return evaluateRational(s->get());
    } catch (const ExpressionError& e) {
      r.fail(n.source(), what + " in exact mode: " + expressionMessage(e, s->get()), e.offset + 1);
    }
  }
  r.fail(n, what + " must be a number or an expression string, not " + typeName(n));
}

engine::Rational exactNumber(const Reader& r, const BulkArray& a, size_t row, size_t k, const std::string& what) {
  const double x = a.value(row, k);
  if (a.isInteger(row, k)) return engine::Rational(mpz_class(std::to_string(static_cast<long long>(x))));
  if (a.given) return engine::shortestDecimal(x);  // numbers without a text (an .npz, Python's arrays)
  const std::string numeral(r.numeral(a, row, k));
  engine::Rational v;
  switch (engine::readDecimal(numeral, v)) {
    case engine::DecimalRead::ok: return v;
    case engine::DecimalRead::too_large:
      r.fail(a, row, static_cast<long>(k), beyondLimit(what + " " + numeral.substr(0, 40) + (numeral.size() > 40 ? "..." : "")));
    case engine::DecimalRead::not_numeral: break;
  }
  r.fail(a, row, static_cast<long>(k), what + ": the numeral '" + numeral.substr(0, 40) + "' at this place cannot be read exactly");
}

}  // namespace flexure::scenes::detail
