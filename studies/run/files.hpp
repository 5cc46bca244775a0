#pragma once
/// The run's data files on disk: written whole or not at all, read back, and CSV fields quoted and
/// split one way for every writer and reader (timeseries, comparison, sweep and bench files).
#include <cstdio>
#include <filesystem>
#include <optional>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace bd::studies {

/// A file written under a temporary name in its target's folder and renamed into place by
/// commit(); removed if never committed, so a reader sees the whole file or none.
class AtomicFile {
 public:
  /// @throws std::runtime_error if the temporary file cannot be created (the message names it).
  explicit AtomicFile(std::filesystem::path target);
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  ~AtomicFile();

  std::FILE* get() { return file_; }
  /// Flushes, closes and renames the file into place.
  /// @throws std::runtime_error if writing or renaming failed (the message names the file).
  void commit();

 private:
  std::filesystem::path target_, temp_;
  std::FILE* file_ = nullptr;
  bool committed_ = false;
};

/// Removes from `dir` the temporaries of AtomicFiles ('.<name>.<pid>.<n>.tmp') whose process is
/// gone: a run killed (SIGKILL, a second Ctrl-C) before its commit leaves them, up to a whole
/// timeseries in size. Those of running processes (a sweep's other points) are kept. Quiet: a
/// temporary that cannot be removed stays.
void remove_stale_temporaries(const std::filesystem::path& dir);

/// Removes from `dir` the scratch folders or files named '<prefix><pid>-...' whose process is gone
/// (a report's gnuplot folder, 'bd-report-<pid>-XXXXXX' in the temporary directory, left by a
/// run killed while it drew). Quiet, as remove_stale_temporaries().
void remove_stale_scratch(const std::filesystem::path& dir, const std::string& prefix);

/// Throws std::runtime_error naming `file` and the key (e.g. "metrics.Fsh_rms") if `j` holds a
/// number that is NaN or an infinity: nlohmann-json would write it as null, a value that was
/// never computed. No value is written as an explicit null.
void check_json_numbers(const nlohmann::ordered_json& j, const std::filesystem::path& file);

/// What is wrong with the output folder `dir` of a single run, in one line naming the file, or ""
/// when its data files are whole: summary.json parses, every CSV of the run (kRunFiles) ends its
/// last line, each of its lines has the header's number of fields, and each timeseries has as
/// many rows as summary.json's samples. A file cut short (a copy interrupted, another program
/// filling the disk) shows here, before `balance-design report` draws from it.
std::string run_folder_problem(const std::filesystem::path& dir);

/// The sweep a folder holds: the complete rows of its sweep.csv (lines after the header) and
/// the points its sweep.json names (-1 when it names none or is unreadable).
struct SweepInFolder {
  long rows{};
  long points{-1};
  std::string source;  // the study file sweep.json names ("" when none)
};

/// The sweep in `dir`, when it holds sweep.json or sweep.csv; sweep.csv is read line by line.
std::optional<SweepInFolder> sweep_in_folder(const std::filesystem::path& dir);

/// "DIR holds an unfinished sweep (k of n points)" when `dir` holds a sweep with fewer complete
/// rows than its points (`points_if_unknown` when sweep.json names none; if that is negative, a
/// sweep without a readable sweep.json counts as unfinished), else "".
std::string unfinished_sweep(const std::filesystem::path& dir, long points_if_unknown);

/// The same for a sweep's folder: sweep.json parses. (A last line of sweep.csv cut short is an
/// interrupted sweep's, which its page shows and --resume drops.)
std::string sweep_folder_problem(const std::filesystem::path& dir);

/// Writes `text` to `file` through an AtomicFile.
/// @throws std::runtime_error if the file cannot be written (the message names it).
void write_text_file(const std::string& text, const std::filesystem::path& file);

/// The whole file at `p`. @throws std::runtime_error naming the file if it cannot be read.
std::string read_file(const std::filesystem::path& p);

/// `text` as one CSV field (RFC 4180): quoted when it holds a comma, a quote or a line break.
std::string csv_field(const std::string& text);

/// `text` as a CSV field on one line: line breaks become spaces, quoted unless empty (a message
/// in the last column of a row, so that every row is one line of the file).
std::string csv_line_field(std::string text);

/// `v` as a CSV number: its exact text ("%.17g"), an empty field for NaN or an infinity (no
/// value).
std::string csv_number(double v);

/// The fields of one CSV line (RFC 4180 quoting; a carriage return outside quotes is dropped).
std::vector<std::string> csv_fields(const std::string& line);
/// The same into `out`, whose strings are reused (no allocation per field when reading many
/// lines of one file into the same vector).
void csv_fields(std::string_view line, std::vector<std::string>& out);

}  // namespace bd::studies
