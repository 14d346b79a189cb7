// The families a sweep reads (sweep.h, openFamily): graph6/sparse6 streams, lists and
// directories of scene files, and scenes with a [sweep] table.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "engine/resources.h"
#include "scenes/expression.h"
#include "scenes/importers.h"
#include "scenes/keys.h"
#include "scenes/scene_document.h"
#include "scenes/toml_text.h"
#include "sweep/sweep.h"

namespace flexure::sweep {

using scenes::SceneError;

std::uint64_t itemSeed(std::uint64_t seed, long long graph, int realization) {
  auto mix = [](std::uint64_t x) {  // splitmix64's finalizer
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
  };
  std::uint64_t h = mix(seed);
  h = mix(h ^ static_cast<std::uint64_t>(graph));
  h = mix(h ^ static_cast<std::uint64_t>(realization));
  return h >> 1;
}

namespace {

// ---- graph6/sparse6 streams ----------------------------------------------------------------

class GraphFamily : public Family {
 public:
  GraphFamily(const std::string& input, const Options& o, std::istream* in)
      : name_(input == "-" ? "stdin" : input), options_(o) {
    if (input == "-") {
      in_ = in ? in : &std::cin;
    } else {
      file_.open(input, std::ios::binary);
      if (!file_) throw SceneError(input, 1, 1, "cannot open the graph file");
      in_ = &file_;
    }
  }

  // The next line into line_ (without its newline); false at the end. A line is refused as
  // soon as it is longer than the limit, before the rest of it is read (a stream without a
  // newline would grow without bound).
  bool boundedLine() {
    constexpr std::size_t kLimit = std::size_t{64} << 20;
    line_.clear();
    std::streambuf* sb = in_->rdbuf();
    for (;;) {
      const auto c = sb->sbumpc();
      if (c == std::char_traits<char>::eof()) {
        if (line_.empty()) {
          in_->setstate(std::ios::eofbit);
          return false;
        }
        return true;
      }
      if (c == '\n') return true;
      if (line_.size() >= kLimit)
        throw SceneError(name_, line_no_ + 1, 1, "a graph6/sparse6 line longer than 64 MiB");
      line_ += static_cast<char>(c);
    }
  }

  bool next(Item& item) override {
    if (r_ == 0 || r_ >= options_.realizations) {
      for (;;) {
        if (!boundedLine()) {
          if (in_->bad()) throw SceneError(name_, line_no_ + 1, 1, "cannot read the graph stream");
          return false;
        }
        ++line_no_;
        if (!line_.empty() && line_.back() == '\r') line_.pop_back();
        for (const char* header : {">>graph6<<", ">>sparse6<<"})
          if (line_.rfind(header, 0) == 0) line_.erase(0, std::string(header).size());
        if (!line_.empty()) break;
      }
      ++graph_;
      r_ = 0;
    }
    item = Item{};
    item.id = next_id_++;
    item.input = name_ + ":" + std::to_string(line_no_);
    item.payload = line_;
    item.line = line_no_;
    item.index = graph_;
    item.extra["graph6"] = line_;
    if (options_.realizations > 1) item.extra["realization"] = r_;
    item.extra["realization_seed"] = itemSeed(options_.seed, graph_, r_);
    ++r_;
    return true;
  }

  scenes::Scene load(const Item& item) const override {
    std::vector<scenes::ImportedGraph> g;
    try {
      g = scenes::readGraph6(item.payload, name_);
    } catch (const SceneError& e) {  // the line's own column, at the stream's line
      throw SceneError(name_, item.line, e.column, e.message);
    }
    if (g.size() != 1) throw SceneError(name_, item.line, 1, "expected one graph on the line");
    if (g[0].edges.empty()) throw SceneError(name_, item.line, 1, "the graph has no edge");
    return scenes::loadGraphScene(g[0], options_.dimension, item.extra["realization_seed"].get<std::uint64_t>(), item.input,
                                  item.input, options_.overrides);
  }

 private:
  std::string name_;
  Options options_;
  std::ifstream file_;
  std::istream* in_ = nullptr;
  std::string line_;
  int line_no_ = 0;
  long long graph_ = -1, next_id_ = 0;
  int r_ = 0;
};

// ---- scene files ---------------------------------------------------------------------------

class SceneListFamily : public Family {
 public:
  SceneListFamily(std::vector<std::string> files, const Options& o)
      : files_(std::move(files)), options_(o) {}

