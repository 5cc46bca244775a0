#pragma once
/// The metrics of a run: one table says, for every metric, its name, unit, the quantity it
/// summarises and how (RMS over the samples or the largest magnitude). Every layer that names,
/// orders or computes a metric (the optimiser, the runner's files, sweeps, reports and the
/// command line) reads this table, so all of them list the metrics in one order.
#include <array>
#include <cmath>
#include <cstddef>
#include <functional>
#include <optional>
#include <string_view>
#include <vector>

#include "core/fourbar/simulate.hpp"
#include "core/metrics.hpp"
#include "core/peaks.hpp"

namespace bd::core {

/// RMS over samples and maximum of magnitudes.
struct Metrics {
  double Fsh_rms{}, Fsh_max{};  // |F̄sh|, its inertial part [N]
  double Msh_rms{}, Msh_max{};  // |Msh|, its inertial part [N m]
  double tau_rms{}, tau_max{};  // |tau| [N m]
  double RA0_rms{}, RA0_max{};  // |R̄A0| [N]
  double RA3_rms{}, RA3_max{};  // |R̄A3| [N]
  /// Outputs that are not rows of the table (kOutputMetrics): the total shaking force and moment
  /// (core::kTotalMetrics) and the joint forces' peaks.
  double Fsh_total_rms{}, Fsh_total_max{};  // |F̄sh| [N]
  double Msh_total_rms{}, Msh_total_max{};  // |Msh| [N m]
  double FA1_max{}, FA2_max{};              // |F̄A1|, |F̄A2| [N]
  /// The counter-rotation shafts' bearing forces (0 without a disc): |R̄C1|, |R̄C3| [N]
  double RC1_rms{}, RC1_max{}, RC3_rms{}, RC3_max{};
};

/// The magnitude a metric summarises, one value per sample.
enum class Quantity {
  kShakingForce,   // |F̄sh|, its inertial part [N]
  kShakingMoment,  // |Msh|, its inertial part [N m]
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
    {"Fsh_rms", "N", "RMS of the inertial shaking force |Fsh|", Quantity::kShakingForce,
     Statistic::kRms, &Metrics::Fsh_rms},
    {"Fsh_max", "N", "peak of the inertial shaking force |Fsh|", Quantity::kShakingForce,
     Statistic::kMax, &Metrics::Fsh_max},
    {"Msh_rms", "N m", "RMS of the inertial shaking moment |Msh|", Quantity::kShakingMoment,
     Statistic::kRms, &Metrics::Msh_rms},
    {"Msh_max", "N m", "peak of the inertial shaking moment |Msh|", Quantity::kShakingMoment,
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
inline double magnitude(const DynamicsSample& s, Quantity quantity) {
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


/// The magnitude an output metric (kOutputMetrics) summarises, one value per sample.
enum class OutputQuantity {
  kTotalShakingForce,   // |F̄sh|, weights and loads included [N]
  kTotalShakingMoment,  // |Msh|, weights and loads included [N m]
  kJointA1,             // |F̄A1| [N]
  kJointA2,             // |F̄A2| [N]
  kCounterCrank,        // |R̄C1|, the crank's counter-rotation shaft on the frame [N]
  kCounterRocker,       // |R̄C3|, the rocker's [N]
};
inline constexpr std::size_t kOutputQuantityCount = 6;

/// The magnitude of `quantity` at one sample.
inline double magnitude(const DynamicsSample& s, OutputQuantity quantity) {
  switch (quantity) {
    case OutputQuantity::kTotalShakingForce:
      return core::magnitude(s.Fsh.x(), s.Fsh.y());
    case OutputQuantity::kTotalShakingMoment:
      return std::abs(s.Msh);
    case OutputQuantity::kJointA1:
      return core::magnitude(s.FA1.x(), s.FA1.y());
    case OutputQuantity::kJointA2:
      return core::magnitude(s.FA2.x(), s.FA2.y());
    case OutputQuantity::kCounterCrank:
      return core::magnitude(s.RC1.x(), s.RC1.y());
    case OutputQuantity::kCounterRocker:
      return core::magnitude(s.RC3.x(), s.RC3.y());
  }
  return 0.0;
}

/// A metric every output lists after the table's, which the optimiser does not take: the total
/// shaking force and moment (core::kTotalMetrics, in its order), then the peaks of the joint
/// forces between moving links.
struct OutputMetricInfo {
  const char* name;
  const char* unit;
  const char* words;
  Statistic statistic;
  double Metrics::*field;
  OutputQuantity quantity;
};
inline constexpr OutputMetricInfo kOutputMetrics[] = {
    {kTotalMetrics[0].name, kTotalMetrics[0].unit, kTotalMetrics[0].words, Statistic::kRms,
     &Metrics::Fsh_total_rms, OutputQuantity::kTotalShakingForce},
    {kTotalMetrics[1].name, kTotalMetrics[1].unit, kTotalMetrics[1].words, Statistic::kMax,
     &Metrics::Fsh_total_max, OutputQuantity::kTotalShakingForce},
    {kTotalMetrics[2].name, kTotalMetrics[2].unit, kTotalMetrics[2].words, Statistic::kRms,
     &Metrics::Msh_total_rms, OutputQuantity::kTotalShakingMoment},
    {kTotalMetrics[3].name, kTotalMetrics[3].unit, kTotalMetrics[3].words, Statistic::kMax,
     &Metrics::Msh_total_max, OutputQuantity::kTotalShakingMoment},
    {"FA1_max", "N", "peak of the joint force |FA1| (crank on coupler)", Statistic::kMax,
     &Metrics::FA1_max, OutputQuantity::kJointA1},
    {"FA2_max", "N", "peak of the joint force |FA2| (coupler on rocker)", Statistic::kMax,
     &Metrics::FA2_max, OutputQuantity::kJointA2},
    // the counter-rotation shafts' bearings: a study lists them only where the disc is
    // (studies::metric_list())
    {"RC1_rms", "N", "RMS of the crank's counter-rotation shaft force |RC1|", Statistic::kRms,
     &Metrics::RC1_rms, OutputQuantity::kCounterCrank},
    {"RC1_max", "N", "peak of the crank's counter-rotation shaft force |RC1|", Statistic::kMax,
     &Metrics::RC1_max, OutputQuantity::kCounterCrank},
    {"RC3_rms", "N", "RMS of the rocker's counter-rotation shaft force |RC3|", Statistic::kRms,
     &Metrics::RC3_rms, OutputQuantity::kCounterRocker},
    {"RC3_max", "N", "peak of the rocker's counter-rotation shaft force |RC3|", Statistic::kMax,
     &Metrics::RC3_max, OutputQuantity::kCounterRocker},
};

/// Where the peaks of a run lie: per row of kMetricTable (RMS rows: their value and t = 0),
/// and per row of kOutputMetrics.
struct PeakList {
  std::vector<Peak> table, output;
};

/// Metrics over the trajectory's samples (all zero when it has none): peaks are the largest
/// samples.
Metrics metrics(const Trajectory& trajectory);

/// The same, with the peaks' places: each the largest sample.
Metrics metrics(const Trajectory& trajectory, PeakList* peaks);

/// Metrics of a driven run of `model` in `scene` (the run's samples in `trajectory`, computed by
/// `formulation`) with every peak resolved between the samples: maximised over time by the exact
/// inverse dynamics at the refined crank angle (core/peaks.hpp), so that it no longer depends on
/// the sample count. A run of whole revolutions is periodic (the last sample's neighbour is the
/// first); a run that stopped early is resolved within its time span. `peaks`, when given,
/// receives where each lies.
Metrics metrics(const FourBar& model, const DrivenScene& scene, const Trajectory& trajectory,
                Formulation formulation, PeakList* peaks = nullptr);

/// The sample of a run at any time t within it, none where it cannot be evaluated.
using SampleAt = std::function<std::optional<DynamicsSample>(double t)>;

/// Metrics of a run with every peak resolved between the samples by `sample_at`, the run's own
/// evaluation at any instant (a four-bar computed by the general planar engine: that engine's,
/// which follows the linkage closer to a dead centre than the closed forms' singular test
/// allows). `period` > 0: the run is periodic with that period.
Metrics metrics(const Trajectory& trajectory, double period, const SampleAt& sample_at,
                PeakList* peaks = nullptr);

/// Metrics of a free run `trajectory` = simulate_free(model, scene, options) with every peak
/// resolved between the samples: maximised over time by the state integrated from the sample
/// before each instant, the last step ending there (free_sample_from(), core/fourbar/simulate.hpp),
/// exact to the integration tolerance as the samples are. The ends of the run are brackets of
/// their own (not periodic).
Metrics metrics(const FourBar& model, const Trajectory& trajectory, const SimulateOptions& options,
                PeakList* peaks = nullptr);

/// Which rows of core::kMetricTable (in its order) to resolve.
using MetricMask = std::array<bool, kMetricCount>;

/// The same, resolving only the peaks of the table's rows that `resolve` marks (all where it is
/// null); the other rows' peaks and every output metric's are their largest samples, as
/// metrics(trajectory) takes them. For an optimiser that reads a few metrics of many runs.
Metrics metrics(const FourBar& model, const Trajectory& trajectory, const SimulateOptions& options,
                const MetricMask* resolve, PeakList* peaks = nullptr);

}  // namespace bd::core
