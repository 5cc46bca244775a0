#pragma once
/// The pieces every report page is built from (studies/report.cpp and the pages of sweeps and
/// work-precision runs): reading a run's data files back, HTML escaping and tables, and drawing
/// charts with gnuplot into inline SVG. Internal to bd_studies.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "core/types.hpp"
#include "studies/run/simulation.hpp"

namespace bd::studies::report_support {

/// A JSON document as summary.json and sweep.json hold it: objects keep their file order.
using Json = nlohmann::ordered_json;
/// Parses JSON text; `name` names it in errors. @throws std::runtime_error on malformed text.
Json parse_json(const std::string& text, const std::string& name);
/// The member `key` of an object, or null when `j` is no object or has no such member.
const Json* member(const Json& j, const std::string& key);
/// A value as text: a string's characters, a number's exact text (the shortest that reads back
/// as the same double), "true"/"false", "" for null.
std::string text(const Json& v);
/// text() of member `key`, "" when there is none.
std::string text(const Json& j, const std::string& key);

/// A CSV file: its header's fields and its rows' fields as written (quoted fields unquoted).
struct Csv {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
};
/// @throws std::runtime_error if the file cannot be read (read_file(), studies/run/files.hpp).
Csv read_csv(const std::filesystem::path& p);
/// At most `max_rows` rows of a CSV file for the charts: the first, the last and rows evenly
/// spaced between, read line by line so that a run of 10^7 samples never sits in memory whole;
/// `total` (when given) gets the file's row count.
/// @throws std::runtime_error if the file cannot be read.
Csv read_csv_decimated(const std::filesystem::path& p, std::size_t max_rows, std::size_t* total);
/// The rows a chart draws of a run's samples (the page stays a few MB at most).
inline constexpr std::size_t kChartRows = 2000;
/// A CSV as a gnuplot data block `$name` (header line first, as the file has it).
std::string datablock(const std::string& name, const Csv& csv);

/// The numbers of a CSV row (an empty field is NaN).
std::vector<double> numbers(const std::vector<std::string>& row);

/// A point as gnuplot data, "x,y" (10 digits).
std::string xy(const Vec2& v);
/// A point for a table, "(x, y)" (6 significant digits, as fmt(): the study's 9.80665 m/s² shows
/// as written; a component that is round-off of the larger one or
/// of `scale`, a position's the linkage's size, shown as 0).
std::string vec_text(const Vec2& v, double scale = 0);
/// A number for a page: 6 significant digits, or "0" where it is round-off of the quantity's
/// `scale` (text::is_round_off(), |v| <= 1e-12 scale: 6.123e-17 for a centre of mass on a link
/// of 0.5 m). A display rule only: data files keep every digit.
std::string fmt_scaled(double v, double scale);
/// The unit a value of this name has on the page ("N", "N m", "kg", ...), "" when none is known:
/// metric names (Fsh_rms, Msh_total_max, RA0_max, tau_rms, added_mass), summary.json keys (mass,
/// position, theta1, omega1, ...).
std::string unit_of(const std::string& name);
/// The unit of a column or entry `name`: the one in brackets at its end ("crank counterweight y
/// from O2 in link axes [m]"), else unit_of(name).
std::string unit_in(const std::string& name);
/// The unit of metric `name` of a run: as summary.json's metric_units gives it (the linkage's
/// own table), else unit_of(name).
std::string metric_unit(const Json& summary, const std::string& name);

/// The natural scales of a run's quantities, for the display rule of round-off (fmt_scaled()).
using Scales = DisplayScales;
/// The scales of a run: the metrics of every design summary.json holds (`metrics`,
/// `balanced_metrics`, `optimized_metrics`, with their units) and the linkage's `size` [m].
Scales run_scales(const Json& summary, double size);
/// `name` with its unit in brackets when it has one ("mass [kg]").
std::string with_unit(const std::string& name);

/// `text` with & < > " escaped for HTML.
std::string esc(const std::string& text);
/// `v` formatted by printf format `f`.
std::string fmt(double v, const char* f = "%.6g");
/// A number as written in a data file as a table cell: 6 significant digits, the exact text on
/// hover; a non-number as escaped text; an empty field as a dash. With a `scale`, round-off of
/// it shows as 0 (fmt_scaled()).
std::string num_cell(const std::string& written, double scale = 0);
/// An object as a two-column table, an array of objects as a table with a column per key; keys
/// with their units (with_unit()), a point mass's radius and thickness of 0 left out. A number
/// whose key (or, in a list of {name, value}, whose name) has a unit with a scale in `scales`
/// shows round-off of that scale as 0.
std::string json_table(const Json& v, const Scales& scales = {});
/// A JSON value as a table cell; a number (or a list of them) that is round-off of `scale` as 0.
std::string json_cell(const Json& v, const Scales& scales = {}, double scale = 0);
/// The "Data files" section: a link and the size of each of `names` that exists in `dir`, in
/// order, and the end of the page.
std::string data_files_html(const std::filesystem::path& dir,
                            const std::vector<std::string>& names);
/// A CSV file as an HTML table (numbers through num_cell(); a column whose name has a unit
/// with a scale in `scales` shows round-off of that scale as 0).
std::string csv_table(const Csv& csv, const Scales& scales = {});
/// The pages' style sheet (inline CSS).
extern const char* const kStyle;

/// `text` as a gnuplot single-quoted string.
std::string gp_string(const std::string& text);
/// True when `p` is a regular file this process may execute.
bool executable(const std::filesystem::path& p);

/// One chart: its file stem (unique on the page), heading, caption and gnuplot commands (ending
/// in a plot).
struct Chart {
  std::string id, heading, caption, commands;
  bool square = false;  // taller canvas (equal-axis plots)
};
/// Runs `gnuplot` once for all charts, after `datablocks` (gnuplot text defining $name data
/// blocks, may be empty); returns each chart's inline SVG, in order. Where that run fails, each
/// chart is drawn by a run of its own, and a chart gnuplot cannot draw from its data (every value
/// of a curve undefined, say) is an HTML notice with gnuplot's reason in place of its SVG.
/// @throws std::runtime_error when no chart can be drawn (gnuplot itself fails; its first error
/// line) or a run that succeeded wrote no SVG.
std::vector<std::string> draw(const std::string& gnuplot, const std::string& datablocks,
                              const std::vector<Chart>& charts);

}  // namespace bd::studies::report_support
