#pragma once
// Test support: the StudyError a study text gives, and the check of its place and one-line text.
#include <gtest/gtest.h>

#include <string>

#include "studies/study/load_study.hpp"

namespace bd::testing {

/// The error parse_study(text, file) throws; a test failure when it throws none.
inline studies::StudyError study_error_of(const std::string& text, const std::string& file) {
  try {
    studies::parse_study(text, file);
  } catch (const studies::StudyError& e) {
    return e;
  }
  ADD_FAILURE() << "no error for:\n" << text;
  return studies::StudyError("none", 0, 0, "no error");
}

/// Checks place and text, and that what() is the one-line "file:line:col: message".
inline void expect_study_error(const std::string& text, const std::string& file, int line,
                               int column, const std::string& message) {
  const studies::StudyError e = study_error_of(text, file);
  EXPECT_EQ(e.file(), file);
  EXPECT_EQ(e.line(), line) << e.what();
  EXPECT_EQ(e.column(), column) << e.what();
  EXPECT_NE(e.message().find(message), std::string::npos)
      << "expected \"" << message << "\" in \"" << e.message() << "\"";
  const std::string what = e.what();
  EXPECT_EQ(what,
            file + ":" + std::to_string(line) + ":" + std::to_string(column) + ": " + e.message());
  EXPECT_EQ(what.find('\n'), std::string::npos) << "not one line: " << what;
}

}  // namespace bd::testing
