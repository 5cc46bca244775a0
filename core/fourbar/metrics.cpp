#include "core/fourbar/metrics.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <numbers>
#include <optional>

#include "core/detail/known_instants.hpp"

namespace bd::core {

const MetricInfo* metric_info(std::string_view name) {
  for (const MetricInfo& m : kMetricTable) {
    if (name == m.name) return &m;
  }
  return nullptr;
}

double magnitude(const DynamicsSample& s, Quantity quantity) {
  switch (quantity) {
    case Quantity::kShakingForce:
      return core::magnitude(s.Fsh_inertial.x(), s.Fsh_inertial.y());
    case Quantity::kShakingMoment:
      return std::abs(s.Msh_inertial);
    case Quantity::kDriveTorque:
      return std::abs(s.tau);
    case Quantity::kReactionA0:
      return core::magnitude(s.RA0.x(), s.RA0.y());
    case Quantity::kReactionA3:
      return core::magnitude(s.RA3.x(), s.RA3.y());
  }
  return 0.0;
}

Metrics metrics(const Trajectory& trajectory) {
  Metrics m;
  const auto& samples = trajectory.samples;
  if (samples.empty()) return m;
  // per row of the table and of the outputs' metrics: the RMS (without overflow) or the running
  // maximum (peak)
  std::array<RmsAccumulator, kMetricCount> rms{};
  std::array<double, kMetricCount> peak{};
  std::array<RmsAccumulator, std::size(kOutputMetrics)> output_rms{};
  std::array<double, std::size(kOutputMetrics)> output_peak{};
  for (const DynamicsSample& s : samples) {
    for (std::size_t k = 0; k < kMetricCount; ++k) {
      const double x = magnitude(s, kMetricTable[k].quantity);
      if (kMetricTable[k].statistic == Statistic::kRms) {
        rms[k].add(x);
      } else {
        peak[k] = std::max(peak[k], x);
      }
    }
    for (std::size_t k = 0; k < output_rms.size(); ++k) {
      const double x = kOutputMetrics[k].magnitude(s);
      if (kOutputMetrics[k].statistic == Statistic::kRms) {
        output_rms[k].add(x);
      } else {
        output_peak[k] = std::max(output_peak[k], x);
      }
    }
  }
  for (std::size_t k = 0; k < kMetricCount; ++k) {
    const MetricInfo& info = kMetricTable[k];
    m.*info.field = info.statistic == Statistic::kRms ? rms[k].rms() : peak[k];
  }
  for (std::size_t k = 0; k < output_rms.size(); ++k) {
    const OutputMetricInfo& info = kOutputMetrics[k];
    m.*info.field = info.statistic == Statistic::kRms ? output_rms[k].rms() : output_peak[k];
  }
  return m;
}

namespace {

// the metrics with the peaks located: refined between the samples by `sample_at` (the sample at
// any time, or none) when given, else the largest samples
Metrics with_peaks(const Trajectory& trajectory, double period,
                   const std::function<std::optional<DynamicsSample>(double)>& sample_at,
                   PeakList* peaks) {
  Metrics m = metrics(trajectory);
  const std::vector<DynamicsSample>& samples = trajectory.samples;
  if (peaks) {
    peaks->table.assign(kMetricCount, Peak{});
    peaks->output.assign(std::size(kOutputMetrics), Peak{});
  }
  if (samples.empty()) return m;
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
  std::vector<double> x(samples.size());
  auto resolve = [&](auto magnitude_of) {
    for (std::size_t i = 0; i < samples.size(); ++i) x[i] = magnitude_of(samples[i]);
    QuantityAt f;
    if (sample_at) {
      f = [&](double s) {
        const std::optional<DynamicsSample>& d = at(s);
        return d ? magnitude_of(*d) : std::nan("");
      };
    }
    return resolved_peak(trajectory.t, x, period, f);
  };
  for (std::size_t k = 0; k < kMetricCount; ++k) {
    const MetricInfo& info = kMetricTable[k];
    if (info.statistic != Statistic::kMax) {
      if (peaks) peaks->table[k] = {m.*info.field, 0.0};
      continue;
    }
    const Peak p = resolve([&](const DynamicsSample& d) { return magnitude(d, info.quantity); });
    m.*info.field = p.value;
    if (peaks) peaks->table[k] = p;
  }
  for (std::size_t k = 0; k < std::size(kOutputMetrics); ++k) {
    const OutputMetricInfo& info = kOutputMetrics[k];
    if (info.statistic != Statistic::kMax) {
      if (peaks) peaks->output[k] = {m.*info.field, 0.0};
      continue;
    }
    const Peak p = resolve(info.magnitude);
    m.*info.field = p.value;
    if (peaks) peaks->output[k] = p;
  }
  return m;
}

}  // namespace

Metrics metrics(const Trajectory& trajectory, PeakList* peaks) {
  return with_peaks(trajectory, 0.0, nullptr, peaks);
}

Metrics metrics(const FourBar& model, const DrivenScene& scene, const Trajectory& trajectory,
                Formulation formulation, PeakList* peaks) {
  const double period =
      trajectory.ok() ? 2 * std::numbers::pi / std::abs(scene.omega1) * scene.revolutions : 0.0;
  return with_peaks(
      trajectory, period,
      [&](double s) -> std::optional<DynamicsSample> {
        const auto d = inverse_dynamics(model, scene.theta1 + scene.omega1 * s, scene.omega1, 0.0,
                                        formulation);
        return d ? std::optional<DynamicsSample>(*d) : std::nullopt;
      },
      peaks);
}

Metrics metrics(const FourBar& model, const Trajectory& trajectory, const SimulateOptions& options,
                PeakList* peaks) {
  // each instant integrated from the latest instant known before it
  detail::KnownInstants<DynamicsSample> known(trajectory.t);
  return with_peaks(
      trajectory, 0.0,
      [&](double s) {
        return known.at(
            s, [&](std::size_t i) -> const DynamicsSample& { return trajectory.samples[i]; },
            [&](double t0, const DynamicsSample& from, double t) {
              return free_sample_from(model, options, t0, from, t);
            });
      },
      peaks);
}

}  // namespace bd::core
