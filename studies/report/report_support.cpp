#include "studies/report/report_support.hpp"

#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <span>
#include <sstream>
#include <stdexcept>

#include "core/number_text.hpp"
#include "studies/run/files.hpp"

namespace bd::studies::report_support {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------------------------
// reading the run's files back

Json parse_json(const std::string& text, const std::string& name) {
  try {
    return Json::parse(text);
  } catch (const Json::exception& e) {
    throw std::runtime_error(name + ": not valid JSON (" + e.what() + ")");
  }
}

const Json* member(const Json& j, const std::string& key) {
  if (!j.is_object()) return nullptr;
  const auto it = j.find(key);
  return it == j.end() ? nullptr : &*it;
}

std::string text(const Json& v) {
  if (v.is_string()) return v.get<std::string>();
  if (v.is_null()) return "";
  return v.dump();
}

std::string text(const Json& j, const std::string& key) {
  const Json* v = member(j, key);
  return v ? text(*v) : std::string();
}

Csv read_csv(const fs::path& p) {
  std::istringstream in(read_file(p));
  Csv csv;
  std::string line;
  if (std::getline(in, line)) csv.header = csv_fields(line);
  while (std::getline(in, line)) {
    if (!line.empty()) csv.rows.push_back(csv_fields(line));
  }
  return csv;
}

Csv read_csv_decimated(const fs::path& p, std::size_t max_rows, std::size_t* total) {
  // first the rows are counted, then every step-th is kept, and the last
  std::size_t rows = 0;
  {
    std::ifstream in(p, std::ios::binary);
    if (!in) throw std::runtime_error("cannot read " + p.string());
    std::string line;
    std::getline(in, line);  // the header
    while (std::getline(in, line))
      if (!line.empty()) ++rows;
  }
  if (total) *total = rows;
  // rows 0, step, 2 step, ... and the last: at most max_rows
  const std::size_t step =
      max_rows > 2 && rows > max_rows ? (rows - 1 + max_rows - 3) / (max_rows - 2) : 1;
  std::ifstream in(p, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + p.string());
  Csv csv;
  std::string line;
  if (std::getline(in, line)) csv.header = csv_fields(line);
  std::size_t i = 0;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    if (i % step == 0 || i + 1 == rows) csv.rows.push_back(csv_fields(line));
    ++i;
  }
  return csv;
}

std::string datablock(const std::string& name, const Csv& csv) {
  std::string b = "$" + name + " << EOD\n";
  for (std::size_t k = 0; k < csv.header.size(); ++k) b += (k ? "," : "") + csv.header[k];
  b += "\n";
  for (const auto& row : csv.rows) {
    for (std::size_t k = 0; k < row.size(); ++k) b += (k ? "," : "") + row[k];
    b += "\n";
  }
  return b + "EOD\n";
}

// the numbers of a timeseries.csv row (columns as kTimeseriesHeader)
std::vector<double> numbers(const std::vector<std::string>& row) {
  std::vector<double> x;
  x.reserve(row.size());
  for (const std::string& f : row)
    x.push_back(f.empty() ? std::nan("") : std::strtod(f.c_str(), nullptr));
  return x;
}

// ---------------------------------------------------------------------------------------------
// HTML pieces

