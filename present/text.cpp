#include "present/text.h"

#include <cstdio>

#include "render/utf8.h"

namespace flexure::present {

std::string jsonText(const nlohmann::ordered_json& j, int indent) {
  return j.dump(indent, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
}

using render::utf8Length;

std::string terminalSafe(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  const auto escape = [&](unsigned char c) {
    char buf[8];
    std::snprintf(buf, sizeof buf, "\\x%02X", c);
    out += buf;
  };
  for (size_t i = 0; i < s.size();) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    const size_t n = utf8Length(s, i);
    if (n == 0) {
      escape(c);
      ++i;
    } else if (n == 1) {
      if ((c < 0x20 && c != '\n' && c != '\t') || c == 0x7F) escape(c);
      else out += static_cast<char>(c);
      ++i;
    } else if (n == 2 && c == 0xC2 && static_cast<unsigned char>(s[i + 1]) < 0xA0) {
      escape(c), escape(static_cast<unsigned char>(s[i + 1]));  // a C1 control
      i += 2;
    } else {
      out.append(s.substr(i, n));
      i += n;
    }
  }
  return out;
}

TerminalFilter::int_type TerminalFilter::overflow(int_type c) {
  if (traits_type::eq_int_type(c, traits_type::eof())) return sync() == 0 ? traits_type::not_eof(c) : c;
  line_ += traits_type::to_char_type(c);
  if (c == '\n' && !flushLine()) return traits_type::eof();
  return c;
}

std::streamsize TerminalFilter::xsputn(const char* s, std::streamsize n) {
  line_.append(s, static_cast<size_t>(n));
  if (line_.find('\n') != std::string::npos && !flushLine()) return 0;
  return n;
}

int TerminalFilter::sync() {
  if (!flushLine()) return -1;
  return target_->pubsync();
}

// Writes what is buffered (whole lines, and the rest at a sync); false when the target fails.
bool TerminalFilter::flushLine() {
  if (line_.empty()) return true;
  const std::string safe = terminalSafe(line_);
  line_.clear();
  return target_->sputn(safe.data(), static_cast<std::streamsize>(safe.size())) ==
         static_cast<std::streamsize>(safe.size());
}

}  // namespace flexure::present
