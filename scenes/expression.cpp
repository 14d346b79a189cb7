#include "scenes/expression.h"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <string>

namespace flexure::scenes {

namespace {

using Node = CompiledExpression::Node;
using Op = CompiledExpression::Op;

const char* const kFunctions[] = {"sqrt", "sin", "cos", "tan", "asin", "acos", "atan", "exp", "log", "abs"};
constexpr int kNumFunctions = 10;

// f(v), f'(v), f''(v) of function `fn` at v.
void functionJet(int fn, double v, double& f0, double& f1, double& f2) {
  switch (fn) {
    case 0: f0 = std::sqrt(v), f1 = 0.5 / f0, f2 = -0.25 / (f0 * v); return;
    case 1: f0 = std::sin(v), f1 = std::cos(v), f2 = -f0; return;
    case 2: f0 = std::cos(v), f1 = -std::sin(v), f2 = -f0; return;
    case 3: f0 = std::tan(v), f1 = 1 + f0 * f0, f2 = 2 * f0 * f1; return;
    case 4: f0 = std::asin(v), f1 = 1 / std::sqrt(1 - v * v), f2 = v * f1 * f1 * f1; return;
    case 5: f0 = std::acos(v), f1 = -1 / std::sqrt(1 - v * v), f2 = v * f1 * f1 * f1; return;
    case 6: f0 = std::atan(v), f1 = 1 / (1 + v * v), f2 = -2 * v * f1 * f1; return;
    case 7: f0 = f1 = f2 = std::exp(v); return;
    case 8: f0 = std::log(v), f1 = 1 / v, f2 = -f1 * f1; return;
    default: f0 = std::fabs(v), f1 = v > 0 ? 1.0 : v < 0 ? -1.0 : 0.0, f2 = 0; return;
  }
}

// A second-order jet in up to 3 variables.
struct Jet {
  double v = 0, g[3] = {0, 0, 0}, h[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
};

Jet chain(const Jet& a, double f0, double f1, double f2) {
  Jet r;
  r.v = f0;
  for (int i = 0; i < 3; ++i) r.g[i] = f1 * a.g[i];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.h[3 * i + j] = f1 * a.h[3 * i + j] + f2 * a.g[i] * a.g[j];
  return r;
}

Jet mul(const Jet& a, const Jet& b) {
  Jet r;
  r.v = a.v * b.v;
  for (int i = 0; i < 3; ++i) r.g[i] = a.g[i] * b.v + b.g[i] * a.v;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      r.h[3 * i + j] = a.h[3 * i + j] * b.v + b.h[3 * i + j] * a.v + a.g[i] * b.g[j] + b.g[i] * a.g[j];
  return r;
}

Jet add(const Jet& a, const Jet& b, double sign) {
  Jet r;
  r.v = a.v + sign * b.v;
  for (int i = 0; i < 3; ++i) r.g[i] = a.g[i] + sign * b.g[i];
  for (int i = 0; i < 9; ++i) r.h[i] = a.h[i] + sign * b.h[i];
  return r;
}

// a^c for a constant exponent c.
Jet powConst(const Jet& a, double c) {
  if (c == 0) return chain(a, 1, 0, 0);
  const double f0 = std::pow(a.v, c);
  const double f1 = c * std::pow(a.v, c - 1);
  const double f2 = c == 1 ? 0.0 : c * (c - 1) * std::pow(a.v, c - 2);
  return chain(a, f0, f1, f2);
}

bool isConst(const std::vector<Node>& nodes, int i) { return nodes[static_cast<size_t>(i)].op == Op::Const; }

// One node's jet from its children's (already in `jets`): the nodes are in post-order, every
// child before its parent, so a forward sweep evaluates the whole expression without recursion
// however long it is.
Jet nodeJet(const std::vector<Node>& nodes, const Jet* jets, size_t i, const double* vars) {
  const Node& n = nodes[i];
  const Jet* a = n.a >= 0 ? &jets[n.a] : nullptr;
  const Jet* b = n.b >= 0 ? &jets[n.b] : nullptr;
  switch (n.op) {
    case Op::Const: {
      Jet r;
      r.v = n.value;
      return r;
    }
    case Op::Var: {
      Jet r;
      r.v = vars[n.index];
      r.g[n.index] = 1.0;
      return r;
    }
    case Op::Add: return add(*a, *b, 1.0);
    case Op::Sub: return add(*a, *b, -1.0);
    case Op::Mul: return mul(*a, *b);
    case Op::Div: {
      const double inv = 1.0 / b->v;
      return mul(*a, chain(*b, inv, -inv * inv, 2 * inv * inv * inv));
    }
    case Op::Pow: {
      if (isConst(nodes, n.b)) return powConst(*a, nodes[static_cast<size_t>(n.b)].value);
      // a^b = exp(b log a)
      const double la = std::log(a->v);
      const Jet e = mul(*b, chain(*a, la, 1 / a->v, -1 / (a->v * a->v)));
      const double ex = std::exp(e.v);
      return chain(e, ex, ex, ex);
    }
    case Op::Neg: {
      Jet r = *a;
      r.v = -r.v;
      for (double& g : r.g) g = -g;
      for (double& h : r.h) h = -h;
      return r;
    }
    case Op::Fn: {
      double f0, f1, f2;
      functionJet(n.index, a->v, f0, f1, f2);
      return chain(*a, f0, f1, f2);
    }
  }
  return Jet{};
}

Jet evalJet(const std::vector<Node>& nodes, const double* vars) {
  thread_local std::vector<Jet> jets;
  jets.resize(nodes.size());
  for (size_t i = 0; i < nodes.size(); ++i) jets[i] = nodeJet(nodes, jets.data(), i, vars);
  return jets.back();
}

}  // namespace

class ExpressionParser {
 public:
  ExpressionParser(std::string_view s, CompiledExpression& out) : s_(s), out_(out) {}

