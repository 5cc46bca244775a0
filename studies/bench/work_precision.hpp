#pragma once
/// Speed against accuracy (`balance-design bench STUDY.yaml`, docs/performance.md).
///
/// Free scene: every formulation x every integrator it supports (core::SimulateOptions::validate)
/// x tolerances 1e-3 ... 1e-13, each run timed (median CPU time of repeats) and compared with a
/// reference computed by a different formulation: work-precision.csv.
/// Driven scene: every formulation x samples per revolution 4 ... 720, each revolution timed and
/// its RMS shaking force and moment compared with those of a 4096-sample revolution computed by
/// a different formulation: driven-convergence.csv. Periodic sampling is the trapezoidal rule
/// of a smooth periodic function, so the RMS converges faster than any power of the samples.
///
/// The report's section "Speed against accuracy" (work_precision_section() in
/// studies/report/report.hpp) charts either file found in the run's folder.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/simulate.hpp"
#include "studies/run/runner.hpp"
#include "studies/study/study.hpp"

namespace bd::studies {

/// How to measure (Ceres-style options: defaults in place, validate() says what is wrong).
struct BenchOptions {
  /// Free scenes: the integrators' relative tolerances; each run's absolute tolerance is 1e-2
  /// times its relative one (the ratio of core::SimulateOptions' defaults, 1e-12 / 1e-10).
  std::vector<double> tolerances = {1e-3, 1e-4,  1e-5,  1e-6,  1e-7, 1e-8,
                                    1e-9, 1e-10, 1e-11, 1e-12, 1e-13};
  /// The reference run: kErk8 (Fehlberg 8(7), its steps ending at every sample) at this
  /// relative tolerance, absolute 1e-2 of it. Checked on the paper example (docs/performance.md)
  /// against CVODE Adams on another formulation at the same tolerance (4e-13 relative at the
  /// final time, 1.3e-13 rad at the samples) and the opened loop's order-5 pair at 1e-13 (2e-13,
  /// 4e-14 rad): errors below ~2e-13 are beyond what it resolves.
  double reference_tolerance = 1e-14;
  /// Driven scenes: samples per revolution, and the reference's.
  std::vector<int> samples = {4, 6, 8, 12, 16, 24, 32, 48, 64, 96, 128, 180, 360, 720};
  int reference_samples = 4096;
  /// Timed runs per point; the median CPU time of the process (CLOCK_PROCESS_CPUTIME_ID) is
  /// reported. A run that did not complete, or took more than `long_run` seconds, is timed once.
  int repeats = 5;
  /// A timed run shorter than this [s] is repeated back to back until this much CPU time has
  /// passed, and the time per run is the average (clock resolution and call overhead).
  double min_time = 2e-3;
  double long_run = 0.5;  // [s]
  /// Called with one line per method measured (the CLI prints it on stderr); may be empty.
  std::function<void(const std::string&)> progress;

