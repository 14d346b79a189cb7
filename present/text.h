// Text that leaves the process: JSON that is always valid (names from the file system need not
// be UTF-8) and lines for a terminal that cannot carry escape sequences from a scene file.
#pragma once

#include <nlohmann/json.hpp>
#include <streambuf>
#include <string>
#include <string_view>

namespace flexure::present {

// `j` as JSON text (indent < 0: one line); bytes that are not UTF-8 become U+FFFD instead of
// throwing.
std::string jsonText(const nlohmann::ordered_json& j, int indent = -1);

// `s` with every control character but newline and tab written as \xHH (C0, DEL, and the C1
// range U+0080..U+009F), and every byte that is not part of valid UTF-8 as \xHH, so that a
// title or an expression cannot move the cursor, retitle the window or hide text.
std::string terminalSafe(std::string_view s);

// A stream buffer that passes whole lines through terminalSafe to `target`: installed on
// std::cout and std::cerr, everything the program prints is safe, whoever wrote it.
class TerminalFilter : public std::streambuf {
 public:
  explicit TerminalFilter(std::streambuf* target) : target_(target) {}
  ~TerminalFilter() override { sync(); }

 protected:
  int_type overflow(int_type c) override;
  std::streamsize xsputn(const char* s, std::streamsize n) override;
  int sync() override;

 private:
  bool flushLine();
  std::streambuf* target_;
  std::string line_;
};

}  // namespace flexure::present