  int parse() {
    const int v = expression();
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
    explicit DepthGuard(ExpressionParser& p) : p(p) {
      if (++p.depth_ > kMaxDepth) p.fail("expression nested too deeply");
    }
    ~DepthGuard() { --p.depth_; }
    ExpressionParser& p;
  };

  const Node& node(int i) const { return out_.nodes_[static_cast<size_t>(i)]; }
  bool constant(int i) const { return node(i).op == Op::Const; }
  int push(Node n) {
    out_.nodes_.push_back(n);
    return static_cast<int>(out_.nodes_.size()) - 1;
  }
  int constantNode(double v) {
    Node n;
    n.value = v;
    return push(n);
  }
  // A binary node, folded when both sides are constant.
  int binary(Op op, int a, int b) {
    if (constant(a) && constant(b)) {
      const double x = node(a).value, y = node(b).value;
      switch (op) {
        case Op::Add: return constantNode(x + y);
        case Op::Sub: return constantNode(x - y);
        case Op::Mul: return constantNode(x * y);
        case Op::Div: return constantNode(x / y);
        default: return constantNode(std::pow(x, y));
      }
    }
    Node n;
    n.op = op, n.a = a, n.b = b;
    return push(n);
  }

  // expression := term (('+'|'-') term)*
  int expression() {
    DepthGuard guard(*this);
    int v = term();
    for (;;) {
      if (accept('+')) v = binary(Op::Add, v, term());
      else if (accept('-')) v = binary(Op::Sub, v, term());
      else return v;
    }
  }
  // term := unary (('*'|'/') unary)*
  int term() {
    int v = unary();
    for (;;) {
      if (accept('*')) {
        v = binary(Op::Mul, v, unary());
      } else if (accept('/')) {
        const size_t at = pos_;
        const int den = unary();
        if (constant(den) && node(den).value == 0.0) {
          pos_ = at;
          fail("division by zero");
        }
        v = binary(Op::Div, v, den);
      } else {
        return v;
      }
    }
  }
  // unary := ('-'|'+') unary | power
  int unary() {
    DepthGuard guard(*this);
    if (accept('-')) {
      const int a = unary();
      if (constant(a)) return constantNode(-node(a).value);
      Node n;
      n.op = Op::Neg, n.a = a;
      return push(n);
    }
    if (accept('+')) return unary();
    return power();
  }
  // power := primary ('^' unary)?
  int power() {
    const int base = primary();
    if (accept('^')) return binary(Op::Pow, base, unary());
    return base;
  }
  int primary() {
    skipSpace();
    if (pos_ >= s_.size()) fail("expected a number, a name or '('");
    const char c = s_[pos_];
    if (accept('(')) {
      const int v = expression();
      if (!accept(')')) fail("expected ')'");
      return v;
    }
    if (std::isdigit(static_cast<unsigned char>(c)) || c == '.') return number();
    if (std::isalpha(static_cast<unsigned char>(c))) return name();
    fail("unexpected '" + std::string(1, c) + "'");
  }
  int number() {
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
      fail("malformed number '" + excerpt(text) + "'");
    }
    return constantNode(v);
  }
  int name() {
    const size_t start = pos_;
    while (pos_ < s_.size() && (std::isalnum(static_cast<unsigned char>(s_[pos_])) || s_[pos_] == '_')) ++pos_;
    const std::string id(s_.substr(start, pos_ - start));
    for (size_t i = 0; i < out_.variables_.size(); ++i)
      if (id == out_.variables_[i]) {
        Node n;
        n.op = Op::Var, n.index = static_cast<int>(i);
        return push(n);
      }
    if (id == "pi") return constantNode(M_PI);
    if (id == "e") return constantNode(M_E);
    for (int f = 0; f < kNumFunctions; ++f) {
      if (id != kFunctions[f]) continue;
      if (!accept('(')) fail("expected '(' after " + id);  // a function's name: short
      const size_t arg_at = pos_;
      const int arg = expression();
      if (!accept(')')) fail("expected ')'");
      if (constant(arg)) {
        double f0, f1, f2;
        functionJet(f, node(arg).value, f0, f1, f2);
        if (!std::isfinite(f0)) {
          pos_ = arg_at;
          fail(id + "(" + std::to_string(node(arg).value) + ") is not a finite number");
        }
        return constantNode(f0);
      }
      Node n;
      n.op = Op::Fn, n.index = f, n.a = arg;
      return push(n);
    }
    pos_ = start;
    std::string known = "pi, e, sqrt, sin, cos, tan, asin, acos, atan, exp, log, abs";
    for (auto v = out_.variables_.rbegin(); v != out_.variables_.rend(); ++v) known = *v + ", " + known;
    fail("unknown name '" + excerpt(id) + "' (known: " + known + ")");
  }

