#pragma once
// Test support: a program started in the background with its output in files, and the rows of
// a sweep.csv, for the tests that interrupt sweeps from outside.
#include <fcntl.h>
#include <spawn.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "tests/support/text.hpp"

extern char** environ;

namespace bd::testing {

/// The rows of a sweep.csv: its whole lines after the header.
inline long sweep_rows(const std::filesystem::path& csv) {
  const std::string text = read(csv);
  const long lines = std::count(text.begin(), text.end(), '\n');
  return lines > 0 ? lines - 1 : 0;
}

/// Starts `args` (args[0] the program's path) in the background, its stdout and stderr written
/// to `out` and `err`; returns its pid, or -1 when it could not be started.
inline pid_t spawn_to_files(std::vector<std::string> args, const std::string& out,
                            const std::string& err) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, out.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, err.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, args[0].c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  return rc == 0 ? pid : -1;
}

}  // namespace bd::testing
