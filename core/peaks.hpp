#pragma once
/// Peaks resolved between samples: the largest value of a smooth quantity over a motion, located
/// by maximising the quantity itself (evaluated exactly at any instant by the caller) inside the
/// bracket of each sampled local maximum, so that the sample count no longer decides a peak.
/// Shared by every linkage type's metrics (core/fourbar/metrics.hpp, core/planar/metrics.hpp).
#include <functional>
#include <limits>
#include <span>
#include <vector>

namespace bd::core {

/// Where a quantity is largest, and its value there.
struct Peak {
  Peak() = default;
  Peak(double value_found, double time) : value(value_found), t(time) {}
  double value{};  // the largest value found, never below the largest sample
  double t{};      // its time [s]
  /// A free scene's inputs there, from the motion at t (a four-bar's crank angle [rad]; a planar
  /// linkage's inputs in the order of its `inputs`, rad or m); empty in a driven scene, whose
  /// inputs follow from t, and where the motion at t could not be had.
  std::vector<double> inputs;
};

/// The quantity at time t, or NaN where it cannot be evaluated (that instant is then skipped).
using QuantityAt = std::function<double(double t)>;

/// Relative tolerance to which a bracket's maximiser is located in time; the peak's value, whose
/// error goes with the square of the time's, is then good to round-off.
inline constexpr double kPeakTimeTolerance = 1e-10;
/// The search also ends, before the bracket closes to kPeakTimeTolerance, once a parabolic step
/// changes the value by less than this relative to it, right after a parabolic step that changed
/// it by less than kPeakSettlingTolerance (near a smooth maximum a step's change is about the
/// value's remaining error, and parabolic steps converge superlinearly, so the second confirms
/// the first is not a chance): the value is then good to about kPeakValueTolerance.
inline constexpr double kPeakValueTolerance = 1e-14;
inline constexpr double kPeakSettlingTolerance = 1e-12;

/// Below this many samples over the motion, resolved_peak() evaluates the quantity between them
/// first: their local maxima alone need not bracket every peak (an engine's drive torque at 5 to
/// 7 samples per turn lost a quarter of its peak; from 8 samples on it was found), and 16 gives
/// that twice over.
inline constexpr std::size_t kMinPeakSamples = 16;

/// At most this many instants are added between two samples of a free run (step_instants()).
inline constexpr long kMaxStepInstants = 256;

/// A free run's instants between its samples where its peaks are looked for too: where the
/// integrator took m > 1 steps from sample i to sample i + 1 (`steps_to[i + 1] - steps_to[i]`),
/// m - 1 instants evenly between the two (at most kMaxStepInstants), in increasing order. The
/// quantity evaluated there with the samples is then at least as fine as the integration's own
/// steps, so a peak the motion resolves has a local maximum near it for resolved_peak() to
/// refine, however few the samples (a free run's peak may lie wholly between two coarse samples
/// where neither is a local maximum). `steps_to`: the steps taken up to each sample; none when
/// its size is not t's. A run that stopped short of its end (`stop` > t.back(), the instant its
/// integration reached, `steps_at_stop` its steps there) adds the instants after its last
/// sample in the same way, and the stop itself: its peaks are searched up to where it stopped,
/// not only to its last sample (the loads close to a limit position are often the run's
/// largest).
std::vector<double> step_instants(std::span<const double> t, std::span<const long> steps_to,
                                  double stop = std::numeric_limits<double>::quiet_NaN(),
                                  long steps_at_stop = 0);

/// The peak of x over the samples x[i] = f(t[i]) (t increasing); with fewer than kMinPeakSamples
/// samples, over those and f evaluated evenly between them. Every sampled local maximum whose
/// parabola through it and its neighbours could reach the largest sample is refined by Brent's
/// maximisation of f on the interval between its neighbours; the largest value found wins.
/// `period` > 0: the samples cover one period of a periodic motion, the end excluded, so the
/// first and last samples are neighbours across it (a driven revolution); 0: an open interval
/// (the ends are brackets of their own). One sample of a periodic motion is densified like a few;
/// one sample of an open one, or no f: the largest sample.
Peak resolved_peak(std::span<const double> t, std::span<const double> x, double period,
                   const QuantityAt& f);

}  // namespace bd::core
