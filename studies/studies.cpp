#include "studies/studies.hpp"

#include <exception>
#include <optional>
#include <stdexcept>
#include <string>
#include <system_error>

#include "core/input_error.hpp"
#include "studies/report/report.hpp"
#include "studies/run/files.hpp"

namespace bd::studies {

namespace fs = std::filesystem;

namespace {
// a file's whole text; none when it cannot be read
std::optional<std::string> read_text(const fs::path& file) {
  try {
    return read_file(file);
  } catch (const std::runtime_error&) {
    return std::nullopt;
  }
}
}  // namespace

std::optional<std::string> try_write_report(const Study& study, const fs::path& dir) {
  try {
    if (study.sweep) {
      write_sweep_report(study, dir);
    } else {
      write_report(study, dir);
    }
    return std::nullopt;
  } catch (const std::exception& e) {
    std::error_code ec;
    fs::remove(dir / "report.html", ec);
    return std::string("report.html not written: ") + e.what();
  }
}

RunResult run_study(const Study& study, const fs::path& out_dir) {
  // a folder holding an unfinished sweep is not overwritten by a single run (its rows would be
  // lost, or mixed with this run's files); a finished one is replaced (write_run())
  if (const std::string why = unfinished_sweep(out_dir, -1); !why.empty()) {
    // the sweep's own study file, as sweep.json names it
    const std::optional<SweepInFolder> sweep = sweep_in_folder(out_dir);
    const std::string file = sweep && !sweep->source.empty() ? sweep->source : "SWEEP-STUDY";
    throw InputError(why + ": continue it with `balance-design run " + file + " --out " +
                     out_dir.string() + " --resume`, or write this run elsewhere with --out");
  }
  // compute first: an invalid scene throws before anything is created on disk
  RunResult result = compute_study(study);
  // `bench`'s measurements belong to the study the folder held: kept for the same study file,
  // removed for another (its report would show another linkage's speed against accuracy)
  if (read_text(out_dir / "study.yaml") !=
      (study.source.empty() ? std::nullopt : read_text(study.source))) {
    remove_bench_files(out_dir);
  }
  write_run(study, result, out_dir);
  Study page = study;
  page.sweep.reset();  // a study page, also for a sweep's base study
  if (auto warning = try_write_report(page, out_dir)) result.warnings.push_back(*warning);
  return result;
}

SweepResult run_sweep(const Study& study, const fs::path& out_dir, const SweepOptions& options) {
  SweepResult result = write_sweep(study, out_dir, options);
  if (auto warning = try_write_report(study, out_dir)) result.warnings.push_back(*warning);
  return result;
}

BenchResult run_bench(const Study& study, const fs::path& out_dir, const BenchOptions& options) {
  remove_bench_files(out_dir);  // no stale measurements in the page run_study() writes
  RunResult run = run_study(study, out_dir);
  BenchResult result = write_bench(study, out_dir, options);
  result.run = std::move(run);
  if (auto warning = try_write_report(study, out_dir)) {
    result.run.warnings.push_back(*warning);
  } else {
    result.report = out_dir / "report.html";
  }
  return result;
}

}  // namespace bd::studies
