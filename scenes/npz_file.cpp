// NumPy's .npy format (numpy.lib.format: a magic string, a version, a header that is a Python
// dict literal, the data) and the zip container of .npz files (the end of the central
// directory, zip64 where numpy writes it, the central directory's entries, each member's local
// header), read with bounds checked at every step: the file may be anything.
#include "scenes/npz_file.h"

#include <zlib.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <set>

#include "scenes/scene.h"

namespace flexure::scenes::detail {

namespace {

constexpr std::uint64_t kMaxBytes = std::uint64_t{4} << 30;

[[noreturn]] void fail(const std::string& file, const std::string& message) { throw SceneError(file, 1, 1, message); }

// A little-endian unsigned integer of `bytes` bytes at `at` (false past the end).
bool le(std::string_view b, std::uint64_t at, int bytes, std::uint64_t& v) {
  if (at > b.size() || b.size() - at < static_cast<std::uint64_t>(bytes)) return false;
  v = 0;
  for (int i = bytes - 1; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(b[at + static_cast<std::uint64_t>(i)]);
  return true;
}

// The value of `'key':` in an .npy header (the text up to the next top-level ',' or '}').
std::string_view headerValue(std::string_view header, std::string_view key) {
  const size_t at = header.find("'" + std::string(key) + "'");
  if (at == std::string_view::npos) return {};
  size_t i = header.find(':', at);
  if (i == std::string_view::npos) return {};
  ++i;
  while (i < header.size() && header[i] == ' ') ++i;
  int depth = 0;
  size_t j = i;
  for (; j < header.size(); ++j) {
    const char c = header[j];
    if (c == '(' || c == '[') {
      ++depth;
    } else if (c == ')' || c == ']') {
      if (depth == 0) break;
      --depth;
    } else if ((c == ',' || c == '}') && depth == 0) {
      break;
    }
  }
  std::string_view v = header.substr(i, j - i);
  while (!v.empty() && v.back() == ' ') v.remove_suffix(1);
  return v;
}

NumpyArray readNpy(std::string_view b, const std::string& file, const std::string& what) {
  const auto bad = [&](const std::string& why) { fail(file, what + why); };
  if (b.size() < 10 || b.substr(0, 6) != std::string_view("\x93NUMPY", 6)) bad("is not a NumPy array (.npy)");
  const int major = static_cast<unsigned char>(b[6]);
  std::uint64_t header_len = 0, start = 0;
  if (major == 1) {
    le(b, 8, 2, header_len);
    start = 10;
  } else if (major == 2 || major == 3) {
    if (!le(b, 8, 4, header_len)) bad("is cut short");
    start = 12;
  } else {
    bad("has .npy format version " + std::to_string(major) + " (1 to 3 are read)");
  }
  if (header_len > b.size() - start) bad("is cut short in its header");
  const std::string_view header = b.substr(start, header_len);
  const std::string_view data = b.substr(start + header_len);
  // descr: '<f8', '|u1', '>i4', ...
  const std::string_view descr = headerValue(header, "descr");
  if (descr.size() < 4 || descr.front() != '\'' || descr.back() != '\'')
    bad("has a type numpy describes as " + std::string(descr.empty() ? "nothing" : descr) +
        ": only arrays of plain numbers are read (not structured, string or object arrays)");
  const std::string type(descr.substr(1, descr.size() - 2));
  const char order = type[0], kind = type[1];
  int size = 0;
  for (size_t i = 2; i < type.size(); ++i) {
    if (type[i] < '0' || type[i] > '9' || size > 100) bad("has the type '" + type + "'");
    size = size * 10 + (type[i] - '0');
  }
  const bool big = order == '>';
  const bool kinds = (kind == 'f' && (size == 4 || size == 8)) ||
                     ((kind == 'i' || kind == 'u') && (size == 1 || size == 2 || size == 4 || size == 8)) ||
                     (kind == 'b' && size == 1);
  if (std::string("<>|=").find(order) == std::string::npos || !kinds)
    bad("has the type '" + type + "': read are integers, floats (4 or 8 bytes) and booleans, not " +
        (kind == 'c' ? "complex numbers" : kind == 'O' ? "Python objects" : kind == 'U' || kind == 'S' ? "strings" : "this"));
  const std::string_view fortran = headerValue(header, "fortran_order");
  if (fortran != "False" && fortran != "True") bad("has no fortran_order in its header");
  // shape: (), (n,), (n, m), ...
  const std::string_view shape = headerValue(header, "shape");
  if (shape.size() < 2 || shape.front() != '(' || shape.back() != ')') bad("has no shape in its header");
  NumpyArray a;
  std::uint64_t count = 1;
  for (size_t i = 1; i + 1 < shape.size();) {
    while (i + 1 < shape.size() && (shape[i] == ' ' || shape[i] == ',')) ++i;
    if (i + 1 >= shape.size()) break;
    std::uint64_t n = 0;
    const size_t first = i;
    while (i + 1 < shape.size() && shape[i] >= '0' && shape[i] <= '9') {
      n = n * 10 + static_cast<std::uint64_t>(shape[i] - '0');
      if (n > kMaxBytes) bad("is too large (a dimension of more than 2^32)");
      ++i;
    }
    if (i == first) bad("has the shape " + std::string(shape));
    a.shape.push_back(static_cast<size_t>(n));
    if (n != 0 && count > kMaxBytes / n) bad("is too large (more than 2^32 values)");
    count *= n;
  }
  if (count * static_cast<std::uint64_t>(size) > data.size())
    bad("is cut short: its shape " + std::string(shape) + " needs " + std::to_string(count * static_cast<std::uint64_t>(size)) +
        " bytes of data, it has " + std::to_string(data.size()));
  a.integer = kind != 'f';
  a.values.resize(static_cast<size_t>(count));
  // Value k of the data in the array's own order.
  const auto value = [&](std::uint64_t k) -> double {
    std::uint64_t u = 0;
    for (int i = 0; i < size; ++i) {
      const int from = big ? i : size - 1 - i;
      u = (u << 8) | static_cast<unsigned char>(data[k * static_cast<std::uint64_t>(size) + static_cast<std::uint64_t>(from)]);
    }
    if (kind == 'f') {
      if (size == 8) {
        double d;
        std::memcpy(&d, &u, 8);
        return d;
      }
      const auto u32 = static_cast<std::uint32_t>(u);
      float f;
      std::memcpy(&f, &u32, 4);
      return f;
    }
    if (kind == 'b') return u != 0 ? 1.0 : 0.0;
    if (kind == 'u') {
      if (u > (std::uint64_t{1} << 53)) bad("holds the integer " + std::to_string(u) + ", beyond 2^53 (not exact as a double)");
      return static_cast<double>(u);
    }
    const int bits = 8 * size;
    std::int64_t s = bits == 64 ? static_cast<std::int64_t>(u) : static_cast<std::int64_t>(u << (64 - bits)) >> (64 - bits);
    if (s > (std::int64_t{1} << 53) || s < -(std::int64_t{1} << 53))
      bad("holds the integer " + std::to_string(s) + ", beyond 2^53 (not exact as a double)");
    return static_cast<double>(s);
  };
  if (fortran == "False" || a.shape.size() < 2) {
    for (std::uint64_t k = 0; k < count; ++k) a.values[static_cast<size_t>(k)] = value(k);
  } else {
    // Fortran order: the first index varies fastest in the data.
    std::vector<std::uint64_t> index(a.shape.size(), 0), stride(a.shape.size(), 1);
    for (size_t d = 1; d < a.shape.size(); ++d) stride[d] = stride[d - 1] * a.shape[d - 1];
    for (std::uint64_t k = 0; k < count; ++k) {
      std::uint64_t at = 0;
      for (size_t d = 0; d < index.size(); ++d) at += index[d] * stride[d];
      a.values[static_cast<size_t>(k)] = value(at);
      for (size_t d = index.size(); d-- > 0;) {
        if (++index[d] < a.shape[d]) break;
        index[d] = 0;
      }
    }
  }
  return a;
}

std::vector<NumpyArray> readZip(std::string_view b, const std::string& file) {
  // The end of the central directory: within the last 22 + 65,535 bytes (its comment).
  std::uint64_t eocd = std::string_view::npos;
  if (b.size() >= 22)
    for (std::uint64_t i = b.size() - 22;; --i) {
      std::uint64_t sig = 0;
      if (le(b, i, 4, sig) && sig == 0x06054b50) {
        eocd = i;
        break;
      }
      if (i == 0 || b.size() - i > 22 + 65535) break;
    }
  if (eocd == std::string_view::npos) fail(file, "is not a zip file (.npz): no end of its central directory");
  std::uint64_t entries = 0, cd_size = 0, cd_offset = 0;
  le(b, eocd + 10, 2, entries);
  le(b, eocd + 12, 4, cd_size);
  le(b, eocd + 16, 4, cd_offset);
  if (entries == 0xFFFF || cd_size == 0xFFFFFFFF || cd_offset == 0xFFFFFFFF) {
    // zip64: its locator just before, pointing at its own end record.
    std::uint64_t sig = 0, record = 0;
    if (eocd < 20 || !le(b, eocd - 20, 4, sig) || sig != 0x07064b50 || !le(b, eocd - 12, 8, record) ||
        !le(b, record, 4, sig) || sig != 0x06064b50 || !le(b, record + 32, 8, entries) || !le(b, record + 40, 8, cd_size) ||
        !le(b, record + 48, 8, cd_offset))
      fail(file, "is a zip64 file whose end records cannot be read");
  }
  if (cd_offset > b.size() || cd_size > b.size() - cd_offset) fail(file, "has its central directory outside the file");
  std::vector<NumpyArray> out;
  std::set<std::string> names;
  std::uint64_t p = cd_offset;
  for (std::uint64_t e = 0; e < entries; ++e) {
    std::uint64_t sig = 0, flags = 0, method = 0, crc = 0, comp = 0, size = 0, name_len = 0, extra_len = 0, comment_len = 0,
                  local = 0;
    if (!le(b, p, 4, sig) || sig != 0x02014b50 || !le(b, p + 8, 2, flags) || !le(b, p + 10, 2, method) ||
        !le(b, p + 16, 4, crc) || !le(b, p + 20, 4, comp) || !le(b, p + 24, 4, size) || !le(b, p + 28, 2, name_len) ||
        !le(b, p + 30, 2, extra_len) || !le(b, p + 32, 2, comment_len) || !le(b, p + 42, 4, local) ||
        b.size() - (p + 46) < name_len + extra_len + comment_len)
      fail(file, "has a broken central directory (entry " + std::to_string(e + 1) + ")");
    const std::string name(b.substr(p + 46, name_len));
    // zip64 sizes and offset: in the extra field 0x0001, those that are 0xFFFFFFFF here, in order.
    for (std::uint64_t x = p + 46 + name_len; x + 4 <= p + 46 + name_len + extra_len;) {
      std::uint64_t id = 0, len = 0;
      le(b, x, 2, id);
      le(b, x + 2, 2, len);
      if (id == 0x0001) {
        std::uint64_t at = x + 4;
        for (std::uint64_t* field : {&size, &comp, &local})
          if (*field == 0xFFFFFFFF && at + 8 <= x + 4 + len) {
            le(b, at, 8, *field);
            at += 8;
          }
      }
      x += 4 + len;
    }
    p += 46 + name_len + extra_len + comment_len;
    const std::string what = "member '" + name + "' ";
    if (flags & 1) fail(file, what + "is encrypted");
    if (method != 0 && method != 8) fail(file, what + "is compressed by method " + std::to_string(method) + " (stored and deflated members are read)");
    if (name.size() < 5 || name.compare(name.size() - 4, 4, ".npy") != 0)
      fail(file, what + "is not a NumPy array (.npy): an .npz holds only those");
    if (!names.insert(name).second) fail(file, what + "is there twice");
    if (size > kMaxBytes) fail(file, what + "is larger than 4 GiB");
    std::uint64_t lname = 0, lextra = 0;
    if (local >= b.size() || !le(b, local, 4, sig) || sig != 0x04034b50 || !le(b, local + 26, 2, lname) || !le(b, local + 28, 2, lextra) ||
        local + 30 + lname + lextra > b.size() || comp > b.size() - (local + 30 + lname + lextra))
      fail(file, what + "has a broken local header or is cut short");
    const std::string_view raw = b.substr(local + 30 + lname + lextra, comp);
    std::string inflated;
    std::string_view member = raw;
    if (method == 8) {
      // Inflated as it comes (the declared size is only a bound: a damaged or hostile header may
      // claim gigabytes for a few bytes), in pieces: zlib counts in 32 bits.
      z_stream z{};
      if (inflateInit2(&z, -MAX_WBITS) != Z_OK) fail(file, what + "cannot be inflated (zlib)");
      z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(raw.data()));
      std::uint64_t in_left = raw.size(), out = 0;
      int rc = Z_OK;
      while (rc == Z_OK) {
        if (out == inflated.size()) {
          if (out > size) {
            rc = Z_BUF_ERROR;  // more than the declared size
            break;
          }
          // (One byte past the size: the stream's end may come after its last byte is out.)
          inflated.resize(static_cast<size_t>(std::min<std::uint64_t>(size + 1, std::max<std::uint64_t>(2 * out, 1 << 20))));
        }
        const uInt in_now = static_cast<uInt>(std::min<std::uint64_t>(in_left, 1u << 30));
        const uInt out_now = static_cast<uInt>(std::min<std::uint64_t>(inflated.size() - out, 1u << 30));
        z.avail_in = in_now;
        z.next_out = reinterpret_cast<Bytef*>(inflated.data() + out);
        z.avail_out = out_now;
        rc = inflate(&z, Z_NO_FLUSH);
        in_left -= in_now - z.avail_in;
        out += out_now - z.avail_out;
        if (rc == Z_OK && in_now == z.avail_in && out_now == z.avail_out) rc = Z_BUF_ERROR;  // no progress
      }
      inflateEnd(&z);
      if (rc != Z_STREAM_END || out != size) fail(file, what + "does not inflate to its " + std::to_string(size) + " bytes");
      inflated.resize(static_cast<size_t>(out));
      member = inflated;
    } else if (comp != size) {
      fail(file, what + "is stored with " + std::to_string(comp) + " bytes for its " + std::to_string(size));
    }
    uLong c = crc32(0L, Z_NULL, 0);
    for (std::uint64_t at = 0; at < member.size(); at += 1u << 30)
      c = crc32(c, reinterpret_cast<const Bytef*>(member.data() + at),
                static_cast<uInt>(std::min<std::uint64_t>(member.size() - at, 1u << 30)));
    if (c != crc) fail(file, what + "fails its checksum (CRC-32): the file is damaged");
    NumpyArray a = readNpy(member, file, what);
    a.name = name.substr(0, name.size() - 4);
    out.push_back(std::move(a));
  }
  return out;
}

}  // namespace

std::vector<NumpyArray> readNumpyBytes(std::string_view bytes, const std::string& file) {
  if (bytes.substr(0, 6) == std::string_view("\x93NUMPY", 6)) {
    NumpyArray a = readNpy(bytes, file, "");
    const size_t slash = file.find_last_of('/');
    std::string stem = slash == std::string::npos ? file : file.substr(slash + 1);
    if (const size_t dot = stem.find_last_of('.'); dot != std::string::npos) stem.erase(dot);
    a.name = stem;
    return {std::move(a)};
  }
  if (bytes.substr(0, 2) == "PK") return readZip(bytes, file);
  fail(file, "is neither a NumPy .npz (a zip file) nor an .npy array");
}

std::vector<NumpyArray> readNumpyFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) fail(path, std::string("cannot open the file: ") + std::strerror(errno));
  const std::streamoff size = in.tellg();
  if (size < 0) fail(path, "cannot read the file");
  if (static_cast<std::uint64_t>(size) > kMaxBytes) fail(path, "is larger than 4 GiB");
  std::string bytes(static_cast<size_t>(size), '\0');
  in.seekg(0);
  if (!in.read(bytes.data(), size)) fail(path, "cannot read the file");
  return readNumpyBytes(bytes, path);
}

}  // namespace flexure::scenes::detail
