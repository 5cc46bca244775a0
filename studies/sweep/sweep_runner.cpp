// Running a sweep: the sweep.csv columns, the points computed on worker threads, the rows
// appended in point order by one writer, the progress display, sweep.json, and resuming an
// interrupted sweep. The points and each point's study come from sweep.cpp, the report from
// sweep_report.cpp.
#include <fcntl.h>
#include <sys/stat.h>
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
#include <fstream>
#include <functional>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

#include "core/input_error.hpp"
#include "core/number_text.hpp"
#include "studies/run/runner.hpp"
#include "studies/sweep/point_setter.hpp"
#include "studies/sweep/sweep.hpp"

namespace bd::studies {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using Json = nlohmann::ordered_json;

namespace {

// the statuses a row may have (sweep.hpp, sweep_columns())
constexpr const char* kStatuses[] = {"ok", "stopped-early", "no-optimum", "bad-input", "error"};

std::string header_line(const Study& study) {
  std::string line;
  for (const std::string& c : sweep_columns(study))
    line += (line.empty() ? "" : ",") + csv_field(c);
  return line;
}

}  // namespace

std::string sweep_fingerprint(const std::string& text) {
  std::uint64_t h = 14695981039346656037ull;
  for (char c : text) {
    h ^= static_cast<unsigned char>(c);
    h *= 1099511628211ull;
  }
  char buf[20];
  std::snprintf(buf, sizeof buf, "%016" PRIx64, h);
  return buf;
}

namespace {

// --- one point -------------------------------------------------------------------------------

// appends the cells of a second design (balanced or optimised): its metrics, added mass and
// inertia, or as many empty cells
// (`count`: how many metrics the study's linkage has)
void second_design_cells(std::string& row, const MetricList* metrics, const MetricList& columns,
                         double added_mass, double added_inertia) {
  if (!metrics) {
    row.append(columns.size() + 2, ',');
    return;
  }
  // by name, in the original's order: a balanced design's own parts (a balance shaft's
  // bearing, as many as the point's synthesis adds) have no column
  for (const MetricValue& c : columns) {
    row += ",";
    for (const MetricValue& m : *metrics) {
      if (m.name == c.name) {
        char buf[32];
        row += text::exact_chars(m.value, buf);
        break;
      }
    }
  }
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

// how many metric cells a row of `study`'s sweep has (a failed point's are all empty)
std::size_t metric_cells(const Study& study) {
  return sweep_columns(study).size() - 3 - study.sweep->parameters.size();
}

}  // namespace

SweepRow sweep_row(const Study& base, int index, std::span<const double> values) {
  std::string head = std::to_string(index);
  for (double v : values) head += "," + text::shortest(v);  // the swept values as a person wrote them
  std::string status = "ok", message;
  std::string body;
  try {
    const Study study = detail::sweep_point_study(base, values);
    const RunResult r = compute_study(study, ComputeParts{.harmonics = false});
    char buf[32];
    for (const MetricValue& m : r.metric_list) {
      body += ',';
      body += text::exact_chars(m.value, buf);
    }
    if (base.balance || base.planar_balance) {
      const bool have = r.balanced && (study.balance || r.balanced->design);
      const auto [mass, inertia] = have ? added(study, r) : std::pair<double, double>{};
      second_design_cells(body, have ? &r.balanced->metric_list : nullptr, r.metric_list, mass,
                          inertia);
    }
    if (base.optimizes()) {
      const bool have = r.optimized && r.optimized->found();
      const auto [mass, inertia] = have ? added(study, r) : std::pair<double, double>{};
      second_design_cells(body, have ? &r.optimized->metric_list : nullptr, r.metric_list, mass,
                          inertia);
    }
    if (r.stopped_early()) {
      status = "stopped-early";
      if (!r.status().ok()) {
        message = r.status().message;
      } else if (r.balanced && !r.balanced->ok()) {
        message = "balanced design: " + r.balanced->status().message;
      } else {
        message = "optimised design: " + r.optimized->status().message;
      }
    } else if (r.optimized && !r.optimized->found()) {
      status = "no-optimum";
      message = r.optimized->message();
    }
  } catch (const InputError& e) {  // StudyError from point_study() included
    status = "bad-input";
    message = e.what();
    body.assign(metric_cells(base), ',');
  } catch (const std::exception& e) {
    status = "error";
    message = e.what();
    body.assign(metric_cells(base), ',');
  } catch (...) {
    status = "error";
    message = "unknown exception";
    body.assign(metric_cells(base), ',');
  }
  SweepRow row;
  row.ok = status == "ok";
  row.text = head + body + "," + status + "," + csv_line_field(message) + "\n";
  return row;
}

namespace {

// --- sweep.json ------------------------------------------------------------------------------

// the grid's range as sweep.json states it: from/to as given, or the values' min and max
std::pair<double, double> range_of(const SweepParameter& p, SweepDesign design) {
  if (design != SweepDesign::kGrid || p.from != p.to || p.values.empty()) return {p.from, p.to};
  const auto [lo, hi] = std::minmax_element(p.values.begin(), p.values.end());
  return {*lo, *hi};
}

// the keys that say which sweep a folder holds (checked when resuming)
Json identity_json(const Study& study, int points) {
  const SweepRequest& req = *study.sweep;
  Json parameters = Json::array();
  for (const SweepParameter& p : req.parameters) {
    const auto [from, to] = range_of(p, req.design);
    Json j = {
        {"path", p.path}, {"scale", p.log_scale ? "log" : "linear"}, {"from", from}, {"to", to}};
    if (req.design == SweepDesign::kGrid) j["values"] = p.values;
    parameters.push_back(j);
  }
  return {{"fingerprint", sweep_fingerprint(req.study_text)},
          {"design", to_string(req.design)},
          {"seed", req.seed},
          {"points", points},
          {"parameters", parameters}};
}

struct Counts {
  const char* status = "running";  // running | interrupted | complete
  int done{}, resumed{}, failed{}, threads{};
  double elapsed_s{};
};

std::string sweep_json(const Study& study, int points, const Counts& c) {
  const Json identity = identity_json(study, points);
  Json j = {{"study", study.name}, {"source", study.source}};
  for (const auto& [key, value] : identity.items()) {
    if (key == "parameters") j["threads"] = c.threads;  // threads after points, as the docs list
    j[key] = value;
  }
  j["status"] = c.status;
  j["done"] = c.done;
  j["resumed"] = c.resumed;
  j["failed"] = c.failed;
  j["elapsed_s"] = std::round(c.elapsed_s * 1000) / 1000;  // to the millisecond
  check_json_numbers(j, "sweep.json");
  return j.dump(2, ' ', false, Json::error_handler_t::replace) + "\n";
}

// --- the folder's earlier sweep --------------------------------------------------------------

std::string read_or_empty(const fs::path& p) {
  std::error_code ec;
  if (!fs::exists(p, ec)) return {};
  return read_file(p);
}

// a value as sweep.json shows it in a message ("nothing" when absent)
std::string shown(const Json& j, const char* key) {
  if (!j.contains(key)) return "nothing";
  const Json& v = j[key];
  return v.is_string() ? v.get<std::string>() : v.dump();
}

// what differs between the folder's sweep.json and this sweep, in words; empty when alike
// (numbers compare as the doubles they read back as: the writer's text is exact)
std::string identity_difference(const Json& old, const Study& study, int points) {
  const Json now = identity_json(study, points);
  if (!old.contains("fingerprint") || old["fingerprint"] != now["fingerprint"]) {
    return "the study file differs (fingerprint " + shown(now, "fingerprint") + ", was " +
           shown(old, "fingerprint") + ")";
  }
  for (const char* key : {"design", "seed", "points"}) {
    if (!old.contains(key) || old[key] != now[key]) {
      return std::string(key) + " " + shown(now, key) + ", was " + shown(old, key);
    }
  }
  if (!old.contains("parameters") || old["parameters"] != now["parameters"]) {
    return "the parameters differ";
  }
  return {};
}

// sweep.csv's complete lines, one at a time (a last line without its '\n' was cut short by a
// kill and is not one), read through a buffer: a sweep of 10^6 rows is never held whole
class CsvLines {
 public:
  explicit CsvLines(const fs::path& file) : in_(file, std::ios::binary) {}
  bool opened() const { return in_.is_open(); }
  // the next complete line, without its '\n'; false at the end
  bool next(std::string& line) {
    if (!std::getline(in_, line) || in_.eof()) return false;
    complete_size_ += line.size() + 1;
    return true;
  }
  // bytes up to the end of the last complete line read
  std::uintmax_t complete_size() const { return complete_size_; }

