// The sweep's report.html: built from sweep.csv and sweep.json alone (plus the study for the
// linkage's inputs), so an interrupted or still running sweep shows what it has, and
// `balance-design report DIR` rebuilds the same page from the same files.
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "studies/report/report.hpp"
#include "studies/report/report_support.hpp"
#include "studies/run/runner.hpp"
#include "studies/sweep/sweep.hpp"

namespace bd::studies {

namespace fs = std::filesystem;

using namespace report_support;  // NOLINT(google-build-using-namespace): the page builders

namespace {

// ---------------------------------------------------------------------------------------------
// the data files

// sweep.csv read record by record (a sweep of a million points is never held whole): records
// split at line ends outside quotes (a message may hold one); a last record without its line end
// was cut short by a kill and is left out. `header` gets the first record, `record` every other,
// with its number (2 for the first row).
bool for_each_record(
    const fs::path& p, const std::function<void(const std::vector<std::string>&)>& header,
    const std::function<void(const std::vector<std::string>&, std::size_t)>& record) {
  std::ifstream in(p, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + p.string());
  std::string rec;
  std::vector<std::string> fields;  // reused from record to record
  bool quoted = false;
  std::size_t n = 0;
  std::vector<char> buf(1 << 16);
  while (in.read(buf.data(), static_cast<std::streamsize>(buf.size())) || in.gcount() > 0) {
    const auto got = static_cast<std::size_t>(in.gcount());
    std::size_t start = 0;  // of the record's part in this block
    for (std::size_t k = 0; k < got; ++k) {
      const char c = buf[k];
      if (c == '"') quoted = !quoted;  // "" inside a quoted field toggles twice
      if (c != '\n' || quoted) continue;
      rec.append(buf.data() + start, k - start);
      start = k + 1;
      ++n;
      if (n == 1) {
        csv_fields(rec, fields);
        header(fields);
      } else if (!rec.empty() && rec != "\r") {
        csv_fields(rec, fields);
        record(fields, n);
      }
      rec.clear();
    }
    rec.append(buf.data() + start, got - start);
  }
  if (n == 0) throw std::runtime_error(p.string() + " has no complete header line");
  return !rec.empty();
}

// a field as a finite number, else nothing
std::optional<double> number(const std::string& field) {
  double v = 0.0;
  const char* end = field.data() + field.size();
  const auto [stop, error] = std::from_chars(field.data(), end, v);
  if (error != std::errc() || stop != end || !std::isfinite(v)) return std::nullopt;
  return v;
}

struct Parameter {
  std::string path;
  std::string label;  // in an engineer's words with its unit (engineer_name())
  bool log_scale = false;
  std::vector<double> values;  // a grid's values, as sweep.json lists them
};

// the main metrics, charted and ranked: their RMS (and, against one parameter, their peak)
struct MainMetric {
  const char* base;  // column stem: <base>_rms, <base>_max
  const char* what;  // axis label
};
constexpr MainMetric kMainMetrics[] = {{"Fsh", "shaking force |Fsh| [N]"},
                                       {"Msh", "shaking moment |Msh| about A0 [N m]"},
                                       {"tau", "drive torque |τ| [N m]"},
                                       {"RA0", "bearing force |RA0| [N]"},
                                       {"RA3", "bearing force |RA3| [N]"}};

// one design's values of a metric: a line or panel of a chart, a row of the best points
struct Series {
  std::string label;    // "original", "balanced", "optimised"
  std::string column;   // e.g. "balanced_Fsh_rms"
  std::string peak;     // the peak's column, drawn dotted against one parameter ("" for none)
  bool second = false;  // a column of the balanced or optimised design
};
// what one chart shows
struct Metric {
  std::string id;    // "Fsh", ..., "added_mass": names the chart
  std::string name;  // "Fsh_rms", "added_mass"
  std::string what;  // axis label, with the unit
  std::vector<Series> series;
};

// sweep.csv as the page uses it: the rows drawn in the charts (all of them up to a few
// thousand points, else a regular sample: see Sweep::sampling) and what is counted over all rows
struct SweepCsv {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;  // the rows charted (and listed, when few)
  bool cut_short = false;
  std::size_t total = 0;   // rows in the file
  std::size_t failed = 0;  // of which status is not ok
  std::vector<std::vector<std::string>> failed_rows;  // the first kFailedRows of them
};

// the least value of a series over every row, and how many rows are at the noise floor
struct Best {
  std::optional<std::vector<std::string>> row;
  double value = std::numeric_limits<double>::infinity();
};

constexpr std::size_t kFailedRows = 50;  // failed points listed; the rest are counted
constexpr std::size_t kPointRows = 100;  // sweeps up to this size list every point
constexpr std::size_t kChartRows = 2000;  // points drawn in a chart, at most (about)
constexpr std::size_t kGridCells = 40;   // a heat map's cells per axis, at most
// Values of a metric below this fraction of its largest value in the sweep are round-off (a
// balanced design's shaking force is 1e-13 of the original's): drawn as zero, never ranked.
constexpr double kNoiseFloor = 1e-9;

struct Sweep {
  // moved, never copied: `tallies` point into `scale` and `best`, whose nodes move with them
  Sweep() = default;
  Sweep(Sweep&&) = default;
  Sweep(const Sweep&) = delete;
  Sweep& operator=(const Sweep&) = delete;

  Json info;  // sweep.json
  SweepCsv csv;
  std::string sampling;  // how the charted rows were chosen, when not all ("" when all)
  std::map<std::string, Best> best;     // by series column, over every row
  std::map<std::string, double> scale;  // by metric name: largest |value| of any of its series
  // per series that sweep.csv has: its column, and where take_row() counts it
  struct Tally {
    std::size_t column;
    bool second;  // of the second design
    double* scale;
    Best* best;
  };
  std::vector<Tally> tallies;
  std::vector<std::pair<double, double>> range;  // each parameter's least and largest value
  // the sample charted: every keep_stride-th point, or on a large grid the values of each
  // parameter whose grid_keep[j][index] is set (grid_ny: the second parameter's values, > 0 then)
  std::size_t keep_stride = 1, grid_ny = 0;
  std::vector<char> grid_keep[2];
  std::vector<Parameter> params;
  std::string design;           // grid, random, lhs
  std::string second;           // column prefix of the second design: "balanced_", "optimized_", ""
  std::string second_label;     // "balanced", "optimised"
  std::vector<Metric> metrics;  // the main metrics sweep.csv has, then the added mass
  std::size_t status_col{}, message_col{};

