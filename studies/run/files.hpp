#pragma once
/// The run's data files on disk: written whole or not at all, read back, and CSV fields quoted and
/// split one way for every writer and reader (timeseries, comparison, sweep and bench files).
#include <cstdio>
#include <filesystem>
#include <string>
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

/// The fields of one CSV line (RFC 4180 quoting; a trailing '\r' is dropped).
std::vector<std::string> csv_fields(const std::string& line);

}  // namespace bd::studies
