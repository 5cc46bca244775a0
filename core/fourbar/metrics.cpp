#include "core/fourbar/metrics.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <numbers>
#include <optional>
#include <span>
#include <vector>

#include "core/detail/known_instants.hpp"
#include "core/fourbar/detail/instant_dynamics.hpp"

namespace bd::core {

const MetricInfo* metric_info(std::string_view name) {
  for (const MetricInfo& m : kMetricTable) {
    if (name == m.name) return &m;
  }
  return nullptr;
}

namespace {

// the Quantity values are 0, 1, ..., kQuantityCount - 1, the last kReactionA3 (as for
// OutputQuantity)
constexpr std::size_t kQuantityCount = static_cast<std::size_t>(Quantity::kReactionA3) + 1;
static_assert(static_cast<std::size_t>(OutputQuantity::kCounterRocker) + 1 == kOutputQuantityCount);
constexpr std::size_t kOutputCount = std::size(kOutputMetrics);

// Every sample's magnitudes, computed once for the RMS, the peaks and their search: a column
// per Quantity, then one per OutputQuantity (a magnitude two metrics summarise, such as the
// total shaking force's RMS and peak, is computed once).
class SampleMagnitudes {
 public:
  explicit SampleMagnitudes(const std::vector<DynamicsSample>& samples)
      : n_(samples.size()), v_(new double[(kQuantityCount + kOutputQuantityCount) * n_]) {
    double* const out = v_.get();
    for (std::size_t i = 0; i < n_; ++i) {
      const DynamicsSample& s = samples[i];
      for (std::size_t q = 0; q < kQuantityCount; ++q)
        out[q * n_ + i] = magnitude(s, static_cast<Quantity>(q));
      for (std::size_t q = 0; q < kOutputQuantityCount; ++q)
        out[(kQuantityCount + q) * n_ + i] = magnitude(s, static_cast<OutputQuantity>(q));
    }
  }
  std::span<const double> of(Quantity quantity) const {
    return column(static_cast<std::size_t>(quantity));
  }
  std::span<const double> output(std::size_t k) const {
    return column(kQuantityCount + static_cast<std::size_t>(kOutputMetrics[k].quantity));
  }