std::string esc(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string fmt(double v, const char* f) {
  char buf[48];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

std::string xy(const Vec2& v) { return fmt(v.x(), "%.10g") + "," + fmt(v.y(), "%.10g"); }

std::string fmt_scaled(double v, double scale) {
  return text::is_round_off(v, scale) ? std::string("0") : fmt(v);
}

std::string vec_text(const Vec2& v, double scale) {
  const double larger = std::max({std::abs(v.x()), std::abs(v.y()), scale});
  auto part = [&](double x) {
    return text::is_round_off(x, larger) && x != 0 ? std::string("0") : fmt(x);
  };
  return "(" + part(v.x()) + ", " + part(v.y()) + ")";
}

namespace {

bool starts(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

}  // namespace

std::string unit_of(const std::string& name) {
  static const std::pair<const char*, const char*> exact[] = {{"mass", "kg"},
                                                              {"added_mass", "kg"},
                                                              {"distance", "m"},
                                                              {"radius", "m"},
                                                              {"thickness", "m"},
                                                              {"position", "m"},
                                                              {"at", "m"},
                                                              {"inertia", "kg m²"},
                                                              {"added_inertia", "kg m²"},
                                                              {"theta1", "rad"},
                                                              {"omega1", "rad/s"},
                                                              {"duration", "s"},
                                                              {"density", "kg/m³"},
                                                              {"eccentricity", "m"},
                                                              {"speeds", "rad/s or m/s"},
                                                              {"rates", "rad/s or m/s"},
                                                              {"start", "rad or m"},
                                                              {"mass_max", "kg"},
                                                              {"distance_max", "m"},
                                                              {"J", "kg m²"},
                                                              {"Fsh_rms_before", "N"},
                                                              {"Fsh_rms_after", "N"},
                                                              {"forward_before", "kg m"},
                                                              {"backward_before", "kg m"},
                                                              {"forward_after", "kg m"},
                                                              {"backward_after", "kg m"},
                                                              {"t", "s"},
                                                              {"tau", "N m"}};
  for (const auto& [n, u] : exact)
    if (name == n) return u;
  if (starts(name, "Fsh")) return "N";
  if (starts(name, "Msh")) return "N m";
  if (starts(name, "tau")) return "N m";
  // reactions and joint forces: R<joint>..., F<joint>...
  if (name.size() > 1 && (name[0] == 'R' || name[0] == 'F') &&
      (std::isupper(static_cast<unsigned char>(name[1])) ||
       std::isdigit(static_cast<unsigned char>(name[1]))))
    return "N";
  return "";
}

std::string unit_in(const std::string& name) {
  if (name.size() > 2 && name.back() == ']') {
    const std::size_t open = name.rfind('[');
    if (open != std::string::npos) return name.substr(open + 1, name.size() - open - 2);
  }
  return unit_of(name);
}

std::string metric_unit(const Json& summary, const std::string& name) {
  if (const Json* units = member(summary, "metric_units")) {
    if (const Json* u = member(*units, name); u && u->is_string()) return u->get<std::string>();
  }
  return unit_of(name);
}

Scales run_scales(const Json& summary, double size) {
  Scales s;
  s.length = size;
  for (const char* key : {"metrics", "balanced_metrics", "optimized_metrics"}) {
    const Json* metrics = member(summary, key);
    if (!metrics || !metrics->is_object()) continue;
    for (const auto& [name, v] : metrics->items()) {
      if (v.is_number()) s.add(metric_unit(summary, name), v.get<double>());
    }
  }
  // an engine's balance shafts: the orders' rotating parts before balancing [kg m]
  const Json* balance = member(summary, "balance");
  const Json* shafts = balance ? member(*balance, "shafts") : nullptr;
  const Json* orders = shafts ? member(*shafts, "orders") : nullptr;
  if (orders && orders->is_array()) {
    for (const Json& o : *orders) {
      for (const char* key : {"forward_before", "backward_before"}) {
        const Json* v = member(o, key);
        if (v && v->is_number()) s.add("kg m", v->get<double>());
      }
    }
  }
  return s;
}

std::string with_unit(const std::string& name) {
  const std::string u = unit_of(name);
  return u.empty() ? name : name + " [" + u + "]";
}

// a number as written in a data file: shown to 6 significant digits, the exact text on hover
std::string num_cell(const std::string& written, double scale) {
  if (written.empty()) return "<td class=\"n\">&ndash;</td>";
  char* end = nullptr;
  const double v = std::strtod(written.c_str(), &end);
  if (end == written.c_str() || *end != '\0') return "<td>" + esc(written) + "</td>";
  return "<td class=\"n\" title=\"" + esc(written) + "\">" + esc(fmt_scaled(v, scale)) + "</td>";
}

// an object as a two-column table, an array of objects as a table with a column per key
std::string json_table(const Json& v, const Scales& scales) {
  std::string h = "<table>";
  // a point mass has no radius or thickness: 0 there means "not a disc"
  auto left_out = [](const std::string& k, const Json& x) {
    return (k == "radius" || k == "thickness") && x.is_number() && x.get<double>() == 0;
  };
  if (v.is_object()) {
    for (const auto& [k, x] : v.items()) {
      if (left_out(k, x)) continue;
      // the momentum left relative to the original's: round-off of 1 shows as 0
      const std::string cell = k == "momentum_left" && x.is_number()
                                   ? num_cell(text(x), 1.0)
                                   : json_cell(x, scales, scales.of(unit_in(k)));
      h += "<tr><th>" + esc(with_unit(k)) + "</th>" + cell + "</tr>";
    }
  } else {
    std::vector<std::string> keys;
    for (const Json& item : v) {
      for (const auto& [k, x] : item.items()) {
        bool seen = false;
        for (const std::string& s : keys) seen = seen || s == k;
        if (!seen && !left_out(k, x)) keys.push_back(k);
      }
    }
    // a column every row leaves out goes; one some rows have keeps them all
    std::vector<std::string> shown;
    for (const std::string& k : keys) {
      bool any = false;
      for (const Json& item : v) {
        const Json* x = member(item, k);
        any = any || (x && !left_out(k, *x));
      }
      if (any) shown.push_back(k);
    }
    keys = shown;
    h += "<tr>";
    for (const std::string& k : keys) h += "<th>" + esc(with_unit(k)) + "</th>";
    h += "</tr>";
    for (const Json& item : v) {
      h += "<tr>";
      // a residual beside its scale (a balance condition): round-off of the scale shows as 0
      const Json* scale = member(item, "scale");
      // a {name, value} entry: the value's unit is the name's ("... y from O2 [m]")
      const Json* name = member(item, "name");
      for (const std::string& k : keys) {
        const Json* x = member(item, k);
        if (x && k == "residual" && x->is_number() && scale && scale->is_number()) {
          h += num_cell(text(*x), std::abs(scale->get<double>()));
        } else {
          const bool named = k == "value" && name && name->is_string();
          const std::string unit = unit_in(named ? name->get<std::string>() : k);
          h += x ? json_cell(*x, scales, scales.of(unit)) : "<td></td>";
        }
      }
      h += "</tr>";
    }
  }
  return h + "</table>";
}

std::string json_cell(const Json& v, const Scales& scales, double quantity_scale) {
  if (v.is_null()) return "<td>&ndash;</td>";
  if (v.is_number()) return num_cell(text(v), quantity_scale);
  if (v.is_boolean() || v.is_string()) return "<td>" + esc(text(v)) + "</td>";
  if (v.is_object()) return "<td>" + json_table(v, scales) + "</td>";
  if (v.empty()) return "<td>none</td>";
  bool objects = true;
  for (const Json& x : v) objects = objects && x.is_object();
  if (objects) return "<td>" + json_table(v, scales) + "</td>";
  // a list of numbers: round-off of its largest (or of its quantity's scale) shows as 0
  double scale = quantity_scale, least = std::numeric_limits<double>::infinity(), largest = -least;
  std::size_t numbers = 0;
  for (const Json& x : v) {
    if (!x.is_number()) continue;
    ++numbers;
    scale = std::max(scale, std::abs(x.get<double>()));
    least = std::min(least, x.get<double>());
    largest = std::max(largest, x.get<double>());
  }
  // a long one (an optimiser's added instants, hundreds): its count and range, the values in
  // summary.json
  constexpr std::size_t kListedValues = 12;
  if (numbers == v.size() && numbers > kListedValues) {
    return "<td>" + std::to_string(numbers) + " values from " + esc(fmt_scaled(least, scale)) +
           " to " + esc(fmt_scaled(largest, scale)) + " (each in summary.json)</td>";
  }
  std::string s;
  for (const Json& x : v) {
    if (x.is_structured()) continue;
    s +=
        (s.empty() ? "" : ", ") + esc(x.is_number() ? fmt_scaled(x.get<double>(), scale) : text(x));
  }
  return "<td>" + s + "</td>";
}

std::string data_files_html(const fs::path& dir, const std::vector<std::string>& names) {
  std::string h = "<h2>Data files</h2>\n<ul>\n";
  for (const std::string& f : names) {
    std::error_code ec;
    const auto size = fs::file_size(dir / f, ec);
    if (ec) continue;
    h += "<li><a href=\"" + esc(f) + "\">" + esc(f) + "</a> (" + std::to_string(size) +
         " bytes)</li>\n";
  }
  return h + "</ul>\n</body>\n</html>\n";
}

std::string csv_table(const Csv& csv, const Scales& scales) {
  std::string h = "<table><tr>";
  std::vector<double> scale;
  for (const std::string& k : csv.header) {
    // each column with its unit, as the data file names it or as the page knows it
    const std::string u = unit_in(k);
    h += "<th>" + esc(k.ends_with("]") || u.empty() ? k : k + " [" + u + "]") + "</th>";
    scale.push_back(scales.of(u));
  }
  h += "</tr>";
  for (const auto& row : csv.rows) {
    h += "<tr>";
    for (std::size_t c = 0; c < row.size(); ++c)
      h += num_cell(row[c], c < scale.size() ? scale[c] : 0.0);
    h += "</tr>";
  }
  return h + "</table>";
}

const char* const kStyle = R"(
body{font-family:system-ui,-apple-system,"Segoe UI",Roboto,sans-serif;margin:0 auto;max-width:1100px;
padding:1em 1.5em;color:#1a1a1a;line-height:1.45}
h1{font-size:1.6em;margin-bottom:.2em}h2{border-bottom:1px solid #ccc;padding-bottom:.2em;margin-top:1.6em}
table{border-collapse:collapse;margin:.5em 0;font-size:.92em}
th,td{border:1px solid #d0d0d0;padding:.2em .55em;text-align:left;vertical-align:top}
th{background:#f3f3f3;font-weight:600}td.n{text-align:right;font-variant-numeric:tabular-nums}
td table{margin:0;font-size:1em}body>table{display:block;overflow-x:auto;max-width:100%}
figure.chart{margin:1em 0}figure.chart svg{width:100%;height:auto;display:block;border:1px solid #e4e4e4}
figcaption{font-size:.9em;color:#444;margin-top:.3em}
.notice{background:#fff6d6;border:1px solid #e0c060;padding:.6em .9em}
.bad{color:#a00000;font-weight:600}.good{color:#006000;font-weight:600}
code{background:#f3f3f3;padding:0 .2em}
)";

// ---------------------------------------------------------------------------------------------
// gnuplot

// `text` as a gnuplot single-quoted string
std::string gp_string(const std::string& text) {
  std::string q = "'";
  for (char c : text) q += c == '\'' ? std::string("''") : std::string(1, c);
  return q + "'";
}

namespace {

std::string sh_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

}  // namespace

bool executable(const fs::path& p) {
  std::error_code ec;
  return fs::is_regular_file(p, ec) && ::access(p.c_str(), X_OK) == 0;
}

namespace {

// a temporary directory, removed with everything in it; named after this process, so that the
// next report removes it if a kill left it behind
class TempDir {
 public:
  TempDir() {
    const fs::path tmp = fs::temp_directory_path();
    remove_stale_scratch(tmp, "bd-report-");
    std::string pattern =
        (tmp / ("bd-report-" + std::to_string(::getpid()) + "-XXXXXX")).string();
    if (::mkdtemp(pattern.data()) == nullptr) {
      throw std::runtime_error("cannot create a temporary directory: " +
                               std::string(std::strerror(errno)));
    }
    path_ = pattern;
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

}  // namespace

namespace {

// the gnuplot SVG with its XML prolog dropped and its ids made unique on the page
std::string inline_svg(std::string svg, const std::string& prefix) {
  const std::size_t start = svg.find("<svg");
  if (start == std::string::npos) throw std::runtime_error("gnuplot wrote no SVG for " + prefix);
  svg.erase(0, start);
  const std::pair<std::string, std::string> swaps[] = {
      {"id='gp", "id='" + prefix + "-gp"},
      {"#gp", "#" + prefix + "-gp"},
      {"id=\"gnuplot_", "id=\"" + prefix + "-gnuplot_"},
      {"id='gnuplot_", "id='" + prefix + "-gnuplot_"},
      {"#gnuplot_", "#" + prefix + "-gnuplot_"}};
  for (const auto& [from, to] : swaps) {
    std::size_t at = 0;
    while ((at = svg.find(from, at)) != std::string::npos) {
      svg.replace(at, from.size(), to);
      at += to.size();
    }
  }
  svg.insert(4, " role=\"img\" aria-label=\"" + esc(prefix) + "\"");
  return svg;
}

}  // namespace

namespace {

// The gnuplot script of `charts` after the data blocks, each writing <id>.svg into `dir`.
std::string chart_script(const std::string& datablocks, std::span<const Chart> charts,
                         const fs::path& dir) {
  std::string script =
      "set datafile separator ','\nset grid\nset key outside right top\n"
      "set encoding utf8\n";
  script += datablocks;
  for (const Chart& c : charts) {
    script += "reset\nset datafile separator ','\nset grid\nset key outside right top\n";
    script += std::string("set terminal svg size 900,") + (c.square ? "600" : "420") +
              " dynamic noenhanced font 'sans,12' background rgb 'white'\n";
    script += "set output " + gp_string((dir / (c.id + ".svg")).string()) + "\n";
    script += c.commands + "\nunset output\n";
  }
  return script;
}

// Runs gnuplot on `script` (written into dir as `name`); empty when it succeeded, else what went
// wrong in one line: the exit status and gnuplot's first error line.
std::string run_gnuplot(const std::string& gnuplot, const std::string& script,
                        const fs::path& dir, const std::string& name) {
  const fs::path script_file = dir / (name + ".gp");
  {
    std::ofstream out(script_file, std::ios::binary);
    out << script;
    if (!out) throw std::runtime_error("cannot write " + script_file.string());
  }
  const fs::path err_file = dir / (name + "-stderr.txt");
  const std::string cmd = sh_quote(gnuplot) + " " + sh_quote(script_file.string()) +
                          " </dev/null >/dev/null 2>" + sh_quote(err_file.string());
  const int status = std::system(cmd.c_str());
  if (status == 0) return "";
  std::string err;
  try {
    err = read_file(err_file);
  } catch (const std::exception&) {
  }
  // the line that says what went wrong
  std::string first;
  std::istringstream lines(err);
  for (std::string line; std::getline(lines, line);) {
    if (line.find_first_not_of(" \t^") == std::string::npos) continue;
    first = line;
    if (line.find("line ") != std::string::npos) break;
  }
  return "gnuplot failed (" + gnuplot + ", status " + std::to_string(status) + ")" +
         (first.empty() ? std::string() : ": " + first);
}

}  // namespace

// Runs gnuplot once for all charts; returns each chart's inline SVG, in order. Where that run
// fails, each chart is drawn by a run of its own, so that data one chart cannot draw (every value
// of a curve undefined, say) costs that chart only: it is replaced by a notice that says why.
std::vector<std::string> draw(const std::string& gnuplot, const std::string& datablocks,
                              const std::vector<Chart>& charts) {
  TempDir tmp;
  const std::string failed = run_gnuplot(gnuplot, chart_script(datablocks, charts, tmp.path()),
                                         tmp.path(), "report");
  std::vector<std::string> svgs;
  if (failed.empty()) {
    for (const Chart& c : charts) {
      svgs.push_back(inline_svg(read_file(tmp.path() / (c.id + ".svg")), c.id));
    }
    return svgs;
  }
  std::size_t drawn = 0;
  for (const Chart& c : charts) {
    // the failed run may have left this chart's picture, whole or cut short: never taken
    const fs::path svg = tmp.path() / (c.id + ".svg");
    std::error_code ec;
    fs::remove(svg, ec);
    const std::string why = run_gnuplot(
        gnuplot, chart_script(datablocks, std::span<const Chart>(&c, 1), tmp.path()), tmp.path(),
        c.id);
    if (why.empty() && fs::exists(svg)) {
      svgs.push_back(inline_svg(read_file(svg), c.id));
      ++drawn;
    } else {
      svgs.push_back("<p class=\"notice\">This chart could not be drawn from the run's data (" +
                     esc(why.empty() ? "gnuplot wrote no picture" : why) +
                     "); its numbers are in the data files.</p>");
    }
  }
  // no chart drawn at all: gnuplot itself does not work here
  if (drawn == 0 && !charts.empty()) throw std::runtime_error(failed);
  return svgs;
}

}  // namespace bd::studies::report_support
