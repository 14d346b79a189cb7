#include "render/gif.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

namespace flexure::render {

namespace {

std::uint32_t rgbAt(const std::uint8_t* p) { return std::uint32_t{p[0]} << 16 | std::uint32_t{p[1]} << 8 | p[2]; }

std::uint32_t word(const std::uint8_t* p) {
  std::uint32_t w;
  std::memcpy(&w, p, 4);
  return w;
}

std::uint64_t mix(std::uint64_t x) {
  x ^= x >> 29;
  x *= 0xbf58476d1ce4e5b9ULL;
  return x ^ (x >> 32);
}

// The 8x8 Bayer matrix (0-63), by the recursion M_2n = [4M, 4M+2; 4M+3, 4M+1].
struct Bayer {
  int m[8][8];
  Bayer() {
    int n = 1;
    m[0][0] = 0;
    for (; n < 8; n *= 2)
      for (int y = n - 1; y >= 0; --y)
        for (int x = n - 1; x >= 0; --x) {
          const int v = 4 * m[y][x];
          m[y][x] = v, m[y][x + n] = v + 2, m[y + n][x] = v + 3, m[y + n][x + n] = v + 1;
        }
  }
};

// The dithering offsets added to each channel before the nearest palette colour is looked up:
// -2..1, a light pattern that breaks the bands of shading and fog without visible grain.
struct Dither {
  int d[8][8];
  Dither() {
    const Bayer b;
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x) d[y][x] = (b.m[y][x] >> 4) - 2;
  }
};
const Dither kDither;

constexpr std::uint8_t kTransparent = 255;
constexpr int kCacheBits = 16;

int gifPts(long index, int fps) { return static_cast<int>(std::llround(index * 100.0 / fps)); }

}  // namespace

GifPaletteBuilder::GifPaletteBuilder() : slots_(size_t{1} << 14, 0) {}

void GifPaletteBuilder::count(std::uint32_t rgb, std::uint32_t n) {
  if (2 * (used_ + 1) > slots_.size()) {
    std::vector<std::uint64_t> old(slots_.size() * 2, 0);
    old.swap(slots_);
    used_ = 0;
    for (std::uint64_t e : old)
      if (e) count(static_cast<std::uint32_t>(e >> 32) - 1, static_cast<std::uint32_t>(e));
  }
  const size_t mask = slots_.size() - 1;
  const std::uint64_t key = std::uint64_t{rgb} + 1;
  for (size_t i = mix(key) & mask;; i = (i + 1) & mask) {
    std::uint64_t& e = slots_[i];
    if (!e) {
      e = key << 32 | n;
      ++used_;
      return;
    }
    if (e >> 32 == key) {
      const std::uint64_t c = std::min<std::uint64_t>((e & 0xffffffffULL) + n, 0xffffffffULL);
      e = key << 32 | c;
      return;
    }
  }
}

void GifPaletteBuilder::add(const Image& image) {
  // Runs of one colour along a row are counted at once: most of a frame is background.
  for (int y = 0; y < image.height; ++y) {
    const std::uint8_t* row = image.pixel(0, y);
    int x = 0;
    while (x < image.width) {
      const std::uint32_t c = rgbAt(row + 4 * x);
      int end = x + 1;
      while (end < image.width && rgbAt(row + 4 * end) == c) ++end;
      count(c, static_cast<std::uint32_t>(end - x));
      x = end;
    }
  }
}

