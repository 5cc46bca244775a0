// Running a sweep: the sweep.csv columns, the points computed on worker threads, the rows
// appended in point order by one writer, the progress display, sweep.json, and resuming an
// interrupted sweep. The points and each point's study come from sweep.cpp, the report from
// sweep_report.cpp.
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cassert>
#include <cerrno>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <map>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

#include "core/input_error.hpp"
#include "core/number_text.hpp"
#include "studies/report/report_support.hpp"
#include "studies/run/runner.hpp"
#include "studies/sweep/sweep.hpp"

namespace bd::studies {

namespace fs = std::filesystem;
namespace rs = report_support;
using Clock = std::chrono::steady_clock;

namespace {

// the metrics in the table's order: the sweep.csv columns after the parameters
constexpr std::size_t kMetrics = core::kMetricCount;

std::vector<double> metric_values(const core::Metrics& m) {
  std::vector<double> values;
  for (const core::MetricInfo& info : core::kMetricTable) values.push_back(m.*info.field);
  return values;
}

// the statuses a row may have (sweep.hpp, sweep_columns())
constexpr const char* kStatuses[] = {"ok", "stopped-early", "no-optimum", "bad-input", "error"};

// a CSV field, quoted (RFC 4180) when it holds a comma, a quote or a line break
std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
  std::string q = "\"";
  for (char c : text) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

// a message as the last field of a row: on one line (so every row is one line of the file, which
// resuming relies on), quoted unless empty
std::string message_field(std::string message) {
  if (message.empty()) return message;
  std::replace(message.begin(), message.end(), '\n', ' ');
  std::replace(message.begin(), message.end(), '\r', ' ');
  std::string q = "\"";
  for (char c : message) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

std::string header_line(const Study& study) {
  std::string line;
  for (const std::string& c : sweep_columns(study))
    line += (line.empty() ? "" : ",") + csv_field(c);
  return line;
}

// FNV-1a 64 of the study text, 16 hex digits: sweep.json's fingerprint
std::string fingerprint(const std::string& text) {
  std::uint64_t h = 14695981039346656037ull;
  for (char c : text) {
    h ^= static_cast<unsigned char>(c);
    h *= 1099511628211ull;
  }
  char buf[20];
  std::snprintf(buf, sizeof buf, "%016" PRIx64, h);
  return buf;
}

// --- one point -------------------------------------------------------------------------------

struct PointRow {
  std::string text;  // the row with its '\n'
  bool ok = false;
};

// appends the cells of a second design (balanced or optimised): its metrics, added mass and
// inertia, or as many empty cells
void second_design_cells(std::string& row, const core::Metrics* metrics, double added_mass,
                         double added_inertia) {
  if (!metrics) {
    row.append(kMetrics + 2, ',');
    return;
  }
  for (double v : metric_values(*metrics)) row += "," + text::exact(v);
  row += "," + text::exact(added_mass) + "," + text::exact(added_inertia);
}

// the added mass and inertia of the balanced or optimised design (comparison.csv's last rows)
std::pair<double, double> added(const Study& study, const RunResult& r) {
  double mass = 0, inertia = 0;
  for (const ComparisonRow& c : comparison(study, r)) {
    if (c.metric == "added_mass") mass = c.after;
    if (c.metric == "added_inertia") inertia = c.after;
  }
  return {mass, inertia};
}

// the row of point `index`: never throws (a point's failure is its row's status)
// (`cells`: how many metric cells a row has)
PointRow point_row(const Study& base, int index, std::span<const double> values,
                   std::size_t cells) {
  std::string head = std::to_string(index);
  for (double v : values) head += "," + text::exact(v);
  std::string status = "ok", message;
  std::string body;
  try {
    const Study study = point_study(base, values);
    const RunResult r = compute_study(study);
    for (double v : metric_values(r.metrics)) body += "," + text::exact(v);
    if (base.balance) {
      const bool have = study.balance && r.balanced;
      const auto [mass, inertia] = have ? added(study, r) : std::pair<double, double>{};
      second_design_cells(body, have ? &r.balanced->metrics : nullptr, mass, inertia);
    }
    if (base.optimize) {
      const bool have = r.optimized && r.optimized->found();
      const auto [mass, inertia] = have ? added(study, r) : std::pair<double, double>{};
      second_design_cells(body, have ? &r.optimized->metrics : nullptr, mass, inertia);
    }
    if (r.stopped_early()) {
      status = "stopped-early";
      if (!r.trajectory.ok()) {
        message = r.trajectory.message;
      } else if (r.balanced && !r.balanced->trajectory.ok()) {
        message = "balanced design: " + r.balanced->trajectory.message;
      } else {
        message = "optimised design: " + r.optimized->trajectory.message;
      }
    } else if (r.optimized && !r.optimized->found()) {
      status = "no-optimum";
      message = r.optimized->result.message;
    }
  } catch (const InputError& e) {  // StudyError from point_study() included
    status = "bad-input";
    message = e.what();
    body.assign(cells, ',');
  } catch (const std::exception& e) {
    status = "error";
    message = e.what();
    body.assign(cells, ',');
  } catch (...) {
    status = "error";
    message = "unknown exception";
    body.assign(cells, ',');
  }
  PointRow row;
  row.ok = status == "ok";
  row.text = head + body + "," + status + "," + message_field(message) + "\n";
  return row;
}

// --- sweep.json ------------------------------------------------------------------------------

// the grid's range as sweep.json states it: from/to as given, or the values' min and max
std::pair<double, double> range_of(const SweepParameter& p, SweepDesign design) {
  if (design != SweepDesign::kGrid || p.from != p.to || p.values.empty()) return {p.from, p.to};
  const auto [lo, hi] = std::minmax_element(p.values.begin(), p.values.end());
  return {*lo, *hi};
}

// the keys that say which sweep a folder holds (checked when resuming), without the braces
std::string identity_json(const Study& study, int points) {
  const SweepRequest& req = *study.sweep;
  std::string j;
  j += "  \"fingerprint\": " + json_string(fingerprint(req.study_text)) + ",\n";
  j += "  \"design\": " + json_string(to_string(req.design)) + ",\n";
  j += "  \"seed\": " + std::to_string(req.seed) + ",\n";
  j += "  \"points\": " + std::to_string(points) + ",\n";
  j += "  \"parameters\": [\n";
  for (std::size_t k = 0; k < req.parameters.size(); ++k) {
    const SweepParameter& p = req.parameters[k];
    const auto [from, to] = range_of(p, req.design);
    j += "    {\"path\": " + json_string(p.path) +
         ", \"scale\": " + (p.log_scale ? "\"log\"" : "\"linear\"") +
         ", \"from\": " + text::exact(from) + ", \"to\": " + text::exact(to);
    if (req.design == SweepDesign::kGrid) {
      j += ", \"values\": [";
      for (std::size_t i = 0; i < p.values.size(); ++i)
        j += (i ? ", " : "") + text::exact(p.values[i]);
      j += "]";
    }
    j += std::string("}") + (k + 1 < req.parameters.size() ? ",\n" : "\n");
  }
  j += "  ],\n";
  return j;
}

struct Counts {
  const char* status = "running";  // running | interrupted | complete
  int done{}, resumed{}, failed{}, threads{};
  double elapsed_s{};
};

std::string sweep_json(const Study& study, int points, const Counts& c) {
  char elapsed[32];
  std::snprintf(elapsed, sizeof elapsed, "%.3f", c.elapsed_s);
  std::string j = "{\n";
  j += "  \"study\": " + json_string(study.name) + ",\n";
  j += "  \"source\": " + json_string(study.source) + ",\n";
  std::string id = identity_json(study, points);
  // threads after points, as the docs list the keys
  const std::size_t at = id.find("  \"parameters\"");
  id.insert(at, "  \"threads\": " + std::to_string(c.threads) + ",\n");
  j += id;
  j += std::string("  \"status\": \"") + c.status + "\",\n";
  j += "  \"done\": " + std::to_string(c.done) + ", \"resumed\": " + std::to_string(c.resumed) +
       ", \"failed\": " + std::to_string(c.failed) + ",\n";
  j += std::string("  \"elapsed_s\": ") + elapsed + "\n";
  return j + "}\n";
}

// --- the folder's earlier sweep --------------------------------------------------------------

// two JSON values alike (numbers compared as written)
bool same_json(const rs::Json& a, const rs::Json& b) {
  if (a.kind != b.kind || a.text != b.text || a.items.size() != b.items.size() ||
      a.fields.size() != b.fields.size()) {
    return false;
  }
  for (std::size_t i = 0; i < a.items.size(); ++i) {
    if (!same_json(a.items[i], b.items[i])) return false;
  }
  for (std::size_t i = 0; i < a.fields.size(); ++i) {
    if (a.fields[i].first != b.fields[i].first ||
        !same_json(a.fields[i].second, b.fields[i].second))
      return false;
  }
  return true;
}

std::string read_or_empty(const fs::path& p) {
  std::error_code ec;
  if (!fs::exists(p, ec)) return {};
  return rs::read_file(p);
}

// what differs between the folder's sweep.json and this sweep, in words; empty when alike
std::string identity_difference(const rs::Json& old, const Study& study, int points) {
  const rs::Json now =
      rs::parse_json("{\n" + identity_json(study, points) + "  \"end\": 0\n}\n", "sweep.json");
  auto shown = [](const rs::Json* v) { return v ? v->text : std::string("nothing"); };
  const rs::Json* f = old.get("fingerprint");
  if (!f || f->text != now.str("fingerprint")) {
    return "the study file differs (fingerprint " + now.str("fingerprint") + ", was " + shown(f) +
           ")";
  }
  for (const char* key : {"design", "seed", "points"}) {
    const rs::Json* v = old.get(key);
    if (!v || v->text != now.str(key)) {
      return std::string(key) + " " + now.str(key) + ", was " + shown(v);
    }
  }
  const rs::Json* p = old.get("parameters");
  if (!p || !same_json(*p, *now.get("parameters"))) return "the parameters differ";
  return {};
}

// the complete rows of a sweep.csv text after its header, and where they end
struct CsvRows {
  bool has_header = false;        // a complete header line
  std::string header;             // without its '\n'
  std::vector<std::string> rows;  // complete lines, without their '\n'
  std::size_t complete_size{};    // bytes up to the last '\n' (the header's included)
};

CsvRows split_rows(const std::string& text) {
  CsvRows out;
  std::size_t start = 0;
  for (std::size_t nl; (nl = text.find('\n', start)) != std::string::npos; start = nl + 1) {
    std::string line = text.substr(start, nl - start);
    if (!out.has_header) {
      out.has_header = true;
      out.header = std::move(line);
    } else {
      out.rows.push_back(std::move(line));
    }
    out.complete_size = nl + 1;
  }
  return out;
}

// what is wrong with kept row i, in words; empty when it is the row of point i of this design
std::string row_problem(const std::string& line, std::size_t i, std::size_t columns,
                        const std::vector<double>& values) {
  const std::vector<std::string> f = rs::csv_fields(line);
  if (f.size() != columns) {
    return "it has " + std::to_string(f.size()) + " fields, the header " + std::to_string(columns);
  }
  if (f[0] != std::to_string(i)) return "its point is '" + f[0] + "'";
  for (std::size_t j = 0; j < values.size(); ++j) {
    if (f[1 + j] != text::exact(values[j])) {
      return "its parameter " + std::to_string(j + 1) + " is " + f[1 + j] + ", the design's " +
             text::exact(values[j]);
    }
  }
  const std::string& status = f[columns - 2];
  if (std::find_if(std::begin(kStatuses), std::end(kStatuses),
                   [&](const char* s) { return status == s; }) == std::end(kStatuses)) {
    return "its status is '" + status + "'";
  }
  return {};
}

[[noreturn]] void refuse(const fs::path& dir, const std::string& why) {
  throw InputError(dir.string() + " holds a sweep of another study or design: " + why +
                   "; remove the folder to start over");
}

// --- writing rows ----------------------------------------------------------------------------

// sweep.csv opened for appending: each row goes out in one write(2), so a kill leaves at most
// one line cut short
class RowFile {
 public:
  explicit RowFile(fs::path file) : file_(std::move(file)) {
    fd_ = ::open(file_.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
    if (fd_ < 0) fail("cannot open");
  }
  RowFile(const RowFile&) = delete;
  RowFile& operator=(const RowFile&) = delete;
  ~RowFile() {
    if (fd_ >= 0) ::close(fd_);
  }

  void append(const std::string& row) {
    const char* p = row.data();
    std::size_t left = row.size();
    while (left > 0) {  // one write unless the kernel takes less (a full disk)
      const ssize_t n = ::write(fd_, p, left);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) fail("cannot write");
      p += n;
      left -= static_cast<std::size_t>(n);
    }
  }

  void close() {
    if (fd_ >= 0 && ::close(fd_) != 0) {
      fd_ = -1;
      fail("cannot write");
    }
    fd_ = -1;
  }

 private:
  [[noreturn]] void fail(const char* what) {
    throw std::runtime_error(std::string(what) + " " + file_.string() + ": " +
                             std::strerror(errno));
  }
  fs::path file_;
  int fd_ = -1;
};

// --- progress --------------------------------------------------------------------------------

// "0:05", "12:34", "1:02:03"
std::string clock_text(double seconds) {
  const long s = std::lround(seconds);
  char buf[32];
  if (s >= 3600) {
    std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", s / 3600, s / 60 % 60, s % 60);
  } else {
    std::snprintf(buf, sizeof buf, "%ld:%02ld", s / 60, s % 60);
  }
  return buf;
}

// "5 s", "3 min 20 s", "2 h 5 min"
std::string duration_text(double seconds) {
  const long s = std::lround(seconds);
  char buf[48];
  if (s >= 3600) {
    std::snprintf(buf, sizeof buf, "%ld h %ld min", s / 3600, s / 60 % 60);
  } else if (s >= 60) {
    std::snprintf(buf, sizeof buf, "%ld min %ld s", s / 60, s % 60);
  } else {
    std::snprintf(buf, sizeof buf, "%ld s", s);
  }
  return buf;
}

// the progress display on stderr: a bar redrawn in place at most ten times a second, or a plain
// line every 10 s; both end with the final state. The rate is over the points run in this
// session, the done count includes the resumed ones.
class Progress {
 public:
  Progress(SweepProgress mode, int points, int resumed)
      : mode_(mode), points_(points), resumed_(resumed), start_(Clock::now()) {
    if (mode_ == SweepProgress::kAuto) {
      mode_ = ::isatty(STDERR_FILENO) ? SweepProgress::kBar : SweepProgress::kLines;
    }
    last_ = start_;
  }

  void update(int done) {
    const Clock::time_point now = Clock::now();
    if (mode_ == SweepProgress::kBar && now - last_ >= std::chrono::milliseconds(100)) {
      draw_bar(done, now);
      last_ = now;
    } else if (mode_ == SweepProgress::kLines && now - last_ >= std::chrono::seconds(10)) {
      print_line(done, now);
      last_ = now;
    }
  }

  void finish(int done) {
    const Clock::time_point now = Clock::now();
    if (mode_ == SweepProgress::kBar) {
      draw_bar(done, now);
      std::fputc('\n', stderr);
      std::fflush(stderr);
    } else if (mode_ == SweepProgress::kLines) {
      print_line(done, now);
    }
  }

 private:
  // points per second in this session, and the seconds left at that rate (< 0: unknown)
  std::pair<double, double> rate_eta(int done, Clock::time_point now) const {
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    const int run = done - resumed_;
    if (run <= 0 || elapsed <= 0) return {0.0, done >= points_ ? 0.0 : -1.0};
    const double rate = run / elapsed;
    return {rate, (points_ - done) / rate};
  }

  double percent(int done) const { return points_ > 0 ? 100.0 * done / points_ : 100.0; }

  void draw_bar(int done, Clock::time_point now) {
    constexpr int kWidth = 20;
    const auto [rate, eta] = rate_eta(done, now);
    const int filled =
        points_ > 0 ? static_cast<int>(kWidth * static_cast<long>(done) / points_) : kWidth;
    char line[160];
    std::snprintf(line, sizeof line, "  sweep [%s%s]  %d/%d  %.1f%%   %.1f points/s  ETA %s",
                  std::string(static_cast<std::size_t>(filled), '#').c_str(),
                  std::string(static_cast<std::size_t>(kWidth - filled), '.').c_str(), done,
                  points_, percent(done), rate, eta < 0 ? "-:--" : clock_text(eta).c_str());
    std::string text = line;
    const std::size_t width = text.size();
    if (width < drawn_) text.append(drawn_ - width, ' ');  // clear the longer line before
    drawn_ = width;
    std::fprintf(stderr, "\r%s", text.c_str());
    std::fflush(stderr);
  }

  void print_line(int done, Clock::time_point now) const {
    const auto [rate, eta] = rate_eta(done, now);
    std::fprintf(stderr, "sweep: %d/%d points (%.1f %%), %.1f points/s, ETA %s\n", done, points_,
                 percent(done), rate, eta < 0 ? "unknown" : duration_text(eta).c_str());
    std::fflush(stderr);
  }

  SweepProgress mode_;
  int points_, resumed_;
  Clock::time_point start_, last_;
  std::size_t drawn_ = 0;  // width of the bar line last drawn
};

// Test hook: with BD_SWEEP_KILL_AFTER_ROWS=N in the environment, the process kills itself
// (SIGKILL) right after sweep.csv holds N rows, so tests can interrupt a sweep at a known
// place. Unset or not a positive number: no effect.
int kill_after_rows() {
  const char* env = std::getenv("BD_SWEEP_KILL_AFTER_ROWS");
  if (!env) return 0;
  char* end = nullptr;
  const long n = std::strtol(env, &end, 10);
  return end != env && *end == '\0' && n > 0 && n < 1'000'000'000 ? static_cast<int>(n) : 0;
}

}  // namespace

std::vector<std::string> sweep_columns(const Study& study) {
  std::vector<std::string> columns = {"point"};
  if (study.sweep) {
    for (const SweepParameter& p : study.sweep->parameters) columns.push_back(p.path);
  }
  for (const core::MetricInfo& m : core::kMetricTable) columns.push_back(m.name);
  for (const char* prefix : {"balanced_", "optimized_"}) {
    if (prefix[0] == 'b' ? !study.balance : !study.optimize) continue;
    for (const core::MetricInfo& m : core::kMetricTable)
      columns.push_back(std::string(prefix) + m.name);
    columns.push_back("added_mass");
    columns.push_back("added_inertia");
  }
  columns.push_back("status");
  columns.push_back("message");
  return columns;
}

SweepResult run_sweep(const Study& study, const fs::path& out_dir, const SweepOptions& options) {
  if (!study.sweep) throw InputError("run_sweep: study '" + study.name + "' has no sweep section");
  const Clock::time_point start = Clock::now();
  const std::vector<std::vector<double>> points = sweep_points(*study.sweep);
  const int n = static_cast<int>(points.size());
  const std::size_t columns = sweep_columns(study).size();
  const std::size_t cells = columns - 3 - study.sweep->parameters.size();  // metric cells
  const std::string header = header_line(study);

  SweepResult result;
  result.points = n;
  result.csv = out_dir / "sweep.csv";
  result.summary = out_dir / "sweep.json";

  // what the folder holds already
  const std::string old_csv = read_or_empty(result.csv);
  const std::string old_json = read_or_empty(result.summary);
  const CsvRows old = split_rows(old_csv);
  std::optional<rs::Json> old_summary;
  if (!old_json.empty()) {
    try {
      old_summary = rs::parse_json(old_json, result.summary.string());
    } catch (const std::runtime_error&) {
      // unreadable: a sweep.csv beside it cannot be checked (below)
    }
  }

  int kept = 0, kept_failed = 0;
  if (!old_csv.empty() && !options.resume) {
    // a finished sweep is replaced; an unfinished one only on request
    int folder_points = n;
    if (old_summary) {
      if (const rs::Json* p = old_summary->get("points"))
        folder_points = std::atoi(p->text.c_str());
    }
    if (static_cast<int>(old.rows.size()) < folder_points) {
      throw InputError(out_dir.string() + " holds an unfinished sweep (" +
                       std::to_string(old.rows.size()) + " of " + std::to_string(folder_points) +
                       " points): pass --resume to continue it, or remove the folder to start "
                       "over");
    }
  } else if (!old_csv.empty() && old.has_header) {
    // resume: the rows must be this sweep's, point by point
    if (!old_summary) refuse(out_dir, "its sweep.json is missing or unreadable");
    if (const std::string why = identity_difference(*old_summary, study, n); !why.empty()) {
      refuse(out_dir, why);
    }
    if (old.header != header) refuse(out_dir, "the sweep.csv header differs");
    if (static_cast<int>(old.rows.size()) > n) {
      refuse(out_dir, "sweep.csv has " + std::to_string(old.rows.size()) + " rows for " +
                          std::to_string(n) + " points");
    }
    for (std::size_t i = 0; i < old.rows.size(); ++i) {
      if (const std::string why = row_problem(old.rows[i], i, columns, points[i]); !why.empty()) {
        throw InputError(result.csv.string() + ": row " + std::to_string(i + 1) + " is not point " +
                         std::to_string(i) + " of this design (" + why +
                         "); remove the folder to start over");
      }
      const std::vector<std::string> f = rs::csv_fields(old.rows[i]);
      if (f[columns - 2] != "ok") ++kept_failed;
    }
    kept = static_cast<int>(old.rows.size());
  }

  const int remaining = n - kept;
  const int wanted = options.threads > 0 ? options.threads
                     : study.sweep->threads > 0
                         ? study.sweep->threads
                         : static_cast<int>(std::thread::hardware_concurrency());
  const int threads = std::min(std::max(wanted, 1), remaining);
  Counts counts;
  counts.done = kept;
  counts.resumed = kept;
  counts.failed = kept_failed;
  counts.threads = threads;

  // the folder, sweep.json (first: a sweep.csv is never left without the sweep.json that
  // identifies it), and sweep.csv: the kept rows (a last line cut short dropped) or a new header
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) {
    throw std::runtime_error("cannot create the output directory " + out_dir.string() + ": " +
                             ec.message());
  }
  write_text_file(sweep_json(study, n, counts), result.summary);
  if (options.resume && old.has_header) {  // checked above: this sweep's header and rows
    if (old.complete_size != old_csv.size()) {
      fs::resize_file(result.csv, old.complete_size, ec);
      if (ec) {
        throw std::runtime_error("cannot truncate " + result.csv.string() + ": " + ec.message());
      }
    }
  } else {
    write_text_file(header + "\n", result.csv);
  }