 private:
  std::ifstream in_;
  std::uintmax_t complete_size_{};
};

// what is wrong with kept row i, in words; empty when it is the row of point i of this design
std::string row_problem(const std::string& line, std::size_t i, std::size_t columns,
                        std::span<const double> values) {
  const std::vector<std::string> f = csv_fields(line);
  if (f.size() != columns) {
    return "it has " + std::to_string(f.size()) + " fields, the header " + std::to_string(columns);
  }
  if (f[0] != std::to_string(i)) return "its point is '" + f[0] + "'";
  for (std::size_t j = 0; j < values.size(); ++j) {
    // compared as numbers: a row written by an earlier version has %.17g text
    if (std::strtod(f[1 + j].c_str(), nullptr) != values[j]) {
      return "its parameter " + std::to_string(j + 1) + " is " + f[1 + j] + ", the design's " +
             text::shortest(values[j]);
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
// one line cut short; a row that cannot be written whole (a full disk, a file-size limit) is
// taken back, so the file ends with whole rows. The file's length is kept here (this is its
// only writer) rather than asked of the kernel for every row.
class RowFile {
 public:
  explicit RowFile(fs::path file) : file_(std::move(file)) {
    fd_ = ::open(file_.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
    if (fd_ < 0) fail("cannot open");
    struct stat st {};
    if (::fstat(fd_, &st) != 0) fail("cannot open");
    end_ = st.st_size;
  }
  RowFile(const RowFile&) = delete;
  RowFile& operator=(const RowFile&) = delete;
  ~RowFile() {
    if (fd_ >= 0) ::close(fd_);
  }

  void append(const std::string& row) {
    const off_t before = end_;
    const char* p = row.data();
    std::size_t left = row.size();
    while (left > 0) {  // one write unless the kernel takes less (a full disk)
      const ssize_t n = ::write(fd_, p, left);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        const int saved = errno == 0 ? ENOSPC : errno;  // write(2) taking 0 bytes: no space
        if (::ftruncate(fd_, before) != 0) {
          // the row stays cut short (--resume drops it); the error said is the write's
        }
        errno = saved;
        fail("cannot write");
      }
      p += n;
      left -= static_cast<std::size_t>(n);
    }
    end_ += static_cast<off_t>(row.size());
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
  off_t end_ = 0;  // the file's length: where the next row starts
};

}  // namespace

std::vector<std::string> sweep_columns(const Study& study) {
  std::vector<std::string> columns = {"point"};
  if (study.sweep) {
    for (const SweepParameter& p : study.sweep->parameters) columns.push_back(p.path);
  }
  for (const std::string& m : metric_names(study)) columns.push_back(m);
  for (const char* prefix : {"balanced_", "optimized_"}) {
    const bool balance = study.balance || study.planar_balance;
    if (prefix[0] == 'b' ? !balance : !study.optimizes()) continue;
    for (const std::string& m : metric_names(study)) columns.push_back(prefix + m);
    columns.push_back("added_mass");
    columns.push_back("added_inertia");
  }
  columns.push_back("status");
  columns.push_back("message");
  return columns;
}

namespace {

// What the folder holds already, checked against this sweep: the rows a resumed sweep keeps.
// sweep.csv is read row by row, never whole.
struct Existing {
  std::uintmax_t csv_size{};       // sweep.csv's bytes as found (0 for none)
  bool has_header = false;         // it has a complete header line
  std::uintmax_t complete_size{};  // bytes up to its last '\n'
  int kept{}, kept_failed{};
};

Existing existing_rows(const Study& study, const fs::path& out_dir, const SweepResult& result,
                       const SweepOptions& options, int n, const std::string& header,
                       std::size_t columns) {
  Existing e;
  std::error_code ec;
  e.csv_size = fs::exists(result.csv, ec) ? fs::file_size(result.csv, ec) : 0;
  if (ec) e.csv_size = 0;
  const std::string old_json = read_or_empty(result.summary);
  std::optional<Json> old_summary;
  if (!old_json.empty()) {
    // unreadable: a sweep.csv beside it cannot be checked (below)
    Json j = Json::parse(old_json, nullptr, false);
    if (!j.is_discarded() && j.is_object()) old_summary = std::move(j);
  }
  if (e.csv_size == 0) return e;
  CsvLines lines(result.csv);
  if (!lines.opened()) throw std::runtime_error("cannot read " + result.csv.string());
  std::string line;
  e.has_header = lines.next(line);
  const bool header_matches = e.has_header && line == header;
  e.complete_size = lines.complete_size();
  if (!options.resume) {
    // a finished sweep is replaced; an unfinished one only on request
    if (const std::string why = unfinished_sweep(out_dir, n); !why.empty()) {
      // --resume continues this study's sweep only: another study's is said to be so
      if (const std::string other =
              old_summary ? identity_difference(*old_summary, study, n) : std::string();
          !other.empty()) {
        throw InputError(why + " of another study (" + other +
                         "): remove the folder to start over, or write this sweep elsewhere "
                         "with --out");
      }
      throw InputError(why + ": pass --resume to continue it, or remove the folder to start over");
    }
    return e;
  }
  if (!e.has_header) return e;
  // resume: the rows must be this sweep's, point by point
  if (!old_summary) refuse(out_dir, "its sweep.json is missing or unreadable");
  if (const std::string why = identity_difference(*old_summary, study, n); !why.empty()) {
    refuse(out_dir, why);
  }
  if (!header_matches) refuse(out_dir, "the sweep.csv header differs");
  PointCursor points(*study.sweep);
  int i = 0;
  for (; lines.next(line); ++i) {
    if (i >= n) {
      long rows = i + 1;
      while (lines.next(line)) ++rows;
      refuse(out_dir, "sweep.csv has " + std::to_string(rows) + " rows for " + std::to_string(n) +
                          " points");
    }
    const auto at = static_cast<std::size_t>(i);
    if (const std::string why = row_problem(line, at, columns, points.at(i)); !why.empty()) {
      throw InputError(result.csv.string() + ": row " + std::to_string(i + 1) + " is not point " +
                       std::to_string(i) + " of this design (" + why +
                       "); remove the folder to start over");
    }
    const std::vector<std::string> f = csv_fields(line);
    if (f[columns - 2] != "ok") ++e.kept_failed;
  }
  e.kept = i;
  e.complete_size = lines.complete_size();
  return e;
}

// The folder, sweep.json (first: a sweep.csv is never left without the sweep.json that
// identifies it), and sweep.csv: the kept rows (a last line cut short dropped) or a new header.
void start_files(const Study& study, const fs::path& out_dir, const SweepResult& result,
                 const SweepOptions& options, const Existing& existing, const std::string& header,
                 const Counts& counts) {
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) {
    throw std::runtime_error("cannot create the output directory " + out_dir.string() + ": " +
                             ec.message());
  }
  remove_stale_temporaries(out_dir);  // of a sweep killed here before
  // a single run's files: the folder holds one sweep and nothing of another study
  for (const char* name : kRunFiles) {
    if (std::string_view(name) == "study.yaml") continue;  // written below
    if (fs::remove(out_dir / name, ec); ec) {
      throw std::runtime_error("cannot remove the earlier run's " + (out_dir / name).string() +
                               ": " + ec.message());
    }
  }
  // the study itself, which `balance-design report DIR` reads from the folder
  if (study.sweep) write_text_file(study.sweep->study_text, out_dir / "study.yaml");
  write_text_file(sweep_json(study, result.points, counts), result.summary);
  if (options.resume && existing.has_header) {  // checked: this sweep's header and rows
    if (existing.complete_size != existing.csv_size) {
      fs::resize_file(result.csv, existing.complete_size, ec);
      if (ec) {
        throw std::runtime_error("cannot truncate " + result.csv.string() + ": " + ec.message());
      }
    }
  } else {
    write_text_file(header + "\n", result.csv);
  }
}

// most rows computed and waiting for an earlier point before they are written: a slow point
// holds back at most this many rows in memory (a few MB), whatever the number of points
constexpr int kRowsAhead = 1 << 14;
// Rows ready in point order that wake the writer, instead of a wake-up per row (a driven point
// costs some 100 µs of CPU, and waking the writer for each row cost a tenth of that in the
// kernel): a 1024th of the points, between 1 and kMaxRowsPerWake, so that a small sweep still
// writes each row as it comes (and a stop, Ctrl-C or a progress hook's, finds few rows
// finished and not yet written). The writer also wakes every `wait` (100 ms alone) and writes
// what is ready, so a finished row waits at most that long before it is in sweep.csv.
constexpr int kMaxRowsPerWake = 256;
int rows_per_wake(int points) { return std::clamp(points / 1024, 1, kMaxRowsPerWake); }

// The points of a sweep being computed: handed out in order to this process's threads and to
// the peers, their rows kept until every earlier point is written.
class PointQueue final : public SweepWork {
 public:
  PointQueue(const SweepRequest& sweep, int first, const SweepOptions& options)
      : points_(sweep),
        next_(first),
        written_(first),
        n_(points_.size()),
        rows_per_wake_(rows_per_wake(n_)),
        options_(options) {}

  // under the lock (lock())
  SweepClaim claim(int count) override {
    if (stopping() || next_ >= n_) return {next_, next_, false};
    if (next_ - written_ >= kRowsAhead) return {next_, next_, true};
    const int begin = next_;
    next_ = std::min(n_, next_ + std::max(count, 1));
    return {begin, next_, false};
  }
  int unclaimed() const override { return n_ - next_; }
  void deliver(int point, SweepRow row) override {
    finished_.emplace(point, std::move(row));
    // the rows ready in order now end at in_order_end_
    if (point == in_order_end_) {
      for (auto it = finished_.find(point); it != finished_.end() && it->first == in_order_end_;
           ++it) {
        ++in_order_end_;
      }
      if (in_order_end_ - written_ >= rows_per_wake_) changed_.notify_one();
    }
  }

  std::unique_lock<std::mutex> lock() { return std::unique_lock<std::mutex>(mutex_); }
  bool stopping() const {
    return halt_.load() || (options_.stop != nullptr && options_.stop->load());
  }
  void halt() { halt_ = true; }

  // a local thread's next point and its values, waiting while too many rows wait to be
  // written; -1 when none
  int next_point(std::vector<double>& values) {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      const SweepClaim c = claim(1);
      if (!c.later) {
        if (c.empty()) return -1;
        // points are claimed in increasing order, as the cursor wants them
        const std::span<const double> v = points_.at(c.begin);
        values.assign(v.begin(), v.end());
        return c.begin;
      }
      room_.wait_for(lock, std::chrono::milliseconds(50));
    }
  }
  void local_row(int point, SweepRow row) {
    const std::lock_guard<std::mutex> lock(mutex_);
    deliver(point, std::move(row));
  }
  void local_worker_done() {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      ++workers_done_;
    }
    changed_.notify_one();
  }

  // the writer: waits (`lock` held) up to `wait` for rows_per_wake_ rows in order, or for the
  // end, then takes the rows ready in point order
  std::vector<SweepRow> ready_rows(std::unique_lock<std::mutex>& lock,
                                   std::chrono::milliseconds wait, int threads, bool peers_done) {
    changed_.wait_for(lock, wait, [&] {
      return (workers_done_ == threads && peers_done) ||
             in_order_end_ - written_ >= rows_per_wake_;
    });
    std::vector<SweepRow> batch;
    for (auto it = finished_.begin(); it != finished_.end() && it->first == written_;
         it = finished_.erase(it)) {
      batch.push_back(std::move(it->second));
      ++written_;
    }
    if (!batch.empty()) room_.notify_all();
    return batch;
  }
  bool workers_done(int threads) const { return workers_done_ == threads; }
  bool nothing_waiting() const { return finished_.empty(); }
  int written() const { return written_; }

 private:
  std::mutex mutex_;
  std::condition_variable changed_, room_;
  std::map<int, SweepRow> finished_;  // rows not written yet (a later point may finish first)
  PointCursor points_;                // the values of the points handed to local threads
  int next_, written_, n_;
  int rows_per_wake_;
  int in_order_end_ = written_;  // the first point after written_ whose row is not finished
  int workers_done_ = 0;
  std::atomic<bool> halt_{false};  // the writer failed: the workers stop too
  const SweepOptions& options_;
};

// Computes points `first`..n-1 on `threads` workers of this process (which take points in order,
// one at a time) and on options.peers (which claim them in chunks), and appends the rows to
// sweep.csv in point order on this thread, the only writer. Returns the number of rows sweep.csv
// holds at the end (fewer than n when stopped); counts.failed counts the failed rows.
int compute_points(const Study& study, int first, int threads, const SweepOptions& options,
                   const fs::path& csv_file, Counts& counts,
                   const std::function<void(int, bool)>& report_progress) {
  PointQueue queue(*study.sweep, first, options);
  RowFile csv(csv_file);
  // with peers, the writer polls them every 2 ms; alone, it wakes for rows
  const auto wait = std::chrono::milliseconds(options.peers ? 2 : 100);
  bool peers_done = options.peers == nullptr;
  {
    std::vector<std::jthread> workers;
    try {
      for (int t = 0; t < threads; ++t) {
        workers.emplace_back([&] {
          std::vector<double> values;
          for (int i; (i = queue.next_point(values)) >= 0;) {
            queue.local_row(i, sweep_row(study, i, values));
          }
          queue.local_worker_done();
        });
      }
      std::unique_lock<std::mutex> lock = queue.lock();
      for (;;) {
        if (!peers_done) peers_done = options.peers->poll(queue);
        std::vector<SweepRow> batch = queue.ready_rows(lock, wait, threads, peers_done);
        const bool last = queue.workers_done(threads) && peers_done && batch.empty();
        assert(!last || queue.nothing_waiting());
        int rows = queue.written() - static_cast<int>(batch.size());
        lock.unlock();
        for (const SweepRow& row : batch) {
          // one write per row, the progress told after each: a progress hook that stops the
          // sweep (an exception) leaves exactly the rows it was told of
          csv.append(row.text);
          if (!row.ok) ++counts.failed;
          counts.done = ++rows;  // what sweep.json says if a later row cannot be written
          report_progress(rows, false);
        }
        // every point handed out has come back once the workers and peers are done, and points
        // are handed out in order: nothing is left behind
        if (last) break;
        lock.lock();
      }
    } catch (...) {
      queue.halt();
      workers.clear();  // joins them
      throw;
    }
  }  // the workers join here
  csv.close();
  return queue.written();
}

}  // namespace

SweepResult write_sweep(const Study& study, const fs::path& out_dir, const SweepOptions& options) {
  if (!study.sweep)
    throw InputError("write_sweep: study '" + study.name + "' has no sweep section");
  const Clock::time_point start = Clock::now();
  const int n = sweep_size(*study.sweep);
  const std::size_t columns = sweep_columns(study).size();
  const std::string header = header_line(study);

  SweepResult result;
  result.points = n;
  result.csv = out_dir / "sweep.csv";
  result.summary = out_dir / "sweep.json";
  const Existing existing = existing_rows(study, out_dir, result, options, n, header, columns);
  const int kept = existing.kept;

  const int wanted = options.threads > 0 ? options.threads
                     : study.sweep->threads > 0
                         ? study.sweep->threads
                         : static_cast<int>(std::thread::hardware_concurrency());
  Counts counts;
  counts.done = kept;
  counts.resumed = kept;
  counts.failed = existing.kept_failed;
  const int local = std::min(std::max(wanted, 1), n - kept);
  counts.threads = local + (options.peers ? options.peers->threads() : 0);
  start_files(study, out_dir, result, options, existing, header, counts);

  auto report_progress = [&](int done, bool last_call) {
    if (!options.progress) return;
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    options.progress(SweepProgress{done, n, kept, elapsed, last_call});
  };
  int written = kept;
  try {
    written = compute_points(study, kept, local, options, result.csv, counts, report_progress);
  } catch (...) {
    // sweep.csv ends with whole rows (the one that failed was taken back); sweep.json says the
    // sweep stopped, not that it is running (a full disk may refuse this too: the error thrown
    // is the one that says why)
    counts.status = "interrupted";
    counts.elapsed_s = std::chrono::duration<double>(Clock::now() - start).count();
    try {
      write_text_file(sweep_json(study, n, counts), result.summary);
    } catch (...) {
    }
    throw;
  }

  counts.done = written;
  counts.status = written == n ? "complete" : "interrupted";
  counts.elapsed_s = std::chrono::duration<double>(Clock::now() - start).count();
  write_text_file(sweep_json(study, n, counts), result.summary);
  report_progress(written, true);

  result.done = written;
  result.elapsed_s = counts.elapsed_s;
  result.resumed = kept;
  result.failed = counts.failed;
  result.interrupted = written < n;
  return result;
}

}  // namespace bd::studies