std::vector<Rgb> GifPaletteBuilder::palette(int colours) const {
  if (colours < 1 || colours > 255) throw std::invalid_argument("a GIF palette has 1-255 colours here");
  struct Entry {
    std::uint8_t c[3];
    std::uint32_t rgb;
    double w;
  };
  std::vector<Entry> entries;
  entries.reserve(used_);
  for (std::uint64_t e : slots_)
    if (e) {
      const std::uint32_t rgb = static_cast<std::uint32_t>(e >> 32) - 1;
      entries.push_back({{static_cast<std::uint8_t>(rgb >> 16), static_cast<std::uint8_t>(rgb >> 8),
                          static_cast<std::uint8_t>(rgb)},
                         rgb,
                         static_cast<double>(e & 0xffffffffULL)});
    }
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) { return a.rgb < b.rgb; });
  std::vector<Rgb> out;
  if (entries.size() <= static_cast<size_t>(colours)) {
    for (const Entry& e : entries) out.push_back({e.c[0], e.c[1], e.c[2]});
    if (out.empty()) out.push_back({0, 0, 0});
    return out;
  }
  struct Box {
    size_t begin, end;
    double error;  // weighted squared distance from the mean, over the three channels
    int axis;      // the channel of largest spread
    Rgb mean;
  };
  const auto measure = [&](size_t begin, size_t end) {
    Box b{begin, end, 0, 0, {0, 0, 0}};
    double w = 0, s[3] = {0, 0, 0}, q[3] = {0, 0, 0};
    for (size_t i = begin; i < end; ++i)
      for (int a = 0; a < 3; ++a) {
        const double v = entries[i].c[a];
        s[a] += entries[i].w * v, q[a] += entries[i].w * v * v;
        if (a == 0) w += entries[i].w;
      }
    double widest = -1;
    for (int a = 0; a < 3; ++a) {
      const double e = std::max(0.0, q[a] - s[a] * s[a] / w);
      b.error += e;
      if (e > widest) widest = e, b.axis = a;
      b.mean[static_cast<size_t>(a)] = static_cast<std::uint8_t>(std::clamp(std::lround(s[a] / w), 0L, 255L));
    }
    // A colour that holds most of its box stands for it exactly: flat areas (the background,
    // a face, an edge's core) keep their colour instead of a mean with their antialiased rims.
    for (size_t i = begin; i < end; ++i)
      if (2 * entries[i].w > w) b.mean = {entries[i].c[0], entries[i].c[1], entries[i].c[2]};
    if (end - begin < 2) b.error = -1;
    return b;
  };
  std::vector<Box> boxes{measure(0, entries.size())};
  while (boxes.size() < static_cast<size_t>(colours)) {
    size_t pick = 0;
    for (size_t i = 1; i < boxes.size(); ++i)
      if (boxes[i].error > boxes[pick].error) pick = i;
    const Box b = boxes[pick];
    if (b.error <= 0) break;
    const int a = b.axis;
    std::sort(entries.begin() + static_cast<std::ptrdiff_t>(b.begin), entries.begin() + static_cast<std::ptrdiff_t>(b.end),
              [a](const Entry& x, const Entry& y) { return x.c[a] != y.c[a] ? x.c[a] < y.c[a] : x.rgb < y.rgb; });
    double total = 0, run = 0;
    for (size_t i = b.begin; i < b.end; ++i) total += entries[i].w;
    size_t cut = b.begin + 1;
    for (size_t i = b.begin; i + 1 < b.end; ++i) {
      run += entries[i].w;
      cut = i + 1;
      if (run >= total / 2) break;
    }
    boxes[pick] = measure(b.begin, cut);
    boxes.push_back(measure(cut, b.end));
  }
  for (const Box& b : boxes) out.push_back(b.mean);
  return out;
}

GifEncoder::GifEncoder(const std::string& path, int width, int height, std::vector<Rgb> palette, int fps)
    : path_(path), width_(width), height_(height), fps_(fps), palette_(std::move(palette)) {
  if (width < 1 || height < 1 || width > 65535 || height > 65535)
    throw std::invalid_argument("a GIF is 1-65535 pixels wide and high, not " + std::to_string(width) + "x" +
                                std::to_string(height));
  if (fps < 1 || fps > 50) throw std::invalid_argument("GIF frame delays are centiseconds: 1-50 frames/s");
  if (palette_.empty() || palette_.size() > 255) throw std::invalid_argument("a GIF palette has 1-255 colours here");
  file_ = std::fopen(path.c_str(), "wb");
  if (!file_) throw std::runtime_error("cannot write " + path + ": " + std::strerror(errno));
  cache_.assign(size_t{1} << kCacheBits, 0);
  const auto u16 = [&](int v) { out_.push_back(static_cast<std::uint8_t>(v)), out_.push_back(static_cast<std::uint8_t>(v >> 8)); };
  put("GIF89a", 6);
  u16(width), u16(height);
  out_.push_back(0xF7);  // a global colour table of 256 entries, 8 bits per channel
  out_.push_back(0), out_.push_back(0);
  for (size_t i = 0; i < 256; ++i)
    for (size_t a = 0; a < 3; ++a) out_.push_back(i < palette_.size() ? palette_[i][a] : 0);
  // NETSCAPE2.0: loop forever.
  const std::uint8_t loop[] = {0x21, 0xFF, 0x0B, 'N', 'E', 'T', 'S', 'C', 'A', 'P', 'E', '2', '.', '0', 3, 1, 0, 0, 0};
  put(loop, sizeof loop);
}

GifEncoder::~GifEncoder() {
  if (file_) std::fclose(file_);
}

