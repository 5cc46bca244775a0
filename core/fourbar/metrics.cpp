#include "core/fourbar/metrics.hpp"

#include <algorithm>
#include <array>
#include <cmath>

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
      return core::magnitude(s.Fsh.x(), s.Fsh.y());
    case Quantity::kShakingMoment:
      return std::abs(s.Msh);
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
  // per row of the table: the RMS (without overflow) or the running maximum (peak)
  std::array<RmsAccumulator, kMetricCount> rms{};
  std::array<double, kMetricCount> peak{};
  for (const DynamicsSample& s : samples) {
    for (std::size_t k = 0; k < kMetricCount; ++k) {
      const double x = magnitude(s, kMetricTable[k].quantity);
      if (kMetricTable[k].statistic == Statistic::kRms) {
        rms[k].add(x);
      } else {
        peak[k] = std::max(peak[k], x);
      }
    }
  }
  for (std::size_t k = 0; k < kMetricCount; ++k) {
    const MetricInfo& info = kMetricTable[k];
    m.*info.field = info.statistic == Statistic::kRms ? rms[k].rms() : peak[k];
  }
  return m;
}

}  // namespace bd::core