  // the workers take points in order from a shared counter and hand finished rows to this
  // thread, the only writer, which appends them in point order
  std::mutex mutex;
  std::condition_variable changed;
  std::map<int, PointRow> finished;  // rows not written yet (a later point may finish first)
  int completed = kept;              // points done, written or not
  int workers_done = 0;
  std::atomic<int> next_point{kept};
  std::atomic<bool> halt{false};  // the writer failed: the workers stop too
  auto stopping = [&] { return halt.load() || (options.stop != nullptr && options.stop->load()); };

  Progress progress(options.progress, n, kept);
  const int kill_after = kill_after_rows();
  int written = kept;
  RowFile csv(result.csv);
  {
    std::vector<std::jthread> workers;
    try {
      for (int t = 0; t < threads; ++t) {
        workers.emplace_back([&] {
          while (!stopping()) {
            const int i = next_point.fetch_add(1);
            if (i >= n) break;
            PointRow row = point_row(study, i, points[static_cast<std::size_t>(i)], cells);
            {
              const std::lock_guard<std::mutex> lock(mutex);
              finished.emplace(i, std::move(row));
              ++completed;
            }
            changed.notify_one();
          }
          {
            const std::lock_guard<std::mutex> lock(mutex);
            ++workers_done;
          }
          changed.notify_one();
        });
      }

      std::unique_lock<std::mutex> lock(mutex);
      for (;;) {
        changed.wait_for(lock, std::chrono::milliseconds(100), [&] {
          return workers_done == threads ||
                 (!finished.empty() && finished.begin()->first == written);
        });
        std::vector<PointRow> batch;  // the next rows in point order
        for (auto it = finished.begin(); it != finished.end() && it->first == written;
             it = finished.erase(it)) {
          batch.push_back(std::move(it->second));
          ++written;
        }
        const bool last = workers_done == threads;
        assert(!last || finished.empty());
        const int done_now = completed;
        lock.unlock();
        int rows = written - static_cast<int>(batch.size());
        for (const PointRow& row : batch) {
          csv.append(row.text);
          if (!row.ok) ++counts.failed;
          if (++rows == kill_after) std::raise(SIGKILL);
        }
        progress.update(done_now);
        // every point started has finished once the workers are done, and points start in
        // order: nothing is left behind
        if (last) break;
        lock.lock();
      }
    } catch (...) {
      halt = true;
      workers.clear();  // joins them
      throw;
    }
  }  // the workers join here
  csv.close();

  counts.done = written;
  counts.status = written == n ? "complete" : "interrupted";
  counts.elapsed_s = std::chrono::duration<double>(Clock::now() - start).count();
  progress.finish(written);
  write_text_file(sweep_json(study, n, counts), result.summary);

  result.done = written;
  result.resumed = kept;
  result.failed = counts.failed;
  result.interrupted = written < n;

  // the report is read back from the files just written; it never fails the sweep
  try {
    write_sweep_report(study, out_dir);
  } catch (const std::exception& e) {
    fs::remove(out_dir / "report.html", ec);  // never a stale page of an earlier run
    std::fprintf(stderr, "balance-design: warning: report.html not written: %s\n", e.what());
  }
  return result;
}

}  // namespace bd::studies
