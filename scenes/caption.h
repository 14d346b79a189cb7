// A filmstrip's caption template ([render] caption): text with fields in braces, read once by
// the scene language and filled in per panel by the presentation layer.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

namespace flexure::scenes {

struct CaptionPiece {
  enum Kind { Text, Sample, ArcLength, Event, Distance } kind = Text;
  std::string text;  // Text: the literal text ("{{" and "}}" already made braces)
  int a = 0, b = 0;  // Distance: the two vertices, as written in the template
};

// A caption that cannot be read: the reason, and where in the pattern (0-based byte offset).
struct CaptionError : std::invalid_argument {
  CaptionError(const std::string& message, size_t offset) : std::invalid_argument(message), offset(offset) {}
  size_t offset;
};

// The pieces of `pattern`: {sample}, {arc_length}, {event}, {distance:I:J}; "{{" and "}}" are
// braces. I and J are vertex numbers counting from `base`, below base + `count`; Distance's
// vertices come back from 0. Throws CaptionError with the reason and its offset for anything
// else, a vertex number out of range (however many digits it has) included.
std::vector<CaptionPiece> parseCaption(const std::string& pattern, int base, int count);

}  // namespace flexure::scenes
