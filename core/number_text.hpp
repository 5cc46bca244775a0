#pragma once
/// The text of a number, in one place for every number the tool writes or says. Built on {fmt}
/// and std::to_chars; each form gives the same characters as the printf conversion it names.
#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <string>
#include <string_view>

namespace bd::text {

/// The characters of exact(v) in `buf`: std::to_chars with precision 17 in the general format,
/// which the standard defines as printf's "%.17g" (the same bytes), computed exactly by the
/// standard library's own algorithm without the C library's arbitrary-precision printf (a sweep
/// writes some twenty numbers a point: with printf they cost as much as a tenth of its physics).
inline std::string_view exact_chars(double v, char (&buf)[32]) {
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 17);
  return {buf, static_cast<std::size_t>(r.ptr - buf)};
}

/// 17 significant digits ("%.17g"): every double reads back as the same double. For numbers in
/// data files (CSV, and JSON through the JSON library, which writes the shortest exact form).
inline std::string exact(double v) {
  char buf[32];
  return std::string(exact_chars(v, buf));
}

/// The shortest text that reads back as the same double ("0.05", not "0.050000000000000003").
inline std::string shortest(double v) { return fmt::format("{}", v); }

/// `n` significant digits ("%.<n>g"): for a person reading a message or a table.
inline std::string digits(double v, int n) { return fmt::format("{:.{}g}", v, n); }

/// The display rule of round-off, one for every table, chart and console line: a value within
/// this fraction of its quantity's natural scale (a position: the linkage's size; a force: the
/// largest force of the run) is round-off of it and shown as 0. Data files keep every digit.
inline constexpr double kRoundOff = 1e-12;

/// True when `v` is round-off of `scale` (|v| <= kRoundOff scale, with a finite scale > 0).
inline bool is_round_off(double v, double scale) {
  return std::isfinite(v) && std::isfinite(scale) && scale > 0 && std::abs(v) <= kRoundOff * scale;
}

/// digits(v, n), or "0" where v is round-off of `scale` (is_round_off()); never "-0".
inline std::string scaled(double v, double scale, int n = 6) {
  return is_round_off(v, scale) ? std::string("0") : digits(v + 0.0, n);
}

/// Appends exact(v) to `out` without building a string (per-row file writers).
inline void append_exact(fmt::memory_buffer& out, double v) {
  char buf[32];
  const std::string_view s = exact_chars(v, buf);
  out.append(s.data(), s.data() + s.size());
}

}  // namespace bd::text
