#pragma once
/// The studies layer's entry points, as the command line uses them: each runs a study and writes
/// its data files (studies/run/, sweep/, bench/), then its report page (studies/report/). A page
/// that cannot be written never fails the run: the result's `warnings` say why (the caller
/// decides whether to show them; library code never prints).
#include <filesystem>
#include <optional>
#include <string>

#include "studies/bench/work_precision.hpp"
#include "studies/run/runner.hpp"
#include "studies/study/study.hpp"
#include "studies/sweep/sweep.hpp"

namespace bd::studies {

/// compute_study() and write_run() into out_dir, then report.html (write_report()).
/// @throws as compute_study() and write_run().
RunResult run_study(const Study& study, const std::filesystem::path& out_dir);

/// write_sweep() into out_dir, then the sweep's report.html (write_sweep_report()); the report's
/// warning, if any, goes to `warning`.
/// @throws as write_sweep().
SweepResult run_sweep(const Study& study, const std::filesystem::path& out_dir,
                      const SweepOptions& options = {});

/// `balance-design bench`: removes out_dir's earlier measurements, runs the study as run_study()
/// does (so the folder is complete), measures it (write_bench()) and rewrites report.html, now
/// with its section "Speed against accuracy".
/// @throws as run_study() and write_bench().
BenchResult run_bench(const Study& study, const std::filesystem::path& out_dir,
                      const BenchOptions& options);

/// Writes the page of the run in `dir` (write_report(), or write_sweep_report() for a study with
/// a sweep). Empty when written, else why not: then no report.html is left in dir (never a page
/// of an earlier run beside this run's files).
std::optional<std::string> try_write_report(const Study& study, const std::filesystem::path& dir);

}  // namespace bd::studies