  bool next(Item& item) override {
    if (at_ >= files_.size()) return false;
    item = Item{};
    item.id = static_cast<long long>(at_);
    item.input = files_[at_];
    item.payload = files_[at_];
    ++at_;
    return true;
  }

  scenes::Scene load(const Item& item) const override { return scenes::loadScene(item.payload, options_.overrides); }

 private:
  std::vector<std::string> files_;
  Options options_;
  size_t at_ = 0;
};

std::unique_ptr<Family> directoryFamily(const std::string& dir, const Options& o) {
  std::vector<std::string> files;
  std::error_code ec;
  for (auto it = std::filesystem::recursive_directory_iterator(dir, ec); !ec && it != decltype(it){}; it.increment(ec)) {
    if (!it->is_regular_file(ec)) continue;
    std::string ext = it->path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
    if (ext == ".toml") files.push_back(it->path().string());
  }
  if (ec) throw SceneError(dir, 1, 1, "cannot list the directory: " + ec.message());
  std::sort(files.begin(), files.end());
  if (files.empty()) throw SceneError(dir, 1, 1, "the directory holds no .toml scene files");
  return std::make_unique<SceneListFamily>(std::move(files), o);
}

std::unique_ptr<Family> listFamily(const std::string& list, const Options& o) {
  std::ifstream in(list, std::ios::binary);
  if (!in) throw SceneError(list, 1, 1, "cannot open the list of scene files");
  const std::string dir = list.find('/') == std::string::npos ? "" : list.substr(0, list.find_last_of('/') + 1);
  std::vector<std::string> files;
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const size_t b = line.find_first_not_of(" \t"), e = line.find_last_not_of(" \t");
    if (b == std::string::npos || line[b] == '#') continue;
    std::string f = line.substr(b, e - b + 1);
    if (f.find('\0') != std::string::npos || std::any_of(f.begin(), f.end(), [](char c) { return static_cast<unsigned char>(c) < 0x20; }))
      throw SceneError(list, n, static_cast<int>(b) + 1, "a control character in a file name");
    if (f[0] != '/' && !scenes::catalogArgument(f)) f = dir + f;
    files.push_back(f);
  }
  if (in.bad()) throw SceneError(list, 1, 1, "cannot read the list of scene files");
  if (files.empty()) throw SceneError(list, 1, 1, "the list names no scene file (one per line; # starts a comment)");
  return std::make_unique<SceneListFamily>(std::move(files), o);
}

// ---- a scene with a [sweep] table ----------------------------------------------------------

// A swept key: its path (tables, then array positions from 0) and its values.
struct Axis {
  std::string key;  // as written, e.g. "system.vertices[3][1]"
  struct Step {
    std::string name;
    long long index = -1;  // an array position, or -1 for a table key
  };
  std::vector<Step> path;
  toml::array values;  // one element per value
  toml::source_region where;
};

[[noreturn]] void failAt(const std::string& file, const toml::source_region& r, const std::string& m) {
  // A bounded message: the keys and values it quotes may be megabytes (scenes/excerpt.h).
  throw SceneError(file, std::max<int>(1, static_cast<int>(r.begin.line)), std::max<int>(1, static_cast<int>(r.begin.column)),
                   scenes::boundedMessage(m));
}

std::vector<Axis::Step> parseKeyPath(const std::string& key, const std::string& file, const toml::source_region& r) {
  std::vector<Axis::Step> path;
  size_t i = 0;
  auto bad = [&](const std::string& why) { failAt(file, r, "swept key '" + key + "': " + why); };
  while (i < key.size()) {
    size_t j = i;
    while (j < key.size() && key[j] != '.' && key[j] != '[') ++j;
    if (j == i) bad("an empty part");
    path.push_back({key.substr(i, j - i), -1});
    i = j;
    while (i < key.size() && key[i] == '[') {
      const size_t close = key.find(']', i);
      if (close == std::string::npos) bad("'[' without ']'");
      const std::string n = key.substr(i + 1, close - i - 1);
      if (n.empty() || n.size() > 9 || !std::all_of(n.begin(), n.end(), ::isdigit)) bad("an array position is a number from 0");
      path.push_back({"", std::stoll(n)});
      i = close + 1;
    }
    if (i < key.size()) {
      if (key[i] != '.') bad("expected '.' or '['");
      if (++i == key.size()) bad("ends with '.'");
    }
  }
  return path;
}

// Numbers from an expression (scenes/expression.h: "2*pi", "sqrt(3)/2").
double number(const std::string& text, const std::string& file, const toml::source_region& r) {
  try {
    return scenes::evaluateExpression(text);
  } catch (const std::exception& e) {
    failAt(file, r, "'" + text + "': " + e.what());
  }
}

constexpr long long kMaxItems = 1'000'000'000;

// The values of one swept key: an array (its elements), "A..B" (the integers from A to B),
// "linspace(A, B, N)", "logspace(A, B, N)" (10^A to 10^B), or one value. `most`: the count the
// other keys' combinations leave (refused before a value is made when there are more).
// `count_only`: only the count, from the range as written, into *count_only (no value made).
toml::array axisValues(const toml::node& n, const std::string& file, long long most, long long* count_only = nullptr) {
  toml::array out;
  const toml::source_region& r = n.source();
  const auto reserve = [&](long long count) {  // false: counted only, make nothing
    if (count > most) failAt(file, r, "the [sweep] has more than 10^9 combinations");
    if (count_only) {
      *count_only = count;
      return false;
    }
    engine::requireMemory("the [sweep]'s " + std::to_string(count) + " values", 64.0 * static_cast<double>(count));
    return true;
  };
  if (const toml::array* a = n.as_array()) {
    if (a->empty()) failAt(file, r, "a swept key needs at least one value");
    if (!reserve(static_cast<long long>(a->size()))) return out;
    return *a;
  }
  const std::string* s = n.as_string() ? &n.as_string()->get() : nullptr;
  auto trim = [](std::string t) {
    const size_t b = t.find_first_not_of(" \t"), e = t.find_last_not_of(" \t");
    return b == std::string::npos ? std::string() : t.substr(b, e - b + 1);
  };
  if (s) {
    const std::string t = trim(*s);
    const size_t dots = t.find("..");
    const bool space = t.rfind("linspace(", 0) == 0, logs = t.rfind("logspace(", 0) == 0;
    if ((space || logs) && t.back() == ')') {
      std::vector<std::string> args;
      int depth = 0;
      std::string cur;
      for (size_t i = 9; i + 1 < t.size(); ++i) {
        const char c = t[i];
        if (c == '(') ++depth;
        if (c == ')') --depth;
        if (c == ',' && depth == 0) args.push_back(trim(cur)), cur.clear();
        else cur += c;
      }
      args.push_back(trim(cur));
      if (args.size() != 3) failAt(file, r, "'" + t + "': linspace and logspace take (start, stop, count)");
      const double a = number(args[0], file, r), b = number(args[1], file, r), c = number(args[2], file, r);
      if (c != std::floor(c) || c < 1 || c > 10'000'000) failAt(file, r, "'" + t + "': the count is a whole number 1..10000000");
      const long long count = static_cast<long long>(c);
      if (!reserve(count)) return out;
      for (long long i = 0; i < count; ++i) {
        // (a (N-1-i) + b i) / (N-1): the ends exact, and 0.1 rather than 0.09999999999999998.
        const double x = count == 1 ? a : (a * static_cast<double>(count - 1 - i) + b * static_cast<double>(i)) / static_cast<double>(count - 1);
        out.push_back(logs ? std::pow(10.0, x) : x);
      }
      return out;
    }
    if (dots != std::string::npos && dots > 0) {
      const std::string a = trim(t.substr(0, dots)), b = trim(t.substr(dots + 2));
      auto integer = [&](const std::string& x, long long& v) {
        if (x.empty() || x.size() > 18) return false;
        size_t i = x[0] == '-' ? 1 : 0;
        if (i == x.size() || !std::all_of(x.begin() + static_cast<long>(i), x.end(), ::isdigit)) return false;
        v = std::stoll(x);
        return true;
      };
      long long lo = 0, hi = 0;
      if (integer(a, lo) && integer(b, hi)) {
        if (hi < lo) failAt(file, r, "'" + t + "': the range runs from a smaller to a larger integer");
        if (hi - lo >= 10'000'000) failAt(file, r, "'" + t + "': more than 10000000 values");
        if (!reserve(hi - lo + 1)) return out;
        for (long long v = lo; v <= hi; ++v) out.push_back(static_cast<int64_t>(v));
        return out;
      }
    }
  }
  if (!reserve(1)) return out;
  out.push_back(n);
  return out;
}

// The swept keys of `t` (its subtables' too), without their values, each with its node.
void sweptKeys(const toml::table& t, const std::string& prefix, const std::string& file,
               std::vector<std::pair<Axis, const toml::node*>>& found) {
  for (const auto& [k, v] : t) {
    const std::string key = prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
    if (const toml::table* sub = v.as_table()) {
      sweptKeys(*sub, key, file, found);
      continue;
    }
    Axis a;
    a.key = key;
    a.where = k.source().begin.line ? k.source() : v.source();
    a.path = parseKeyPath(key, file, a.where);
    found.emplace_back(std::move(a), &v);
  }
}

// The swept keys of `t`, each with its values; `product`: the combinations so far. Every key's
// count and their product come first, from the ranges as written: a [sweep] with too many
// combinations is refused before any key's values are made.
void flatten(const toml::table& t, const std::string& prefix, const std::string& file, std::vector<Axis>& axes,
             long long& product) {
  std::vector<std::pair<Axis, const toml::node*>> found;
  sweptKeys(t, prefix, file, found);
  for (const auto& [a, v] : found) {
    long long count = 0;
    axisValues(*v, file, kMaxItems / product, &count);
    product *= count;
  }
  for (auto& [a, v] : found) {
    a.values = axisValues(*v, file, kMaxItems);
    axes.push_back(std::move(a));
  }
}

// The node `path` names in `doc` (tables created on the way, array positions must exist), set
// to `value`. Returns "" or what is wrong.
std::string setAt(toml::table& doc, const std::vector<Axis::Step>& path, const toml::node& value) {
  toml::node* at = &doc;
  for (size_t i = 0; i < path.size(); ++i) {
    const Axis::Step& s = path[i];
    const bool last = i + 1 == path.size();
    if (s.index < 0) {
      toml::table* t = at->as_table();
      if (!t) return "'" + s.name + "' is inside something that is not a table";
      if (last) {
        t->insert_or_assign(s.name, value);
        return "";
      }
      toml::node* n = t->get(s.name);
      if (!n) {
        if (path[i + 1].index >= 0) return "the scene has no '" + s.name + "'";
        n = &t->insert_or_assign(s.name, toml::table{}).first->second;
      }
      at = n;
    } else {
      toml::array* a = at->as_array();
      if (!a) return "position [" + std::to_string(s.index) + "] of something that is not an array";
      if (s.index >= static_cast<long long>(a->size()))
        return "position [" + std::to_string(s.index) + "] of an array of " + std::to_string(a->size());
      if (last) {
        a->replace(a->begin() + s.index, value);
        return "";
      }
      at = &(*a)[static_cast<size_t>(s.index)];
    }
  }
  return "";
}

class ParameterFamily : public Family {
 public:
  ParameterFamily(const std::string& file, toml::table doc, std::vector<Axis> axes, const Options& o)
      : file_(file), doc_(std::move(doc)), axes_(std::move(axes)), options_(o) {
    total_ = 1;
    for (const Axis& a : axes_) {
      total_ *= static_cast<long long>(a.values.size());
      if (total_ > kMaxItems) failAt(file_, a.where, "the [sweep] has more than 10^9 combinations");
    }
    // Every key must name a place in the scene, checked at once rather than on every item.
    for (const Axis& a : axes_) {
      toml::table copy = doc_;
      const std::string bad = setAt(copy, a.path, *a.values.get(0));
      if (!bad.empty()) failAt(file_, a.where, "swept key '" + a.key + "': " + bad);
      if (a.path.size() >= 2 && a.path[1].index < 0 && a.path[0].index < 0) {
        const std::string& table = a.path[0].name;
        std::string type;
        if (table == "system")
          if (const toml::node* t = doc_["system"]["type"].node(); t && t->is_string()) type = t->as_string()->get();
        if (table == "output") continue;
        const auto known = scenes::keysOf(table, type);
        if (!known.empty() && std::find(known.begin(), known.end(), a.path[1].name) == known.end())
          failAt(file_, a.where, "swept key '" + a.key + "': [" + table + "] has no key '" + a.path[1].name + "'");
      }
    }
  }

