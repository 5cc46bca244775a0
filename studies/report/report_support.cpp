#include "studies/report/report_support.hpp"

#include <stdlib.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace bd::studies::report_support {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------------------------
// reading the run's files back

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + p.string());
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

namespace {

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

}  // namespace

Json parse_json(const std::string& text, const std::string& name) {
  return JsonParser(text, name).parse();
}

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

std::string fmt(double v, const char* f) {
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

}  // namespace bd::studies::report_support
