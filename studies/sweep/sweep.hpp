#pragma once
/// Parameter sweeps (docs/study-format.md "sweep"): the points of a sweep design, the study of
/// each point, and run_sweep(), which runs the study at every point in parallel and writes one
/// row per point to sweep.csv as it goes, so an interrupted sweep resumes where it stopped.
#include <atomic>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "studies/study/study.hpp"
#include "studies/study/sweep_request.hpp"

namespace bd::studies {

/// The design's points in order: points[i][j] is point i's value of parameter j.
/// Grid: the Cartesian product, the first parameter varying slowest. Random and LHS: drawn from
/// the request's seed by a generator of our own (not the standard library's distributions), so
/// the same request gives the same points, bit for bit, with every compiler and machine.
std::vector<std::vector<double>> sweep_points(const SweepRequest& request);

/// The study at one point of `base`'s sweep: base.sweep->study_text with each parameter's path
/// set to values[j] (written "%.17g"), the sweep section removed, parsed and checked as
/// parse_study() does (balance and optimize sections included). The point's study keeps
/// base's name and source. Precondition: base.sweep is set, values.size() equals the number of
/// parameters.
/// @throws StudyError if the study at this point is invalid (e.g. a mass below zero, a linkage
///         that cannot assemble); the message is parse_study()'s, with its file:line:column.
Study point_study(const Study& base, std::span<const double> values);

/// The sweep.csv columns after `point` and the parameters' paths, in order. The metrics are
/// the original design's (core::Metrics, as in summary.json); a study with a balance section
/// adds the balanced design's as balanced_<metric>, one with an optimize section the optimum's
/// as optimized_<metric>, each followed by added_mass and added_inertia; `status` and
/// `message` come last.
///   point,<path 1>,...,<path n>,Fsh_rms,Fsh_max,Msh_rms,Msh_max,tau_rms,tau_max,RA0_max,
///   RA3_max,RA0_rms,RA3_rms[,balanced_...|optimized_...,added_mass,added_inertia],status,message
/// `status` is one of: ok, stopped-early (a simulation stopped; its metrics are over the samples
/// computed), no-optimum (the optimiser found no design; the optimum's columns are empty),
/// bad-input (the point's study is invalid; every metric is empty), error (an unexpected failure,
/// e.g. out of memory; every metric is empty). `message` says why, quoted as CSV text on one line
/// (line breaks become spaces), empty when ok.
std::vector<std::string> sweep_columns(const Study& study);

/// How run_sweep() shows progress on stderr.
enum class SweepProgress {
  kAuto,   // a bar with rate and ETA redrawn in place when stderr is a terminal, else kLines
  kBar,    // the bar
  kLines,  // a plain line every 10 s and at the end
  kNone,
};

struct SweepOptions {
  /// Continue the sweep in out_dir: keep the rows of sweep.csv (dropping a last line cut short),
  /// after checking that they belong to this study and design, and run the missing points.
  bool resume = false;
  int threads = 0;  // > 0 overrides the request's
  SweepProgress progress = SweepProgress::kAuto;
  /// When it becomes true (e.g. set by a SIGINT handler), no new point is started; the points
  /// running finish and are written, and run_sweep() returns with interrupted set.
  const std::atomic<bool>* stop = nullptr;
};

struct SweepResult {
  int points{};     // in the design
  int done{};       // rows in sweep.csv at the end (resumed ones included)
  int resumed{};    // rows kept from an earlier run
  int failed{};     // rows whose status is not ok
  bool interrupted = false;
  std::filesystem::path csv;      // out_dir/sweep.csv
  std::filesystem::path summary;  // out_dir/sweep.json
  bool complete() const { return done == points; }
};

/// Runs `study` at every point of its sweep, `threads` at a time, and writes into out_dir:
/// sweep.csv (header sweep_columns(), one row per point in point order, each row appended and
/// flushed once it and every earlier point are done, numbers "%.17g"), sweep.json (the study,
/// the design, every parameter and the counts; rewritten at the start and at the end), and
/// report.html (write_sweep_report()). A point's failure is its row's status, never the
/// sweep's.
/// @throws bd::InputError if out_dir holds a sweep that cannot be resumed (another study or
///         design, or rows that do not match the design), or holds an unfinished sweep and
///         options.resume is false (the message says to pass --resume).
/// @throws std::runtime_error if a file cannot be written.
/// Test hook: with BD_SWEEP_KILL_AFTER_ROWS=N in the environment the process kills itself
/// (SIGKILL) right after sweep.csv holds N rows (tests of resuming an interrupted sweep).
SweepResult run_sweep(const Study& study, const std::filesystem::path& out_dir,
                      const SweepOptions& options = {});

/// The sweep's report.html text, built from out_dir's sweep.csv and sweep.json: the study's
/// inputs and design, the counts and failed points, and charts of every metric against the
/// parameter (one parameter), heat maps (two parameters on a grid) or coloured scatter plots
/// (two parameters, random or LHS), and each metric against each parameter (more than two).
/// Without gnuplot (empty `gnuplot`) the page has the tables and says the charts need it.
/// @throws std::runtime_error if a file cannot be read or gnuplot fails.
std::string sweep_report_html(const Study& study, const std::filesystem::path& dir,
                              const std::string& gnuplot);
/// Writes dir/report.html (sweep_report_html() with find_gnuplot()) under a temporary name
/// renamed into place, and returns its path.
std::filesystem::path write_sweep_report(const Study& study, const std::filesystem::path& dir);

}  // namespace bd::studies
