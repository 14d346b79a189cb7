#include "scenes/caption.h"

#include <cctype>
#include <charconv>
#include <stdexcept>

#include "scenes/excerpt.h"

namespace flexure::scenes {

namespace {

// A vertex number of {distance:I:J} at `at` in `pattern`: digits (blanks before them and a sign
// allowed), read as the number written, refused out of [base, base + count) with its offset;
// `end` past it.
int vertexNumber(const std::string& pattern, size_t at, size_t& end, int base, int count) {
  while (at < pattern.size() && (pattern[at] == ' ' || pattern[at] == '\t')) ++at;
  size_t i = at;
  if (i < pattern.size() && (pattern[i] == '-' || pattern[i] == '+')) ++i;
  const size_t digits = i;
  while (i < pattern.size() && std::isdigit(static_cast<unsigned char>(pattern[i]))) ++i;
  if (i == digits) throw CaptionError("{distance:I:J} needs two vertex numbers", at);
  end = i;
  const std::string written = pattern.substr(at, i - at);
  long long v = 0;
  const char* first = pattern.data() + (pattern[at] == '+' ? at + 1 : at);
  const auto [ptr, ec] = std::from_chars(first, pattern.data() + i, v);
  const bool inside = ec == std::errc() && ptr == pattern.data() + i && v >= base && v < static_cast<long long>(base) + count;
  if (!inside)
    throw CaptionError("{distance:I:J}: vertex " + excerpt(written) + " is out of range: vertices are numbered " +
                           std::to_string(base) + ".." + std::to_string(static_cast<long long>(base) + count - 1),
                       at);
  return static_cast<int>(v - base);
}

}  // namespace

std::vector<CaptionPiece> parseCaption(const std::string& pattern, int base, int count) {
  std::vector<CaptionPiece> out;
  const auto text = [&](char c) {
    if (out.empty() || out.back().kind != CaptionPiece::Text) out.push_back({});
    out.back().text += c;
  };
  for (size_t i = 0; i < pattern.size(); ++i) {
    const char c = pattern[i];
    if ((c == '{' || c == '}') && i + 1 < pattern.size() && pattern[i + 1] == c) {
      text(c), ++i;
      continue;
    }
    if (c == '}') throw CaptionError("a '}' without its '{' (write \"}}\" for a brace)", i);
    if (c != '{') {
      text(c);
      continue;
    }
    const size_t end = pattern.find('}', i);
    if (end == std::string::npos) throw CaptionError("a '{' without its '}' (write \"{{\" for a brace)", i);
    const std::string field = pattern.substr(i + 1, end - i - 1);
    CaptionPiece p;
    static const std::string kDistance = "distance:";
    if (field == "sample") p.kind = CaptionPiece::Sample;
    else if (field == "arc_length") p.kind = CaptionPiece::ArcLength;
    else if (field == "event") p.kind = CaptionPiece::Event;
    else if (field.rfind(kDistance, 0) == 0) {
      size_t at = i + 1 + kDistance.size(), after = at;
      p.a = vertexNumber(pattern, at, after, base, count);
      if (after >= end || pattern[after] != ':') throw CaptionError("{distance:I:J} needs two vertex numbers", after);
      p.b = vertexNumber(pattern, after + 1, at, base, count);
      if (at != end) throw CaptionError("{distance:I:J}: unexpected '" + excerpt(pattern.substr(at, end - at)) + "'", at);
      p.kind = CaptionPiece::Distance;
    } else {
      throw CaptionError("unknown field {" + excerpt(field) + "}; known: {sample}, {arc_length}, {event}, {distance:I:J}", i);
    }
    out.push_back(p);
    i = end;
  }
  return out;
}

}  // namespace flexure::scenes