  std::optional<std::size_t> col(const std::string& name) const {
    for (std::size_t i = 0; i < csv.header.size(); ++i)
      if (csv.header[i] == name) return i;
    return std::nullopt;
  }
  const std::string& status(std::size_t r) const { return csv.rows[r][status_col]; }
  // a row's values count for the original design when all its simulations ran to the end; a
  // point without an optimum keeps its original design's values (only the optimum's are empty)
  bool usable(std::size_t r, bool second_design) const {
    const std::string& s = status(r);
    return s == "ok" || (!second_design && s == "no-optimum");
  }
  // column `name` of a series at row r, when the row counts for the series' design
  std::optional<double> value(std::size_t r, const Series& se, const std::string& name) const {
    const auto c = col(name);
    if (!c || !usable(r, se.second)) return std::nullopt;
    return number(csv.rows[r][*c]);
  }
  std::optional<double> value(std::size_t r, const Series& se) const {
    return value(r, se, se.column);
  }
  // parameter j's value at row r (written for every point, failed ones too)
  std::optional<double> x(std::size_t r, std::size_t j) const { return number(csv.rows[r][1 + j]); }
  const std::string& x_text(std::size_t r, std::size_t j) const { return csv.rows[r][1 + j]; }
  // a metric's round-off floor: values at or below it are zero to the arithmetic
  double floor(const Metric& m) const {
    const auto it = scale.find(m.id);
    return it == scale.end() ? 0.0 : kNoiseFloor * it->second;
  }
  // every series of the metrics, the original design's first
  std::vector<Series> all_series() const {
    std::vector<Series> out;
    for (const bool of_second : {false, true})
      for (const Metric& m : metrics)
        for (const Series& se : m.series)
          if (se.second == of_second) out.push_back(se);
    return out;
  }
};

void check_header(Sweep& s, const fs::path& csv_file, const fs::path& json_file,
                  const Study& study);
std::string engineer_name(const std::string& path, const Study& study);
void choose_sample(Sweep& s, std::size_t points);
void take_row(Sweep& s, const std::vector<std::string>& row);

Sweep load_sweep(const Study& study, const fs::path& dir) {
  const fs::path json_file = dir / "sweep.json";
  const fs::path csv_file = dir / "sweep.csv";
  if (!fs::exists(json_file)) {
    throw std::runtime_error(json_file.string() + " not found: not the output folder of a sweep");
  }
  if (!fs::exists(csv_file)) {
    throw std::runtime_error(csv_file.string() +
                             " not found: the sweep has not written its rows (run it again with "
                             "--resume)");
  }
  Sweep s;
  s.info = parse_json(read_file(json_file), json_file.string());
  s.design = text(s.info, "design");
  if (const Json* ps = member(s.info, "parameters")) {
    for (const Json& p : (*ps)) {
      Parameter q;
      q.path = text(p, "path");
      q.label = engineer_name(q.path, study);
      q.log_scale = text(p, "scale") == "log";
      if (const Json* values = member(p, "values")) {
        for (const Json& v : (*values)) {
          if (const auto d = number(text(v))) q.values.push_back(*d);
        }
      }
      s.params.push_back(std::move(q));
    }
  }
  if (s.params.empty()) throw std::runtime_error(json_file.string() + " lists no parameters");

  std::size_t points = 0;
  if (const auto n = number(text(s.info, "points")); n && *n > 0) {
    points = static_cast<std::size_t>(*n);
  }
  bool have_header = false;
  s.csv.cut_short = for_each_record(
      csv_file, [&](const std::vector<std::string>& h) { s.csv.header = h; },
      [&](const std::vector<std::string>& row, std::size_t n) {
        if (!have_header) {
          check_header(s, csv_file, json_file, study);
          have_header = true;
          choose_sample(s, points);
        }
        if (row.size() != s.csv.header.size()) {
          throw std::runtime_error(csv_file.string() + ": record " + std::to_string(n) +
                                   " has " + std::to_string(row.size()) + " fields, the header " +
                                   std::to_string(s.csv.header.size()));
        }
        take_row(s, row);
      });
  if (!have_header) check_header(s, csv_file, json_file, study);
  return s;
}

// the header against sweep.json, then the metrics it has
void check_header(Sweep& s, const fs::path& csv_file, const fs::path& json_file,
                  const Study& study) {
  const auto& h = s.csv.header;
  bool header_ok = h.size() >= s.params.size() + 3 && h.front() == "point" &&
                   h[h.size() - 2] == "status" && h.back() == "message";
  for (std::size_t j = 0; header_ok && j < s.params.size(); ++j)
    header_ok = h[1 + j] == s.params[j].path;
  if (!header_ok) {
    std::string expected = "point";
    for (const Parameter& p : s.params) expected += "," + p.path;
    throw std::runtime_error(csv_file.string() + ": its header does not match " +
                             json_file.string() + " (expected " + expected +
                             ",<metrics>,status,message)");
  }
  s.status_col = h.size() - 2;
  s.message_col = h.size() - 1;
  if (s.col("balanced_Fsh_rms")) {
    s.second = "balanced_";
    s.second_label = "balanced";
  } else if (s.col("optimized_Fsh_rms")) {
    s.second = "optimized_";
    s.second_label = "optimised";
  }
  // the drive torque is zero in free motion: no chart of it there
  const bool driven = std::holds_alternative<core::DrivenScene>(study.scene) ||
                      std::holds_alternative<core::planar::DrivenScene>(study.scene);
  for (const MainMetric& m : kMainMetrics) {
    const std::string base = m.base;
    if (base == "tau" && !driven) continue;
    if (!s.col(base + "_rms")) continue;
    std::string what = m.what;
    if (!study.is_fourbar()) {
      // a planar linkage's moment is about the origin; its one input's drive may be a slide's
      if (base == "Msh") what = "shaking moment |Msh| about the origin [N m]";
      if (base == "tau" && study.planar().inputs.size() == 1 &&
          study.planar().inputs[0].kind == core::planar::Input::Kind::kSlide) {
        what = "drive force |τ| [N]";
      }
    }
    Metric metric{base, base + "_rms", what, {{"original", base + "_rms", base + "_max", false}}};
    if (!s.second.empty() && s.col(s.second + base + "_rms")) {
      metric.series.push_back(
          {s.second_label, s.second + base + "_rms", s.second + base + "_max", true});
    }
    s.metrics.push_back(std::move(metric));
  }
  // what the second design costs: the mass it adds (negative when it takes mass away)
  if (!s.second.empty() && s.col("added_mass")) {
    s.metrics.push_back({"added_mass",
                         "added_mass",
                         "added mass [kg]",
                         {{s.second_label, "added_mass", "", true}}});
  }
  s.range.assign(s.params.size(), {std::numeric_limits<double>::infinity(),
                                   -std::numeric_limits<double>::infinity()});
  for (const Metric& m : s.metrics) {
    for (const Series& se : m.series) {
      if (const auto c = s.col(se.column)) {
        s.tallies.push_back({*c, se.second, &s.scale[m.id], &s.best[se.column]});
      }
    }
  }
}

// Which rows the charts draw: all of a sweep of up to kChartRows points; of a larger grid of two
// parameters at most kGridCells values of each, evenly spread from the first value to the last
// (both always drawn: the edge of a design space is where optima often lie); else every k-th
// point (random and LHS points come in random order, so the sample is as random as the design).
void choose_sample(Sweep& s, std::size_t points) {
  s.keep_stride = 1;
  if (points <= kChartRows) return;
  if (s.params.size() == 2 && s.design == "grid" && !s.params[0].values.empty() &&
      !s.params[1].values.empty()) {
    s.grid_ny = s.params[1].values.size();
    std::string counts[2];
    for (std::size_t j = 0; j < 2; ++j) {
      Parameter& p = s.params[j];
      const std::size_t n = p.values.size();
      const std::size_t m = std::min(n, kGridCells);
      s.grid_keep[j].assign(n, 0);
      std::vector<double> kept;
      for (std::size_t t = 0; t < m; ++t) {
        // index t (n - 1) / (m - 1), rounded: distinct for distinct t as n >= m
        const std::size_t i = m == 1 ? 0 : (t * (n - 1) + (m - 1) / 2) / (m - 1);
        s.grid_keep[j][i] = 1;
        kept.push_back(p.values[i]);
      }
      p.values = std::move(kept);
      counts[j] = std::to_string(m) + " of the " + std::to_string(n) + " values";
    }
    s.sampling = counts[0] + " of " + s.params[0].path + " and " + counts[1] + " of " +
                 s.params[1].path + ", each from its first value to its last (" +
                 std::to_string(s.params[0].values.size()) + " x " +
                 std::to_string(s.params[1].values.size()) + " of the grid's points)";
    return;
  }
  s.keep_stride = (points + kChartRows - 1) / kChartRows;
  s.sampling = "one in every " + std::to_string(s.keep_stride) + " points (" +
               std::to_string((points + s.keep_stride - 1) / s.keep_stride) + " of " +
               std::to_string(points) + ")";
}

// one row of sweep.csv: counted, ranked, and kept when charted
void take_row(Sweep& s, const std::vector<std::string>& row) {
  ++s.csv.total;
  const std::string& status = row[s.status_col];
  const bool ok = status == "ok";
  if (!ok) {
    ++s.csv.failed;
    if (s.csv.failed_rows.size() < kFailedRows) s.csv.failed_rows.push_back(row);
  }
  for (std::size_t j = 0; j < s.params.size(); ++j) {
    if (const auto x = number(row[1 + j])) {
      s.range[j].first = std::min(s.range[j].first, *x);
      s.range[j].second = std::max(s.range[j].second, *x);
    }
  }
  const bool no_optimum = !ok && status == "no-optimum";
  for (const Sweep::Tally& t : s.tallies) {
    if (!(ok || (!t.second && no_optimum))) continue;
    const auto v = number(row[t.column]);
    if (!v) continue;
    *t.scale = std::max(*t.scale, std::abs(*v));
    if (*v < t.best->value) {
      t.best->value = *v;
      t.best->row = row;
    }
  }
  // charted?
  const auto index = number(row[0]);
  const std::size_t i = index && *index >= 0 ? static_cast<std::size_t>(*index) : 0;
  bool keep = true;
  if (s.grid_ny > 0) {
    const std::size_t ix = i / s.grid_ny, iy = i % s.grid_ny;
    keep = ix < s.grid_keep[0].size() && s.grid_keep[0][ix] && s.grid_keep[1][iy];
  } else if (s.keep_stride > 1) {
    keep = i % s.keep_stride == 0;
  }
  if (keep) s.csv.rows.push_back(row);
}

// ---------------------------------------------------------------------------------------------
// tables

std::string td(const std::string& html) { return "<td>" + html + "</td>"; }

std::string status_section(const Sweep& s, const fs::path& dir) {
  const std::string status = text(s.info, "status");
  const std::size_t rows = s.csv.total;
  const std::size_t failed = s.csv.failed;
  const std::string points = text(s.info, "points");
  const std::string source = text(s.info, "source");
  const std::string resume = "<code>balance-design run " +
                             esc(source.empty() ? std::string("STUDY.yaml") : source) + " --out " +
                             esc(dir.string()) + " --resume</code>";

  std::string h = "<h2>Status</h2>\n";
  if (status == "complete") {
    h += "<p class=\"good\">Complete: " + std::to_string(rows) + " of " + esc(points) +
         " points done.</p>\n";
  } else if (status == "interrupted") {
    h += "<p class=\"notice bad\">Interrupted after " + std::to_string(rows) + " of " +
         esc(points) + " points. To run the missing points, keeping these rows: " + resume +
         "</p>\n";
  } else {
    h += "<p class=\"notice bad\">Status &ldquo;" + esc(status) +
         "&rdquo;: the sweep was "
         "running when this page was written, or it was stopped without the chance to say so; " +
         std::to_string(rows) + " of " + esc(points) +
         " points are in sweep.csv. If it no longer runs, continue it with " + resume + "</p>\n";
  }
  if (s.csv.cut_short) {
    h += "<p class=\"notice\">The last line of sweep.csv was cut short (the sweep was stopped "
         "while writing it) and is left out; a resumed run writes that point again.</p>\n";
  }
  h += "<table><tr><th>points in the design</th>" + num_cell(points) + "</tr>";
  h += "<tr><th>rows in sweep.csv</th>" + num_cell(std::to_string(rows)) + "</tr>";
  h += "<tr><th>of which failed (status not ok)</th><td class=\"n" +
       std::string(failed > 0 ? " bad" : "") + "\">" + std::to_string(failed) + "</td></tr>";
  const std::pair<const char*, const char*> facts[] = {{"status", "status (sweep.json)"},
                                                       {"done", "done (sweep.json)"},
                                                       {"resumed", "rows kept from an earlier run"},
                                                       {"failed", "failed (sweep.json)"},
                                                       {"elapsed_s", "elapsed [s]"}};
  for (const auto& [key, what] : facts) {
    if (const Json* v = member(s.info, key))
      h += std::string("<tr><th>") + what + "</th>" + json_cell(*v) + "</tr>";
  }
  return h + "</table>\n";
}

std::string values_text(const Json& values) {
  const std::size_t n = values.size();
  std::string t;
  for (std::size_t i = 0; i < n; ++i) {
    if (n > 12 && i == 6) {
      t += ", &hellip;";
      i = n - 3;
    }
    const auto v = number(text(values[i]));
    t += (t.empty() ? "" : ", ") + std::string("<span title=\"" + esc(text(values[i])) + "\">") +
         esc(v ? fmt(*v) : text(values[i])) + "</span>";
  }
  if (n > 12) t += " (" + std::to_string(n) + " values)";
  return t;
}

std::string design_section(const Sweep& s) {
  const Json& j = s.info;
  std::string h = "<h2>Design</h2>\n<table>";
  h += "<tr><th>design</th><td>" + esc(s.design) + "</td></tr>";
  if (s.design != "grid" && member(j, "seed"))
    h += "<tr><th>seed</th>" + json_cell(*member(j, "seed")) + "</tr>";
  if (const Json* v = member(j, "points")) h += "<tr><th>points</th>" + json_cell(*v) + "</tr>";
  if (const Json* v = member(j, "threads")) h += "<tr><th>threads</th>" + json_cell(*v) + "</tr>";
  if (const Json* v = member(j, "fingerprint")) {
    h += "<tr><th>study file fingerprint</th><td><code>" + esc(text(*v)) + "</code></td></tr>";
  }
  h += "</table>\n<table><tr><th>parameter (path in the study file)</th><th>unit</th>"
       "<th>scale</th><th>from</th><th>to</th><th>values</th></tr>";
  if (const Json* ps = member(j, "parameters")) {
    std::size_t i = 0;
    for (const Json& p : (*ps)) {
      const Json* from = member(p, "from");
      const Json* to = member(p, "to");
      const Json* values = member(p, "values");
      // the unit of the engineer's name of the parameter (the values are SI)
      const std::string unit = i < s.params.size() && s.params[i].label != s.params[i].path
                                   ? unit_in(s.params[i].label)
                                   : "";
      ++i;
      h += "<tr><td><code>" + esc(text(p, "path")) + "</code></td><td>" + esc(unit) + "</td><td>" +
           esc(text(p, "scale")) + "</td>" + (from ? json_cell(*from) : "<td></td>") +
           (to ? json_cell(*to) : "<td></td>") +
           td(values ? values_text(*values)
                     : std::string(s.design == "lhs" ? "Latin hypercube draws"
                                                     : "uniform random draws") +
                           (text(p, "scale") == "log" ? " (uniform in log)" : "")) +
           "</tr>";
    }
  }
  h += "</table>\n";
  if (s.design == "grid" && s.params.size() > 1) {
    h += "<p>Grid points run through the Cartesian product of the values, the first parameter "
         "varying slowest.</p>\n";
  }
  return h;
}

// the parameters' header cells, and one row's parameter cells
std::string param_headers(const Sweep& s) {
  std::string h;
  for (const Parameter& p : s.params) {
    h += "<th>" + esc(p.label) + (p.label == p.path ? "" : "<br><code>" + esc(p.path) + "</code>") +
         "</th>";
  }
  return h;
}
std::string param_cells(const Sweep& s, const std::vector<std::string>& row) {
  std::string h;
  for (std::size_t j = 0; j < s.params.size(); ++j) h += num_cell(row[1 + j]);
  return h;
}
std::string param_cells(const Sweep& s, std::size_t r) { return param_cells(s, s.csv.rows[r]); }

std::string best_section(const Sweep& s) {
  bool added_mass = false;
  for (const Metric& m : s.metrics) added_mass = added_mass || m.id == "added_mass";
  std::string h =
      "<h2>Best points</h2>\n<p>The point with the least value of each main metric "
      "(RMS over the samples)" +
      std::string(added_mass ? " and of the added mass" : "") +
      ", among the points whose status is ok";
  if (s.second == "optimized_") h += " (for the original design also those without an optimum)";
  h += ".</p>\n<table><tr><th>metric</th><th>least value</th><th>unit</th><th>at point</th>" +
       param_headers(s) + "</tr>";
  bool any = false, noise = false;
  std::map<std::string, double> floors;      // by series column
  std::map<std::string, std::string> units;  // by series column, from its chart's axis label
  for (const Metric& m : s.metrics) {
    for (const Series& se : m.series) {
      floors[se.column] = s.floor(m);
      units[se.column] = unit_in(m.what);
    }
  }
  for (const Series& se : s.all_series()) {
    const auto it = s.best.find(se.column);
    if (it == s.best.end() || !it->second.row) continue;
    any = true;
    const std::vector<std::string>& row = *it->second.row;
    const std::string& written = row[*s.col(se.column)];
    const std::string unit = "<td>" + esc(units[se.column]) + "</td>";
    if (it->second.value <= floors[se.column]) {
      // round-off: no point is better than another, and the value is 0 (exact on hover)
      noise = true;
      h += "<tr><th>" + esc(se.column) + "</th><td class=\"n\" title=\"" + esc(written) +
           "\">0</td>" + unit + "<td colspan=\"" + std::to_string(1 + s.params.size()) +
           "\">zero to round-off (every value at or below " + fmt(floors[se.column]) +
           " ranks alike)</td></tr>";
      continue;
    }
    h += "<tr><th>" + esc(se.column) + "</th>" + num_cell(written) + unit + num_cell(row[0]) +
         param_cells(s, row) + "</tr>";
  }
  if (!any) {
    h += "<tr><td colspan=\"" + std::to_string(4 + s.params.size()) +
         "\">no point has finished with status ok yet</td></tr>";
  }
  h += "</table>\n";
  if (noise) {
    h += "<p>Values below " + fmt(kNoiseFloor, "%g") +
         " of a metric's largest value in the sweep are round-off of an exact zero (a fully "
         "balanced design's shaking force, for one): they are not ranked, and the charts draw "
         "them as zero.</p>\n";
  }
  return h;
}

std::string failed_section(const Sweep& s) {
  const std::size_t failed = s.csv.failed;
  if (failed == 0)
    return "<h2>Failed points</h2>\n<p>None: every point ran with status ok.</p>\n";
  std::string h = "<h2>Failed points</h2>\n<p>" + std::to_string(failed) +
                  " point(s) did not finish with status ok (stopped-early: a simulation stopped, "
                  "no-optimum: the optimiser found no design, bad-input: the study at that point "
                  "is invalid, error: an unexpected failure). They are left out of the charts and "
                  "the best points (a point "
                  "without an optimum keeps its original design's values there).</p>\n"
                  "<table><tr><th>point</th>" +
                  param_headers(s) + "<th>status</th><th>message</th></tr>";
  for (const std::vector<std::string>& row : s.csv.failed_rows) {
    h += "<tr>" + num_cell(row[0]) + param_cells(s, row) + "<td class=\"bad\">" +
         esc(row[s.status_col]) + "</td><td>" + esc(row[s.message_col]) + "</td></tr>";
  }
  h += "</table>\n";
  if (failed > kFailedRows) {
    h += "<p>&hellip; and " + std::to_string(failed - kFailedRows) +
         " more (see <a href=\"sweep.csv\">sweep.csv</a>).</p>\n";
  }
  return h;
}

std::string points_section(const Sweep& s) {
  std::string h = "<h2>Points</h2>\n";
  if (s.csv.total > kPointRows) {
    return h + "<p>" + std::to_string(s.csv.total) +
           " points: every one, with every metric, is in <a "
           "href=\"sweep.csv\">sweep.csv</a>.</p>\n";
  }
  h += "<p>The main metrics (RMS) of every point; all its metrics are in "
       "<a href=\"sweep.csv\">sweep.csv</a>.</p>\n<table><tr><th>point</th>" +
       param_headers(s);
  // each series' column, with its unit (its chart's) and its metric's largest value in the sweep
  // (round-off of it shows as 0)
  std::map<std::string, std::pair<std::string, double>> of_column;
  for (const Metric& m : s.metrics) {
    const auto scale = s.scale.find(m.id);
    for (const Series& se : m.series) {
      of_column[se.column] = {unit_in(m.what), scale == s.scale.end() ? 0.0 : scale->second};
    }
  }
  std::vector<std::pair<std::size_t, double>> cols;
  for (const Series& se : s.all_series()) {
    const auto& [unit, scale] = of_column[se.column];
    cols.emplace_back(*s.col(se.column), scale);
    h += "<th>" + esc(se.column) + (unit.empty() ? "" : " [" + esc(unit) + "]") + "</th>";
  }
  h += "<th>status</th></tr>";
  for (std::size_t r = 0; r < s.csv.rows.size(); ++r) {
    h += "<tr>" + num_cell(s.csv.rows[r][0]) + param_cells(s, r);
    for (const auto& [c, scale] : cols) h += num_cell(s.csv.rows[r][c], scale);
    h += "<td" + std::string(s.status(r) == "ok" ? "" : " class=\"bad\"") + ">" + esc(s.status(r)) +
         "</td></tr>";
  }
  return h + "</table>\n";
}

std::string study_section(const Study& study, const Sweep& s) {
  std::string h = "<h2>Study</h2>\n<p>The study file's values; at each point the swept ";
  std::string swept;
  for (const Parameter& p : s.params)
    swept += (swept.empty() ? "" : ", ") + ("<code>" + esc(p.path) + "</code>");
  h += swept + " take the point's values instead.</p>\n<table>";
  h += "<tr><th>scene</th><td>" + std::string(scene_type(study.scene)) + "</td></tr>";
  if (const auto* free = std::get_if<core::FreeScene>(&study.scene)) {
    h += "<tr><th>theta1 [rad]</th><td class=\"n\">" + fmt(free->theta1) + "</td></tr>";
    h += "<tr><th>omega1 [rad/s] (initial)</th><td class=\"n\">" + fmt(free->omega1) + "</td></tr>";
    h += "<tr><th>duration [s]</th><td class=\"n\">" + fmt(free->duration) + "</td></tr>";
    h += "<tr><th>samples</th><td class=\"n\">" + std::to_string(free->samples) + "</td></tr>";
    h += "<tr><th>tolerance</th><td class=\"n\">" + fmt(study.tolerance) + "</td></tr>";
  } else if (const auto* driven = std::get_if<core::DrivenScene>(&study.scene)) {
    h += "<tr><th>theta1 [rad] at t = 0</th><td class=\"n\">" + fmt(driven->theta1) + "</td></tr>";
    h += "<tr><th>omega1 [rad/s] (constant)</th><td class=\"n\">" + fmt(driven->omega1) +
         "</td></tr>";
    h += "<tr><th>revolutions</th><td class=\"n\">" + std::to_string(driven->revolutions) +
         "</td></tr>";
    h += "<tr><th>samples per revolution</th><td class=\"n\">" + std::to_string(driven->samples) +
         "</td></tr>";
  }
  h += "<tr><th>method</th><td>" + esc(study.method_name()) + "</td></tr>";
  if (study.balance) {
    const balance::BalanceRequest& b = study.balance->request;
    h += std::string("<tr><th>balance</th><td>force ") + (b.force ? "full" : "none") + ", moment " +
         (b.moment ? "full" : "none") + "</td></tr>";
  }
  if (study.optimize) {
    h += "<tr><th>optimize</th><td>minimise " + esc(objective_text(*study.optimize)) +
         "; constraints: " + esc(constraints_text(*study.optimize)) + "</td></tr>";
  } else if (study.planar_optimize) {
    h += "<tr><th>optimize</th><td>minimise " + esc(objective_text(*study.planar_optimize)) +
         "; constraints: " + esc(constraints_text(*study.planar_optimize)) + "</td></tr>";
  }
  h += "</table>\n<h3>Linkage</h3>\n" + linkage_tables_html(study);
  return h;
}

// ---------------------------------------------------------------------------------------------
// charts

std::string num(double v) { return fmt(v, "%.17g"); }

// a perceptually uniform palette (viridis), readable in grey too
const char* const kPalette =
    "set palette defined (0 '#440154', 0.25 '#3b528b', 0.5 '#21918c', 0.75 '#5ec962', "
    "1 '#fde725')\n";

// a swept value in an engineer's words with its unit, e.g. "coupler mass m2 [kg]" or "speed of
// input crank [rad/s]", from its path in the study file (the path itself when it is not one of
// these); `study` names a planar linkage's inputs and their kinds
std::string engineer_name(const std::string& path, const Study& study) {
  const std::vector<std::string> k = [&] {
    std::vector<std::string> parts;
    std::string part;
    for (const char c : path) {
      if (c == '.' || c == '[' || c == ']') {
        if (!part.empty()) parts.push_back(part);
        part.clear();
      } else {
        part += c;
      }
    }
    if (!part.empty()) parts.push_back(part);
    return parts;
  }();
  if (k.empty()) return path;
  const auto is = [&](std::initializer_list<const char*> keys) {
    if (k.size() != keys.size()) return false;
    std::size_t i = 0;
    for (const char* key : keys) {
      if (*key != '*' && k[i] != key) return false;
      ++i;
    }
    return true;
  };
  const std::map<std::string, std::string> links = {{"crank", "1"}, {"coupler", "2"},
                                                    {"rocker", "3"}};
  const auto axis = [](const std::string& i) { return std::string(i == "0" ? "x" : "y"); };
  if (is({"linkage", "frame"})) return "frame length l4 [m]";
  if (k[0] == "linkage" && k.size() >= 3) {
    // a four-bar's links (crank, coupler, rocker) or a planar linkage's (links.NAME.FIELD)
    const bool planar = k[1] == "links" && k.size() == 4;
    const std::string name = planar ? k[2] : k[1];
    const std::string field = planar ? k[3] : k[2];
    const auto n = links.find(name);
    const std::string sub = !planar && n != links.end() ? n->second : "";
    const std::map<std::string, std::string> fields = {
        {"length", "length l" + sub + " [m]"},
        {"mass", "mass m" + sub + " [kg]"},
        {"inertia", "inertia I" + sub + " about its centre of mass [kg m²]"},
        {"s", "centre of mass s" + sub + " [m]"},
        {"sigma", "centre-of-mass angle σ" + sub + " [rad]"},
        {"e", "centre of mass e" + sub + " along the link [m]"},
        {"f", "centre of mass f" + sub + " across the link [m]"}};
    if (const auto f = fields.find(field); f != fields.end() && (planar || k.size() == 3)) {
      return name + " " + f->second;
    }
  }
  // a planar linkage's other parts
  if (is({"linkage", "nodes", "*", "*"})) return "node " + k[2] + " " + axis(k[3]) + " [m]";
  if (is({"linkage", "nodes", "*", "at", "*"})) return "node " + k[2] + " " + axis(k[4]) + " [m]";
  if (is({"linkage", "point_masses", "*"})) return "point mass at " + k[2] + " [kg]";
  if (is({"linkage", "springs", "*", "*"})) {
    const std::map<std::string, std::string> fields = {{"stiffness", "stiffness [N/m]"},
                                                       {"free_length", "free length [m]"},
                                                       {"damping", "damping [N s/m]"}};
    if (const auto f = fields.find(k[3]); f != fields.end())
      return "spring " + k[2] + " " + f->second;
  }
  if (is({"linkage", "balance_shafts", "*", "*"})) {
    const std::map<std::string, std::string> fields = {
        {"mass", "mass [kg]"}, {"inertia", "inertia [kg m²]"}, {"ratio", "speed ratio"}};
    if (const auto f = fields.find(k[3]); f != fields.end())
      return "balance shaft " + k[2] + " " + f->second;
  }
  if (is({"linkage", "balance_shafts", "*", "*", "*"}) && (k[3] == "at" || k[3] == "eccentricity"))
    return "balance shaft " + k[2] + " " + (k[3] == "at" ? "position " : "eccentricity ") +
           axis(k[4]) + " [m]";
  if (is({"linkage", "counterweights", "*", "mass"}))
    return "counterweight on " + k[2] + " mass [kg]";
  if (is({"linkage", "counterweights", "*", "inertia"}))
    return "counterweight on " + k[2] + " inertia [kg m²]";
  if (is({"linkage", "counterweights", "*", "at", "*"}))
    return "counterweight on " + k[2] + " position " + axis(k[4]) + " [m]";
  if (is({"linkage", "inputs", "*", "torque"})) return "drive torque on " + k[2] + " [N m]";
  if (is({"linkage", "inputs", "*", "force"})) return "drive force on " + k[2] + " [N]";
  if (is({"loads", "gravity", "*"})) return "gravity g" + axis(k[2]) + " [m/s²]";
  if (is({"loads", "*", "force", "*"})) return k[1] + " force F" + axis(k[3]) + " [N]";
  if (is({"loads", "*", "moment"})) return k[1] + " moment [N m]";
  if (is({"loads", "links", "*", "force", "*"})) return k[2] + " force F" + axis(k[4]) + " [N]";
  if (is({"loads", "links", "*", "moment"})) return k[2] + " moment [N m]";
  if (is({"loads", "nodes", "*", "force", "*"}))
    return "force F" + axis(k[4]) + " at node " + k[2] + " [N]";
  if (is({"scene", "*"})) {
    const std::map<std::string, std::string> scene = {
        {"omega1", "crank speed ω1 [rad/s]"},
        {"theta1", "initial crank angle θ1 [rad]"},
        {"duration", "duration [s]"}};
    if (const auto f = scene.find(k[1]); f != scene.end()) return f->second;
  }
  // a planar scene's value per input: named by the input, in its unit (an angle's or a slide's)
  if (is({"scene", "*", "*"}) && !study.is_fourbar()) {
    const auto& inputs = study.planar().inputs;
    const std::size_t i = static_cast<std::size_t>(std::strtoul(k[2].c_str(), nullptr, 10));
    const std::map<std::string, std::pair<std::string, std::string>> scene = {
        {"speeds", {"speed", "/s"}}, {"start", {"start", ""}}, {"rates", {"initial rate", "/s"}}};
    const auto f = scene.find(k[1]);
    if (f != scene.end() && i < inputs.size()) {
      const bool angle = inputs[i].kind == core::planar::Input::Kind::kAngle;
      return f->second.first + " of input " + inputs[i].name + " [" + (angle ? "rad" : "m") +
             f->second.second + "]";
    }
  }
  return path;
}

std::string axis_label(const Parameter& p) { return p.label + (p.log_scale ? " (log scale)" : ""); }

// a value as charted: round-off below the metric's floor drawn as zero
double charted(double v, double floor) { return std::abs(v) <= floor ? 0.0 : v; }

// " Drawn: every k-th point ...; the tables count every point." when the chart is a sample
std::string sample_note(const Sweep& s) {
  if (s.sampling.empty()) return {};
  return " Drawn: " + s.sampling + " of sweep.csv's " + std::to_string(s.csv.total) +
         " rows; the best points and the counts are over every row.";
}

// The cell of grid value v among a parameter's values: from halfway to the lower neighbour to
// halfway to the upper one (halfway in log for a log-scale parameter), the end cells as wide
// outside their value as inside, so a non-uniform list of values is drawn at its true places.
std::pair<double, double> cell_edges(const Parameter& p, double v) {
  const auto f = [&](double x) { return p.log_scale ? std::log(x) : x; };
  const auto g = [&](double y) { return p.log_scale ? std::exp(y) : y; };
  std::vector<double> u;
  for (const double x : p.values) u.push_back(f(x));
  std::sort(u.begin(), u.end());
  u.erase(std::unique(u.begin(), u.end()), u.end());
  const double fv = f(v);
  if (u.size() < 2) {
    const double half = p.log_scale || fv == 0 ? 0.5 : 0.05 * std::abs(fv);
    return {g(fv - half), g(fv + half)};
  }
  std::size_t i = 0;  // the grid value nearest v
  for (std::size_t k = 1; k < u.size(); ++k)
    if (std::abs(u[k] - fv) < std::abs(u[i] - fv)) i = k;
  const double lo = i > 0 ? 0.5 * (u[i - 1] + u[i]) : u[0] - 0.5 * (u[1] - u[0]);
  const double hi = i + 1 < u.size() ? 0.5 * (u[i] + u[i + 1]) : u[i] + 0.5 * (u[i] - u[i - 1]);
  return {g(lo), g(hi)};
}

struct Charts {
  std::string datablocks;
  std::vector<Chart> charts;
  int blocks = 0;
  // a new data block of `lines`; returns its name
  std::string block(const std::vector<std::string>& lines) {
    const std::string name = "$d" + std::to_string(blocks++);
    datablocks += name + " << EOD\n";
    for (const std::string& l : lines) datablocks += l + "\n";
    datablocks += "EOD\n";
    return name;
  }
};

// The commands of one axis ("x" or "y") over [lo, hi]: its range and, on a log scale, tics at
// 1, 2, 5 (or every digit, or only 1 over many decades) times the powers of ten inside it,
// since gnuplot's own log tics sit at whole decades only and a range within a decade gets none.
std::string axis(const char* a, double lo, double hi, bool log_scale) {
  std::string c = std::string("set ") + a + "range [" + num(lo) + ":" + num(hi) + "]\n";
  if (!log_scale || !(lo > 0) || !(lo < hi)) return c;
  c += std::string("set logscale ") + a + "\n";
  const auto tics = [&](std::initializer_list<double> digits) {
    std::vector<double> t;
    for (double decade = std::pow(10.0, std::floor(std::log10(lo))); decade <= hi; decade *= 10)
      for (const double d : digits)
        if (d * decade >= lo && d * decade <= hi) t.push_back(d * decade);
    return t;
  };
  std::vector<double> t = tics({1, 2, 5});
  if (t.size() < 3) t = tics({1, 2, 3, 4, 5, 6, 7, 8, 9});
  if (t.size() > 10) t = tics({1});  // many decades: their powers of ten alone
  if (t.size() < 2) return c;
  c += std::string("set ") + a + "tics (";
  for (std::size_t i = 0; i < t.size(); ++i) c += (i ? ", " : "") + fmt(t[i], "%.6g");
  return c + ")\n";
}

// the axis of parameter j just around its values in sweep.csv (gnuplot's autoscale would round
// out to the next tic, a whole decade on a log axis)
std::string axis(const Sweep& s, std::size_t j, const char* a) {
  double lo = s.range[j].first, hi = s.range[j].second;
  if (!(lo <= hi)) return {};
  const bool log_scale = s.params[j].log_scale && lo > 0;
  if (log_scale) {
    const double pad = lo < hi ? std::pow(hi / lo, 0.03) : 1.1;
    lo /= pad;
    hi *= pad;
  } else {
    const double pad = lo < hi ? 0.03 * (hi - lo) : (lo != 0 ? 0.1 * std::abs(lo) : 1.0);
    lo -= pad;
    hi += pad;
  }
  return axis(a, lo, hi, log_scale);
}

// " the original design left, the balanced one right, each with its own colour scale" when a
// metric has two designs
std::string panels_text(const Metric& m) {
  if (m.series.size() < 2) return {};
  return "; the " + m.series[0].label + " design left, the " + m.series[1].label +
         " one right, each with its own colour scale";
}

// one parameter: each metric (RMS solid, peak dotted) against it, the designs overlaid
void one_parameter(const Sweep& s, Charts& out) {
  for (const Metric& m : s.metrics) {
    std::string plot;
    for (const Series& se : m.series) {
      const std::string lt = se.second ? "2" : "1";  // one colour per design on every chart
      std::vector<std::pair<double, std::string>> pts;
      for (std::size_t r = 0; r < s.csv.rows.size(); ++r) {
        const auto x = s.x(r, 0);
        const auto v = s.value(r, se);
        const auto peak = se.peak.empty() ? v : s.value(r, se, se.peak);
        if (x && v && peak) {
          pts.emplace_back(*x, num(*x) + "," + num(charted(*v, s.floor(m))) + "," +
                                   num(charted(*peak, s.floor(m))));
        }
      }
      if (pts.empty()) continue;
      std::stable_sort(pts.begin(), pts.end(),
                       [](const auto& a, const auto& b) { return a.first < b.first; });
      std::vector<std::string> lines;
      for (auto& p : pts) lines.push_back(std::move(p.second));
      const std::string d = out.block(lines);
      const std::string style = std::string(se.second ? " dt 2" : "") + " lt " + lt;
      plot += std::string(plot.empty() ? "" : ", ") + d +
              " using 1:2 with linespoints lw 2 pt 7 ps 0.6" + style + " title " +
              gp_string(se.peak.empty() ? se.label : se.label + " RMS");
      if (!se.peak.empty()) {
        plot += ", " + d + " using 1:3 with lines lw 1.2 dt 3 lt " + lt + " title " +
                gp_string(se.label + " max");
      }
    }
    if (plot.empty()) continue;
    const bool peaks = !m.series.front().peak.empty();
    const std::string caption =
        peaks ? m.name + " (solid, points) and " + m.id + "_max (dotted) of each point"
              : m.name + " of each point";
    out.charts.push_back(
        {"sweep-" + m.id, m.name + " against " + s.params[0].label,
         caption + " against " + s.params[0].label +
             (m.series.size() > 1
                  ? ", the " + m.series[1].label + " design dashed over the " + m.series[0].label
                  : std::string()) +
             "; points whose status is not ok are left out; values below " +
             fmt(kNoiseFloor, "%g") + " of the largest are round-off, drawn as zero." +
             sample_note(s),
         "set title " + gp_string(m.id + ": " + m.what) + "\nset xlabel " +
             gp_string(axis_label(s.params[0])) + "\nset ylabel " + gp_string(m.what) + "\n" +
             axis(s, 0, "x") + "plot " + plot});
  }
}

// the panels of one chart side by side in one SVG
std::string side_by_side(const std::string& title, const std::vector<std::string>& panels) {
  std::string c = "set multiplot layout 1," + std::to_string(panels.size()) + " title " +
                  gp_string(title) + "\n";
  for (const std::string& p : panels) c += p + "\n";
  return c + "unset multiplot";
}

// the data line of the least value among `v` (value, data line) pairs, or nothing when it is
// round-off (at or below `floor`: then no point is less than another)
// Where a two-parameter chart's red circle goes, "x,y": the point of the least value over every
// row of sweep.csv (the best points table's), which on a large sweep may lie between the points
// drawn; none when the least of those drawn is zero to round-off.
std::optional<std::string> minimum_line(const Sweep& s, const Series& se,
                                        const std::vector<std::pair<double, std::string>>& v,
                                        double floor) {
  std::size_t best = 0;
  for (std::size_t i = 1; i < v.size(); ++i)
    if (v[i].first < v[best].first) best = i;
  if (v[best].first <= floor) return std::nullopt;
  if (const auto it = s.best.find(se.column);
      it != s.best.end() && it->second.row && it->second.value > floor) {
    const std::vector<std::string>& row = *it->second.row;
    const auto x = number(row[1]), y = number(row[2]);
    if (x && y) return num(*x) + "," + num(*y);
  }
  return v[best].second;
}

// what a two-parameter chart's red circle marks (minimum_line()), for its caption
std::string least_circle_note() {
  return "red circle: the least value over every point, as the best points table ranks them "
         "(none where every value is round-off: below " +
         fmt(kNoiseFloor, "%g") + " of the metric's largest, drawn as zero).";
}

// two parameters on a grid: a heat map of each metric per design, one rectangle per point
// spanning halfway to its neighbours
void heat_maps(const Sweep& s, Charts& out) {
  const Parameter& px = s.params[0];
  const Parameter& py = s.params[1];
  // the plotted range: every grid value's cell
  double x_lo = std::numeric_limits<double>::infinity(), x_hi = -x_lo;
  double y_lo = x_lo, y_hi = -x_lo;
  for (const double v : px.values) {
    const auto [lo, hi] = cell_edges(px, v);
    x_lo = std::min(x_lo, lo);
    x_hi = std::max(x_hi, hi);
  }
  for (const double v : py.values) {
    const auto [lo, hi] = cell_edges(py, v);
    y_lo = std::min(y_lo, lo);
    y_hi = std::max(y_hi, hi);
  }
  const std::string ranges =
      axis("x", x_lo, x_hi, px.log_scale) + axis("y", y_lo, y_hi, py.log_scale);
  for (const Metric& m : s.metrics) {
    std::vector<std::string> panels;
    for (const Series& se : m.series) {
      std::vector<std::string> cells, failed;
      std::vector<std::pair<double, std::string>> values;
      for (std::size_t r = 0; r < s.csv.rows.size(); ++r) {
        const auto x = s.x(r, 0);
        const auto y = s.x(r, 1);
        if (!x || !y) continue;
        const auto [xa, xb] = cell_edges(px, *x);
        const auto [ya, yb] = cell_edges(py, *y);
        const std::string cell =
            num(*x) + "," + num(*y) + "," + num(xa) + "," + num(xb) + "," + num(ya) + "," + num(yb);
        if (const auto v = s.value(r, se)) {
          cells.push_back(cell + "," + num(charted(*v, s.floor(m))));
          values.emplace_back(*v, num(*x) + "," + num(*y));
        } else {
          failed.push_back(cell);
        }
      }
      if (cells.empty() && failed.empty()) continue;
      std::string title_note, cb = "\nset autoscale cb";
      std::string p = "\nset xlabel " +
                      gp_string(axis_label(px)) + "\nset ylabel " + gp_string(axis_label(py)) +
                      "\n" + ranges + "unset key\nunset grid\nplot ";
      std::string items;
      if (!cells.empty()) {
        items += out.block(cells) +
                 " using 1:2:3:4:5:6:7 with boxxyerror fs solid 1.0 noborder lc palette notitle";
      }
      if (!failed.empty()) {
        items += std::string(items.empty() ? "" : ", ") + out.block(failed) +
                 " using 1:2:3:4:5:6 with boxxyerror fs solid 1.0 noborder lc rgb '#c8c8c8' "
                 "notitle";
      }
      const auto least = values.empty() ? std::nullopt : minimum_line(s, se, values, s.floor(m));
      if (least) {
        items += ", " + out.block({*least}) +
                 " using 1:2 with points pt 6 ps 2 lw 2 lc rgb '#e00000' notitle";
      } else if (!values.empty()) {
        cb = "\nset cbrange [0:1]";  // all zero to round-off: one colour, no false contrast
        title_note = " (every value zero to round-off)";
      }
      panels.push_back("set title " + gp_string(se.label + title_note) + cb + p + items);
    }
    if (panels.empty()) continue;
    out.charts.push_back({"sweep-" + m.id, m.name + " over " + px.label + " and " + py.label,
                          m.name + " (" + m.what +
                              ") at each grid point, one rectangle per point reaching "
                              "halfway to its neighbours" +
                              panels_text(m) + ". Grey: failed points; blank: points not run; " +
                              least_circle_note() + sample_note(s),
                          kPalette + side_by_side(m.name + ": " + m.what, panels), true});
  }
}

// two parameters drawn at random: each point coloured by the metric
void scatter_maps(const Sweep& s, Charts& out) {
  const Parameter& px = s.params[0];
  const Parameter& py = s.params[1];
  for (const Metric& m : s.metrics) {
    std::vector<std::string> panels;
    for (const Series& se : m.series) {
      std::vector<std::string> pts, failed;
      std::vector<std::pair<double, std::string>> values;
      for (std::size_t r = 0; r < s.csv.rows.size(); ++r) {
        const auto x = s.x(r, 0);
        const auto y = s.x(r, 1);
        if (!x || !y) continue;
        if (const auto v = s.value(r, se)) {
          pts.push_back(num(*x) + "," + num(*y) + "," + num(charted(*v, s.floor(m))));
          values.emplace_back(*v, num(*x) + "," + num(*y));
        } else {
          failed.push_back(num(*x) + "," + num(*y));
        }
      }
      if (pts.empty() && failed.empty()) continue;
      std::string title_note, cb = "\nset autoscale cb";
      std::string p = "\nset xlabel " +
                      gp_string(axis_label(px)) + "\nset ylabel " + gp_string(axis_label(py)) +
                      "\n" + axis(s, 0, "x") + axis(s, 1, "y") + "unset key\nplot ";
      std::string items;
      if (!pts.empty()) {
        items += out.block(pts) + " using 1:2:3 with points pt 7 ps 1.1 lc palette notitle";
      }
      if (!failed.empty()) {
        items += std::string(items.empty() ? "" : ", ") + out.block(failed) +
                 " using 1:2 with points pt 2 ps 1.1 lw 2 lc rgb '#808080' notitle";
      }
      const auto least = values.empty() ? std::nullopt : minimum_line(s, se, values, s.floor(m));
      if (least) {
        items += ", " + out.block({*least}) +
                 " using 1:2 with points pt 6 ps 2.2 lw 2 lc rgb '#e00000' notitle";
      } else if (!values.empty()) {
        cb = "\nset cbrange [0:1]";
        title_note = " (every value zero to round-off)";
      }
      panels.push_back("set title " + gp_string(se.label + title_note) + cb + p + items);
    }
    if (panels.empty()) continue;
    out.charts.push_back({"sweep-" + m.id, m.name + " over " + px.label + " and " + py.label,
                          m.name + " (" + m.what + ") at each point of the " +
                              (s.design == "lhs" ? "Latin-hypercube" : "random") +
                              " design, by colour" + panels_text(m) +
                              ". Grey crosses: failed points; " + least_circle_note() +
                              sample_note(s),
                          kPalette + side_by_side(m.name + ": " + m.what, panels), true});
  }
}

// more than two parameters: each metric against each parameter, a small chart each
void metric_by_parameter(const Sweep& s, Charts& out) {
  const std::size_t n = s.params.size();
  const std::size_t cols = std::min<std::size_t>(n, 3);
  const std::size_t rows = (n + cols - 1) / cols;
  for (const Metric& m : s.metrics) {
    std::vector<std::string> blocks, labels;
    std::vector<bool> second;
    for (const Series& se : m.series) {
      std::vector<std::string> lines;
      for (std::size_t r = 0; r < s.csv.rows.size(); ++r) {
        const auto v = s.value(r, se);
        if (!v) continue;
        std::string line;
        bool ok = true;
        for (std::size_t j = 0; j < n && ok; ++j) {
          const auto x = s.x(r, j);
          ok = x.has_value();
          if (ok) line += num(*x) + ",";
        }
        if (ok) lines.push_back(line + num(charted(*v, s.floor(m))));
      }
      if (lines.empty()) continue;
      blocks.push_back(out.block(lines));
      labels.push_back(se.label);
      second.push_back(se.second);
    }
    if (blocks.empty()) continue;
    std::string c = "set multiplot layout " + std::to_string(rows) + "," + std::to_string(cols) +
                    " title " + gp_string(m.name + ": " + m.what) + "\n";
    for (std::size_t j = 0; j < n; ++j) {
      c += "unset logscale\nset xtics autofreq\n" + axis(s, j, "x") + "set xlabel " +
           gp_string(axis_label(s.params[j])) + "\nset ylabel " +
           gp_string(j % cols == 0 ? m.name : std::string()) + "\n" +
           (j == 0 && blocks.size() > 1 ? "set key inside top left box opaque samplen 1\n"
                                        : "unset key\n") +
           "plot ";
      for (std::size_t b = 0; b < blocks.size(); ++b) {
        c += std::string(b ? ", " : "") + blocks[b] + " using " + std::to_string(j + 1) + ":" +
             std::to_string(n + 1) + " with points pt " + (second[b] ? "6 lt 2" : "7 lt 1") +
             " ps 0.6 title " + gp_string(labels[b]);
      }
      c += "\n";
    }
    c += "unset multiplot";
    out.charts.push_back(
        {"sweep-" + m.id, m.name + " against each parameter",
         m.name + " (" + m.what + ") of each point against each parameter in turn" +
             (m.series.size() > 1 ? ", the " + m.series[0].label + " design filled, the " +
                                        m.series[1].label + " one open"
                                  : std::string()) +
             "; points whose status is not ok are left out." + sample_note(s),
         c, rows > 1});
  }
}

Charts sweep_charts(const Sweep& s) {
  Charts out;
  if (s.params.size() == 1) {
    one_parameter(s, out);
  } else if (s.params.size() == 2 && s.design == "grid" && !s.params[0].values.empty() &&
             !s.params[1].values.empty()) {
    heat_maps(s, out);
  } else if (s.params.size() == 2) {
    scatter_maps(s, out);
  } else {
    metric_by_parameter(s, out);
  }
  return out;
}

}  // namespace

std::string sweep_report_html(const Study& study, const fs::path& dir, const std::string& gnuplot) {
  const Sweep s = load_sweep(study, dir);
  const std::string name = text(s.info, "study").empty() ? study.name : text(s.info, "study");
  const std::string source = text(s.info, "source");

  std::string h =
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
      "<title>" +
      esc(name) + " &mdash; balance-design sweep report</title>\n<style>" + kStyle +
      "</style>\n</head>\n<body>\n";
  h += "<h1>" + esc(name) +
       " (sweep)</h1>\n<p>balance-design report of the sweep of the study <code>" +
       esc(source.empty() ? std::string("(built in code)") : source) +
       "</code>: the study run at every point of the design below. Every number below is read "
       "from <a href=\"sweep.csv\">sweep.csv</a> and <a href=\"sweep.json\">sweep.json</a> in "
       "this folder (the linkage's inputs from the study file); hover over a number to see it "
       "as written there.</p>\n";
  h += status_section(s, dir);
  h += design_section(s);
  h += best_section(s);
  h += failed_section(s);

  h += "<h2>Charts</h2>\n";
  const Charts charts = sweep_charts(s);
  if (gnuplot.empty()) {
    h += "<p class=\"notice\">The charts need gnuplot, which was not found on this machine "
         "(install it, e.g. <code>apt-get install gnuplot-nox</code>, then rebuild this page with "
         "<code>balance-design report DIR</code>). The tables and sweep.csv hold every "
         "number.</p>\n";
  } else if (charts.charts.empty()) {
    h += "<p>No point has finished with status ok yet: nothing to chart.</p>\n";
  } else {
    const std::vector<std::string> svgs = draw(gnuplot, charts.datablocks, charts.charts);
    for (std::size_t i = 0; i < charts.charts.size(); ++i) {
      const Chart& c = charts.charts[i];
      h += "<h3>" + esc(c.heading) + "</h3>\n<figure class=\"chart\" id=\"chart-" + c.id + "\">\n" +
           svgs[i] + "\n<figcaption>" + esc(c.caption) + "</figcaption>\n</figure>\n";
    }
  }
  h += points_section(s);
  h += study_section(study, s);

  return h + data_files_html(dir, {"sweep.csv", "sweep.json"});
}

fs::path write_sweep_report(const Study& study, const fs::path& dir) {
  const std::string html = sweep_report_html(study, dir, find_gnuplot());
  const fs::path target = dir / "report.html";
  write_text_file(html, target);  // whole or not at all (runner.hpp)
  return target;
}

}  // namespace bd::studies
