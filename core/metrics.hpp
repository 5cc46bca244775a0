#pragma once
/// What the metric tables of every linkage type share (core/fourbar/metrics.hpp for the
/// four-bar, core/planar/metrics.hpp for general planar linkages): each metric summarises one
/// magnitude over a run's samples, as its RMS or its peak. Every table lists, per quantity, the
/// RMS and then the peak.
///
/// The shaking force Fsh and moment Msh of every table are their inertial parts (-Σ m a and
/// -dH/dt: what balancing acts on, zero for a balanced design whatever its weight and loads).
/// What the frame feels in all, the weights and the applied loads included, follows every
/// table's own metrics as the total metrics below.
#include <cmath>
#include <cstddef>
#include <span>

namespace bd::core {

/// How the samples' magnitudes become one number.
enum class Statistic {
  kRms,  // sqrt(Σ x² / n)
  kMax,  // max x
};

/// |(a, b)|: sqrt(a² + b²) where that is exact to round-off, std::hypot where a square leaves
/// double's range (a force of 1e200 N has the magnitude 1e200, not inf; issue 17). The common
/// case keeps its bits: results stay identical to the plain formula.
inline double magnitude(double a, double b) {
  const double r = std::sqrt(a * a + b * b);
  if (std::isnormal(r) || (a == 0 && b == 0)) return r;
  return std::hypot(a, b);
}

/// RMS of magnitudes x_i: sqrt(Σ x² / n), the plain sum while it stays finite and, when a square
/// overflows, the sum scaled by the largest |x| (as LAPACK's dnrm2), so an RMS of 1e200 N is
/// 1e200, not inf. A NaN among the x stays NaN.
class RmsAccumulator {
 public:
  void add(double x) {
    ++n_;
    plain_ += x * x;
    x = std::abs(x);
    if (x > scale_) {
      scaled_ = 1.0 + scaled_ * (scale_ / x) * (scale_ / x);
      scale_ = x;
    } else if (x > 0 || x != x) {
      scaled_ += (x / scale_) * (x / scale_);
    }
  }
  double rms() const {
    if (n_ == 0) return 0.0;
    const double n = static_cast<double>(n_);
    if (std::isfinite(plain_) && (plain_ > 0 || scale_ == 0)) return std::sqrt(plain_ / n);
    return scale_ * std::sqrt(scaled_ / n);
  }

 private:
  std::size_t n_ = 0;
  double plain_ = 0.0;
  double scale_ = 0.0;   // the largest |x| so far
  double scaled_ = 0.0;  // Σ (x / scale_)²
};

/// The RMS of the magnitudes x, as RmsAccumulator gives it (the same bits): the plain sum in one
/// pass, the scaled one only where a square leaves double's range.
inline double rms_of(std::span<const double> x) {
  if (x.empty()) return 0.0;
  double plain = 0.0;
  for (const double v : x) plain += v * v;
  if (std::isfinite(plain) && plain > 0) return std::sqrt(plain / static_cast<double>(x.size()));
  RmsAccumulator scaled;
  for (const double v : x) scaled.add(v);
  return scaled.rms();
}

/// One of the total shaking force's and moment's metrics (inertial and static parts together).
struct TotalMetricInfo {
  const char* name;   // summary.json key, CSV column and row
  const char* unit;   // "N" or "N m"
  const char* words;  // for tables and help
  bool force;         // the force |Fsh| (else the moment |Msh|)
  Statistic statistic;
};
/// The total metrics, in the order every table lists them after its own.
inline constexpr TotalMetricInfo kTotalMetrics[] = {
    {"Fsh_total_rms", "N", "RMS of the total shaking force |Fsh|, weights and loads included",
     true, Statistic::kRms},
    {"Fsh_total_max", "N", "peak of the total shaking force |Fsh|, weights and loads included",
     true, Statistic::kMax},
    {"Msh_total_rms", "N m", "RMS of the total shaking moment |Msh|, weights and loads included",
     false, Statistic::kRms},
    {"Msh_total_max", "N m", "peak of the total shaking moment |Msh|, weights and loads included",
     false, Statistic::kMax},
};

}  // namespace bd::core
