#pragma once
/// Loading and validating a study file (docs/study-format.md).
#include <string>

#include "core/input_error.hpp"
#include "studies/study/study.hpp"

namespace bd::studies {

/// A mistake in a study file, with where it is. what() is one line,
/// "FILE:LINE:COLUMN: message" (line and column 1-based), or "FILE: message" when the mistake
/// has no place in the text (the file cannot be read).
class StudyError : public InputError {
 public:
  StudyError(std::string file, int line, int column, std::string message);
  const std::string& file() const { return file_; }
  int line() const { return line_; }      // 1-based; 0 when unknown
  int column() const { return column_; }  // 1-based; 0 when unknown
  const std::string& message() const { return message_; }

 private:
  std::string file_;
  int line_;
  int column_;
  std::string message_;
};

/// Reads and validates the study file at `path` (errors name the file as `path` is written).
/// @throws StudyError on any mistake: unreadable file, YAML syntax, unknown key, wrong type,
///         missing or non-physical value, a linkage that cannot assemble at the initial crank
///         angle, or a method that is not available yet.
Study load_study(const std::string& path);

/// Same for study text already in memory; `source_name` names it in errors and in Study::source.
/// @throws StudyError as load_study().
Study parse_study(const std::string& yaml_text, const std::string& source_name);

}  // namespace bd::studies
