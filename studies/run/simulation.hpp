#pragma once
/// The one place a run dispatches on the linkage type and method: the study's scene simulated by
/// the four-bar's closed form, by the general engine on a four-bar (its samples mapped back to
/// the four-bar's, so every four-bar output reads the same), or by the general engine on a
/// planar linkage; and the run's metrics, from the four-bar's table or the planar linkage's.
#include <optional>
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
  std::optional<double> t;  // a peak: the time where it lies [s]
  /// a peak of a free scene: the inputs' values where it lies (a four-bar's crank angle; a
  /// planar linkage's inputs), from the motion; empty otherwise
  std::vector<double> inputs{};
};
using MetricList = std::vector<MetricValue>;

/// The natural scales of a run's quantities, for the display rule of round-off
/// (text::is_round_off(): a value within 1e-12 of its scale is shown as 0, on the report page
/// and the terminal alike): a position's is the linkage's size (linkage_size()), a force's the
/// largest force of the run (any metric in N of any of its designs), a moment's the largest
/// moment of the run or that force times the size, whichever is larger.
struct DisplayScales {
  double length = 0, force = 0, moment = 0;
  double imbalance = 0;  // a shaking force's rotating parts per unit speed squared [kg m]
  /// Takes a metric of the run, `value` in `unit`, into the force, moment or imbalance scale.
  void add(const std::string& unit, double value);
  /// Takes every metric of `metrics`.
  void add(const MetricList& metrics);
  /// The scale of a quantity in `unit` ("m", "N", "N m", "kg m"); 0 (none: the values' own)
  /// otherwise.
  double of(const std::string& unit) const;
};

/// How a run ended, whatever the linkage type.
struct RunStatus {
  core::SimulationStatus status = core::SimulationStatus::kNotRun;
  std::string message;
  std::size_t samples{};
  long steps{}, rhs_evaluations{};
  bool ok() const { return status == core::SimulationStatus::kCompleted; }
};

/// How a four-bar's or a planar linkage's run ended.
RunStatus run_status(const core::Trajectory& trajectory);
RunStatus run_status(const core::planar::Trajectory& trajectory);

/// A free run's integration tolerances: relative, and absolute on the coordinates and rates.
struct Tolerances {
  double relative = 1e-10;
  double absolute = 1e-12;
};

/// A simulation of a study: a four-bar's trajectory (`fourbar`) or a planar linkage's table
/// (`planar`), the other left empty.
struct Simulation {
  MethodChoice method;
  core::Trajectory fourbar;
  core::planar::Trajectory planar;
  /// A four-bar study's driven run on the general engine (truss): the engine's own run, of which
  /// `fourbar` is the four-bar's view, by which its peaks are resolved; empty otherwise.
  core::planar::Trajectory engine;
  bool is_planar{};
  Tolerances tolerances;  // a free run's, as it was integrated

  RunStatus status() const;
  bool ok() const {
    return (is_planar ? planar.status : fourbar.status) == core::SimulationStatus::kCompleted;
  }
};

/// Simulates the study's scene with the method choose_method() gives it. A planar linkage's free
/// run on `auto` that stops at a limit position is repeated on the stabilised DAE (truss-dae),
/// which passes through it; the method's reason then says so.
/// @throws bd::InputError if the scene or options are invalid.
Simulation simulate(const Study& study);
/// The same with a given method (the balanced or optimised design's own choice).
Simulation simulate(const Study& study, const MethodChoice& method);

/// The same with given tolerances (the bench's runs; simulate() above integrates at the study's
/// tolerance and the integrators' default absolute tolerance, 1e-12). Driven scenes ignore them.
Simulation simulate(const Study& study, const MethodChoice& method, const Tolerances& tolerances);

/// The run's metrics in its table's order: a four-bar's (core::kMetricTable, then
/// core::kTotalMetrics) or a planar linkage's (core::planar::metric_table()). In a driven scene
/// every peak is resolved between the samples by the exact inverse dynamics (core/peaks.hpp; a
/// four-bar's by its closed form, by the general engine when the run took it: it follows the
/// linkage closer to a dead centre than the closed forms' singular test); in a
/// four-bar's free scene by the state integrated from the sample before each instant
/// (core::free_sample_from()); in a planar linkage's free scene by the run continued from its
/// state at the latest known instant before each instant, on its route
/// (core::planar::free_state_from()).
MetricList metric_list(const Study& study, const Simulation& simulation);
/// A four-bar's run's metrics, as metric_list() computes them, with where their peaks lie.
core::Metrics fourbar_metrics(const Study& study, const Simulation& simulation,
                              core::PeakList* peaks = nullptr);
/// A four-bar's metrics in the table's order (with the peaks' times when given); the
/// counter-rotation shafts' bearing forces (RC1_*, RC3_*) only where `model` has that disc.
MetricList metric_list(const core::FourBar& model, const core::Metrics& metrics,
                       const core::PeakList* peaks = nullptr);
/// A run that stopped before its first sample has no metrics: each value of `list` becomes NaN
/// (written as null in summary.json, shown as "none") and has no peak time. Returns `list`.
MetricList& without_samples_none(MetricList& list, const Simulation& simulation);
/// The names of the metrics a run of the study has, in its table's order.
std::vector<std::string> metric_names(const Study& study);

}  // namespace bd::studies
