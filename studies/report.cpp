#include "studies/report.hpp"

#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include "core/kinematics.hpp"
#include "core/model.hpp"
#include "core/principal_vectors.hpp"

namespace bd::studies {

namespace fs = std::filesystem;

namespace {

// ---------------------------------------------------------------------------------------------
// reading the run's files back

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + p.string());
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// a JSON value as summary.json writes it; numbers keep their text exactly as written
struct Json {
  enum class Kind { kNull, kBool, kNumber, kString, kArray, kObject } kind = Kind::kNull;
  std::string text;                                  // number as written, string, "true"/"false"
  std::vector<Json> items;                           // array
  std::vector<std::pair<std::string, Json>> fields;  // object, in file order

  const Json* get(const std::string& key) const {
    for (const auto& [k, v] : fields)
      if (k == key) return &v;
    return nullptr;
  }
  std::string str(const std::string& key) const {
    const Json* v = get(key);
    return v ? v->text : std::string();
  }
};

class JsonParser {
 public:
  JsonParser(const std::string& text, std::string name) : s_(text), name_(std::move(name)) {}
  Json parse() {
    Json v = value();
    space();
    if (i_ != s_.size()) fail("trailing characters");
    return v;
  }

 private:
  [[noreturn]] void fail(const char* what) const {
    throw std::runtime_error(name_ + ": not valid JSON (" + what + " at byte " +
                             std::to_string(i_) + ")");
  }
  void space() {
    while (i_ < s_.size() && std::strchr(" \t\r\n", s_[i_]) != nullptr) ++i_;
  }
  bool eat(char c) {
    space();
    if (i_ < s_.size() && s_[i_] == c) {
      ++i_;
      return true;
    }
    return false;
  }
  std::string string_body() {
    if (!eat('"')) fail("expected a string");
    std::string out;
    while (i_ < s_.size() && s_[i_] != '"') {
      char c = s_[i_++];
      if (c == '\\') {
        if (i_ >= s_.size()) fail("bad escape");
        const char e = s_[i_++];
        switch (e) {
          case 'n':
            out += '\n';
            break;
          case 't':
            out += '\t';
            break;
          case 'r':
            out += '\r';
            break;
          case 'b':
            out += '\b';
            break;
          case 'f':
            out += '\f';
            break;
          case 'u': {
            if (i_ + 4 > s_.size()) fail("bad escape");
            const unsigned code = static_cast<unsigned>(std::stoul(s_.substr(i_, 4), nullptr, 16));
            i_ += 4;
            if (code < 0x80) {
              out += static_cast<char>(code);
            } else {
              out += '?';  // summary.json escapes control characters only
            }
            break;
          }
          default:
            out += e;
        }
      } else {
        out += c;
      }
    }
    if (i_ >= s_.size()) fail("unterminated string");
    ++i_;
    return out;
  }
  Json value() {
    space();
    if (i_ >= s_.size()) fail("unexpected end");
    Json v;
    const char c = s_[i_];
    if (c == '{') {
      ++i_;
      v.kind = Json::Kind::kObject;
      if (eat('}')) return v;
      do {
        std::string key = string_body();
        if (!eat(':')) fail("expected ':'");
        v.fields.emplace_back(std::move(key), value());
      } while (eat(','));
      if (!eat('}')) fail("expected '}'");
    } else if (c == '[') {
      ++i_;
      v.kind = Json::Kind::kArray;
      if (eat(']')) return v;
      do v.items.push_back(value());
      while (eat(','));
      if (!eat(']')) fail("expected ']'");
    } else if (c == '"') {
      v.kind = Json::Kind::kString;
      v.text = string_body();
    } else if (s_.compare(i_, 4, "null") == 0) {
      i_ += 4;
    } else if (s_.compare(i_, 4, "true") == 0 || s_.compare(i_, 5, "false") == 0) {
      v.kind = Json::Kind::kBool;
      v.text = s_[i_] == 't' ? "true" : "false";
      i_ += v.text.size();
    } else {
      const std::size_t start = i_;
      while (i_ < s_.size() && std::strchr("+-0123456789.eE", s_[i_]) != nullptr) ++i_;
      if (i_ == start) fail("unexpected character");
      v.kind = Json::Kind::kNumber;
      v.text = s_.substr(start, i_ - start);
    }
    return v;
  }

