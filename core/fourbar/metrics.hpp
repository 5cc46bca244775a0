#pragma once
/// The metrics of a run: one table says, for every metric, its name, unit, the quantity it
/// summarises and how (RMS over the samples or the largest magnitude). Every layer that names,
/// orders or computes a metric (the optimiser, the runner's files, sweeps, reports and the
/// command line) reads this table, so all of them list the metrics in one order.
#include <cstddef>
#include <string_view>

#include "core/fourbar/simulate.hpp"
#include "core/metrics.hpp"

namespace bd::core {

/// RMS over samples and maximum of magnitudes.
struct Metrics {
  double Fsh_rms{}, Fsh_max{};  // |F̄sh| [N]
  double Msh_rms{}, Msh_max{};  // |Msh| [N m]
  double tau_rms{}, tau_max{};  // |tau| [N m]
  double RA0_rms{}, RA0_max{};  // |R̄A0| [N]
  double RA3_rms{}, RA3_max{};  // |R̄A3| [N]
};

/// The magnitude a metric summarises, one value per sample.
enum class Quantity {
  kShakingForce,   // |F̄sh| [N]
  kShakingMoment,  // |Msh| [N m]
  kDriveTorque,    // |tau| [N m]
  kReactionA0,     // |R̄A0|, the crank's support [N]
  kReactionA3,     // |R̄A3|, the rocker's support [N]
};

/// One row of the metric table.
struct MetricInfo {
  const char* name;   // "Fsh_rms": summary.json key, CSV column and row, study-file name
  const char* unit;   // "N" or "N m"
  const char* words;  // "RMS of the shaking force |Fsh|", for tables and help
  Quantity quantity;
  Statistic statistic;
  double Metrics::*field;  // where Metrics holds it
};

/// The metrics, in the one order every file and table uses: per quantity its RMS, then its
/// peak.
inline constexpr MetricInfo kMetricTable[] = {
    {"Fsh_rms", "N", "RMS of the shaking force |Fsh|", Quantity::kShakingForce, Statistic::kRms,
     &Metrics::Fsh_rms},
    {"Fsh_max", "N", "peak of the shaking force |Fsh|", Quantity::kShakingForce, Statistic::kMax,
     &Metrics::Fsh_max},
    {"Msh_rms", "N m", "RMS of the shaking moment |Msh|", Quantity::kShakingMoment, Statistic::kRms,
     &Metrics::Msh_rms},
    {"Msh_max", "N m", "peak of the shaking moment |Msh|", Quantity::kShakingMoment,
     Statistic::kMax, &Metrics::Msh_max},
    {"tau_rms", "N m", "RMS of the drive torque |tau|", Quantity::kDriveTorque, Statistic::kRms,
     &Metrics::tau_rms},
    {"tau_max", "N m", "peak of the drive torque |tau|", Quantity::kDriveTorque, Statistic::kMax,
     &Metrics::tau_max},
    {"RA0_rms", "N", "RMS of the crank bearing force |RA0|", Quantity::kReactionA0, Statistic::kRms,
     &Metrics::RA0_rms},
    {"RA0_max", "N", "peak of the crank bearing force |RA0|", Quantity::kReactionA0,
     Statistic::kMax, &Metrics::RA0_max},
    {"RA3_rms", "N", "RMS of the rocker bearing force |RA3|", Quantity::kReactionA3,
     Statistic::kRms, &Metrics::RA3_rms},
    {"RA3_max", "N", "peak of the rocker bearing force |RA3|", Quantity::kReactionA3,
     Statistic::kMax, &Metrics::RA3_max},
};
inline constexpr std::size_t kMetricCount = std::size(kMetricTable);

/// The table's row named `name`, else null.
const MetricInfo* metric_info(std::string_view name);

/// The magnitude of `quantity` at one sample.
double magnitude(const DynamicsSample& sample, Quantity quantity);

/// Metrics over the trajectory's samples (all zero when it has none).
Metrics metrics(const Trajectory& trajectory);

}  // namespace bd::core
