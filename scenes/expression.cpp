#include "scenes/expression.h"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <string>

namespace flexure::scenes {

namespace {

class Parser {
 public:
  explicit Parser(std::string_view s) : s_(s) {}

  double parse() {
    const double v = expression();
    skipSpace();
    if (pos_ < s_.size()) fail("unexpected '" + std::string(1, s_[pos_]) + "'");
    return v;
  }

 private:
  static constexpr int kMaxDepth = 200;

  [[noreturn]] void fail(const std::string& message) const {
    throw ExpressionError(message, static_cast<int>(pos_));
  }
  void skipSpace() {
    while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_]))) ++pos_;
  }
  bool accept(char c) {
    skipSpace();
    if (pos_ < s_.size() && s_[pos_] == c) {
      ++pos_;
      return true;
    }
    return false;
  }
  struct DepthGuard {
    explicit DepthGuard(Parser& p) : p(p) {
      if (++p.depth_ > kMaxDepth) p.fail("expression nested too deeply");
    }
    ~DepthGuard() { --p.depth_; }
    Parser& p;
  };

  // expression := term (('+'|'-') term)*
  double expression() {
    DepthGuard guard(*this);
    double v = term();
    for (;;) {
      if (accept('+')) v += term();
      else if (accept('-')) v -= term();
      else return v;
    }
  }
  // term := unary (('*'|'/') unary)*
  double term() {
    double v = unary();
    for (;;) {
      if (accept('*')) {
        v *= unary();
      } else if (accept('/')) {
        const size_t at = pos_;
        const double den = unary();
        if (den == 0.0) {
          pos_ = at;
          fail("division by zero");
        }
        v /= den;
      } else {
        return v;
      }
    }
  }
  // unary := ('-'|'+') unary | power
  double unary() {
    DepthGuard guard(*this);
    if (accept('-')) return -unary();
    if (accept('+')) return unary();
    return power();
  }
  // power := primary ('^' unary)?
  double power() {
    const double base = primary();
    if (accept('^')) return std::pow(base, unary());
    return base;
  }
  double primary() {
    skipSpace();
    if (pos_ >= s_.size()) fail("expected a number, a name or '('");
    const char c = s_[pos_];
    if (accept('(')) {
      const double v = expression();
      if (!accept(')')) fail("expected ')'");
      return v;
    }
    if (std::isdigit(static_cast<unsigned char>(c)) || c == '.') return number();
    if (std::isalpha(static_cast<unsigned char>(c))) return name();
    fail("unexpected '" + std::string(1, c) + "'");
  }
  double number() {
    const size_t start = pos_;
    while (pos_ < s_.size() && (std::isdigit(static_cast<unsigned char>(s_[pos_])) || s_[pos_] == '.')) ++pos_;
    if (pos_ < s_.size() && (s_[pos_] == 'e' || s_[pos_] == 'E')) {
      size_t p = pos_ + 1;
      if (p < s_.size() && (s_[p] == '+' || s_[p] == '-')) ++p;
      if (p < s_.size() && std::isdigit(static_cast<unsigned char>(s_[p]))) {
        pos_ = p;
        while (pos_ < s_.size() && std::isdigit(static_cast<unsigned char>(s_[pos_]))) ++pos_;
      }
    }
    const std::string text(s_.substr(start, pos_ - start));
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (end != text.c_str() + text.size() || text == ".") {
      pos_ = start;
      fail("malformed number '" + text + "'");
    }
    return v;
  }
  double name() {
    const size_t start = pos_;
    while (pos_ < s_.size() && (std::isalnum(static_cast<unsigned char>(s_[pos_])) || s_[pos_] == '_')) ++pos_;
    const std::string id(s_.substr(start, pos_ - start));
    if (id == "pi") return M_PI;
    if (id == "e") return M_E;
    using Fn = double (*)(double);
    static const struct { const char* name; Fn fn; } functions[] = {
        {"sqrt", [](double v) { return std::sqrt(v); }}, {"sin", [](double v) { return std::sin(v); }},
        {"cos", [](double v) { return std::cos(v); }},   {"tan", [](double v) { return std::tan(v); }},
        {"asin", [](double v) { return std::asin(v); }}, {"acos", [](double v) { return std::acos(v); }},
        {"atan", [](double v) { return std::atan(v); }}, {"exp", [](double v) { return std::exp(v); }},
        {"log", [](double v) { return std::log(v); }},   {"abs", [](double v) { return std::fabs(v); }},
    };
    for (const auto& f : functions) {
      if (id != f.name) continue;
      if (!accept('(')) fail("expected '(' after " + id);
      const size_t arg_at = pos_;
      const double arg = expression();
      if (!accept(')')) fail("expected ')'");
      const double v = f.fn(arg);
      if (!std::isfinite(v)) {
        pos_ = arg_at;
        fail(id + "(" + std::to_string(arg) + ") is not a finite number");
      }
      return v;
    }
    pos_ = start;
    fail("unknown name '" + id + "' (known: pi, e, sqrt, sin, cos, tan, asin, acos, atan, exp, log, abs)");
  }

  std::string_view s_;
  size_t pos_ = 0;
  int depth_ = 0;
};

}  // namespace

double evaluateExpression(std::string_view text) {
  Parser p(text);
  const double v = p.parse();
  if (!std::isfinite(v)) throw ExpressionError("the expression is not a finite number", 0);
  return v;
}

}  // namespace flexure::scenes
