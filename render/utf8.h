// Text that every writer can carry: strict UTF-8 (RFC 3629: no overlong forms, no encoded
// surrogates, nothing past U+10FFFF) and only characters that XML 1.0, TeX and PDF strings take.
// One cleaner for every writer of text from a scene (SVG, TikZ, PDF, image captions).
#pragma once

#include <string>
#include <string_view>

namespace flexure::render {

// The length of the valid UTF-8 sequence at s[i] (1..4), or 0 when it is not one.
size_t utf8Length(std::string_view s, size_t i);

// The code point of the valid sequence of length n at s[i].
char32_t codePoint(std::string_view s, size_t i, size_t n);

// A Unicode noncharacter (U+FDD0..U+FDEF, and U+xFFFE, U+xFFFF in every plane): XML 1.0 does not
// allow U+FFFE and U+FFFF, and none of them is text.
bool isNoncharacter(char32_t c);

// `s` with every byte that is not part of valid UTF-8 and every noncharacter replaced by
// U+FFFD, and every control character (C0 but none, DEL, C1) by a space.
std::string cleanText(std::string_view s);

}  // namespace flexure::render
