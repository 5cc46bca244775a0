// The balance-design executable running sweeps: killed midway (a real SIGKILL from outside, and
// one the test sets off after a known row) and resumed to the rows of an uninterrupted run, Ctrl-C
// (SIGINT) ending with exit code 5 and the rows kept, the progress output, validate and report
// of a sweep study. Needs the executable built (target balance-design).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "studies/studies.hpp"
#include "studies/study/load_study.hpp"
#include "tests/support/studies.hpp"
#include "tests/support/spawn.hpp"
#include "tests/support/text.hpp"

namespace {

namespace fs = std::filesystem;

const std::string kExe = BD_BINARY_DIR "/bin/balance-design";
const std::string kExamples = BD_SOURCE_DIR "/studies/examples";

using bd::testing::quote;

using bd::testing::read;
const auto rows = bd::testing::sweep_rows;


// the paper's loaded linkage in free motion over 20 s, `count` points of a Latin hypercube: a
// few milliseconds a point, so one thread takes a second or two
std::string free_sweep(int count) { return bd::testing::paper_free_lhs_sweep(count, ""); }

class SweepCli : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(fs::exists(kExe)) << kExe << " not built (cmake --build build --target "
                                  << "balance-design)";
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("bd_sweep_cli_test_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    // the sweep's page without charts: gnuplot's time is not what these tests are about
    ::setenv("BD_GNUPLOT", "/nonexistent", 1);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // runs `balance-design ARGS` in dir_, keeping stdout and stderr; returns the exit code, or
  // 128 + the signal that ended it
  int run(const std::string& args, const std::string& env = "") {
    const std::string cmd = "cd " + quote(dir_.string()) + " && " + env + " " + quote(kExe) + " " +
                            args + " >" + quote((dir_ / "stdout.txt").string()) + " 2>" +
                            quote((dir_ / "stderr.txt").string());
    const int status = std::system(cmd.c_str());
    out_ = read(dir_ / "stdout.txt");
    err_ = read(dir_ / "stderr.txt");
    fs::remove(dir_ / "stdout.txt");
    fs::remove(dir_ / "stderr.txt");
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  }

  // starts `balance-design ARGS...` (absolute paths) in the background, its output to files
  pid_t start(const std::vector<std::string>& args) {
    std::vector<std::string> all = {kExe};
    all.insert(all.end(), args.begin(), args.end());
    const pid_t pid = bd::testing::spawn_to_files(all, (dir_ / "child-stdout.txt").string(),
                                                  (dir_ / "child-stderr.txt").string());
    EXPECT_GT(pid, 0) << "posix_spawn failed";
    return pid;
  }

  // waits until `csv` has at least `wanted` rows (true), or the child has ended (false)
  bool wait_for_rows(pid_t pid, const fs::path& csv, long wanted) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    while (std::chrono::steady_clock::now() < deadline) {
      if (rows(csv) >= wanted) return true;
      int status = 0;
      if (::waitpid(pid, &status, WNOHANG) == pid) {
        ended_ = status;
        return false;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    return false;
  }

  // the child's wait status
  int finish(pid_t pid) {
    if (ended_ >= 0) return ended_;
    int status = 0;
    ::waitpid(pid, &status, 0);
    return status;
  }

  fs::path dir_;
  std::string out_, err_;
  int ended_ = -1;
};

TEST_F(SweepCli, KilledSweepResumesToTheRowsOfAnUninterruptedRun) {
  std::ofstream(dir_ / "free.yaml") << free_sweep(300);
  const std::string study = (dir_ / "free.yaml").string();
  ASSERT_EQ(run("free.yaml --out full --progress none"), 0) << err_;
  const std::string full = read(dir_ / "full" / "sweep.csv");
  ASSERT_EQ(rows(dir_ / "full" / "sweep.csv"), 300);

  // one thread, killed (SIGKILL: no handler runs) once three rows are written
  const pid_t pid =
      start({study, "--out", (dir_ / "killed").string(), "--threads", "1", "--progress", "none"});
  ASSERT_GT(pid, 0);
  const fs::path csv = dir_ / "killed" / "sweep.csv";
  const bool midway = wait_for_rows(pid, csv, 3);
  if (midway) ::kill(pid, SIGKILL);
  const int status = finish(pid);
  ASSERT_TRUE(midway) << "the sweep ended before the kill";
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);
  const long kept = rows(csv);
  EXPECT_GE(kept, 3);
  EXPECT_LT(kept, 300);
  EXPECT_NE(read(dir_ / "killed" / "sweep.json").find("\"status\": \"running\""),
            std::string::npos);

  // without --resume the unfinished sweep is kept and refused
  EXPECT_EQ(run("free.yaml --out killed --progress none"), 2);
  EXPECT_NE(err_.find("killed holds an unfinished sweep ("), std::string::npos) << err_;
  EXPECT_NE(err_.find("pass --resume to continue it"), std::string::npos) << err_;
  EXPECT_EQ(err_.find('\n'), err_.size() - 1) << err_;

  // resumed: every row once, the same bytes as the uninterrupted run
  ASSERT_EQ(run("free.yaml --out killed --resume --progress none"), 0) << err_;
  EXPECT_NE(out_.find("free: sweep complete, 300 of 300 points ("), std::string::npos) << out_;
  EXPECT_NE(out_.find(" resumed), 0 failed, "), std::string::npos) << out_;
  EXPECT_EQ(read(csv), full);
  EXPECT_NE(read(dir_ / "killed" / "sweep.json").find("\"status\": \"complete\""),
            std::string::npos);
}

TEST_F(SweepCli, ResumeCompletesASweepKilledAfterAKnownRow) {
  const std::string example = kExamples + "/paper-fourbar-sweep.yaml";
  ASSERT_EQ(run(quote(example) + " --out full --progress none"), 0) << err_;
  const std::string full = read(dir_ / "full" / "sweep.csv");
  ASSERT_EQ(rows(dir_ / "full" / "sweep.csv"), 441);

  // a child process runs the sweep through the library and kills itself (SIGKILL: nothing runs
  // after it) right after the 57th row is written: the test's own hook, at a known place
  const fs::path part = dir_ / "part";
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    bd::studies::SweepOptions options;
    options.threads = 2;
    options.progress = [](const bd::studies::SweepProgress& p) {
      if (p.done == 57) ::raise(SIGKILL);
    };
    try {
      bd::studies::run_sweep(bd::studies::load_study(example), part, options);
    } catch (...) {
    }
    std::_Exit(0);  // not reached when the hook fires
  }
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << "status " << status;
  EXPECT_EQ(rows(part / "sweep.csv"), 57);
  EXPECT_EQ(full.compare(0, read(part / "sweep.csv").size(), read(part / "sweep.csv")), 0);

