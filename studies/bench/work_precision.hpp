#pragma once
/// Speed against accuracy (`balance-design bench STUDY.yaml`, docs/performance.md).
///
/// Every method of the study's linkage type is measured, named as the study file's `method:`:
/// a four-bar's formulations (mass-matrix, opened-loop, complex-masses) and the general planar
/// engine on it (truss, truss-dae), or a planar linkage's routes (truss, truss-dae). Each run is
/// what the runner computes for that method (studies::simulate, studies/run/simulation.hpp).
///
/// Free scene: every method x every integrator it supports x tolerances 1e-3 ... 1e-13, each run
/// timed (median CPU time of repeats) and compared with a reference computed by a different
/// method: work-precision.csv.
/// Driven scene: every method (the general engine as truss: a driven scene has no route) x
/// samples per revolution 4 ... 720, each revolution timed and its RMS shaking force and moment
/// compared with those of a 4096-sample revolution: driven-convergence.csv. Periodic sampling
/// is the trapezoidal rule of a smooth periodic function, so the RMS converges faster than any
/// power of the samples. A planar scene given by a duration instead of revolutions is sampled
/// over its duration (both ends included: not periodic, so no spectral convergence).
///
/// The error of a free run is measured on the linkage's positions, on one scale for any
/// linkage: its link angles [rad], and its slider positions and moving node coordinates divided
/// by the linkage's length scale (core::planar::Model::length_scale(), its longest element; for
/// a four-bar the longest of crank, coupler and rocker, with A1 and A2 its moving nodes).
///
/// The report's section "Speed against accuracy" (work_precision_section() in
/// studies/report/report.hpp) charts either file found in the run's folder.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "core/simulation.hpp"
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
  /// relative tolerance, absolute 1e-2 of it, by another method than the one it judges wherever
  /// one follows the motion (reference_methods()). docs/performance.md ("How it is measured")
  /// has how closely the references of different methods agree: digits beyond that agreement
  /// are the references' limit, not the runs'.
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

/// One row of work-precision.csv: one method, integrator and tolerance.
struct WorkPrecisionRow {
  Method method{};  // never kAuto
  core::Integrator integrator{};
  double tolerance{};  // relative (absolute 1e-2 of it)
  Method reference_method{};
  core::Integrator reference_integrator{};
  double reference_tolerance{};
  core::SimulationStatus status = core::SimulationStatus::kNotRun;
  std::string message;              // the run's, one line
  double cpu_time{};                // median CPU time of one run [s]
  int repeats{};                    // timed runs behind the median
  long steps{}, rhs_evaluations{};  // of one run (core::Trajectory)
  std::size_t samples{};            // samples the run computed
  /// The largest difference from the reference at the final time over the link angles [rad],
  /// slider positions and moving node coordinates divided by the length scale [-] (the file's
  /// header comment), and -log10 of it: correct digits (16 when the error is 0). NaN when the run
  /// or the reference stopped early.
  double final_error{}, digits{};
  /// The same difference, largest over all samples both runs computed (NaN when none).
  double max_error{};
};

/// One row of driven-convergence.csv: one method and number of samples per revolution.
struct DrivenConvergenceRow {
  Method method{};  // never kAuto or kTrussDae
  int samples{};    // per revolution (over the duration of a planar scene given by one)
  Method reference_method{};
  int reference_samples{};
  core::SimulationStatus status = core::SimulationStatus::kNotRun;
  std::string message;
  double cpu_time{};  // median CPU time of one revolution (or duration) with its metrics [s]
  int repeats{};
  double Fsh_rms{}, Msh_rms{};  // [N], [N m]
  /// |rms - rms_ref| / rms_ref; NaN when the reference's RMS is 0 or a run failed.
  double Fsh_rms_error{}, Msh_rms_error{};
};

/// The header lines of the two files (without the newline).
inline constexpr const char* kWorkPrecisionHeader =
    "method,integrator,tolerance,reference_method,reference_integrator,"
    "reference_tolerance,status,cpu_time,repeats,steps,rhs_evaluations,samples,final_error,"
    "digits,max_error,message";
inline constexpr const char* kDrivenConvergenceHeader =
    "method,samples,reference_method,reference_samples,status,cpu_time,repeats,"
    "Fsh_rms,Msh_rms,Fsh_rms_error,Msh_rms_error,message";

/// The methods a bench measures on the study (free: is_free(study.scene)), in the files' order:
/// a four-bar's formulations in core::kFormulations' order, then the general engine (truss,
/// and truss-dae in a free scene; none when the four-bar has counter-rotating inertias, which
/// the general engine does not model); a planar linkage's truss, and truss-dae in a free scene.
std::vector<Method> bench_methods(const Study& study);

/// The methods whose runs may serve as the reference of `method` on the study's linkage, in
/// order of preference: the first whose reference run completes is used, else the last. Free
/// scenes (reference runs by kErk8 at options.reference_tolerance):
/// - mass-matrix: complex-masses; complex-masses: mass-matrix (the same equation set up
///   otherwise: they agree to round-off);
/// - opened-loop, and the general engine on a four-bar: mass-matrix, complex-masses, then the
///   opened loop (the one formulation through limit positions);
/// - a planar linkage's truss: truss-dae, then truss; truss-dae: truss, then truss-dae (the
///   other route; the same route only where the other cannot follow the motion).
/// Driven scenes (reference runs of options.reference_samples): mass-matrix: complex-masses;
/// the other four-bar methods: mass-matrix; a planar linkage's truss: truss (the one method).
std::vector<Method> reference_methods(const Study& study, Method method);

/// The work-precision study of the study's free scene and linkage (the original design; its
/// method and tolerance are not used): bench_methods() x every integrator each supports x
/// options.tolerances, each against its reference (reference_methods()). Rows in the order
/// method, integrator, tolerance.
/// @throws bd::InputError if the study's scene is not free or the options are invalid.
std::vector<WorkPrecisionRow> work_precision(const Study& study, const BenchOptions& options);

/// The sample convergence of the study's driven scene: one revolution (a four-bar's from its
/// theta1 at its omega1; a planar linkage's of its first angle input), or a planar scene's
/// duration, per method and sample count, against its reference (reference_methods()) with
/// options.reference_samples samples.
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
  /// The rows whose run stopped early (status other than completed): each keeps what its run
  /// computed up to the stop, with the status and message.
  std::size_t stopped_early() const;
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