  const std::string& s_;
  std::string name_;
  std::size_t i_ = 0;
};

// a CSV file: its header's fields and its rows' fields as written (quoted fields unquoted)
struct Csv {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
};

std::vector<std::string> csv_fields(const std::string& line) {
  std::vector<std::string> out(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        out.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        out.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      out.emplace_back();
    } else if (c != '\r') {
      out.back() += c;
    }
  }
  return out;
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

std::string fmt(double v, const char* f = "%.6g") {
  char buf[48];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

// a number as written in a data file: shown to 6 significant digits, the exact text on hover
std::string num_cell(const std::string& written) {
  if (written.empty()) return "<td class=\"n\">&ndash;</td>";
  char* end = nullptr;
  const double v = std::strtod(written.c_str(), &end);
  if (end == written.c_str() || *end != '\0') return "<td>" + esc(written) + "</td>";
  return "<td class=\"n\" title=\"" + esc(written) + "\">" + esc(fmt(v)) + "</td>";
}

std::string json_cell(const Json& v);

// an object as a two-column table, an array of objects as a table with a column per key
std::string json_table(const Json& v) {
  std::string h = "<table>";
  if (v.kind == Json::Kind::kObject) {
    for (const auto& [k, x] : v.fields) {
      h += "<tr><th>" + esc(k) + "</th>" + json_cell(x) + "</tr>";
    }
  } else {
    std::vector<std::string> keys;
    for (const Json& item : v.items) {
      for (const auto& [k, x] : item.fields) {
        bool seen = false;
        for (const std::string& s : keys) seen = seen || s == k;
        if (!seen) keys.push_back(k);
      }
    }
    h += "<tr>";
    for (const std::string& k : keys) h += "<th>" + esc(k) + "</th>";
    h += "</tr>";
    for (const Json& item : v.items) {
      h += "<tr>";
      for (const std::string& k : keys) {
        const Json* x = item.get(k);
        h += x ? json_cell(*x) : "<td></td>";
      }
      h += "</tr>";
    }
  }
  return h + "</table>";
}

std::string json_cell(const Json& v) {
  switch (v.kind) {
    case Json::Kind::kNull:
      return "<td>&ndash;</td>";
    case Json::Kind::kNumber:
      return num_cell(v.text);
    case Json::Kind::kBool:
    case Json::Kind::kString:
      return "<td>" + esc(v.text) + "</td>";
    case Json::Kind::kObject:
      return "<td>" + json_table(v) + "</td>";
    case Json::Kind::kArray: {
      if (v.items.empty()) return "<td>none</td>";
      bool objects = true;
      for (const Json& x : v.items) objects = objects && x.kind == Json::Kind::kObject;
      if (objects) return "<td>" + json_table(v) + "</td>";
      std::string s;
      for (const Json& x : v.items) {
        if (x.kind == Json::Kind::kObject || x.kind == Json::Kind::kArray) continue;
        s +=
            (s.empty() ? "" : ", ") +
            esc(x.kind == Json::Kind::kNumber ? fmt(std::strtod(x.text.c_str(), nullptr)) : x.text);
      }
      return "<td>" + s + "</td>";
    }
  }
  return "<td></td>";
}

std::string csv_table(const Csv& csv) {
  std::string h = "<table><tr>";
  for (const std::string& k : csv.header) h += "<th>" + esc(k) + "</th>";
  h += "</tr>";
  for (const auto& row : csv.rows) {
    h += "<tr>";
    for (const std::string& f : row) h += num_cell(f);
    h += "</tr>";
  }
  return h + "</table>";
}

constexpr const char* kStyle = R"(
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

std::string sh_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

bool executable(const fs::path& p) {
  std::error_code ec;
  return fs::is_regular_file(p, ec) && ::access(p.c_str(), X_OK) == 0;
}

// a temporary directory, removed with everything in it
class TempDir {
 public:
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "bd-report-XXXXXX").string();
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

// one chart: its file stem, heading, caption and gnuplot commands (ending in a plot)
struct Chart {
  std::string id, heading, caption, commands;
  bool square = false;  // taller canvas (equal-axis plots)
};

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

// runs gnuplot once for all charts; returns each chart's inline SVG, in order
std::vector<std::string> draw(const std::string& gnuplot, const std::string& datablocks,
                              const std::vector<Chart>& charts) {
  TempDir tmp;
  std::string script =
      "set datafile separator ','\nset grid\nset key outside right top\n"
      "set encoding utf8\n";
  script += datablocks;
  for (const Chart& c : charts) {
    script += "reset\nset datafile separator ','\nset grid\nset key outside right top\n";
    script += std::string("set terminal svg size 900,") + (c.square ? "600" : "420") +
              " dynamic noenhanced font 'sans,12' background rgb 'white'\n";
    script += "set output " + gp_string((tmp.path() / (c.id + ".svg")).string()) + "\n";
    script += c.commands + "\nunset output\n";
  }
  const fs::path script_file = tmp.path() / "report.gp";
  {
    std::ofstream out(script_file, std::ios::binary);
    out << script;
    if (!out) throw std::runtime_error("cannot write " + script_file.string());
  }
  const fs::path err_file = tmp.path() / "gnuplot-stderr.txt";
  const std::string cmd = sh_quote(gnuplot) + " " + sh_quote(script_file.string()) +
                          " </dev/null >/dev/null 2>" + sh_quote(err_file.string());
  const int status = std::system(cmd.c_str());
  if (status != 0) {
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
    throw std::runtime_error("gnuplot failed (" + gnuplot + ", status " + std::to_string(status) +
                             ")" + (first.empty() ? std::string() : ": " + first));
  }
  std::vector<std::string> svgs;
  for (const Chart& c : charts) {
    svgs.push_back(inline_svg(read_file(tmp.path() / (c.id + ".svg")), c.id));
  }
  return svgs;
}

// ---------------------------------------------------------------------------------------------
// the linkage drawn at a few samples

struct PoseSample {
  std::size_t index{};
  double t{};
  core::Pose pose;
  core::Joints joints;
  core::PrincipalPoints principal;
  Vec2 S{0, 0};
};

core::FourBarState state_of(const std::vector<double>& x) {
  core::FourBarState s;
  s.theta1 = x[1];
  s.theta2 = x[2];
  s.theta3 = x[3];
  s.omega1 = x[4];
  s.omega2 = x[5];
  s.omega3 = x[6];
  s.alpha1 = x[7];
  s.alpha2 = x[8];
  s.alpha3 = x[9];
  return s;
}

PoseSample pose_sample(const core::FourBar& model, const std::vector<double>& x, std::size_t i) {
  PoseSample p;
  p.index = i;
  p.t = x[0];
  const core::FourBarState s = state_of(x);
  p.pose = core::pose_of(s);
  p.joints = core::joint_positions(model, p.pose);
  p.principal = core::opened_loop_principal_points(model, p.pose);
  p.S = core::centre_of_mass_frame(model, s).r;
  return p;
}

std::string xy(const Vec2& v) { return fmt(v.x(), "%.10g") + "," + fmt(v.y(), "%.10g"); }

std::string vec_text(const Vec2& v) {
  return "(" + fmt(v.x(), "%.4g") + ", " + fmt(v.y(), "%.4g") + ")";
}

// ---------------------------------------------------------------------------------------------

const char* branch_text(core::Branch b) { return b == core::Branch::kPlus ? "+1" : "-1"; }

std::string linkage_tables(const Study& study) {
  const core::FourBar& m = study.model;
  std::string h =
      "<table><tr><th>link</th><th>length l [m]</th><th>mass m [kg]</th>"
      "<th>s [m]</th><th>&sigma; [rad]</th><th>e [m]</th><th>f [m]</th>"
      "<th>inertia I [kg m&sup2;]</th></tr>";
  for (int k = 1; k <= 3; ++k) {
    const core::Link& l = core::link(m, k);
    h += "<tr><th>" + std::to_string(k) + " " + core::link_name(k) + "</th><td class=\"n\">" +
         fmt(l.length) + "</td><td class=\"n\">" + fmt(l.mass) + "</td><td class=\"n\">" +
         fmt(l.s()) + "</td><td class=\"n\">" + fmt(l.sigma()) + "</td><td class=\"n\">" +
         fmt(l.e) + "</td><td class=\"n\">" + fmt(l.f) + "</td><td class=\"n\">" + fmt(l.inertia) +
         "</td></tr>";
  }
  h += "<tr><th>4 frame</th><td class=\"n\">" + fmt(m.frame_length) +
       "</td><td colspan=\"6\">A0 at the origin, A3 at (l4, 0)</td></tr></table>";
  h += "<p>Branch " + std::string(branch_text(m.branch)) + "; Grashof class " +
       core::to_string(core::classify_grashof(m)) + " (the crank " +
       (core::crank_turns_fully(m) ? "turns fully" : "cannot turn fully") +
       "); total moving mass " + fmt(core::total_mass(m)) + " kg.</p>";
  const core::CounterRotation* discs[] = {&m.counter_rotations.crank, &m.counter_rotations.rocker};
  if (core::has_counter_rotations(m)) {
    h += "<table><tr><th>counter-rotation</th><th>J [kg m&sup2;]</th><th>shaft at [m]</th></tr>";
    const char* names[] = {"crank", "rocker"};
    for (int i = 0; i < 2; ++i) {
      if (discs[i]->inertia <= 0) continue;
      h += std::string("<tr><th>") + names[i] + "</th><td class=\"n\">" + fmt(discs[i]->inertia) +
           "</td><td>" + vec_text(discs[i]->at) + "</td></tr>";
    }
    h += "</table>";
  }
  h += "<h3>Loads</h3><table><tr><th></th><th>force at the centre of mass [N]</th>"
       "<th>moment [N m]</th></tr>";
  h += "<tr><th>gravity g [m/s&sup2;]</th><td>" + vec_text(m.loads.gravity) + "</td><td></td></tr>";
  for (int k = 1; k <= 3; ++k) {
    const core::LinkLoad& l = core::link_load(m, k);
    h += std::string("<tr><th>") + core::link_name(k) + "</th><td>" + vec_text(l.force) +
         "</td><td class=\"n\">" + fmt(l.moment) + "</td></tr>";
  }
  return h + "</table>";
}

// the run facts of summary.json (or of its balanced_run / optimized_run) as a table
std::string run_table(const Json& run, const std::string& what) {
  std::string h = "<table>";
  if (const Json* method = run.get("method")) {
    h += "<tr><th>method</th><td><b>" + esc(method->str("used")) + "</b> (requested " +
         esc(method->str("requested")) + ")<br>" + esc(method->str("reason")) + "</td></tr>";
  }
  const bool ok = run.str("ok") == "true";
  h += "<tr><th>status</th><td class=\"" + std::string(ok ? "good" : "bad") + "\">" +
       esc(run.str("status")) + "</td></tr>";
  h += "<tr><th>message</th><td>" + esc(run.str("message")) + "</td></tr>";
  h += "<tr><th>samples</th><td>" + esc(run.str("samples")) + "</td></tr>";
  h += "<tr><th>integrator steps, dynamics evaluations</th><td>" + esc(run.str("steps")) + ", " +
       esc(run.str("rhs_evaluations")) + "</td></tr>";
  if (!ok) {
    h += "<tr><td colspan=\"2\" class=\"bad\">The " + what +
         " simulation stopped early: the charts and metrics cover the samples computed.</td></tr>";
  }
  return h + "</table>";
}

}  // namespace

std::string find_gnuplot() {
  const char* env = std::getenv("BD_GNUPLOT");
  const std::string name = env && *env ? env : "gnuplot";
  if (name.find('/') != std::string::npos) return executable(name) ? name : std::string();
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "/usr/bin:/bin");
  for (std::string d; std::getline(dirs, d, ':');) {
    const fs::path p = fs::path(d.empty() ? "." : d) / name;
    if (executable(p)) return p.string();
  }
  return {};
}