  // the command line resumes it to the uninterrupted run's bytes
  ASSERT_EQ(run(quote(example) + " --out part --resume --progress none"), 0) << err_;
  EXPECT_NE(out_.find("441 of 441 points (57 resumed)"), std::string::npos) << out_;
  EXPECT_EQ(read(part / "sweep.csv"), full);
}

TEST_F(SweepCli, InterruptExitsFiveAndKeepsTheRows) {
  std::ofstream(dir_ / "free.yaml") << free_sweep(300);
  const std::string study = (dir_ / "free.yaml").string();
  const pid_t pid =
      start({study, "--out", (dir_ / "stopped").string(), "--threads", "1", "--progress", "lines"});
  ASSERT_GT(pid, 0);
  const fs::path csv = dir_ / "stopped" / "sweep.csv";
  const bool midway = wait_for_rows(pid, csv, 3);
  if (midway) ::kill(pid, SIGINT);
  const int status = finish(pid);
  ASSERT_TRUE(midway) << "the sweep ended before the interrupt";
  ASSERT_TRUE(WIFEXITED(status)) << "ended by signal " << WTERMSIG(status);
  EXPECT_EQ(WEXITSTATUS(status), 5);

  const long kept = rows(csv);
  EXPECT_GE(kept, 3);
  EXPECT_LT(kept, 300);
  const std::string text = read(csv);
  EXPECT_EQ(text.back(), '\n');  // whole rows only
  EXPECT_NE(read(dir_ / "stopped" / "sweep.json").find("\"status\": \"interrupted\""),
            std::string::npos);
  const std::string err = read(dir_ / "child-stderr.txt");
  const std::string n = std::to_string(kept);
  EXPECT_NE(err.find(study + ": sweep interrupted after " + n +
                     " of 300 points: run again with --resume to compute the rest\n"),
            std::string::npos)
      << err;
  EXPECT_NE(err.find("stopping once the points running are done"), std::string::npos) << err;
  // the last progress line says the sweep stopped (no time left to wait for)
  EXPECT_NE(err.find("sweep: " + n + "/300 points ("), std::string::npos) << err;
  EXPECT_TRUE(std::regex_search(
      err, std::regex("sweep: " + n + R"(/300 points \([0-9.]+ %\), [0-9.]+ points/s, stopped\n)")))
      << err;
  EXPECT_NE(
      read(dir_ / "child-stdout.txt").find("free: sweep interrupted, " + n + " of 300 points"),
      std::string::npos);

  // the rows kept are the first of the sweep, and --resume completes it
  ASSERT_EQ(run("free.yaml --out full --progress none"), 0) << err_;
  const std::string full = read(dir_ / "full" / "sweep.csv");
  EXPECT_EQ(full.compare(0, text.size(), text), 0);
  ASSERT_EQ(run("free.yaml --out stopped --resume --progress none"), 0) << err_;
  EXPECT_EQ(read(csv), full);
}

