// The shared [system] readers of scenes/system_reader.h: the start configuration (with its
// dimension and extent checked), pins, lists of vertex numbers, flags, ModelErrors at their item.
#include "scenes/system_reader.h"

#include <cmath>
#include <map>

#include "scenes/exact_number.h"
#include "scenes/scene.h"

namespace flexure::scenes::detail {

using engine::Matrix;

namespace {

// "2 or 3"
std::string dimensionsText(const std::vector<int>& allowed_dims) {
  std::string dims;
  for (size_t k = 0; k < allowed_dims.size(); ++k) dims += (k ? " or " : "") + std::to_string(allowed_dims[k]);
  return dims;
}

// The size of the configuration (largest coordinate range), not its distance from 0: a
// square of side 1e-200 has squared lengths that underflow.
void checkExtent(const Reader& r, const toml::node& verts, const Matrix& p) {
  const double extent = p.cols() > 1 ? (p.rowwise().maxCoeff() - p.rowwise().minCoeff()).maxCoeff() : 0.0;
  if (extent > 0 && extent < kMinExtent)
    r.fail(verts, "the vertices span only " + fmt(extent) + "; configurations must span at least " +
                      fmt(kMinExtent) + " (squared lengths must not underflow): rescale them");
}

// readVertices of an array read from the text (scenes/bulk_arrays.h): the same checks and
// messages, at the same places.
Matrix readVertices(const Reader& r, const BulkArray& a, const std::vector<int>& allowed_dims) {
  const int d = static_cast<int>(a.width(0));
  if (std::find(allowed_dims.begin(), allowed_dims.end(), d) == allowed_dims.end())
    r.fail(a, 0, -1, "a vertex has " + std::to_string(d) + " coordinates; this system type needs " + dimensionsText(allowed_dims));
  Matrix p(d, static_cast<Eigen::Index>(a.rows()));
  for (size_t i = 0; i < a.rows(); ++i) {
    if (static_cast<int>(a.width(i)) != d)
      r.fail(a, i, -1, "vertex " + std::to_string(i + 1) + " has " + std::to_string(a.width(i)) +
                           " coordinates, but the first vertex has " + std::to_string(d));
    for (int k = 0; k < d; ++k) {
      const double x = a.value(i, static_cast<size_t>(k));
      if (std::abs(x) > kMaxCoordinate)
        r.fail(a, i, k, "coordinate " + fmt(x) + " is beyond +-" + fmt(kMaxCoordinate) +
                            ": squared lengths must stay finite; rescale the configuration");
      p(k, static_cast<Eigen::Index>(i)) = x;
    }
  }
  if (r.exact()) {
    auto q = std::make_shared<engine::RationalMatrix>(d, static_cast<int>(a.rows()));
    for (size_t i = 0; i < a.rows(); ++i)
      for (int k = 0; k < d; ++k) (*q)(k, static_cast<int>(i)) = exactNumber(r, a, i, static_cast<size_t>(k), "coordinate");
    r.exactPoints() = std::move(q);
  }
  return p;
}

}  // namespace

Matrix readVertices(const Reader& r, const toml::table& sys, std::vector<int> allowed_dims) {
  const toml::node& vertices_node = r.require(sys, "vertices", "[system]");
  if (const BulkArray* a = r.bulk(vertices_node)) {
    Matrix p = readVertices(r, *a, allowed_dims);
    checkExtent(r, vertices_node, p);
    return p;
  }
  const toml::array& verts = r.array(vertices_node, "vertices");
  if (verts.empty()) r.fail(verts, "vertices is empty");
  int d = -1;
  Matrix p;
  for (size_t i = 0; i < verts.size(); ++i) {
    const toml::array& v = r.array(verts[i], "vertex " + std::to_string(i + 1));
    if (d < 0) {
      d = static_cast<int>(v.size());
      if (std::find(allowed_dims.begin(), allowed_dims.end(), d) == allowed_dims.end())
        r.fail(v, "a vertex has " + std::to_string(d) + " coordinates; this system type needs " + dimensionsText(allowed_dims));
      p.resize(d, static_cast<Eigen::Index>(verts.size()));
    } else if (static_cast<int>(v.size()) != d) {
      r.fail(v, "vertex " + std::to_string(i + 1) + " has " + std::to_string(v.size()) +
                    " coordinates, but the first vertex has " + std::to_string(d));
    }
    for (int k = 0; k < d; ++k) {
      const double x = r.number(v[k], "coordinate");
      if (std::abs(x) > kMaxCoordinate)
        r.fail(v[k], "coordinate " + fmt(x) + " is beyond +-" + fmt(kMaxCoordinate) +
                         ": squared lengths must stay finite; rescale the configuration");
      p(k, static_cast<Eigen::Index>(i)) = x;
    }
  }
  if (r.exact()) {
    // The exact mode: the same coordinates as rationals, as the file writes them.
    auto q = std::make_shared<engine::RationalMatrix>(d, static_cast<int>(verts.size()));
    for (size_t i = 0; i < verts.size(); ++i) {
      const toml::array& v = *verts[i].as_array();
      for (int k = 0; k < d; ++k) (*q)(k, static_cast<int>(i)) = exactNumber(r, v[static_cast<size_t>(k)], "coordinate");
    }
    r.exactPoints() = std::move(q);
  }
  checkExtent(r, verts, p);
  return p;
}

FlatArray::FlatArray(const Reader& r, const toml::node& n, const std::string& key) : r_(r), node_(n), bulk_(r.bulk(n)) {
  if (!bulk_) array_ = &r.array(n, key);
}

double FlatArray::number(size_t i, const std::string& what) const {
  return bulk_ ? bulk_->value(i, 0) : r_.number((*array_)[i], what);
}

engine::Rational FlatArray::exact(size_t i, const std::string& what) const {
  return bulk_ ? exactNumber(r_, *bulk_, i, 0, what) : exactNumber(r_, (*array_)[i], what);
}

engine::RationalMatrix exactStart(const Reader& r, const engine::Matrix& p) {
  if (r.exactPoints() && r.exactPoints()->rows == p.rows() && r.exactPoints()->cols == p.cols()) return *r.exactPoints();
  engine::RationalMatrix q(static_cast<int>(p.rows()), static_cast<int>(p.cols()));
  for (int b = 0; b < q.cols; ++b)
    for (int k = 0; k < q.rows; ++k) q(k, b) = engine::shortestDecimal(p(k, b));
  return q;
}

engine::Rational squaredDistance(const engine::RationalMatrix& q, int a, int b) {
  engine::Rational s = 0;
  for (int k = 0; k < q.rows; ++k) {
    const engine::Rational t = q(k, a) - q(k, b);
    s += t * t;
  }
  return s;
}

int FlatArray::vertex(const VertexIndexer& vi, size_t i, const std::string& what) const {
  return bulk_ ? vi(*bulk_, i, 0, what) : vi((*array_)[i], what);
}

void FlatArray::fail(size_t i, const std::string& message) const {
  if (bulk_) r_.fail(*bulk_, i, 0, message);
  r_.fail((*array_)[i], message);
}

std::vector<int> readPinned(const Reader& r, const toml::table& sys, const VertexIndexer& vi) {
  std::vector<int> pinned;
  const toml::node* n = sys.get("pinned");
  if (!n) return pinned;
  const FlatArray a(r, *n, "pinned");
  std::vector<char> seen(static_cast<size_t>(std::max(vi.count, 0)), 0);
  for (size_t i = 0; i < a.size(); ++i) {
    const int v = a.vertex(vi, i, "pinned vertex");
    if (seen[static_cast<size_t>(v)]) a.fail(i, "vertex " + std::to_string(v + vi.base) + " is pinned twice");
    seen[static_cast<size_t>(v)] = 1;
    pinned.push_back(v);
  }
  return pinned;
}

namespace {

// What is wrong with a list of `size` vertices that needs min_size..max_size ("": nothing).
std::string listSizeProblem(size_t size, const std::string& what, size_t min_size, size_t max_size) {
  if (size >= min_size && size <= max_size) return "";
  const std::string want = min_size == max_size ? std::to_string(min_size)
                           : max_size == static_cast<size_t>(-1) ? "at least " + std::to_string(min_size)
                           : std::to_string(min_size) + " to " + std::to_string(max_size);
  return what + " lists " + want + (want == "at least 1" ? " vertex" : " vertices") + ", this one " + std::to_string(size);
}

void checkListSize(const Reader& r, const BulkArray& a, size_t row, const std::string& what, size_t min_size,
                   size_t max_size) {
  if (const std::string why = listSizeProblem(a.width(row), what, min_size, max_size); !why.empty()) r.fail(a, row, -1, why);
}

}  // namespace

std::vector<std::vector<int>> readVertexLists(const Reader& r, const toml::table& sys, const std::string& key,
                                              const VertexIndexer& vi, const std::string& what, size_t min_size,
                                              size_t max_size, bool required) {
  std::vector<std::vector<int>> out;
  const toml::node* n = sys.get(key);
  if (!n) {
    if (required) r.require(sys, key, "[system]");
    return out;
  }
  if (const BulkArray* b = r.bulk(*n)) {
    for (size_t i = 0; i < b->rows(); ++i) {
      checkListSize(r, *b, i, what, min_size, max_size);
      std::vector<int> list;
      for (size_t k = 0; k < b->width(i); ++k) list.push_back(vi(*b, i, k, what + " vertex"));
      out.push_back(std::move(list));
    }
    return out;
  }
  const toml::array& a = r.array(*n, key);
  for (const toml::node& en : a) {
    const toml::array& e = r.array(en, what);
    if (const std::string why = listSizeProblem(e.size(), what, min_size, max_size); !why.empty()) r.fail(e, why);
    std::vector<int> list;
    for (const toml::node& v : e) list.push_back(vi(v, what + " vertex"));
    out.push_back(std::move(list));
  }
  return out;
}

// A ModelError points at an item of a [system] key: fail there.
[[noreturn]] void failAt(const Reader& r, const toml::table& sys, const engine::ModelError& e) {
  if (const toml::node* n = sys.get(e.key)) {
    if (const BulkArray* b = r.bulk(*n); b && e.item >= 0 && static_cast<size_t>(e.item) < b->rows())
      r.fail(*b, static_cast<size_t>(e.item), -1, e.what());
    if (const toml::array* a = n->as_array(); a && e.item >= 0 && static_cast<size_t>(e.item) < a->size())
      r.fail(*a->get(static_cast<size_t>(e.item)), e.what());
    r.fail(*n, e.what());
  }
  r.fail(sys.source(), e.what());
}

// sys.get(key) as a boolean (default false).
bool optionalFlag(const Reader& r, const toml::table& sys, const char* key) {
  const toml::node* n = sys.get(key);
  return n ? readFlag(r, *n, key) : false;
}

// A key's [i, j]: two vertices, 0-based.
std::array<int, 2> vertexPair(const Reader& r, const toml::node& n, const std::string& key, int base, int vertices) {
  const toml::array& a = r.array(n, key);
  if (a.size() != 2) r.fail(n, key + " names 2 vertices, not " + std::to_string(a.size()));
  const VertexIndexer vi{r, base, vertices};
  return {vi(a[0], key + " vertex"), vi(a[1], key + " vertex")};
}

}  // namespace flexure::scenes::detail
