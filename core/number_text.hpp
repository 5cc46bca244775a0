#pragma once
/// The text of a number, in one place for every number the tool writes or says. Built on {fmt};
/// each form gives the same characters as the printf conversion it names.
#include <fmt/format.h>

#include <string>

namespace bd::text {

/// 17 significant digits ("%.17g"): every double reads back as the same double. For numbers in
/// data files (CSV, and JSON through the JSON library, which writes the shortest exact form).
inline std::string exact(double v) { return fmt::format("{:.17g}", v); }

/// The shortest text that reads back as the same double ("0.05", not "0.050000000000000003").
inline std::string shortest(double v) { return fmt::format("{}", v); }

/// `n` significant digits ("%.<n>g"): for a person reading a message or a table.
inline std::string digits(double v, int n) { return fmt::format("{:.{}g}", v, n); }

/// Appends exact(v) to `out` without building a string (per-row file writers).
inline void append_exact(fmt::memory_buffer& out, double v) {
  fmt::format_to(std::back_inserter(out), "{:.17g}", v);
}

}  // namespace bd::text