TEST_F(SweepCli, ProgressOutputAndSummaryLine) {
  const std::string example = quote(kExamples + "/paper-fourbar-sweep.yaml");
  // stderr is a file, not a terminal: auto gives plain lines, one every 10 s and one at the end
  // (only that one when the sweep takes less than 10 s, as in the Release build; under the
  // sanitizers it takes a minute)
  ASSERT_EQ(run(example + " --out res"), 0) << err_;
  EXPECT_TRUE(std::regex_match(
      err_, std::regex(R"((sweep: [0-9]+/441 points \([0-9]+\.[0-9] %\), [0-9]+\.[0-9] points/s, )"
                       R"(ETA (unknown|([0-9]+ h )?([0-9]+ min )?[0-9]+ (s|min))\n)*)"
                       R"(sweep: 441/441 points \(100\.0 %\), [0-9]+\.[0-9] points/s, done\n)")))
      << err_;
  EXPECT_TRUE(std::regex_match(
      out_, std::regex(R"(paper-fourbar-sweep: sweep complete, 441 of 441 points, 0 failed, )"
                       R"([0-9]+\.[0-9] s; wrote res/sweep\.csv, sweep\.json, report\.html\n)")))
      << out_;
  for (const char* file : {"sweep.csv", "sweep.json", "report.html"}) {
    EXPECT_TRUE(fs::exists(dir_ / "res" / file)) << file;
  }
  EXPECT_FALSE(fs::exists(dir_ / "res" / "timeseries.csv"));

  // the bar, forced: redrawn in place with '\r', ending with a newline
  ASSERT_EQ(run(example + " --out bar --progress bar --threads 1"), 0) << err_;
  EXPECT_EQ(err_.rfind("\r  sweep [", 0), 0u) << err_;
  const std::size_t last = err_.rfind('\r');
  ASSERT_NE(last, std::string::npos);
  EXPECT_TRUE(std::regex_match(
      err_.substr(last),
      std::regex(
          R"(\r  sweep \[#{20}\]  441/441  100\.0%   [0-9]+\.[0-9] points/s  done *\n)")))
      << err_.substr(last);

  // --threads 0: one per core, as sweep.threads: 0
  ASSERT_EQ(run(example + " --out none --progress none --threads 0"), 0) << err_;
  EXPECT_TRUE(err_.empty()) << err_;

  // the same rows whatever the threads
  EXPECT_EQ(read(dir_ / "bar" / "sweep.csv"), read(dir_ / "res" / "sweep.csv"));
  EXPECT_EQ(read(dir_ / "none" / "sweep.csv"), read(dir_ / "res" / "sweep.csv"));
}

