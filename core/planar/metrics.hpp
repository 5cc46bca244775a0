#pragma once
/// The metrics of a planar linkage's run, built for its model as the four-bar's table is
/// (core/metrics.hpp): per quantity its RMS over the samples, then its peak, in this order:
/// Fsh, Msh, the drive efforts (tau, or tau_<input> with several inputs), the reaction of every
/// ground node and frame guide (R<name>); then the peak of every joint force (F<joint>_max);
/// then the total shaking force and moment (core::kTotalMetrics). Fsh and Msh are their inertial
/// parts (the columns Fshx_inertial, Fshy_inertial, Msh_inertial); the totals are Fshx, Fshy, Msh.
/// Each is the magnitude of one column (Msh, tau) or of an x, y pair of columns.
#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "core/metrics.hpp"
#include "core/peaks.hpp"
#include "core/planar/dynamics.hpp"
#include "core/planar/simulate.hpp"
#include "core/series.hpp"

namespace bd::core::planar {

struct ColumnMetric {
  std::string name;   // "Fsh_rms", "RA0_max", "FA1_max"
  std::string unit;   // "N", "N m"
  std::string words;  // "RMS of the shaking force |Fsh|"
  Statistic statistic = Statistic::kRms;
  std::vector<std::string> columns;  // one column, or the x and y columns of a vector
};

/// The model's metric table.
std::vector<ColumnMetric> metric_table(const Model& model);

/// The table's values over the rows of `table` (0 for a table without rows): peaks are the
/// largest samples (the optimiser's objectives, for speed; a run's reported metrics resolve
/// them, below).
std::vector<double> metric_values(const std::vector<ColumnMetric>& metrics, const Series& table);

/// The table's values over a driven run of `model` in `scene` (the run's samples in
/// `run.table`), with every peak resolved between the samples: maximised over time by the exact
/// inverse dynamics at the refined instant (core/peaks.hpp), so that it no longer depends on the
/// sample count. A run of whole revolutions of one moving input is periodic (the last sample's
/// neighbour is the first); any other run is resolved within its time span. `peaks`, when given,
/// receives per metric where its peak lies (RMS rows: the value and t = 0).
std::vector<double> metric_values(const Model& model, const DrivenScene& scene,
                                  const std::vector<ColumnMetric>& metrics, const Trajectory& run,
                                  std::vector<Peak>* peaks = nullptr);

/// The period of a driven run of `model` in `scene` when it is whole revolutions of one moving
/// input run to the end (the last sample's neighbour is then the first), else 0.
double driven_period(const Model& model, const DrivenScene& scene, const Trajectory& run);

/// The whole row of a driven run's table at any time s, not only at its samples: the nodes solved
/// from the nearest sample's (periodic runs: modulo the period, as metric_values() reads them),
/// then the inverse dynamics at the inputs' values and speeds at s. The model, scene and run are
/// held by reference and must outlive it.
class DrivenRows {
 public:
  DrivenRows(const Model& model, const DrivenScene& scene, const Trajectory& run);
  ~DrivenRows();
  DrivenRows(const DrivenRows&) = delete;
  DrivenRows& operator=(const DrivenRows&) = delete;
  /// The row at s (run.table's columns), valid until the next call; null where the position
  /// cannot be solved or lands away from the samples' branch (a node further than a quarter of
  /// the linkage's size from the nearest sample's), or the dynamics cannot be evaluated.
  const double* at(double s);
  /// driven_period() of the run.
  double period() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

/// The table's values over a free run `run` = simulate_free(model, scene, options), with every
/// peak resolved between the samples: maximised over time by the run continued to each instant
/// by its own route, integrator and tolerances (free_state_from(), core/planar/simulate.hpp),
/// from the latest instant known before it (a sample, or an instant an earlier step of any
/// quantity's search computed), so that it no longer depends on the sample count. An instant
/// the integration cannot reach, or where a node lies away from where the samples around it
/// have it (another assembly), is skipped: the peak is then never below the largest sample.
/// `peaks` as above. A run without states (Trajectory::states) keeps its largest samples.
std::vector<double> metric_values(const Model& model, const SimulateOptions& options,
                                  const std::vector<ColumnMetric>& metrics, const Trajectory& run,
                                  std::vector<Peak>* peaks = nullptr);

/// The gradients of the table's metrics over a run with sensitivities: row k, column j is
/// d(metrics[k])/d(run.parameters[j]). An RMS's derivative is Σ_i v_i · dv_i / (n · RMS) over
/// the samples' vectors v_i of its columns (0 where the RMS is 0); a peak's is that of the
/// largest sample's magnitude, v · dv / |v| (the first of equal largest ones, as
/// metric_values() takes it; 0 where the magnitude is 0). Needs a completed run.
Eigen::MatrixXd metric_gradients(const std::vector<ColumnMetric>& metrics,
                                 const FreeSensitivities& run);

/// The same with the peaks resolved between the samples: `peaks` as
/// metric_values(model, options, metrics, run.trajectory, &peaks) locates them (the run's own
/// options). A peak's derivative is v · dv / |v| at the instant of its peak
/// (free_derivatives_at(), core/planar/simulate.hpp; where that fails, at the largest sample);
/// an RMS's as above.
Eigen::MatrixXd metric_gradients(const Model& model, const SimulateOptions& options,
                                 const std::vector<ColumnMetric>& metrics,
                                 const FreeSensitivities& run, const std::vector<Peak>& peaks);

}  // namespace bd::core::planar