  std::string_view s_;
  CompiledExpression& out_;
  size_t pos_ = 0;
  int depth_ = 0;
};

CompiledExpression::CompiledExpression(std::string_view text, std::vector<std::string> variables)
    : text_(text), variables_(std::move(variables)) {
  if (variables_.size() > 3) throw ExpressionError("at most 3 variables", 0);
  ExpressionParser p(text, *this);
  const int root = p.parse();
  // Keep only what the root depends on (constant folding leaves dead nodes), in post-order:
  // the root last.
  std::vector<int> index(nodes_.size(), -1);
  index[static_cast<size_t>(root)] = 0;
  for (int i = root; i >= 0; --i) {
    const Node& n = nodes_[static_cast<size_t>(i)];
    if (index[static_cast<size_t>(i)] < 0) continue;
    if (n.a >= 0) index[static_cast<size_t>(n.a)] = 0;
    if (n.b >= 0) index[static_cast<size_t>(n.b)] = 0;
  }
  std::vector<Node> live;
  for (int i = 0; i <= root; ++i) {
    if (index[static_cast<size_t>(i)] < 0) continue;
    Node n = nodes_[static_cast<size_t>(i)];
    if (n.a >= 0) n.a = index[static_cast<size_t>(n.a)];
    if (n.b >= 0) n.b = index[static_cast<size_t>(n.b)];
    index[static_cast<size_t>(i)] = static_cast<int>(live.size());
    live.push_back(n);
  }
  nodes_ = std::move(live);
}

double CompiledExpression::value(const double* vars) const { return evalJet(nodes_, vars).v; }

void CompiledExpression::evaluate(const double* vars, double* f, double* gradient, double* hessian) const {
  const Jet j = evalJet(nodes_, vars);
  const int n = numVariables();
  *f = j.v;
  if (gradient)
    for (int i = 0; i < n; ++i) gradient[i] = j.g[i];
  if (hessian)
    for (int r = 0; r < n; ++r)
      for (int c = 0; c < n; ++c) hessian[r * n + c] = j.h[3 * r + c];
}

bool CompiledExpression::usesVariable(int i) const {
  for (const Node& n : nodes_)
    if (n.op == Op::Var && n.index == i) return true;
  return false;
}

double evaluateExpression(std::string_view text) {
  const CompiledExpression e(text, {});
  const double v = e.value(nullptr);
  if (!std::isfinite(v)) throw ExpressionError("the expression is not a finite number", 0);
  return v;
}

}  // namespace flexure::scenes
