#include "studies/run/files.hpp"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include "core/number_text.hpp"
#include "studies/run/runner.hpp"

namespace bd::studies {

namespace fs = std::filesystem;

namespace {

[[noreturn]] void fail(const char* what, const fs::path& p) {
  throw std::runtime_error(std::string(what) + " " + p.string() + ": " + std::strerror(errno));
}

// a process id or counter as written in a temporary's name
bool digits(const std::string& t) {
  return !t.empty() && t.size() < 10 &&
         std::all_of(t.begin(), t.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// true when the process `pid_text` (digits) no longer exists; false for this process, and for
// one that exists or that we may not ask about
bool process_gone(const std::string& pid_text) {
  const auto pid = static_cast<pid_t>(std::stol(pid_text));
  if (pid == ::getpid() || pid <= 0) return false;
  return ::kill(pid, 0) != 0 && errno == ESRCH;
}

std::string quote(const std::string& text) {
  std::string q = "\"";
  for (char c : text) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

}  // namespace

AtomicFile::AtomicFile(fs::path target) : target_(std::move(target)) {
  static std::atomic<unsigned> counter{0};
  // appended piece by piece: GCC 12 at -O3 warns falsely on `"." + std::string&&` (GCC bug
  // 105329, -Wrestrict)
  std::string name = ".";
  name.append(target_.filename().string()).append(".").append(std::to_string(::getpid()));
  name.append(".").append(std::to_string(counter++)).append(".tmp");
  temp_ = target_.parent_path() / name;
  file_ = std::fopen(temp_.c_str(), "wbx");
  if (!file_) fail("cannot create", target_);  // the user's file named, not the temporary
}

AtomicFile::~AtomicFile() {
  if (file_) std::fclose(file_);
  if (!committed_) {
    std::error_code ec;
    fs::remove(temp_, ec);
  }
}

void AtomicFile::commit() {
  const bool write_error = std::fflush(file_) != 0 || std::ferror(file_) != 0;
  const int saved = errno;
  const bool close_error = std::fclose(file_) != 0;
  file_ = nullptr;
  if (write_error || close_error) {
    errno = write_error ? saved : errno;
    fail("cannot write", target_);
  }
  std::error_code ec;
  fs::rename(temp_, target_, ec);
  if (ec) {
    throw std::runtime_error("cannot rename " + temp_.string() + " to " + target_.string() + ": " +
                             ec.message());
  }
  committed_ = true;
}

void remove_stale_temporaries(const fs::path& dir) {
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    // .<target>.<pid>.<counter>.tmp
    if (name.size() < 8 || name[0] != '.' || !name.ends_with(".tmp")) continue;
    const std::string stem = name.substr(0, name.size() - 4);
    const std::size_t counter = stem.rfind('.');
    if (counter == std::string::npos || counter == 0) continue;
    const std::size_t pid_at = stem.rfind('.', counter - 1);
    if (pid_at == std::string::npos || pid_at == 0) continue;
    const std::string pid_text = stem.substr(pid_at + 1, counter - pid_at - 1);
    const std::string counter_text = stem.substr(counter + 1);
    if (!digits(pid_text) || !digits(counter_text)) continue;
    if (!process_gone(pid_text)) continue;
    std::error_code rm;
    fs::remove(it->path(), rm);
  }
}

void remove_stale_scratch(const fs::path& dir, const std::string& prefix) {
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    // <prefix><pid>-...
    if (!name.starts_with(prefix)) continue;
    const std::size_t dash = name.find('-', prefix.size());
    if (dash == std::string::npos) continue;
    const std::string pid_text = name.substr(prefix.size(), dash - prefix.size());
    if (!digits(pid_text) || !process_gone(pid_text)) continue;
    std::error_code rm;
    fs::remove_all(it->path(), rm);
  }
}

namespace {

// `key.sub[3]` of the first number in `j` that is not finite, or ""
std::string non_finite_at(const nlohmann::ordered_json& j, const std::string& at) {
  if (j.is_number_float()) {
    return std::isfinite(j.get<double>()) ? std::string() : (at.empty() ? "(the top)" : at);
  }
  if (j.is_object()) {
    for (const auto& [key, value] : j.items()) {
      if (std::string where = non_finite_at(value, at.empty() ? key : at + "." + key);
          !where.empty()) {
        return where;
      }
    }
  } else if (j.is_array()) {
    for (std::size_t k = 0; k < j.size(); ++k) {
      if (std::string where = non_finite_at(j[k], at + "[" + std::to_string(k) + "]");
          !where.empty()) {
        return where;
      }
    }
  }
  return {};
}

// the number of rows of the CSV data file `file` and what is wrong with it ("" when whole),
// read line by line: a run's timeseries of 10^7 samples is some 5 GB, never held whole
std::string csv_file_problem(const fs::path& file, std::size_t* rows) {
  *rows = 0;
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + file.string());
  std::string line;
  std::vector<std::string> fields;  // reused from line to line
  std::size_t header_fields = 0, line_no = 0;
  while (std::getline(in, line)) {
    // getline stops at the file's end without a line end only on a last line cut short
    if (in.eof()) return "its last line is cut short (no line end)";
    csv_fields(line, fields);
    ++line_no;
    if (line_no == 1) {
      header_fields = fields.size();
    } else if (fields.size() != header_fields) {
      return "line " + std::to_string(line_no) + " has " + std::to_string(fields.size()) +
             " fields, the header " + std::to_string(header_fields) + " (cut short)";
    }
  }
  if (line_no == 0) return "empty";
  *rows = line_no - 1;
  return {};
}

}  // namespace

void check_json_numbers(const nlohmann::ordered_json& j, const fs::path& file) {
  if (const std::string where = non_finite_at(j, ""); !where.empty()) {
    throw std::runtime_error("internal error: " + file.string() + " would hold a number that is " +
                             "not finite at " + where + " (written as null, as if never computed)");
  }
}

namespace {

// the JSON object in `file`, or a discarded value when it is no JSON object
nlohmann::ordered_json json_object(const fs::path& file) {
  nlohmann::ordered_json j = nlohmann::ordered_json::parse(read_file(file), nullptr, false);
  if (!j.is_object()) j = nlohmann::ordered_json(nlohmann::ordered_json::value_t::discarded);
  return j;
}

}  // namespace

std::string sweep_folder_problem(const fs::path& dir) {
  const fs::path file = dir / "sweep.json";
  if (json_object(file).is_discarded()) {
    return file.string() + ": not valid JSON (cut short or damaged)";
  }
  return {};
}

std::optional<SweepInFolder> sweep_in_folder(const fs::path& dir) {
  std::error_code ec;
  const fs::path json = dir / "sweep.json", csv = dir / "sweep.csv";
  const bool has_json = fs::exists(json, ec), has_csv = fs::exists(csv, ec);
  if (!has_json && !has_csv) return std::nullopt;
  SweepInFolder s;
  if (has_json) {
    const nlohmann::ordered_json j = json_object(json);
    if (!j.is_discarded() && j.contains("points") && j["points"].is_number_integer()) {
      s.points = j["points"].get<long>();
    }
    if (!j.is_discarded() && j.contains("source") && j["source"].is_string()) {
      s.source = j["source"].get<std::string>();
    }
  }
  std::ifstream in(csv, std::ios::binary);
  std::string line;
  long lines = 0;
  while (std::getline(in, line) && !in.eof()) ++lines;  // a last line without '\n' is cut short
  s.rows = std::max(0L, lines - 1);
  return s;
}

std::string unfinished_sweep(const fs::path& dir, long points_if_unknown) {
  const std::optional<SweepInFolder> sweep = sweep_in_folder(dir);
  if (!sweep) return {};
  if (sweep->points < 0 && points_if_unknown < 0) {
    return dir.string() + " holds a sweep (" + std::to_string(sweep->rows) +
           " points done) without a readable sweep.json";
  }
  const long points = sweep->points >= 0 ? sweep->points : points_if_unknown;
  if (sweep->rows >= points) return {};
  return dir.string() + " holds an unfinished sweep (" + std::to_string(sweep->rows) + " of " +
         std::to_string(points) + " points)";
}

std::string run_folder_problem(const fs::path& dir) {
  const fs::path summary_file = dir / "summary.json";
  const nlohmann::ordered_json summary = json_object(summary_file);
  if (summary.is_discarded()) {
    return summary_file.string() + ": not valid JSON (cut short or damaged)";
  }
  std::error_code ec;
  // each timeseries and the run in summary.json that gives its samples
  const std::pair<const char*, const char*> series[] = {{"timeseries.csv", ""},
                                                        {"balanced-timeseries.csv", "balanced_run"},
                                                        {"optimized-timeseries.csv", "optimized_run"}};
  for (const char* name : kRunFiles) {
    const std::string_view n(name);
    if (!n.ends_with(".csv")) continue;
    const fs::path file = dir / name;
    if (!fs::exists(file, ec)) continue;
    std::size_t rows = 0;
    if (const std::string why = csv_file_problem(file, &rows); !why.empty()) {
      return file.string() + ": " + why;
    }
    for (const auto& [csv, run] : series) {
      if (n != csv) continue;
      const nlohmann::ordered_json& owner = *run ? summary.value(run, nlohmann::ordered_json()) : summary;
      if (!owner.is_object() || !owner.contains("samples") || !owner["samples"].is_number_unsigned()) {
        continue;
      }
      const auto samples = owner["samples"].get<std::size_t>();
      if (rows != samples) {
        return file.string() + ": " + std::to_string(rows) + " rows where summary.json says " +
               std::to_string(samples) + " samples (cut short)";
      }
    }
  }
  return {};
}

void write_text_file(const std::string& text, const fs::path& file) {
  AtomicFile out(file);
  if (std::fwrite(text.data(), 1, text.size(), out.get()) != text.size()) {
    fail("cannot write", file);
  }
  out.commit();
}

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + p.string());
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
  return quote(text);
}

