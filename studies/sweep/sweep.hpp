#pragma once
/// Parameter sweeps (docs/study-format.md "sweep"): the points of a sweep design, the study of
/// each point, and run_sweep(), which runs the study at every point in parallel and writes one
/// row per point to sweep.csv as it goes, so an interrupted sweep resumes where it stopped.
#include <atomic>
#include <filesystem>
#include <functional>
#include <memory>
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

/// How many points the design has (sweep_points().size(), without computing them).
int sweep_size(const SweepRequest& request);

/// The design's points one at a time, in increasing order, without holding them all (a sweep
/// of 10^6 points would hold 10^6 vectors): the same values as sweep_points(), bit for bit. A
/// grid point comes from its index; a random one from the generator moved on past the points
/// skipped (a few nanoseconds each); a Latin hypercube keeps its strata, 4 bytes per point and
/// parameter, and one generator per parameter.
class PointCursor {
 public:
  explicit PointCursor(const SweepRequest& request);
  PointCursor(PointCursor&&) noexcept;
  PointCursor& operator=(PointCursor&&) noexcept;
  ~PointCursor();

  /// Points in the design.
  int size() const;
  /// Point i's values (one per parameter), valid until the next call. Precondition:
  /// 0 <= i < size(), and i is at least the previous call's i (points may be skipped).
  std::span<const double> at(int i);

 private:
  struct State;
  std::unique_ptr<State> state_;
};

/// The study at one point of `base`'s sweep: base.sweep->study_text with each parameter's path
/// set to values[j] (written "%.17g"), the sweep section removed, parsed and checked as
/// parse_study() does (balance and optimize sections included). The point's study keeps
/// base's name and source. Precondition: base.sweep is set, values.size() equals the number of
/// parameters.
/// @throws StudyError if the study at this point is invalid (e.g. a mass below zero, a linkage
///         that cannot assemble); the message is parse_study()'s, with its file:line:column.
Study point_study(const Study& base, std::span<const double> values);

/// The fingerprint of a study text as sweep.json gives it: FNV-1a 64, 16 hex digits.
std::string sweep_fingerprint(const std::string& study_text);

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

/// Where a sweep stands, for a progress display.
struct SweepProgress {
  int done{};          // rows in sweep.csv (resumed ones included)
  int points{};        // in the design
  int resumed{};       // rows kept from an earlier run
  double elapsed_s{};  // since this run started [s]
  bool finished{};     // the last call of the run
};

/// One row of sweep.csv as computed: its text with its '\n', and whether its status is ok.
struct SweepRow {
  std::string text;
  bool ok = false;
};

/// The row of point `index` of `study`'s sweep, `values` its parameters' values (one of
/// sweep_points()): the point's study run by compute_study(). Never throws: a point's failure is
/// its row's status. The same point gives the same bytes in any process, thread or order.
SweepRow sweep_row(const Study& study, int index, std::span<const double> values);

/// Points handed out by write_sweep(): the next ones in point order, or none.
struct SweepClaim {
  int begin{}, end{};  // points [begin, end); empty when there are none to hand out
  bool later = false;  // none now, because the rows waiting to be written reached their bound:
                       // ask again shortly
  bool empty() const { return end <= begin; }
};

/// What write_sweep() offers to points computed elsewhere (SweepPeers::poll()).
class SweepWork {
 public:
  virtual ~SweepWork() = default;
  /// The next up to `count` points not yet handed out (none once all are, or the sweep stops).
  virtual SweepClaim claim(int count) = 0;
  /// How many points are not yet handed out.
  virtual int unclaimed() const = 0;
  /// The row of a point handed out by claim().
  virtual void deliver(int point, SweepRow row) = 0;
};

/// Workers outside this process (the other ranks of an MPI run, cli/mpi_sweep.cpp), polled by
/// write_sweep()'s writer thread every few milliseconds while its own threads compute points.
class SweepPeers {
 public:
  virtual ~SweepPeers() = default;
  /// Their threads, all together (for sweep.json).
  virtual int threads() const = 0;
  /// Answers the peers' requests (claim()) and hands their rows over (deliver()); returns true
  /// once every peer has finished and delivered every point it claimed.
  virtual bool poll(SweepWork& work) = 0;
};

struct SweepOptions {
  /// Continue the sweep in out_dir: keep the rows of sweep.csv (dropping a last line cut short),
  /// after checking that they belong to this study and design, and run the missing points.
  bool resume = false;
  int threads = 0;  // > 0 overrides the request's
  /// Called on the calling thread after every row appended to sweep.csv, and once more at the
  /// end with `finished` set (a display draws from it; may be empty).
  std::function<void(const SweepProgress&)> progress;
  /// When it becomes true (e.g. set by a SIGINT handler), no new point is started; the points
  /// running finish and are written, and write_sweep() returns with interrupted set.
  const std::atomic<bool>* stop = nullptr;
  /// Workers in other processes that take points too (may be null: this process's threads only).
  SweepPeers* peers = nullptr;
};

struct SweepResult {
  int points{};   // in the design
  int done{};     // rows in sweep.csv at the end (resumed ones included)
  int resumed{};  // rows kept from an earlier run
  int failed{};   // rows whose status is not ok
  bool interrupted = false;
  double elapsed_s{};                 // this run's points, as sweep.json's elapsed_s [s]
  std::filesystem::path csv;          // out_dir/sweep.csv
  std::filesystem::path summary;      // out_dir/sweep.json
  std::vector<std::string> warnings;  // what went wrong besides the points (the report page)
  bool complete() const { return done == points; }
};

/// Runs `study` at every point of its sweep, `threads` at a time, and writes into out_dir:
/// sweep.csv (header sweep_columns(), one row per point in point order, each row appended and
/// flushed once it and every earlier point are done, numbers "%.17g") and sweep.json (the study,
/// the design, every parameter and the counts; rewritten at the start and at the end). A point's
/// failure is its row's status, never the sweep's. (The page comes from write_sweep_report();
/// run_sweep() in studies/studies.hpp does both.)
/// @throws bd::InputError if out_dir holds a sweep that cannot be resumed (another study or
///         design, or rows that do not match the design), or holds an unfinished sweep and
///         options.resume is false (the message says to pass --resume).
/// @throws std::runtime_error if a file cannot be written.
SweepResult write_sweep(const Study& study, const std::filesystem::path& out_dir,
                        const SweepOptions& options = {});

}  // namespace bd::studies
