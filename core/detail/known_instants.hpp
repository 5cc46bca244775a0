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
#include <map>
#include <optional>
#include <span>

namespace bd::core::detail {

/// `State`: what a run continues from at one instant (with what the peak searches read there).
template <class State>
class KnownInstants {
 public:
  /// `t`: the run's sample times, increasing (the span must outlive this).
  explicit KnownInstants(std::span<const double> t) : t_(t) {}

  /// The state at time s within the samples' span, none outside it: `integrate(t0, from, s)`
  /// continues `from`, the state at t0 <= s, to s (none where it cannot), from the latest known
  /// instant at or before s, a sample (`sample(i)`: the state of sample i) or an instant an
  /// earlier call computed, which is kept.
  template <class SampleOf, class Integrate>
  std::optional<State> at(double s, const SampleOf& sample, const Integrate& integrate) {
    if (t_.empty() || !(s >= t_.front()) || !(s <= t_.back())) return std::nullopt;
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
  std::map<double, State> known_;
};

}  // namespace bd::core::detail
