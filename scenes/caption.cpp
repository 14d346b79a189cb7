#include "scenes/caption.h"

#include <cstdio>
#include <stdexcept>

namespace flexure::scenes {

std::vector<CaptionPiece> parseCaption(const std::string& pattern) {
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
    if (c == '}') throw std::invalid_argument("a '}' without its '{' (write \"}}\" for a brace)");
    if (c != '{') {
      text(c);
      continue;
    }
    const size_t end = pattern.find('}', i);
    if (end == std::string::npos) throw std::invalid_argument("a '{' without its '}' (write \"{{\" for a brace)");
    const std::string field = pattern.substr(i + 1, end - i - 1);
    CaptionPiece p;
    char tail = 0;
    if (field == "sample") p.kind = CaptionPiece::Sample;
    else if (field == "arc_length") p.kind = CaptionPiece::ArcLength;
    else if (field == "event") p.kind = CaptionPiece::Event;
    else if (std::sscanf(field.c_str(), "distance:%d:%d%c", &p.a, &p.b, &tail) == 2) p.kind = CaptionPiece::Distance;
    else throw std::invalid_argument("unknown field {" + field + "}; known: {sample}, {arc_length}, {event}, {distance:I:J}");
    out.push_back(p);
    i = end;
  }
  return out;
}

}  // namespace flexure::scenes
