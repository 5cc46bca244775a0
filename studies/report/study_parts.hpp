#pragma once
/// Internal to studies/report/: the parts of a study's report page that every linkage type shares
/// (the head, the simulation and scene, the metrics table, the charts, the data files); the
/// linkage's own tables and charts come from fourbar_page.cpp or planar_page.cpp.
#include <filesystem>
#include <string>
#include <vector>

#include "studies/report/animation.hpp"
#include "studies/report/report_support.hpp"
#include "studies/study/study.hpp"

namespace bd::studies::report_support {

/// The run's second design, when the folder has one: "balanced" or "optimized", its label
/// ("balanced", "optimised") and its samples' file.
struct SecondDesign {
  std::string key, label, file;
  bool present() const { return !key.empty(); }
};
SecondDesign second_design(const Json& summary, const std::filesystem::path& dir);

/// The page's head and title, and its first paragraph.
std::string page_start(const Study& study, const Json& summary);
/// The run facts of summary.json (or of its balanced_run / optimized_run) as a table; `free`:
/// the scene integrates (a driven one has no integrator steps to show).
std::string run_table(const Json& run, const std::string& what, bool free);
/// "Simulation": the status first, the run facts and the scene.
std::string simulation_section(const Json& summary);
/// "Metrics": the metrics of summary.json, beside the second design's and their ratio; a value
/// that is round-off of the run's scale of its unit (`scales`: the largest force of the run, ...)
/// or of the larger of the two shows as 0, and so does the ratio of such a value. Each peak
/// says where the original's lies (its time, and the inputs there; `study` names them).
std::string metrics_section(const Study& study, const Json& summary, const SecondDesign& second,
                            const std::string& notes, const Scales& scales);
/// "Comparison" (comparison.csv), when the folder has it; round-off as in metrics_section().
std::string comparison_section(const std::filesystem::path& dir, const Json& summary,
                               const SecondDesign& second, const Scales& scales);
/// "Harmonic orders" (harmonics.csv), when the folder has it: the amplitudes per design and order
/// of the inertial shaking force and moment, round-off of the run's forces (moments) as 0.
std::string harmonics_section(const std::filesystem::path& dir, const Scales& scales);
/// The balanced or optimised design's section: its summary.json section and its run (or the
/// notice that no optimum was found); round-off of `scales` shows as 0 (json_table()).
std::string second_design_section(const Json& summary, const SecondDesign& second,
                                  const Scales& scales);
/// "Charts": each chart drawn by gnuplot with its heading and caption, or the notice that the
/// charts need gnuplot; when the run's `samples` are more than the charts' `drawn`, a note that
/// the charts show every so many of them and the data files hold all.
std::string charts_section(const std::string& gnuplot, const std::string& datablocks,
                           const std::vector<Chart>& charts, std::size_t samples = 0,
                           std::size_t drawn = 0);
/// The Pareto front of pareto.csv, when the folder has a design on it or an optimum to mark
/// (no chart otherwise): the front's designs, the original design and the chosen optimum (from
/// comparison.csv), axes with their units; the points without a design are counted in the
/// caption. Its data go into `datablocks`.
std::vector<Chart> pareto_charts(const std::filesystem::path& dir, std::string& datablocks);
/// A bar chart per design of harmonics.csv (when the folder has it): the amplitudes of orders
/// 1..N of the shaking force (its parts turning with the input and against it) [N], and of the
/// shaking moment and the drive torque [N m], every design on the same axes. Its data (the
/// file's numbers as written, round-off of the run's forces or moments as 0) go into
/// `datablocks` as $harmonics_<design>; a side whose every bar is too small to see at its
/// axis's scale says so in the chart.
std::vector<Chart> harmonic_charts(const std::filesystem::path& dir, std::string& datablocks,
                                   const Scales& scales);

/// True when the run's samples are whole periods of a driven motion (a four-bar's revolutions;
/// a planar linkage's revolutions of its one input) and it ran to the end: its hodograph closes
/// with the first sample.
bool periodic_run(const Scene& scene, const Json& summary);
/// The x axis of the charts over the run: a gnuplot `using` expression and its label. A driven
/// scene's is the driven crank's angle in degrees (1-based column `angle_column`, 0: none), a
/// free scene's the time.
struct RunAxis {
  std::string x, label;
};
RunAxis run_axis(const Scene& scene, int angle_column);
/// A data block `$name` (header "x,y") of columns `cx`, `cy` (1-based) of `csv`, and the first
/// row again at the end when `close`; a value that is round-off of `scale` as 0.
std::string xy_block(const std::string& name, const Csv& csv, int cx, int cy, bool close,
                     double scale = 0);

/// The gnuplot column (1-based) of `name` in a timeseries header; 0 when absent.
int gp_column(const Csv& ts, const std::string& name);
/// The metrics table's legend of the shaking force and moment about `about` ("A0", "the
/// origin"): Fsh, Msh are the inertial part (what balancing acts on, and what the verdicts,
/// ratios and objectives take), Fsh_total, Msh_total the total with the weights and loads.
std::string shaking_metrics_note(const std::string& about);
/// The columns a chart of the shaking force or moment draws (1-based; the inertial part's, or
/// the total's in a timeseries.csv without the parts), and the sentence its caption adds: which
/// part it is, and, where the run has weights or applied loads (the static columns of `ts` not
/// all 0), how the total differs (by a constant shift when the static part is one).
struct ShakingColumns {
  int x = 0, y = 0, moment = 0;
  std::string force_note, moment_note;
};
ShakingColumns shaking_columns(const Csv& ts);

/// A linkage animation with its heading and caption.
struct AnimationFigure {
  Animation animation;
  std::string heading, caption;
};
/// "The linkage in motion": each animation (those with shapes) with its heading and caption.
std::string animations_section(const std::vector<AnimationFigure>& figures);
/// "Pareto front": pareto.csv as a table, when the folder has it (round-off of `scales` as 0).
std::string pareto_section(const std::filesystem::path& dir, const Scales& scales);
/// The data files a study's folder may hold, in the order the report lists them: the run's
/// (kRunFiles, studies/run/runner.hpp), then `balance-design bench`'s.
std::vector<std::string> data_files();
/// The gnuplot axis label of the time axis of a scene.
std::string time_axis(const Scene& scene);

}  // namespace bd::studies::report_support