  bool next(Item& item) override {
    if (at_ >= total_) return false;
    item = Item{};
    item.id = at_;
    item.index = at_;
    item.input = file_;
    Json params = Json::object();
    const std::vector<size_t> choice = choiceOf(at_);
    for (size_t k = 0; k < axes_.size(); ++k) params[axes_[k].key] = jsonOf(*axes_[k].values.get(choice[k]));
    item.extra["parameters"] = std::move(params);
    ++at_;
    return true;
  }

  scenes::Scene load(const Item& item) const override {
    toml::table doc = doc_;
    const std::vector<size_t> choice = choiceOf(item.index);
    for (size_t k = 0; k < axes_.size(); ++k) {
      const std::string bad = setAt(doc, axes_[k].path, *axes_[k].values.get(choice[k]));
      if (!bad.empty()) failAt(file_, axes_[k].where, "swept key '" + axes_[k].key + "': " + bad);
    }
    return scenes::loadSceneFromDocument(std::move(doc), file_, options_.overrides);
  }

 private:
  // Combination `index` as one value position per axis (the last axis varies fastest).
  std::vector<size_t> choiceOf(long long index) const {
    std::vector<size_t> choice(axes_.size());
    for (size_t k = axes_.size(); k-- > 0;) {
      choice[k] = static_cast<size_t>(index % static_cast<long long>(axes_[k].values.size()));
      index /= static_cast<long long>(axes_[k].values.size());
    }
    return choice;
  }