std::string report_html(const Study& study, const fs::path& dir, const std::string& gnuplot) {
  const fs::path summary_file = dir / "summary.json";
  if (!fs::exists(summary_file)) {
    throw std::runtime_error(summary_file.string() + " not found: not the output folder of a run");
  }
  const Json summary = JsonParser(read_file(summary_file), summary_file.string()).parse();
  const Csv ts = read_csv(dir / "timeseries.csv");

  // the second design, if any
  std::string second, second_label, second_file;
  if (summary.get("balanced_run") && fs::exists(dir / "balanced-timeseries.csv")) {
    second = "balanced";
    second_label = "balanced";
    second_file = "balanced-timeseries.csv";
  } else if (summary.get("optimized_run") && fs::exists(dir / "optimized-timeseries.csv")) {
    second = "optimized";
    second_label = "optimised";
    second_file = "optimized-timeseries.csv";
  }
  const bool has_comparison = !second.empty() && fs::exists(dir / "comparison.csv");
  const bool has_pareto = fs::exists(dir / "pareto.csv");

  const std::string name = summary.str("study").empty() ? study.name : summary.str("study");
  std::string h =
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
      "<title>" +
      esc(name) + " &mdash; balance-design report</title>\n<style>" + kStyle +
      "</style>\n</head>\n<body>\n";
  h += "<h1>" + esc(name) + "</h1>\n<p>balance-design report of the study <code>" +
       esc(summary.str("source").empty() ? std::string("(built in code)") : summary.str("source")) +
       "</code>. Every number below is read from the data files of this folder; hover over a "
       "number to see it as written there.</p>\n";

  // status first: whether the run can be trusted
  const bool ok = summary.str("ok") == "true";
  h += "<h2>Simulation</h2>\n";
  if (!ok) {
    h += "<p class=\"notice bad\">The simulation stopped early: " + esc(summary.str("message")) +
         "</p>\n";
  }
  h += run_table(summary, "original design's");
  if (const Json* scene = summary.get("scene")) {
    h += "<h3>Scene</h3>" + json_table(*scene);
    h += "<p>Integrator relative tolerance " + esc(summary.str("tolerance")) + ".</p>\n";
  }

  h += "<h2>Linkage</h2>\n" + linkage_tables(study);

  // metrics, side by side with the second design's when there is one
  h += "<h2>Metrics</h2>\n<table><tr><th>metric</th><th>original</th>";
  const Json* metrics = summary.get("metrics");
  const Json* second_metrics = second.empty() ? nullptr : summary.get(second + "_metrics");
  const Json* reduction = summary.get("reduction");
  if (second_metrics) h += "<th>" + esc(second_label) + "</th><th>ratio</th>";
  h += "</tr>";
  if (metrics) {
    for (const auto& [k, v] : metrics->fields) {
      h += "<tr><th>" + esc(k) + "</th>" + json_cell(v);
      if (second_metrics) {
        const Json* s = second_metrics->get(k);
        const Json* r = reduction ? reduction->get(k) : nullptr;
        h += (s ? json_cell(*s) : "<td></td>") + (r ? json_cell(*r) : "<td></td>");
      }
      h += "</tr>";
    }
  }
  h += "</table>\n<p>Fsh, Msh: shaking force [N] and moment about A0 [N m] on the frame; tau: "
       "drive torque [N m]; RA0, RA3: forces on the ground at the bearings [N]. RMS over the "
       "samples, max of magnitudes.</p>\n";

  if (has_comparison) {
    h += "<h2>Comparison</h2>\n<p>From <a href=\"comparison.csv\">comparison.csv</a>: the original "
         "(before) and the " +
         second_label + " design (after), ratio after/before.</p>" +
         csv_table(read_csv(dir / "comparison.csv"));
  }
  Csv pareto;
  if (has_pareto) {
    pareto = read_csv(dir / "pareto.csv");
  }

  // the linkage at four samples evenly spread over the run, and the path of S
  std::vector<std::vector<double>> rows;
  for (const auto& r : ts.rows) rows.push_back(numbers(r));
  std::vector<PoseSample> poses;
  std::vector<Vec2> s_path;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (rows[i].size() < 18) continue;
    s_path.push_back(pose_sample(study.model, rows[i], i).S);
  }
  if (!rows.empty()) {
    const std::size_t n = rows.size();
    for (std::size_t k = 0; k < 4 && k < n; ++k) {
      const std::size_t i = k * n / std::min<std::size_t>(4, n);
      if (rows[i].size() >= 18) poses.push_back(pose_sample(study.model, rows[i], i));
    }
  }

  // charts
  const fs::path abs_dir = fs::absolute(dir);
  const std::string ts_file = gp_string((abs_dir / "timeseries.csv").string());
  const std::string ts2_file = second.empty() ? "" : gp_string((abs_dir / second_file).string());
  const std::string drive_x = std::holds_alternative<core::DrivenScene>(study.scene)
                                  ? "t [s] (crank driven at constant speed)"
                                  : "t [s]";
  std::vector<Chart> charts;
  if (!rows.empty()) {
    charts.push_back(
        {"angles", "Link angles",
         "theta1, theta2, theta3 over the run (cf. paper Fig. 7), from timeseries.csv.",
         "set title 'Link angles'\nset xlabel " + gp_string(drive_x) +
             "\nset ylabel 'angle [rad]'\n"
             "plot " +
             ts_file +
             " skip 1 using 1:2 with lines lw 2 title 'θ1 crank', "
             "'' skip 1 using 1:3 with lines lw 2 title 'θ2 coupler', "
             "'' skip 1 using 1:4 with lines lw 2 title 'θ3 rocker'"});
    charts.push_back({"reactions", "Support reactions",
                      "Forces of the mechanism on the ground at A0 and A3 (cf. paper Fig. 8), "
                      "original design.",
                      "set title 'Support reactions (original design)'\nset xlabel " +
                          gp_string(drive_x) +
                          "\nset ylabel 'force on the ground [N]'\n"
                          "plot " +
                          ts_file +
                          " skip 1 using 1:11 with lines lw 2 title 'RA0x', "
                          "'' skip 1 using 1:12 with lines lw 2 title 'RA0y', "
                          "'' skip 1 using 1:13 with lines lw 2 title 'RA3x', "
                          "'' skip 1 using 1:14 with lines lw 2 title 'RA3y'"});
    std::string hodo =
        "set title 'Shaking-force hodograph'\nset size ratio -1\n"
        "set xlabel 'Fshx [N]'\nset ylabel 'Fshy [N]'\n"
        "plot " +
        ts_file + " skip 1 using 15:16 with lines lw 2 title 'original'";
    std::string msh = "set title 'Shaking moment about A0'\nset xlabel " + gp_string(drive_x) +
                      "\nset ylabel 'Msh [N m]'\nplot " + ts_file +
                      " skip 1 using 1:17 with lines lw 2 title 'original'";
    std::string drive = "set title 'Drive torque and bearing loads'\nset xlabel " +
                        gp_string(drive_x) +
                        "\nset ylabel 'bearing load [N]'\n"
                        "set y2label 'drive torque τ [N m]'\nset ytics nomirror\nset y2tics\n"
                        "plot " +
                        ts_file +
                        " skip 1 using 1:(sqrt($11**2+$12**2)) with lines lw 2 "
                        "lt 1 title '|RA0|', '' skip 1 using 1:(sqrt($13**2+$14**2)) with lines "
                        "lw 2 lt 2 title '|RA3|', '' skip 1 using 1:18 axes x1y2 with lines lw 2 "
                        "lt 3 title 'τ'";
    if (!second.empty()) {
      hodo += ", " + ts2_file + " skip 1 using 15:16 with linespoints lw 2 dt 2 pt 6 pi 25 title " +
              gp_string(second_label);
      msh += ", " + ts2_file + " skip 1 using 1:17 with lines lw 2 dt 2 title " +
             gp_string(second_label);
      drive += ", " + ts2_file +
               " skip 1 using 1:(sqrt($11**2+$12**2)) with lines lw 2 lt 1 dt 2 "
               "title '|RA0| " +
               second_label +
               "', '' skip 1 using 1:(sqrt($13**2+$14**2)) with "
               "lines lw 2 lt 2 dt 2 title '|RA3| " +
               second_label +
               "', '' skip 1 using 1:18 "
               "axes x1y2 with lines lw 2 lt 3 dt 2 title 'τ " +
               second_label + "'";
    }
    const std::string overlay =
        second.empty() ? "" : " The " + second_label + " design is dashed (" + second_file + ").";
    charts.push_back(
        {"hodograph", "Shaking-force hodograph",
         "The tip of the shaking force F̄sh = R̄A0 + R̄A3 over the run, equal axes." + overlay, hodo,
         true});
    charts.push_back({"shaking-moment", "Shaking moment",
                      "Shaking moment on the frame about A0 over the run." + overlay, msh});
    charts.push_back({"drive", "Drive torque and bearing loads",
                      "Magnitudes of the bearing forces at A0 and A3 (left axis) and the drive "
                      "torque (right axis; zero in free motion)." +
                          overlay,
                      drive});
  }
  std::string datablocks;
  if (!poses.empty()) {
    datablocks += "$links << EOD\n";
    for (std::size_t k = 0; k < poses.size(); ++k) {
      const core::Joints& j = poses[k].joints;
      for (const Vec2* p : {&j.A0, &j.A1, &j.A2, &j.A3}) datablocks += xy(*p) + "\n";
      datablocks += "\n\n";  // a new data set per pose (index k)
    }
    datablocks += "EOD\n$frame << EOD\n0,0\n" + fmt(study.model.frame_length, "%.10g") + ",0\n";
    datablocks += "EOD\n$principal << EOD\n";
    for (std::size_t k = 0; k < poses.size(); ++k) {
      const core::PrincipalPoints& p = poses[k].principal;
      for (const Vec2* q : {&p.P1, &p.P2, &p.P3})
        datablocks += xy(*q) + "," + std::to_string(k + 1) + "\n";
    }
    datablocks += "EOD\n$S << EOD\n";
    for (std::size_t k = 0; k < poses.size(); ++k)
      datablocks += xy(poses[k].S) + "," + std::to_string(k + 1) + "\n";
    datablocks += "EOD\n$Spath << EOD\n";
    for (const Vec2& s : s_path) datablocks += xy(s) + "\n";
    datablocks += "EOD\n";
    std::string cmd = "set title 'The linkage at " + std::to_string(poses.size()) +
                      " samples, principal points and the centre of mass S'\n"
                      "set size ratio -1\nset xlabel 'x [m]'\nset ylabel 'y [m]'\n"
                      "set offsets graph 0.05, graph 0.05, graph 0.05, graph 0.05\n";
    const core::Joints& j0 = poses.front().joints;
    const char* jn[] = {"A0", "A1", "A2", "A3"};
    const Vec2* jp[] = {&j0.A0, &j0.A1, &j0.A2, &j0.A3};
    for (int i = 0; i < 4; ++i) {
      cmd += "set label " + gp_string(jn[i]) + " at " + xy(*jp[i]) + " offset 0.6,0.6\n";
    }
    const core::PrincipalPoints& p0 = poses.front().principal;
    const char* pn[] = {"P1", "P2", "P3"};
    const Vec2* pp[] = {&p0.P1, &p0.P2, &p0.P3};
    for (int i = 0; i < 3; ++i) {
      cmd += "set label " + gp_string(pn[i]) + " at " + xy(*pp[i]) + " offset 0.6,-0.8 tc lt 1\n";
    }
    cmd += "plot ";
    for (std::size_t k = 0; k < poses.size(); ++k) {
      cmd += "$links index " + std::to_string(k) +
             " using 1:2 with linespoints lw 2 pt 7 ps 0.8 lt " + std::to_string(k + 1) +
             " title " +
             gp_string("θ1 = " + fmt(poses[k].pose.theta1, "%.3g") +
                       " rad, t = " + fmt(poses[k].t, "%.3g") + " s") +
             ", ";
    }
    cmd +=
        "$frame using 1:2 with lines lw 3 lc 'gray40' title 'frame A0-A3', "
        "$principal using 1:2:3 with points pt 6 ps 1.4 lc variable notitle, "
        "$S using 1:2:3 with points pt 5 ps 1.2 lc variable notitle, "
        "NaN with points pt 6 ps 1.4 lc 'black' title 'principal points P1 P2 P3 (opened loop)', "
        "NaN with points pt 5 ps 1.2 lc 'black' title 'S (system centre of mass)', "
        "$Spath using 1:2 with lines lw 1.5 lc 'black' dt 3 title 'path of S'";
    charts.push_back({"linkage", "The linkage",
                      "Joints and link lines at " + std::to_string(poses.size()) +
                          " samples spread evenly over the run (same colour per sample), the "
                          "opened-loop principal points P1, P2, P3 (open circles) and the system "
                          "centre of mass S (filled squares), with the path S traces over all " +
                          std::to_string(s_path.size()) +
                          " samples; computed from the model and timeseries.csv (original design).",
                      cmd, true});
  }
  if (has_pareto && pareto.header.size() >= 3) {
    charts.push_back({"pareto", "Pareto front",
                      "Each point a design found by the epsilon-constraint method (pareto.csv); "
                      "points without a design are left out.",
                      "set title 'Pareto front'\nset xlabel " + gp_string(pareto.header[1]) +
                          "\nset ylabel " + gp_string(pareto.header[2]) + "\nplot " +
                          gp_string((abs_dir / "pareto.csv").string()) +
                          " skip 1 using 2:3 with linespoints lw 2 pt 7 title 'front'"});
  }

  h += "<h2>Charts</h2>\n";
  if (gnuplot.empty()) {
    h += "<p class=\"notice\">The charts need gnuplot, which was not found on this machine "
         "(install it, e.g. <code>apt-get install gnuplot-nox</code>, then rebuild this page with "
         "<code>balance-design report DIR</code>). The tables and the data files below hold every "
         "number.</p>\n";
  } else {
    const std::vector<std::string> svgs = draw(gnuplot, datablocks, charts);
    for (std::size_t i = 0; i < charts.size(); ++i) {
      h += "<h3>" + esc(charts[i].heading) + "</h3>\n<figure class=\"chart\" id=\"chart-" +
           charts[i].id + "\">\n" + svgs[i] + "\n<figcaption>" + esc(charts[i].caption) +
           "</figcaption>\n</figure>\n";
    }
  }
  if (!poses.empty()) {
    h += "<h3>The linkage at the drawn samples</h3><table><tr><th>sample</th><th>t [s]</th>"
         "<th>&theta;1 [rad]</th><th>A1</th><th>A2</th><th>P1</th><th>P2</th><th>P3</th>"
         "<th>S</th></tr>";
    for (const PoseSample& p : poses) {
      h += "<tr><td class=\"n\">" + std::to_string(p.index + 1) + "</td><td class=\"n\">" +
           fmt(p.t) + "</td><td class=\"n\">" + fmt(p.pose.theta1) + "</td><td>" +
           vec_text(p.joints.A1) + "</td><td>" + vec_text(p.joints.A2) + "</td><td>" +
           vec_text(p.principal.P1) + "</td><td>" + vec_text(p.principal.P2) + "</td><td>" +
           vec_text(p.principal.P3) + "</td><td>" + vec_text(p.S) + "</td></tr>";
    }
    h += "</table>\n";
  }

  if (!second.empty()) {
    const char* section = second == "balanced" ? "balance" : "optimize";
    h += std::string("<h2>") + (second == "balanced" ? "Balanced design" : "Optimised design") +
         "</h2>\n";
    if (const Json* s = summary.get(section)) h += json_table(*s);
    if (const Json* run = summary.get(second + "_run")) {
      h += "<h3>Its simulation (same scene)</h3>" + run_table(*run, second_label + " design's");
    }
  } else if (const Json* s = summary.get("optimize")) {
    h +=
        "<h2>Optimisation</h2>\n<p class=\"notice bad\">No optimum was found.</p>" + json_table(*s);
  }
  if (has_pareto) {
    h += "<h2>Pareto front</h2>\n<p>From <a href=\"pareto.csv\">pareto.csv</a>.</p>" +
         csv_table(pareto);
  }
  h += "<h2>Data files</h2>\n<ul>\n";
  for (const char* f :
       {"timeseries.csv", "summary.json", "balanced-timeseries.csv", "balanced.yaml",
        "optimized-timeseries.csv", "optimized.yaml", "comparison.csv", "pareto.csv"}) {
    std::error_code ec;
    const auto size = fs::file_size(dir / f, ec);
    if (ec) continue;
    h += std::string("<li><a href=\"") + f + "\">" + f + "</a> (" + std::to_string(size) +
         " bytes)</li>\n";
  }
  h += "</ul>\n</body>\n</html>\n";
  return h;
}

fs::path write_report(const Study& study, const fs::path& dir) {
  const std::string html = report_html(study, dir, find_gnuplot());
  const fs::path target = dir / "report.html";
  const fs::path temp = dir / (".report.html." + std::to_string(::getpid()) + ".tmp");
  {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    out << html;
    out.close();
    if (!out) {
      std::error_code ec;
      fs::remove(temp, ec);
      throw std::runtime_error("cannot write " + temp.string());
    }
  }
  std::error_code ec;
  fs::rename(temp, target, ec);
  if (ec) {
    fs::remove(temp, ec);
    throw std::runtime_error("cannot rename " + temp.string() + " to " + target.string());
  }
  return target;
}

}  // namespace bd::studies