std::string csv_line_field(std::string text) {
  if (text.empty()) return text;
  std::replace(text.begin(), text.end(), '\n', ' ');
  std::replace(text.begin(), text.end(), '\r', ' ');
  return quote(text);
}

// NaN and infinities are no data: an empty field (issue 17)
std::string csv_number(double v) { return std::isfinite(v) ? text::exact(v) : std::string(); }

void csv_fields(std::string_view line, std::vector<std::string>& out) {
  std::size_t k = 0;  // the field being read
  auto next_field = [&]() -> std::string& {
    if (k == out.size()) return out.emplace_back();
    out[k].clear();
    return out[k];
  };
  std::string* field = &next_field();
  bool quoted = false;
  const std::size_t n = line.size();
  for (std::size_t i = 0; i < n;) {
    if (quoted) {  // up to the closing quote; "" is a quote
      const std::size_t q = line.find('"', i);
      if (q == std::string_view::npos) {
        field->append(line.substr(i));
        break;
      }
      field->append(line.substr(i, q - i));
      if (q + 1 < n && line[q + 1] == '"') {
        *field += '"';
        i = q + 2;
      } else {
        quoted = false;
        i = q + 1;
      }
      continue;
    }
    std::size_t j = i;  // up to the next comma or quote; a carriage return is left out
    while (j < n && line[j] != ',' && line[j] != '"' && line[j] != '\r') ++j;
    field->append(line.substr(i, j - i));
    if (j == n) break;
    if (line[j] == ',') {
      ++k;
      field = &next_field();
    } else if (line[j] == '"') {
      quoted = true;
    }
    i = j + 1;
  }
  out.resize(k + 1);
}

std::vector<std::string> csv_fields(const std::string& line) {
  std::vector<std::string> out;
  csv_fields(line, out);
  return out;
}

}  // namespace bd::studies