void GifEncoder::put(const void* data, size_t n) {
  const auto* p = static_cast<const std::uint8_t*>(data);
  out_.insert(out_.end(), p, p + n);
}

std::uint8_t GifEncoder::nearest(std::uint32_t rgb) {
  std::uint64_t& slot = cache_[mix(rgb) & ((size_t{1} << kCacheBits) - 1)];
  const std::uint64_t tag = std::uint64_t{rgb} + 1;
  if (slot >> 8 == tag) return static_cast<std::uint8_t>(slot);
  const int r = static_cast<int>(rgb >> 16), g = static_cast<int>(rgb >> 8 & 255), b = static_cast<int>(rgb & 255);
  int best = 0, best_d = 1 << 30;
  for (size_t k = 0; k < palette_.size(); ++k) {
    const int dr = r - palette_[k][0], dg = g - palette_[k][1], db = b - palette_[k][2];
    const int d = dr * dr + dg * dg + db * db;
    if (d < best_d) best_d = d, best = static_cast<int>(k);
  }
  slot = tag << 8 | static_cast<std::uint64_t>(best);
  return static_cast<std::uint8_t>(best);
}

void GifEncoder::mapRect(const Image& image, int x0, int y0, int x1, int y1, bool diff) {
  indices_.resize(static_cast<size_t>(x1 - x0) * static_cast<size_t>(y1 - y0));
  std::uint8_t* out = indices_.data();
  for (int y = y0; y < y1; ++y) {
    const std::uint8_t* row = image.pixel(0, y);
    const std::uint8_t* before = diff ? &previous_[static_cast<size_t>(y) * width_ * 4] : nullptr;
    const int* d = kDither.d[y & 7];
    // Along a run of one colour, the index depends only on the column's dithering phase.
    std::uint32_t run_colour = 0;
    int known = 0;  // bit p: phase p's index is in phase[p]
    std::uint8_t phase[8];
    for (int x = x0; x < x1; ++x) {
      const std::uint8_t* p = row + 4 * x;
      if (diff && word(p) == word(before + 4 * x)) {
        *out++ = kTransparent;
        continue;
      }
      const std::uint32_t c = rgbAt(p);
      if (c != run_colour || !known) {
        run_colour = c, known = 0;
        // A palette colour is itself, and so is a colour within one level of its nearest:
        // dithering is for the colours between them (a flat background dithered toward a near
        // grey was neither exact nor compressible; the shaded faces of the sphere packing are
        // 11 % smaller and half as far off without the noise).
        const std::uint8_t n = nearest(c);
        const Rgb& q = palette_[n];
        if (std::abs(q[0] - p[0]) <= 1 && std::abs(q[1] - p[1]) <= 1 && std::abs(q[2] - p[2]) <= 1) {
          std::fill(phase, phase + 8, n);
          known = 255;
        }
      }
      const int k = x & 7;
      if (!(known >> k & 1)) {
        const int o = d[k];
        const auto ch = [o](int v) { return static_cast<std::uint32_t>(std::clamp(v + o, 0, 255)); };
        phase[k] = nearest(ch(p[0]) << 16 | ch(p[1]) << 8 | ch(p[2]));
        known |= 1 << k;
      }
      *out++ = phase[k];
    }
  }
}

// LZW with 8-bit codes as GIF has it (clear 256, end 257, codes up to 12 bits; the code size
// grows as giflib's encoder and every decoder expect), packed into sub-blocks of 255 bytes. The
// dictionary is a hash table of (prefix << 8 | byte) << 12 | code in 64 KB (a direct table of
// 4096 x 256 codes, 4 MB, missed the cache on most pixels).
void GifEncoder::compress() {
  constexpr std::uint32_t kClear = 256, kEnd = 257, kMaxCode = 4095;
  constexpr int kHashBits = 14;
  constexpr std::uint32_t kMask = (1u << kHashBits) - 1;
  dict_.assign(size_t{1} << kHashBits, 0);  // 0: empty (no code below 258 is stored)
  std::vector<std::uint8_t>& bytes = packed_;
  bytes.clear();
  std::uint32_t acc = 0;
  int bits = 0, size = 9;
  std::uint32_t next = kEnd + 1, limit = 1u << size;
  const auto emit = [&](std::uint32_t code) {
    acc |= code << bits;
    bits += size;
    while (bits >= 8) bytes.push_back(static_cast<std::uint8_t>(acc)), acc >>= 8, bits -= 8;
    if (next >= limit && size < 12) ++size, limit <<= 1;
  };
  emit(kClear);
  std::uint32_t prefix = indices_[0];
  for (size_t i = 1; i < indices_.size(); ++i) {
    const std::uint32_t key = prefix << 8 | indices_[i];
    std::uint32_t h = (key * 2654435761u) >> (32 - kHashBits);
    for (;;) {
      const std::uint32_t e = dict_[h];
      if (e == 0 || e >> 12 == key) break;
      h = (h + 1) & kMask;
    }
    if (dict_[h]) {
      prefix = dict_[h] & kMaxCode;
      continue;
    }
    emit(prefix);
    if (next >= kMaxCode) {
      emit(kClear);
      size = 9, next = kEnd + 1, limit = 1u << size;
      std::fill(dict_.begin(), dict_.end(), 0u);
    } else {
      dict_[h] = key << 12 | next++;
    }
    prefix = indices_[i];
  }
  emit(prefix);
  emit(kEnd);
  if (bits > 0) bytes.push_back(static_cast<std::uint8_t>(acc));
  out_.push_back(8);
  for (size_t i = 0; i < bytes.size(); i += 255) {
    const size_t n = std::min<size_t>(255, bytes.size() - i);
    out_.push_back(static_cast<std::uint8_t>(n));
    put(bytes.data() + i, n);
  }
  out_.push_back(0);
}

