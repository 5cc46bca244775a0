#pragma once
// The sweep's progress on stderr: a bar redrawn in place at most ten times a second (on a
// terminal), or a plain line every 10 s; both end with the final state. The rate is over the
// points run in this session, the done count includes the resumed ones.
#include <chrono>
#include <string>

#include "studies/sweep/sweep.hpp"

namespace bd::cli {

class SweepDisplay {
 public:
  enum class Mode { kAuto, kBar, kLines, kNone };
  /// "auto", "bar", "lines" or "none"; kAuto is a bar when stderr is a terminal, else lines.
  static Mode mode_named(const std::string& name);

  explicit SweepDisplay(Mode mode);
  /// Draws `p` (as studies::SweepOptions::progress is called).
  void show(const studies::SweepProgress& p);

 private:
  void draw_bar(const studies::SweepProgress& p);
  void print_line(const studies::SweepProgress& p) const;

  Mode mode_;
  std::chrono::steady_clock::time_point last_;
  std::size_t drawn_ = 0;  // width of the bar line last drawn
};

}  // namespace bd::cli
