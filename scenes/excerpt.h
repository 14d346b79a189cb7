// A bounded excerpt of user text for messages: an error quotes at most this much of what was
// written (a 1 MB expression is not echoed whole), around the place it is about.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace flexure::scenes {

// The characters a quoted excerpt shows at most (the ellipses aside).
constexpr size_t kExcerptWidth = 60;

// `text` whole when it is at most `width` bytes; else a window of about `width` bytes around
// byte `at` (0-based), cut at UTF-8 character boundaries, with "..." where text was left out.
inline std::string excerpt(std::string_view text, size_t at = 0, size_t width = kExcerptWidth) {
  if (text.size() <= width) return std::string(text);
  if (at > text.size()) at = text.size();
  size_t from = at > width / 2 ? at - width / 2 : 0;
  if (from + width > text.size()) from = text.size() - width;
  size_t to = from + width;
  const auto continuation = [&](size_t i) { return i < text.size() && (static_cast<unsigned char>(text[i]) & 0xC0) == 0x80; };
  while (from > 0 && continuation(from)) --from;
  while (to < text.size() && continuation(to)) ++to;
  return (from > 0 ? "..." : "") + std::string(text.substr(from, to - from)) + (to < text.size() ? "..." : "");
}

// The most a message says: one that still quotes more than this (a caller that quotes a value
// whole) is cut to its start and its end.
constexpr size_t kMaxMessage = 1000;

inline std::string boundedMessage(const std::string& message) {
  if (message.size() <= kMaxMessage) return message;
  return excerpt(message, 0, kMaxMessage / 2) + excerpt(message, message.size(), kMaxMessage / 4).substr(3);
}

}  // namespace flexure::scenes