void GifEncoder::add(Image& image, int index) {
  if (!file_) throw std::logic_error("GifEncoder::add after finish");
  if (image.width != width_ || image.height != height_ ||
      image.rgba.size() != static_cast<size_t>(width_) * height_ * 4)
    throw std::invalid_argument("a GIF frame of the wrong size");
  // The rectangle that changed since the previous frame (all of the first); inside it the
  // unchanged pixels are transparent. A frame that changed nothing is one transparent pixel.
  int x0 = 0, y0 = 0, x1 = width_, y1 = height_;
  const bool diff = !previous_.empty();  // the first frame leaves the encoder its pixels
  if (diff) {
    x0 = width_, y0 = height_, x1 = 0, y1 = 0;
    for (int y = 0; y < height_; ++y) {
      const std::uint8_t* a = image.pixel(0, y);
      const std::uint8_t* b = &previous_[static_cast<size_t>(y) * width_ * 4];
      if (std::memcmp(a, b, static_cast<size_t>(width_) * 4) == 0) continue;
      int l = 0, r = width_;
      while (word(a + 4 * l) == word(b + 4 * l)) ++l;
      while (word(a + 4 * (r - 1)) == word(b + 4 * (r - 1))) --r;
      x0 = std::min(x0, l), x1 = std::max(x1, r), y0 = std::min(y0, y), y1 = y + 1;
    }
    if (x1 <= x0) x0 = 0, y0 = 0, x1 = 1, y1 = 1;
  }
  mapRect(image, x0, y0, x1, y1, diff);
  const int delay = gifPts(index + 1L, fps_) - gifPts(index, fps_);
  // Graphic control: leave the frame in place, the delay, index 255 transparent after the first.
  const std::uint8_t control[] = {0x21, 0xF9, 4, static_cast<std::uint8_t>(1 << 2 | (diff ? 1 : 0)),
                                  static_cast<std::uint8_t>(delay), static_cast<std::uint8_t>(delay >> 8),
                                  kTransparent, 0};
  put(control, sizeof control);
  const std::uint8_t descriptor[] = {0x2C,
                                     static_cast<std::uint8_t>(x0), static_cast<std::uint8_t>(x0 >> 8),
                                     static_cast<std::uint8_t>(y0), static_cast<std::uint8_t>(y0 >> 8),
                                     static_cast<std::uint8_t>(x1 - x0), static_cast<std::uint8_t>((x1 - x0) >> 8),
                                     static_cast<std::uint8_t>(y1 - y0), static_cast<std::uint8_t>((y1 - y0) >> 8),
                                     0};
  put(descriptor, sizeof descriptor);
  compress();
  image.rgba.swap(previous_);
  if (out_.size() >= (size_t{1} << 20)) {
    if (std::fwrite(out_.data(), 1, out_.size(), file_) != out_.size())
      throw std::runtime_error("cannot write " + path_ + ": " + std::strerror(errno));
    out_.clear();
  }
}

void GifEncoder::finish() {
  if (!file_) return;
  out_.push_back(0x3B);
  const bool written = std::fwrite(out_.data(), 1, out_.size(), file_) == out_.size();
  const int err = errno;
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  out_.clear();
  if (!written || !closed) throw std::runtime_error("cannot write " + path_ + ": " + std::strerror(written ? errno : err));
}

}  // namespace flexure::render
