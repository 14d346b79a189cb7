// A filmstrip's caption template ([render] caption): text with fields in braces, read once by
// the scene language and filled in per panel by the presentation layer.
#pragma once

#include <string>
#include <vector>

namespace flexure::scenes {

struct CaptionPiece {
  enum Kind { Text, Sample, ArcLength, Event, Distance } kind = Text;
  std::string text;  // Text: the literal text ("{{" and "}}" already made braces)
  int a = 0, b = 0;  // Distance: the two vertices, as written in the template
};

// The pieces of `pattern`: {sample}, {arc_length}, {event}, {distance:I:J}; "{{" and "}}" are
// braces. Throws std::invalid_argument with the reason for anything else.
std::vector<CaptionPiece> parseCaption(const std::string& pattern);

}  // namespace flexure::scenes
