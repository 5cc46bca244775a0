#pragma once
/// Internal to core, not part of its API (core/detail/xy.hpp says what the detail folders hold).
///
/// What both linkage types' free peaks share (core/fourbar/metrics.cpp, core/planar/metrics.cpp):
/// the instants of a free run whose state is known exactly, its samples and those a peak search
/// has computed, each further instant integrated from the latest of them before it. Brent's
/// steps close in on a peak (core/peaks.hpp), so each integration spans a fraction of a sample
/// interval; every quantity's search shares the instants.
#include <algorithm>
#include <cstddef>
#include <iterator>
#include <limits>
#include <map>
#include <optional>
#include <span>
#include <utility>

namespace bd::core::detail {

/// `State`: what a run continues from at one instant (with what the peak searches read there).
template <class State>
class KnownInstants {
 public:
  /// `t`: the run's sample times, increasing (the span must outlive this); `stop`: where a run
  /// that stopped short of its end had integrated to, past its last sample (NaN otherwise).
  explicit KnownInstants(std::span<const double> t,
                         double stop = std::numeric_limits<double>::quiet_NaN())
      : t_(t), end_(t.empty() ? stop : std::max(t.back(), stop)) {}

  /// The state at time s from the first sample to the end (the last sample, or the stop past
  /// it), none outside: `integrate(t0, from, s)`
  /// continues `from`, the state at t0 <= s, to s (none where it cannot), from the latest known
  /// instant at or before s, a sample (`sample(i)`: the state of sample i) or an instant an
  /// earlier call computed, which is kept.
  /// Takes the state at time s as known (a stopped run's state where it stopped).
  void add(double s, State state) { known_.insert_or_assign(s, std::move(state)); }

  template <class SampleOf, class Integrate>
  std::optional<State> at(double s, const SampleOf& sample, const Integrate& integrate) {
    if (t_.empty() || !(s >= t_.front()) || !(s <= end_)) return std::nullopt;
    const auto i =
        static_cast<std::size_t>(std::upper_bound(t_.begin(), t_.end(), s) - t_.begin()) - 1;
    double t0 = t_[i];
    std::optional<State> r;
    if (auto k = known_.upper_bound(s); k != known_.begin() && std::prev(k)->first > t0) {
      --k;
      t0 = k->first;
      r = integrate(t0, k->second, s);
    } else {
      r = integrate(t0, sample(i), s);
    }
    if (r && s > t0) known_.emplace(s, *r);
    return r;
  }

 private:
  std::span<const double> t_;
  double end_;
  std::map<double, State> known_;
};

}  // namespace bd::core::detail
