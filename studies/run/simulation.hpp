#pragma once
/// The one place a run dispatches on the linkage type and method: the study's scene simulated by
/// the four-bar's closed form, by the general engine on a four-bar (its samples mapped back to
/// the four-bar's, so every four-bar output reads the same), or by the general engine on a
/// planar linkage; and the run's metrics, from the four-bar's table or the planar linkage's.
#include <string>
#include <vector>

#include "core/fourbar/metrics.hpp"
#include "core/fourbar/simulate.hpp"
#include "core/planar/simulate.hpp"
#include "studies/study/method.hpp"
#include "studies/study/study.hpp"

namespace bd::studies {

/// One metric of a run: name and unit from its linkage type's table, and its value.
struct MetricValue {
  std::string name, unit;
  double value{};
};
using MetricList = std::vector<MetricValue>;

/// How a run ended, whatever the linkage type.
struct RunStatus {
  core::SimulationStatus status = core::SimulationStatus::kNotRun;
  std::string message;
  std::size_t samples{};
  long steps{}, rhs_evaluations{};
  bool ok() const { return status == core::SimulationStatus::kCompleted; }
};

/// A simulation of a study: a four-bar's trajectory (`fourbar`) or a planar linkage's table
/// (`planar`), the other left empty.
struct Simulation {
  MethodChoice method;
  core::Trajectory fourbar;
  core::planar::Trajectory planar;
  bool is_planar{};

  RunStatus status() const;
};

/// Simulates the study's scene with the method choose_method() gives it. A planar linkage's free
/// run on `auto` that stops at a limit position is repeated on the stabilised DAE (truss-dae),
/// which passes through it; the method's reason then says so.
/// @throws bd::InputError if the scene or options are invalid.
Simulation simulate(const Study& study);
/// The same with a given method (the balanced or optimised design's own choice).
Simulation simulate(const Study& study, const MethodChoice& method);

/// The run's metrics in its table's order: a four-bar's (core::kMetricTable) or a planar
/// linkage's (core::planar::metric_table()).
MetricList metric_list(const Study& study, const Simulation& simulation);
/// A four-bar's metrics in the table's order.
MetricList metric_list(const core::Metrics& metrics);
/// The names of the metrics a run of the study has, in its table's order.
std::vector<std::string> metric_names(const Study& study);

}  // namespace bd::studies
