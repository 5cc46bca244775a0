#pragma once
/// Running a study: simulate its scene, then write timeseries.csv and summary.json
/// (docs/study-format.md, "Outputs"); for a study with a balance section also the balanced
/// design's balanced-timeseries.csv, balanced.yaml and comparison.csv; for a study with an
/// optimize section the optimum's optimized-timeseries.csv, optimized.yaml, comparison.csv and,
/// with a Pareto front, pareto.csv.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "balance/planar_moment.hpp"
#include "balance/planar_shafts.hpp"
#include "core/fourbar/metrics.hpp"
#include "core/fourbar/simulate.hpp"
#include "optimize/optimize.hpp"
#include "optimize/planar.hpp"
#include "studies/run/files.hpp"
#include "studies/run/harmonics.hpp"
#include "studies/run/simulation.hpp"
#include "studies/study/study.hpp"

namespace bd::studies {

/// The header line of timeseries.csv (without the newline).
inline constexpr const char* kTimeseriesHeader =
    "t,theta1,theta2,theta3,omega1,omega2,omega3,alpha1,alpha2,alpha3,RA0x,RA0y,RA3x,RA3y,Fshx,"
    "Fshy,Msh,tau,Fshx_inertial,Fshy_inertial,Msh_inertial,Fshx_static,Fshy_static,Msh_static,"
    "RC1x,RC1y,RC3x,RC3y,FA1x,FA1y,FA2x,FA2y";

/// Every file write_run() may write into a run's folder, in the order the report lists them.
/// write_run() removes those of an earlier run first, so no file of another study or design is
/// left beside the new ones.
inline constexpr const char* kRunFiles[] = {"study.yaml",
                                            "timeseries.csv",
                                            "summary.json",
                                            "balanced-timeseries.csv",
                                            "balanced.yaml",
                                            "optimized-timeseries.csv",
                                            "optimized.yaml",
                                            "comparison.csv",
                                            "harmonics.csv",
                                            "pareto.csv"};

/// The header line of comparison.csv (without the newline).
inline constexpr const char* kComparisonHeader = "metric,before,after,ratio";

/// The balanced design's run in a balance study (same scene, method chosen for it alike).
struct BalancedRun {
  MethodChoice method;              // formulation used for the balanced design, and why
  core::Trajectory trajectory;      // a four-bar study: its samples and status
  core::Metrics metrics;            // a four-bar study: over its samples
  core::planar::Trajectory planar;  // a planar study: its samples' table and status
  /// A planar study: the design, synthesised from the original's motion; empty when the original
  /// stopped early (then `planar` is not run and its message says why).
  std::optional<balance::planar::ForceBalance> design;
  /// A planar study with balance.shafts: the shafts added to the design (design->linkage has
  /// them; its added mass, RMS force and message include them).
  std::optional<balance::planar::ShaftBalance> shafts;
  /// A planar study with balance.moment: full, when full force balance was reached: the
  /// counter-rotations added (design->linkage has them; its added inertia and message include
  /// them).
  std::optional<balance::planar::MomentBalance> moment;
  bool is_planar{};
  MetricList metric_list;              // its metrics in its table's order (either type)
  std::optional<Harmonics> harmonics;  // its harmonic orders (a driven scene)
  std::filesystem::path timeseries;    // out_dir/balanced-timeseries.csv
  std::filesystem::path study_file;    // out_dir/balanced.yaml
  std::filesystem::path comparison;    // out_dir/comparison.csv
  /// How its simulation ended (either linkage type).
  RunStatus status() const;
  bool ok() const { return status().ok(); }
};

/// The optimisation in an optimize study, and the optimum's run (same scene, method chosen for it
/// alike).
struct OptimizedRun {
  bool is_planar{};                           // a planar linkage's study
  optimize::OptimizeResult result;            // a four-bar study: what optimize() returned
                                              // (termination kNotRun, with a message, when it
                                              // was not run)
  optimize::planar::Result planar_result;     // a planar study: optimize::planar::optimize()'s
  std::vector<std::string> variable_names;    // of the result's x, in order
  int design_variables{};                     // the first ones of x: the design's own (the rest
                                              // are bound variables of a four-bar's peaks)
  std::vector<optimize::ParetoPoint> pareto;  // with optimize.pareto, point by point (a four-bar)
  std::vector<optimize::planar::ParetoPoint> planar_pareto;  // the same, a planar linkage's
  MethodChoice method;                 // formulation used for the optimum, and why
  core::Trajectory trajectory;         // a four-bar study: the optimum simulated
  core::Metrics metrics;               // a four-bar study: over its samples
  core::planar::Trajectory planar;     // a planar study: the optimum simulated
  MetricList metric_list;              // its metrics in its table's order (either type)
  std::optional<Harmonics> harmonics;  // its harmonic orders (a driven scene)
  std::filesystem::path timeseries;    // out_dir/optimized-timeseries.csv (when found)
  std::filesystem::path study_file;    // out_dir/optimized.yaml (when found)
  std::filesystem::path comparison;    // out_dir/comparison.csv (when found)
  std::filesystem::path pareto_file;   // out_dir/pareto.csv (with a front, when found)
  /// How the optimiser ended, and its message (either type).
  optimize::Termination termination() const {
    return is_planar ? planar_result.termination : result.termination;
  }
  const std::string& message() const { return is_planar ? planar_result.message : result.message; }
  /// True when the optimiser returned a design (converged, or the budget ran out at a feasible
  /// point): the optimum was simulated and its files written.
  bool found() const {
    return optimize::found_design(termination());
  }
  /// True when the optimiser ran and found no design (infeasible, or it failed): exit code 4.
  bool failed() const {
    return termination() == optimize::Termination::kInfeasible ||
           termination() == optimize::Termination::kFailed;
  }
  /// How the optimum's simulation ended (either linkage type).
  RunStatus status() const;
};

struct RunResult;
/// How the original design's simulation of a run ended.
RunStatus simulation_status(const RunResult& result);

/// What a run did and where its files are.
struct RunResult {
  MethodChoice method;                    // formulation used, and why (the original design)
  core::Trajectory trajectory;            // a four-bar study: every sample computed and the status
  core::Metrics metrics;                  // a four-bar study: over the samples computed
  core::planar::Trajectory planar;        // a planar study: the samples' table and the status
  MetricList metric_list;                 // every study: its metrics in its table's order
  std::optional<Harmonics> harmonics;     // a driven scene: the orders of Fsh and Msh
  std::filesystem::path timeseries;       // out_dir/timeseries.csv
  std::filesystem::path harmonics_file;   // out_dir/harmonics.csv (with harmonics)
  std::filesystem::path summary;          // out_dir/summary.json
  std::optional<BalancedRun> balanced;    // set when the study has a balance section
  std::optional<OptimizedRun> optimized;  // set when the study has an optimize section
  std::vector<std::string> warnings;      // what went wrong besides the run (the report page)
  /// True when every simulation ran to the end (the original's, the balanced design's, the
  /// optimum's) and an optimize study found its optimum.
  /// How the original design's simulation ended (either linkage type).
  RunStatus status() const { return simulation_status(*this); }
  bool ok() const {
    return status().ok() && (!balanced || balanced->ok()) &&
           (!optimized || (optimized->found() && optimized->status().ok()));
  }
  /// True when a simulation stopped early (the original's, the balanced design's or the
  /// optimum's): exit code 3.
  bool stopped_early() const {
    return !status().ok() || (balanced && !balanced->ok()) ||
           (optimized && optimized->found() && !optimized->status().ok());
  }
};

/// One row of comparison.csv: a metric of the original design (before) and of the balanced or
/// optimised one (after), and after/before (empty when before is 0).
struct ComparisonRow {
  std::string metric;  // "Fsh_rms", ..., "added_mass", "added_inertia"
  double before{}, after{};
  std::optional<double> ratio;
};
/// The metrics of two designs paired by name, in the first's order, then the second's metrics
/// the first lacks (a balance shaft's bearing force: 0 before), with after/before: the rows of
/// comparison.csv and summary.json's `reduction`.
std::vector<ComparisonRow> compare_metrics(const MetricList& before, const MetricList& after);
/// The rows of comparison.csv, in order: the metrics in their table's order (a four-bar's
/// Fsh_rms, Fsh_max, Msh_rms, Msh_max, tau_rms, tau_max, RA0_rms, RA0_max, RA3_rms, RA3_max; a
/// planar linkage's from core::planar::metric_table()), then the balanced design's metrics the
/// original lacks (a balance shaft's bearing force, 0 before), then added_mass, added_inertia.
/// In an optimize study added_mass and added_inertia are those of studies::added_mass() and
/// added_inertia() (negative when the optimum takes mass away).
/// Precondition: result.balanced is set (with its design, for a planar linkage), or
/// result.optimized has found its optimum.
std::vector<ComparisonRow> comparison(const Study& study, const RunResult& result);

/// What compute_study() computes besides each design's run and metrics.
struct ComputeParts {
  /// The harmonic orders of the shaking force and moment (harmonics.csv and the page; a
  /// sweep's rows hold none, and their FFTs cost a sixth of a driven point).
  bool harmonics = true;
};

/// What run_study() (studies/studies.hpp) computes, without writing anything: simulates the study's
/// scene, and with a balance section the balanced design, with an optimize section solves the
/// design problem and simulates the optimum (each as run_study() describes). The result's file
/// paths stay empty. Pure: the same study gives the same result, bit for bit, and the call is safe
/// from several threads at once (run_sweep() computes its points so). Ipopt solves are serialised
/// by a mutex: Debian 12's Ipopt 3.11.9 calls MUMPS, which is not thread-safe, and has no lock of
/// its own (Ipopt takes one around MUMPS from 3.14 on).
/// @throws bd::InputError as run_study().
RunResult compute_study(const Study& study, const ComputeParts& parts = {});

/// Writes the data files of a computed run into out_dir (creating out_dir when needed) and sets
/// the result's file paths. `timeseries.csv` and `summary.json`; each file is written to a
/// temporary file in out_dir and renamed into place, so no half-written output is ever left.
/// When the simulation stopped early, every sample computed is written and summary.json records
/// the status and message. A study with a balance section also writes the balanced design's
/// `balanced-timeseries.csv`, `balanced.yaml` (study_yaml() of the balanced design) and
/// `comparison.csv`; summary.json gets `balance`, `balanced_run`, `balanced_metrics` and
/// `reduction`. A study with an optimize section whose optimum was found writes
/// `optimized-timeseries.csv`, `optimized.yaml`, `comparison.csv` and, with optimize.pareto,
/// `pareto.csv`; summary.json gets `optimize`, `optimized_run`, `optimized_metrics` and
/// `reduction`. When the optimiser found no design only the original's files are written and
/// summary.json says why. summary.json is always written last: its presence means the other
/// files are complete.
/// @throws std::runtime_error if an output file cannot be written (the message names it).
void write_run(const Study& study, RunResult& result, const std::filesystem::path& out_dir);

/// Writes a table of samples as CSV: its column names, then one row per sample, "%.17g" (a
/// planar linkage's timeseries.csv).
/// @throws std::runtime_error if the file cannot be written.
void write_table(const core::Series& table, const std::filesystem::path& file);

/// A four-bar's samples as a table with timeseries.csv's columns (kTimeseriesHeader), one row per
/// sample: what write_timeseries() writes, and what the Python module hands out.
core::Series timeseries_table(const core::Trajectory& trajectory);

/// Writes the samples as timeseries.csv content (header, one row per sample, "%.17g").
/// @throws std::runtime_error if the file cannot be written.
void write_timeseries(const core::Trajectory& trajectory, const std::filesystem::path& file);

/// The summary.json text of a run (UTF-8, ends in a newline).
std::string summary_json(const Study& study, const RunResult& result);

/// The comparison.csv text of a balance or optimize study's run: kComparisonHeader, then one row
/// per comparison() entry, numbers "%.17g", ratio empty when before is 0.
std::string comparison_csv(const Study& study, const RunResult& result);

/// The balanced.yaml text of a four-bar's balance study: study_yaml(balanced_study(study)) with a
/// header comment saying where it came from.
std::string balanced_yaml(const Study& study);
/// The balanced.yaml text of a planar linkage's balance study: the design's study with a header
/// comment saying where it came from and which counterweights it carries.
std::string balanced_yaml(const Study& study, const balance::planar::ForceBalance& design);

/// The optimized.yaml text of an optimize study whose optimum was found:
/// study_yaml(optimized_study(study, design)) (planar_optimized_study() for a planar linkage)
/// with a header comment saying how it was found.
std::string optimized_yaml(const Study& study, const OptimizedRun& run);

/// The pareto.csv text: header `epsilon,<first>,<second>,termination,verification_error` and the
/// design variables' names, then one row per point ("%.17g"; numbers empty for a point where no
/// design was found). Precondition: the study's optimize section (either type's) has a pareto.
std::string pareto_csv(const Study& study, const OptimizedRun& run);

}  // namespace bd::studies
