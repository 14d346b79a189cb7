#include "sweep/where.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>

#include "scenes/keys.h"

namespace flexure::sweep {

using Json = nlohmann::ordered_json;

struct Where::Node {
  enum Kind { Literal, Field, Not, Neg, And, Or, Compare, Arith } kind;
  Json value;                     // Literal
  std::vector<std::string> path;  // Field
  std::string op;                 // Compare, Arith
  std::unique_ptr<Node> a, b;
  int height = 1;  // of the tree below and including this node
};

namespace {

using Node = Where::Node;
using NodePtr = std::unique_ptr<Node>;

class Parser {
 public:
  Parser(const std::string& text, const std::vector<std::string>& fields, std::vector<std::string>& used)
      : s_(text), fields_(fields), used_(used) {}

  NodePtr parse() {
    NodePtr n = orExpr();
    skip();
    if (i_ < s_.size()) fail("unexpected '" + s_.substr(i_, 1) + "'");
    return n;
  }

 private:
  [[noreturn]] void fail(const std::string& m) const { throw WhereError(i_, m); }
  void skip() {
    while (i_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[i_]))) ++i_;
  }
  static bool identChar(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }
  // The keyword `w` (a whole word) or the symbol `sym`, consumed when present.
  bool accept(const char* w, const char* sym = nullptr) {
    skip();
    const std::string word(w);
    if (s_.compare(i_, word.size(), word) == 0 && (i_ + word.size() >= s_.size() || !identChar(s_[i_ + word.size()]))) {
      i_ += word.size();
      return true;
    }
    if (sym && s_.compare(i_, std::string(sym).size(), sym) == 0) {
      i_ += std::string(sym).size();
      return true;
    }
    return false;
  }
  // The tree's height is bounded too: a chain of left-associative operators (a - b - c ...)
  // deepens it by one per operator without any nesting, and the evaluation recurses (the
  // fuzzer's 37 KB chain overflowed the stack).
  static constexpr int kMaxHeight = 2500;
  NodePtr make(Node::Kind k, NodePtr a = nullptr, NodePtr b = nullptr, std::string op = "") {
    auto n = std::make_unique<Node>();
    n->height = 1 + std::max(a ? a->height : 0, b ? b->height : 0);
    if (n->height > kMaxHeight)
      fail("more than " + std::to_string(kMaxHeight) + " operations in a row: split the expression");
    n->kind = k, n->a = std::move(a), n->b = std::move(b), n->op = std::move(op);
    return n;
  }
  NodePtr orExpr() {
    NodePtr n = andExpr();
    while (accept("or", "||")) n = make(Node::Or, std::move(n), andExpr());
    return n;
  }
  NodePtr andExpr() {
    NodePtr n = notExpr();
    while (accept("and", "&&")) n = make(Node::And, std::move(n), notExpr());
    return n;
  }
  // Nesting (parentheses, not, unary minus) is bounded: the parser and the evaluation recurse.
  struct Deeper {
    Parser& p;
    explicit Deeper(Parser& parser) : p(parser) {
      if (++p.depth_ > kMaxDepth) p.fail("nested more than " + std::to_string(kMaxDepth) + " levels deep");
    }
    ~Deeper() { --p.depth_; }
  };
  static constexpr int kMaxDepth = 100;

  NodePtr notExpr() {
    skip();
    if (s_.compare(i_, 2, "!=") != 0 && accept("not", "!")) {
      Deeper d(*this);
      return make(Node::Not, notExpr());
    }
    return compare();
  }
  NodePtr compare() {
    NodePtr n = sum();
    skip();
    for (const char* op : {"==", "!=", "<=", ">=", "<", ">"}) {
      if (s_.compare(i_, std::string(op).size(), op) == 0) {
        i_ += std::string(op).size();
        return make(Node::Compare, std::move(n), sum(), op);
      }
    }
    if (i_ < s_.size() && s_[i_] == '=') fail("'=' compares nothing: write '=='");
    return n;
  }
  // One level of left-associative arithmetic: operands from `next`, operators from `ops`.
  NodePtr arithmetic(const std::string& ops, NodePtr (Parser::*next)()) {
    NodePtr n = (this->*next)();
    for (;;) {
      skip();
      if (i_ >= s_.size() || ops.find(s_[i_]) == std::string::npos) return n;
      const std::string op(1, s_[i_++]);
      n = make(Node::Arith, std::move(n), (this->*next)(), op);
    }
  }
  NodePtr sum() { return arithmetic("+-", &Parser::product); }
  NodePtr product() { return arithmetic("*/", &Parser::unary); }
  NodePtr unary() {
    skip();
    if (i_ < s_.size() && s_[i_] == '-') {
      Deeper d(*this);
      ++i_;
      return make(Node::Neg, unary());
    }
    return primary();
  }
  NodePtr primary() {
    skip();
    if (i_ >= s_.size()) fail("the expression ends where a value is expected");
    const char c = s_[i_];
    if (c == '(') {
      Deeper d(*this);
      ++i_;
      NodePtr n = orExpr();
      skip();
      if (i_ >= s_.size() || s_[i_] != ')') fail("expected ')'");
      ++i_;
      return n;
    }
    auto lit = [](Json v) {
      auto n = std::make_unique<Node>();
      n->kind = Node::Literal, n->value = std::move(v);
      return n;
    };
    if (c == '\'' || c == '"') {
      const size_t start = i_++;
      std::string v;
      while (i_ < s_.size() && s_[i_] != c) v += s_[i_++];
      if (i_ >= s_.size()) {
        i_ = start;
        fail("the string is not closed");
      }
      ++i_;
      return lit(v);
    }
    if (std::isdigit(static_cast<unsigned char>(c)) || c == '.') {
      const char* begin = s_.c_str() + i_;
      char* end = nullptr;
      const double v = std::strtod(begin, &end);
      if (end == begin) fail("not a number");
      i_ += static_cast<size_t>(end - begin);
      return lit(v);
    }
    if (!identChar(c)) fail("unexpected '" + std::string(1, c) + "'");
    const size_t start = i_;
    while (i_ < s_.size() && (identChar(s_[i_]) || s_[i_] == '.')) ++i_;
    const std::string name = s_.substr(start, i_ - start);
    if (name == "true") return lit(true);
    if (name == "false") return lit(false);
    if (name == "null") return lit(nullptr);
    if (std::find(fields_.begin(), fields_.end(), name) == fields_.end()) {
      std::string best;
      int best_d = 4;
      for (const auto& f : fields_) {
        const int d = scenes::editDistance(name, f);
        if (d < best_d) best_d = d, best = f;
      }
      i_ = start;
      fail("unknown field '" + name + "'" + (best.empty() ? "" : " (did you mean '" + best + "'?)"));
    }
    if (std::find(used_.begin(), used_.end(), name) == used_.end()) used_.push_back(name);
    auto n = std::make_unique<Node>();
    n->kind = Node::Field;
    for (size_t at = 0;;) {
      const size_t dot = name.find('.', at);
      n->path.push_back(name.substr(at, dot == std::string::npos ? std::string::npos : dot - at));
      if (dot == std::string::npos) break;
      at = dot + 1;
    }
    return n;
  }

