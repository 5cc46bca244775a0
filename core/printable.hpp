#pragma once
/// Text from a file inside a message: control characters escaped, so a message stays one line.
#include <fmt/format.h>

#include <string>
#include <string_view>

namespace bd::text {

/// `s` with every control character written as an escape (\n, \t, \r, \0, else \xNN), so
/// that text from a file (a key holding a newline or a NUL) keeps a message on one line.
inline std::string printable(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  for (const char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x20 && u != 0x7f) {
      out += c;
    } else if (c == '\n') {
      out += "\\n";
    } else if (c == '\t') {
      out += "\\t";
    } else if (c == '\r') {
      out += "\\r";
    } else if (c == '\0') {
      out += "\\0";
    } else {
      out += fmt::format("\\x{:02x}", u);
    }
  }
  return out;
}

/// One character of a text in quotes for a message: ',' or '\n'.
inline std::string quoted_char(char c) { return "'" + printable(std::string_view(&c, 1)) + "'"; }

}  // namespace bd::text
