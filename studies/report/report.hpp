#pragma once
/// The study report: `report.html` in a run's output folder, one self-contained page (inline CSS
/// and SVG, no scripts, no network) with the study's inputs, the method used and why, the
/// simulation status, the metrics, the comparison and Pareto tables and charts drawn by gnuplot.
/// Every number of the run comes from the folder's own data files (summary.json, timeseries.csv,
/// balanced-/optimized-timeseries.csv, comparison.csv, pareto.csv), read back; the linkage's
/// inputs come from the study.
#include <filesystem>
#include <string>

#include "studies/study/study.hpp"

namespace bd::studies {

/// The gnuplot program the report uses: $BD_GNUPLOT when set (a name looked up in PATH, or a
/// path), else "gnuplot" looked up in PATH. Empty when it cannot be found or is not executable,
/// so `BD_GNUPLOT=/nonexistent` simulates a machine without gnuplot.
std::string find_gnuplot();

/// The report.html text of the run whose data files are in `dir` (written by run_study() for
/// `study`). Charts are drawn by `gnuplot` (a program as find_gnuplot() returns it); with an
/// empty `gnuplot` the page has the tables and data-file links and says the charts need gnuplot.
/// @throws std::runtime_error if dir has no summary.json or timeseries.csv, a file cannot be
///         read, or gnuplot fails (the message has gnuplot's first error line).
std::string report_html(const Study& study, const std::filesystem::path& dir,
                        const std::string& gnuplot);

/// The study's linkage as HTML tables: links (l, m, s, σ, e, f, I), frame, branch, Grashof class,
/// counter-rotations and loads; the study page and the sweep page show them.
std::string linkage_tables_html(const Study& study);

/// Writes `dir/report.html` (report_html() with find_gnuplot()), under a temporary name renamed
/// into place, and returns its path.
/// @throws std::runtime_error as report_html(), or if the file cannot be written.
std::filesystem::path write_report(const Study& study, const std::filesystem::path& dir);

}  // namespace bd::studies