  /// `--quick`: tolerances 1e-4, 1e-7, 1e-10, one repeat (the test's configuration).
  static BenchOptions quick();
  /// Empty when valid, else the problem in words.
  std::string validate() const;
};

/// One row of work-precision.csv: one formulation, integrator and tolerance.
struct WorkPrecisionRow {
  core::Formulation formulation{};
  core::Integrator integrator{};
  double tolerance{};  // relative (absolute 1e-2 of it)
  core::Formulation reference_formulation{};
  core::Integrator reference_integrator{};
  double reference_tolerance{};
  core::SimulationStatus status = core::SimulationStatus::kNotRun;
  std::string message;              // the run's, one line
  double cpu_time{};                // median CPU time of one run [s]
  int repeats{};                    // timed runs behind the median
  long steps{}, rhs_evaluations{};  // of one run (core::Trajectory)
  std::size_t samples{};            // samples the run computed
  /// Largest relative error of theta1..theta3 at the final time, and -log10 of it: significant
  /// correct digits (16 when the error is 0). NaN when the run or the reference stopped early.
  double final_error{}, digits{};
  /// Largest |theta_k - theta_k,ref| over k = 1..3 and all samples both runs computed [rad].
  double max_error{};
};

/// One row of driven-convergence.csv: one formulation and number of samples per revolution.
struct DrivenConvergenceRow {
  core::Formulation formulation{};
  int samples{};  // per revolution
  core::Formulation reference_formulation{};
  int reference_samples{};
  core::SimulationStatus status = core::SimulationStatus::kNotRun;
  std::string message;
  double cpu_time{};  // median CPU time of one revolution [s]
  int repeats{};
  double Fsh_rms{}, Msh_rms{};  // [N], [N m]
  /// |rms - rms_ref| / rms_ref; NaN when the reference's RMS is 0 or a run failed.
  double Fsh_rms_error{}, Msh_rms_error{};
};

/// The header lines of the two files (without the newline).
inline constexpr const char* kWorkPrecisionHeader =
    "formulation,integrator,tolerance,reference_formulation,reference_integrator,"
    "reference_tolerance,status,cpu_time,repeats,steps,rhs_evaluations,samples,final_error,"
    "digits,max_error,message";
inline constexpr const char* kDrivenConvergenceHeader =
    "formulation,samples,reference_formulation,reference_samples,status,cpu_time,repeats,"
    "Fsh_rms,Msh_rms,Fsh_rms_error,Msh_rms_error,message";

/// The work-precision study of the study's free scene and model (the original design; its
/// method and tolerance are not used). The reference of formulation F is the first run that
/// completes of: complex-masses (F = mass-matrix) or mass-matrix (otherwise), and for the
/// opened loop, when neither reduced formulation can follow the motion (a crank reaching its
/// limits), the opened loop itself. Rows in the order formulation, integrator, tolerance.
/// @throws bd::InputError if the study's scene is not free or the options are invalid.
std::vector<WorkPrecisionRow> work_precision(const Study& study, const BenchOptions& options);

/// The sample convergence of the study's driven scene (one revolution from its theta1 at its
/// omega1). The reference of formulation F is computed by complex-masses (F = mass-matrix) or
/// mass-matrix (otherwise) with options.reference_samples samples.
/// @throws bd::InputError if the study's scene is not driven or the options are invalid.
std::vector<DrivenConvergenceRow> driven_convergence(const Study& study,
                                                     const BenchOptions& options);

/// The files' text: header, one row per entry, numbers "%.17g", NaN as an empty field, the
/// message quoted (RFC 4180).
std::string work_precision_csv(const std::vector<WorkPrecisionRow>& rows);
std::string driven_convergence_csv(const std::vector<DrivenConvergenceRow>& rows);

/// What a bench measured and where its file is.
struct BenchResult {
  RunResult run;                                  // the study run (run_bench() fills it)
  std::vector<WorkPrecisionRow> free_rows;        // free scenes
  std::vector<DrivenConvergenceRow> driven_rows;  // driven scenes
  std::filesystem::path csv;                      // work-precision.csv or driven-convergence.csv
  std::filesystem::path report;                   // report.html (empty when it was not written)
};

/// Measures the study's scene (work_precision() or driven_convergence()) and writes
/// work-precision.csv or driven-convergence.csv into out_dir, under a temporary name renamed
/// into place. (run_bench() in studies/studies.hpp runs the study first and writes the page.)
/// @throws bd::InputError for invalid options.
/// @throws std::runtime_error if the file cannot be written.
BenchResult write_bench(const Study& study, const std::filesystem::path& out_dir,
                        const BenchOptions& options);

/// Removes out_dir's work-precision.csv and driven-convergence.csv, so a page never shows the
/// measurements of an earlier bench.
void remove_bench_files(const std::filesystem::path& out_dir);

}  // namespace bd::studies