 private:
  std::span<const double> column(std::size_t c) const { return {v_.get() + c * n_, n_}; }
  std::size_t n_;
  std::unique_ptr<double[]> v_;  // left uninitialised: every value is written above
};

double statistic_of(std::span<const double> x, Statistic statistic) {
  if (statistic == Statistic::kRms) return rms_of(x);
  double peak = 0.0;
  for (const double v : x) peak = std::max(peak, v);
  return peak;
}

Metrics metrics_of(const SampleMagnitudes& magnitudes) {
  Metrics m;
  for (const MetricInfo& info : kMetricTable)
    m.*info.field = statistic_of(magnitudes.of(info.quantity), info.statistic);
  for (std::size_t k = 0; k < kOutputCount; ++k)
    m.*kOutputMetrics[k].field = statistic_of(magnitudes.output(k), kOutputMetrics[k].statistic);
  return m;
}

}  // namespace

Metrics metrics(const Trajectory& trajectory) {
  if (trajectory.samples.empty()) return {};
  return metrics_of(SampleMagnitudes(trajectory.samples));
}

namespace {

// the metrics with the peaks located: refined between the samples by `sample_at` (the sample at
// any time, or none) when given, else the largest samples; with `resolve`, only the table's rows
// it marks are refined (the others and the output metrics are their largest samples)
Metrics with_peaks(const Trajectory& trajectory, double period,
                   const std::function<std::optional<DynamicsSample>(double)>& sample_at,
                   PeakList* peaks, const MetricMask* resolve = nullptr) {
  const std::vector<DynamicsSample>& samples = trajectory.samples;
  if (peaks) {
    peaks->table.assign(kMetricCount, Peak{});
    peaks->output.assign(std::size(kOutputMetrics), Peak{});
  }
  if (samples.empty()) return {};
  // the RMS rows from the samples' magnitudes, the peak rows by their searches
  const SampleMagnitudes magnitudes(samples);
  Metrics m;
  // the sample at time s, computed once for every quantity's search
  double cached_t = std::nan("");
  std::optional<DynamicsSample> cached;
  auto at = [&](double s) -> const std::optional<DynamicsSample>& {
    if (s != cached_t) {
      cached_t = s;
      cached = sample_at(s);
    }
    return cached;
  };
  // a free run's instants between samples where the integrator stepped more than once, evaluated
  // once for every refined peak: the samples with them (their magnitudes) are what the refined
  // peaks search
  std::vector<double> dense_t;
  std::vector<DynamicsSample> dense;
  bool any_refined = resolve == nullptr;
  for (std::size_t k = 0; resolve && k < kMetricCount; ++k)
    any_refined = any_refined || (*resolve)[k];
  if (sample_at && any_refined) {
    const std::vector<double> extra =
        step_instants(trajectory.t, trajectory.steps_to, trajectory.stop_time, trajectory.steps);
    dense_t.reserve(samples.size() + extra.size());
    dense.reserve(samples.size() + extra.size());
    std::size_t e = 0;
    for (std::size_t i = 0; i < samples.size() && !extra.empty(); ++i) {
      dense_t.push_back(trajectory.t[i]);
      dense.push_back(samples[i]);
      for (; e < extra.size() && (i + 1 == samples.size() || extra[e] < trajectory.t[i + 1]); ++e) {
        if (const std::optional<DynamicsSample>& d = at(extra[e])) {
          dense_t.push_back(extra[e]);
          dense.push_back(*d);
        }
      }
    }
  }
  const bool densified = dense.size() > samples.size();
  const std::unique_ptr<const SampleMagnitudes> dense_magnitudes =
      densified ? std::make_unique<const SampleMagnitudes>(dense) : nullptr;
  auto refine = [&](std::span<const double> x, std::span<const double> x_dense, bool refined,
                    auto magnitude_of) {
    QuantityAt f;
    if (sample_at && refined) {
      f = [&](double s) {
        const std::optional<DynamicsSample>& d = at(s);
        return d ? magnitude_of(*d) : std::nan("");
      };
      if (densified) return resolved_peak(dense_t, x_dense, period, f);
    }
    return resolved_peak(trajectory.t, x, period, f);
  };
  for (std::size_t k = 0; k < kMetricCount; ++k) {
    const MetricInfo& info = kMetricTable[k];
    if (info.statistic != Statistic::kMax) {
      m.*info.field = rms_of(magnitudes.of(info.quantity));
      if (peaks) peaks->table[k] = {m.*info.field, 0.0};
      continue;
    }
    const Peak p =
        refine(magnitudes.of(info.quantity),
               densified ? dense_magnitudes->of(info.quantity) : std::span<const double>(),
               !resolve || (*resolve)[k],
               [&](const DynamicsSample& d) { return magnitude(d, info.quantity); });
    m.*info.field = p.value;
    if (peaks) peaks->table[k] = p;
  }
  for (std::size_t k = 0; k < std::size(kOutputMetrics); ++k) {
    const OutputMetricInfo& info = kOutputMetrics[k];
    if (info.statistic != Statistic::kMax) {
      m.*info.field = rms_of(magnitudes.output(k));
      if (peaks) peaks->output[k] = {m.*info.field, 0.0};
      continue;
    }
    const Peak p = refine(
        magnitudes.output(k), densified ? dense_magnitudes->output(k) : std::span<const double>(),
        resolve == nullptr, [&](const DynamicsSample& d) { return magnitude(d, info.quantity); });
    m.*info.field = p.value;
    if (peaks) peaks->output[k] = p;
  }
  return m;
}

}  // namespace

Metrics metrics(const Trajectory& trajectory, PeakList* peaks) {
  return with_peaks(trajectory, 0.0, nullptr, peaks);
}

Metrics metrics(const Trajectory& trajectory, double period, const SampleAt& sample_at,
                PeakList* peaks) {
  return with_peaks(trajectory, period, sample_at, peaks);
}

Metrics metrics(const FourBar& model, const DrivenScene& scene, const Trajectory& trajectory,
                Formulation formulation, PeakList* peaks) {
  const double period =
      trajectory.ok() ? 2 * std::numbers::pi / std::abs(scene.omega1) * scene.revolutions : 0.0;
  // the instants as simulate_driven() computes its samples, the model's constants once
  const detail::DynamicsConstants constants = detail::dynamics_constants(model);
  detail::ClosedInstant instant;
  return with_peaks(
      trajectory, period,
      [&](double s) -> std::optional<DynamicsSample> {
        const double theta1 = scene.theta1 + scene.omega1 * s;
        if (constants.counter_rotations) {
          const auto d = inverse_dynamics(model, theta1, scene.omega1, 0.0, formulation);
          return d ? std::optional<DynamicsSample>(*d) : std::nullopt;
        }
        std::optional<DynamicsSample> d(std::in_place);
        if (detail::driven_instant_at(model, constants, theta1, detail::crank_vector(model, theta1),
                                      scene.omega1, formulation, instant, *d)) {
          return std::nullopt;
        }
        return d;
      },
      peaks);
}

Metrics metrics(const FourBar& model, const Trajectory& trajectory, const SimulateOptions& options,
                PeakList* peaks) {
  return metrics(model, trajectory, options, nullptr, peaks);
}

Metrics metrics(const FourBar& model, const Trajectory& trajectory, const SimulateOptions& options,
                const MetricMask* resolve, PeakList* peaks) {
  // each instant integrated from the latest instant known before it
  detail::KnownInstants<DynamicsSample> known(trajectory.t, trajectory.stop_time);
  if (trajectory.stop) known.add(trajectory.stop_time, *trajectory.stop);
  const auto sample_at = [&](double s) {
    return known.at(
        s, [&](std::size_t i) -> const DynamicsSample& { return trajectory.samples[i]; },
        [&](double t0, const DynamicsSample& from, double t) {
          return free_sample_from(model, options, t0, from, t);
        });
  };
  const Metrics m = with_peaks(trajectory, 0.0, sample_at, peaks, resolve);
  // where each peak lies: the crank's angle there
  const auto locate = [&](Peak& p) {
    if (const std::optional<DynamicsSample> d = sample_at(p.t)) p.inputs = {d->state.theta1};
  };
  for (std::size_t k = 0; peaks && k < kMetricCount; ++k)
    if (kMetricTable[k].statistic == Statistic::kMax) locate(peaks->table[k]);
  for (std::size_t k = 0; peaks && k < kOutputCount; ++k)
    if (kOutputMetrics[k].statistic == Statistic::kMax) locate(peaks->output[k]);
  return m;
}

}  // namespace bd::core