TEST_F(SweepCli, ValidatePrintsTheDesignAndWritesNothing) {
  ASSERT_EQ(run("validate " + quote(kExamples + "/paper-fourbar-sweep.yaml")), 0) << err_;
  EXPECT_TRUE(err_.empty()) << err_;
  EXPECT_NE(out_.find(": ok (study paper-fourbar-sweep, driven scene, method auto)\n"
                      "  sweep    grid design, 441 points, 2 parameters\n"
                      "    linkage.coupler.mass: 21 values (1, 1.2, 1.4, ..., 5)\n"
                      "    linkage.coupler.s: 21 values (0.5, 0.6, 0.7, ..., 2.5)\n"),
            std::string::npos)
      << out_;
  EXPECT_TRUE(fs::is_empty(dir_));

  std::ofstream(dir_ / "free.yaml") << free_sweep(50);
  ASSERT_EQ(run("validate free.yaml"), 0) << err_;
  EXPECT_NE(out_.find("  sweep    lhs design, 50 points, 2 parameters, seed 1\n"
                      "    linkage.coupler.mass: drawn from 1 to 5\n"
                      "    scene.omega1: drawn from -2 to 2\n"),
            std::string::npos)
      << out_;
}

TEST_F(SweepCli, ReportRebuildsTheSweepPage) {
  ASSERT_EQ(run(quote(kExamples + "/paper-fourbar-sweep.yaml") + " --out res --progress none"), 0)
      << err_;
  ASSERT_TRUE(fs::exists(dir_ / "res" / "report.html"));
  const std::string first = read(dir_ / "res" / "report.html");
  fs::remove(dir_ / "res" / "report.html");
  EXPECT_EQ(run("report res"), 0) << err_;
  EXPECT_NE(out_.find("wrote res/report.html"), std::string::npos) << out_;
  EXPECT_EQ(read(dir_ / "res" / "report.html"), first);

  // the study file named by sweep.json's source is gone
  fs::create_directories(dir_ / "orphan");
  std::ofstream(dir_ / "orphan" / "sweep.json")
      << "{\n  \"study\": \"x\",\n  \"source\": \"gone.yaml\"\n}\n";
  EXPECT_EQ(run("report orphan"), 2);
  EXPECT_NE(err_.find("gone.yaml: cannot open the study file"), std::string::npos) << err_;
  EXPECT_NE(err_.find("orphan/sweep.json"), std::string::npos) << err_;
  EXPECT_EQ(err_.find('\n'), err_.size() - 1) << err_;
}

TEST_F(SweepCli, SweepOptionsAreChecked) {
  const std::string example = quote(kExamples + "/paper-fourbar-sweep.yaml");
  EXPECT_EQ(run(example + " --threads -1"), 2);
  EXPECT_EQ(run(example + " --threads 1025"), 2);
  EXPECT_EQ(run(example + " --progress fancy"), 2);
  EXPECT_FALSE(fs::exists(dir_ / "results"));
  // --resume is for sweeps
  EXPECT_EQ(run(quote(kExamples + "/paper-fourbar-driven.yaml") + " --out res --resume"), 2);
  EXPECT_NE(err_.find("--resume continues a sweep, and this study has no sweep section"),
            std::string::npos)
      << err_;
  EXPECT_FALSE(fs::exists(dir_ / "res"));
}

TEST_F(SweepCli, HelpDescribesSweeps) {
  EXPECT_EQ(run("--help"), 0);
  for (const char* text : {"sweep.csv", "sweep.json", "--resume", "  5  sweep interrupted",
                           "stopped-early", "bad-input"}) {
    EXPECT_NE(out_.find(text), std::string::npos) << text;
  }
  EXPECT_EQ(run("run --help"), 0);
  for (const char* text : {"--resume", "--threads", "--progress"}) {
    EXPECT_NE(out_.find(text), std::string::npos) << text;
  }
}

}  // namespace
