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
      return s.Fsh.norm();
    case Quantity::kShakingMoment:
      return std::abs(s.Msh);
    case Quantity::kDriveTorque:
      return std::abs(s.tau);
    case Quantity::kReactionA0:
      return s.RA0.norm();
    case Quantity::kReactionA3:
      return s.RA3.norm();
  }
  return 0.0;
}

Metrics metrics(const Trajectory& trajectory) {
  Metrics m;
  const auto& samples = trajectory.samples;
  if (samples.empty()) return m;
  // per row of the table: the sum of squares (RMS) or the running maximum (peak)
  std::array<double, kMetricCount> acc{};
  for (const DynamicsSample& s : samples) {
    for (std::size_t k = 0; k < kMetricCount; ++k) {
      const double x = magnitude(s, kMetricTable[k].quantity);
      acc[k] = kMetricTable[k].statistic == Statistic::kRms ? acc[k] + x * x : std::max(acc[k], x);
    }
  }
  const double n = static_cast<double>(samples.size());
  for (std::size_t k = 0; k < kMetricCount; ++k) {
    const MetricInfo& info = kMetricTable[k];
    m.*info.field = info.statistic == Statistic::kRms ? std::sqrt(acc[k] / n) : acc[k];
  }
  return m;
}

}  // namespace bd::core