  const std::string& s_;
  const std::vector<std::string>& fields_;
  std::vector<std::string>& used_;
  size_t i_ = 0;
  int depth_ = 0;
};

bool truth(const Json& v) {
  if (v.is_boolean()) return v.get<bool>();
  if (v.is_number()) return v.get<double>() != 0.0;
  if (v.is_string()) return !v.get_ref<const std::string&>().empty();
  if (v.is_null()) return false;
  return !v.empty();
}

Json eval(const Node& n, const Json& item) {
  switch (n.kind) {
    case Node::Literal: return n.value;
    case Node::Field: {
      const Json* at = &item;
      for (const auto& k : n.path) {
        if (!at->is_object()) return nullptr;
        const auto it = at->find(k);
        if (it == at->end()) return nullptr;
        at = &*it;
      }
      return *at;
    }
    case Node::Not: return !truth(eval(*n.a, item));
    case Node::Neg: {
      const Json v = eval(*n.a, item);
      return v.is_number() ? Json(-v.get<double>()) : Json(nullptr);
    }
    case Node::And: return truth(eval(*n.a, item)) && truth(eval(*n.b, item));
    case Node::Or: return truth(eval(*n.a, item)) || truth(eval(*n.b, item));
    case Node::Arith: {
      const Json a = eval(*n.a, item), b = eval(*n.b, item);
      if (!a.is_number() || !b.is_number()) return nullptr;
      const double x = a.get<double>(), y = b.get<double>();
      switch (n.op[0]) {
        case '+': return x + y;
        case '-': return x - y;
        case '*': return x * y;
        default: return x / y;
      }
    }
    case Node::Compare: {
      const Json a = eval(*n.a, item), b = eval(*n.b, item);
      const std::string& op = n.op;
      int order = 0;  // -1, 0, 1; 2: not ordered
      if (a.is_number() && b.is_number()) {
        const double x = a.get<double>(), y = b.get<double>();
        order = std::isnan(x) || std::isnan(y) ? 2 : x < y ? -1 : x > y ? 1 : 0;
      } else if (a.is_string() && b.is_string()) {
        const int c = a.get_ref<const std::string&>().compare(b.get_ref<const std::string&>());
        order = c < 0 ? -1 : c > 0 ? 1 : 0;
      } else if (a.type() == b.type() && (a.is_boolean() || a.is_null())) {
        if (op != "==" && op != "!=") return false;
        order = a == b ? 0 : 2;
      } else {
        return op == "!=";
      }
      if (op == "==") return order == 0;
      if (op == "!=") return order != 0;
      if (order == 2) return false;
      if (op == "<") return order < 0;
      if (op == "<=") return order <= 0;
      if (op == ">") return order > 0;
      return order >= 0;
    }
  }
  return nullptr;
}

void collect(const Json& j, const std::string& prefix, std::vector<std::string>& out) {
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string path = prefix.empty() ? it.key() : prefix + "." + it.key();
    out.push_back(path);
    if (it->is_object()) collect(*it, path, out);
  }
}

}  // namespace

Where::Where(std::string text, const std::vector<std::string>& fields) : text_(std::move(text)) {
  root_ = Parser(text_, fields, used_).parse();
}
Where::~Where() = default;
Where::Where(Where&&) noexcept = default;
Where& Where::operator=(Where&&) noexcept = default;

bool Where::operator()(const Json& item) const { return truth(eval(*root_, item)); }

std::vector<std::string> fieldPaths(const Json& j) {
  std::vector<std::string> out;
  if (j.is_object()) collect(j, "", out);
  return out;
}

}  // namespace flexure::sweep
