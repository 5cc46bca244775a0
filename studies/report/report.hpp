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

/// The report's "Speed against accuracy" section (HTML, starting with an <h2>) of the study's
/// bench, built from dir/work-precision.csv or dir/driven-convergence.csv: log-log charts drawn
/// by `gnuplot` (free: CPU time against the final-time error, the methods compared by their
/// fronts, then one chart per method with a line per integrator; driven: RMS error and CPU time
/// against samples per revolution, or over the duration of a planar scene given by one), a
/// compact table, and a notice of the runs that stopped early. Without gnuplot, the tables and
/// a notice. Empty when neither file exists.
/// @throws std::runtime_error if a file cannot be read or gnuplot fails.
std::string work_precision_section(const Study& study, const std::filesystem::path& dir,
                                   const std::string& gnuplot);

}  // namespace bd::studies