  static Json jsonOf(const toml::node& n) {
    if (const auto* i = n.as_integer()) return i->get();
    if (const auto* f = n.as_floating_point()) return f->get();
    if (const auto* b = n.as_boolean()) return b->get();
    if (const auto* s = n.as_string()) return s->get();
    if (const auto* a = n.as_array()) {
      Json out = Json::array();
      for (const toml::node& e : *a) out.push_back(jsonOf(e));
      return out;
    }
    std::ostringstream os;
    os << toml::toml_formatter(*n.as_table());
    return os.str();
  }

  std::string file_;
  toml::table doc_;
  std::vector<Axis> axes_;
  Options options_;
  long long total_ = 1, at_ = 0;
};

}  // namespace

std::unique_ptr<Family> openFamily(const std::string& input, const Options& o, std::istream* in) {
  if (input == "-" || scenes::isGraphFile(input)) return std::make_unique<GraphFamily>(input, o, in);
  std::error_code ec;
  if (std::filesystem::is_directory(input, ec)) return directoryFamily(input, o);
  std::string ext = input.substr(input.find_last_of('.') == std::string::npos ? input.size() : input.find_last_of('.'));
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  if (ext == ".toml") {
    const std::string text = scenes::readSceneFile(input);
    toml::table doc = scenes::parseToml(text, input);
    const toml::node* sw = doc.get("sweep");
    if (!sw) return std::make_unique<SceneListFamily>(std::vector<std::string>{input}, o);
    try {
      const toml::table* t = sw->as_table();
      if (!t) failAt(input, sw->source(), "[sweep] must be a table of keys and their values");
      if (t->empty()) failAt(input, sw->source(), "[sweep] names no key");
      std::vector<Axis> axes;
      long long product = 1;
      flatten(*t, "", input, axes, product);
      // The first key varies slowest: the order of the file, not of the table.
      std::stable_sort(axes.begin(), axes.end(), [](const Axis& a, const Axis& b) {
        return std::make_pair(a.where.begin.line, a.where.begin.column) <
               std::make_pair(b.where.begin.line, b.where.begin.column);
      });
      doc.erase("sweep");
      return std::make_unique<ParameterFamily>(input, std::move(doc), std::move(axes), o);
    } catch (const SceneError& e) {
      // Positions in the file as written, before its shorthand was quoted.
      throw SceneError(e.file, e.line, scenes::quoteSweepShorthand(text).originalColumn(e.line, e.column), e.message);
    }
  }
  if (scenes::catalogArgument(input))
    return std::make_unique<SceneListFamily>(std::vector<std::string>{input}, o);
  if (scenes::isImportable(input))
    return std::make_unique<SceneListFamily>(std::vector<std::string>{input}, o);
  return listFamily(input, o);
}

}  // namespace flexure::sweep
