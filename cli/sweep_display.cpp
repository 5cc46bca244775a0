#include "cli/sweep_display.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <utility>

namespace bd::cli {

namespace {

using Clock = std::chrono::steady_clock;

// "0:05", "12:34", "1:02:03"
std::string clock_text(double seconds) {
  const long s = std::lround(seconds);
  if (s >= 3600) return fmt::format("{}:{:02}:{:02}", s / 3600, s / 60 % 60, s % 60);
  return fmt::format("{}:{:02}", s / 60, s % 60);
}

// "5 s", "3 min 20 s", "2 h 5 min"
std::string duration_text(double seconds) {
  const long s = std::lround(seconds);
  if (s >= 3600) return fmt::format("{} h {} min", s / 3600, s / 60 % 60);
  if (s >= 60) return fmt::format("{} min {} s", s / 60, s % 60);
  return fmt::format("{} s", s);
}

// points per second in this session, and the seconds left at that rate (< 0: unknown)
std::pair<double, double> rate_eta(const studies::SweepProgress& p) {
  const int run = p.done - p.resumed;
  if (run <= 0 || p.elapsed_s <= 0) return {0.0, p.done >= p.points ? 0.0 : -1.0};
  const double rate = run / p.elapsed_s;
  return {rate, (p.points - p.done) / rate};
}

// "ETA ..." while the sweep runs; at its last call "done", or "stopped" when points are left (a
// stop or Ctrl-C: no time is left to wait for)
std::string eta_text(const studies::SweepProgress& p, double eta, const char* unknown,
                     std::string (*text)(double)) {
  if (p.finished) return p.done >= p.points ? "done" : "stopped";
  return "ETA " + (eta < 0 ? std::string(unknown) : text(eta));
}

double percent(const studies::SweepProgress& p) {
  return p.points > 0 ? 100.0 * p.done / p.points : 100.0;
}

}  // namespace

SweepDisplay::Mode SweepDisplay::mode_named(const std::string& name) {
  return name == "bar"     ? Mode::kBar
         : name == "lines" ? Mode::kLines
         : name == "none"  ? Mode::kNone
                           : Mode::kAuto;
}

SweepDisplay::SweepDisplay(Mode mode) : mode_(mode), last_(Clock::now()) {
  if (mode_ == Mode::kAuto) mode_ = ::isatty(STDERR_FILENO) ? Mode::kBar : Mode::kLines;
}

void SweepDisplay::show(const studies::SweepProgress& p) {
  const Clock::time_point now = Clock::now();
  if (mode_ == Mode::kBar) {
    if (p.finished || now - last_ >= std::chrono::milliseconds(100)) {
      draw_bar(p);
      last_ = now;
    }
    if (p.finished) {
      std::fputc('\n', stderr);
      std::fflush(stderr);
    }
  } else if (mode_ == Mode::kLines) {
    if (p.finished || now - last_ >= std::chrono::seconds(10)) {
      print_line(p);
      last_ = now;
    }
  }
}

void SweepDisplay::draw_bar(const studies::SweepProgress& p) {
  constexpr int kWidth = 20;
  const auto [rate, eta] = rate_eta(p);
  const int filled =
      p.points > 0 ? static_cast<int>(kWidth * static_cast<long>(p.done) / p.points) : kWidth;
  std::string text =
      fmt::format("  sweep [{}{}]  {}/{}  {:.1f}%   {:.1f} points/s  {}",
                  std::string(static_cast<std::size_t>(filled), '#'),
                  std::string(static_cast<std::size_t>(kWidth - filled), '.'), p.done, p.points,
                  percent(p), rate, eta_text(p, eta, "-:--", clock_text));
  const std::size_t width = text.size();
  if (width < drawn_) text.append(drawn_ - width, ' ');  // clear the longer line before
  drawn_ = width;
  std::fprintf(stderr, "\r%s", text.c_str());
  std::fflush(stderr);
}

void SweepDisplay::print_line(const studies::SweepProgress& p) const {
  const auto [rate, eta] = rate_eta(p);
  std::fprintf(stderr, "sweep: %d/%d points (%.1f %%), %.1f points/s, %s\n", p.done, p.points,
               percent(p), rate, eta_text(p, eta, "unknown", duration_text).c_str());
  std::fflush(stderr);
}

}  // namespace bd::cli
