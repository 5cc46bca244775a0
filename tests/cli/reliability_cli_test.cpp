// The program against hostile input and injected faults (issue 17, docs/reliability.md): it
// ends, with one line and the documented exit code, whatever the study file holds; killed at any
// moment it leaves each output file old or new and whole; a full disk, an unwritable folder or a
// folder in the way is one line, not a crash; an allocation failing in the middle of a sweep's
// point fails that point only; `report` refuses a folder whose data files are cut short.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "core/number_text.hpp"
#include "studies/report/report.hpp"
#include "studies/run/files.hpp"
#include "studies/studies.hpp"
#include "studies/study/load_study.hpp"
#include "tests/support/allocation_counter.hpp"
#include "tests/support/text.hpp"

extern char** environ;

namespace {

namespace fs = std::filesystem;
const std::string kExe = BD_BINARY_DIR "/bin/balance-design";
const std::string kExamples = BD_SOURCE_DIR "/studies/examples";
using bd::testing::count;
using bd::testing::quote;
using bd::testing::read;

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAsan = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kAsan = true;
#else
constexpr bool kAsan = false;
#endif
#else
constexpr bool kAsan = false;
#endif

// a memory limit for a child: 2 GB of address space, or under AddressSanitizer (which reserves
// terabytes of address space for its shadow) 2 GB of resident memory, which it enforces itself
std::string memory_limit() {
  if (!kAsan) return "ulimit -v 2000000; ";
  const char* old = std::getenv("ASAN_OPTIONS");
  return "export ASAN_OPTIONS=" + quote(std::string(old ? old : "") + ":hard_rss_limit_mb=2000") +
         "; ";
}

// the paper's driven four-bar with full force balance (a balanced design, its study file and the
// comparison besides the original's files), `samples` samples, crank speed `omega1`
std::string balanced_study(int samples, double omega1) {
  std::string text = read(kExamples + "/paper-fourbar-driven-force-balanced.yaml");
  auto swap = [&text](const std::string& key, const std::string& value) {
    const std::size_t at = text.find("\n  " + key + ":");
    const std::size_t end = text.find('\n', at + 1);
    text.replace(at, end - at, "\n  " + key + ": " + value);
  };
  swap("samples", std::to_string(samples));
  swap("omega1", bd::text::exact(omega1));
  return text;
}

// every line of a CSV text whole: as many fields as the header, the last line ended
void expect_whole_rows(const std::string& csv, const std::string& what) {
  ASSERT_FALSE(csv.empty()) << what;
  EXPECT_EQ(csv.back(), '\n') << what;
  std::size_t fields = 0;
  std::size_t line = 0;
  for (std::size_t at = 0; at < csv.size();) {
    const std::size_t end = std::min(csv.find('\n', at), csv.size());
    const std::size_t n = bd::studies::csv_fields(csv.substr(at, end - at)).size();
    if (line++ == 0) fields = n;
    EXPECT_EQ(n, fields) << what << " line " << line;
    at = end + 1;
  }
}

class ReliabilityCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(fs::exists(kExe)) << kExe << " not built";
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("bd_reliability_cli_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // `balance-design ARGS` in dir_ under 20 s and 2 GB of address space (a hang or a runaway
  // allocation ends as a failure, not as a stuck test); the exit code, -1 when killed
  // (`limits`: more shell before the program, e.g. "ulimit -f 64; ")
  int run(const std::string& args, const std::string& limits = "") {
    const std::string cmd = "cd " + quote(dir_.string()) + " && (" + memory_limit() + limits +
                            "exec timeout 120 " + quote(kExe) + " " + args +
                            ") >out.txt 2>err.txt";
    const int status = std::system(cmd.c_str());
    err_ = read(dir_ / "err.txt");
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

  // starts `balance-design ARGS...` in the background (output to files in dir_)
  pid_t start(const std::vector<std::string>& args) {
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    const std::string out = (dir_ / "child-out.txt").string();
    const std::string err = (dir_ / "child-err.txt").string();
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, out.c_str(),
                                     O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, err.c_str(),
                                     O_WRONLY | O_CREAT | O_TRUNC, 0644);
    std::vector<std::string> all = {kExe};
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& a : all) argv.push_back(a.data());
    argv.push_back(nullptr);
    pid_t pid = -1;
    const int rc = posix_spawn(&pid, kExe.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    EXPECT_EQ(rc, 0) << "posix_spawn failed";
    return rc == 0 ? pid : -1;
  }

  // one line on stderr
  void expect_one_line() const {
    EXPECT_FALSE(err_.empty());
    EXPECT_EQ(err_.find('\n'), err_.size() - 1) << err_;
  }

  fs::path dir_;
  std::string err_;
};

// Finding 1: a file holding only ',' grew past 17 GB in a minute (yaml-cpp's LoadAll)
TEST_F(ReliabilityCliTest, AStrayCommaEndsAsOneLocatedLine) {
  std::ofstream(dir_ / "comma.yaml") << ",";
  for (const char* command : {"validate", "run"}) {
    EXPECT_EQ(run(std::string(command) + " comma.yaml"), 2) << command << ": " << err_;
    EXPECT_EQ(err_.rfind("comma.yaml:1:1: unexpected ','", 0), 0u) << err_;
    EXPECT_EQ(err_.find('\n'), err_.size() - 1) << err_;
  }
  EXPECT_FALSE(fs::exists(dir_ / "results"));
}

// Finding 7: a key holding a newline printed it raw, splitting the message
TEST_F(ReliabilityCliTest, AKeyWithANewlineStaysOnOneLine) {
  std::ofstream(dir_ / "nl.yaml") << "\"na\\nme\": t\n";
  EXPECT_EQ(run("validate nl.yaml"), 2) << err_;
  EXPECT_NE(err_.find("'na\\nme'"), std::string::npos) << err_;
  EXPECT_EQ(err_.find('\n'), err_.size() - 1) << err_;
}

// --- fault injection -------------------------------------------------------------------------

// The files of a finished run in `dir`, name -> bytes (hidden temporaries left out)
std::map<std::string, std::string> files_of(const fs::path& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name[0] != '.') out[name] = read(e.path());
  }
  return out;
}

// Killed (SIGKILL: no handler, no clean-up) at random moments while it rewrites a folder that
// holds another run's files, the run leaves each file either as the old run wrote it or as the
// new one does, whole, or absent; hidden temporaries only under their own names; and the next
// run removes those and leaves exactly the new files.
TEST_F(ReliabilityCliTest, KilledAtRandomMomentsEachFileIsOldOrNewAndWhole) {
  ::setenv("BD_GNUPLOT", "/nonexistent", 1);  // the page without charts: same bytes every run
  std::ofstream(dir_ / "a.yaml") << balanced_study(20000, 6.283185307179586);
  std::ofstream(dir_ / "b.yaml") << balanced_study(20000, 3.0);
  // both runs into the same folder, named the same way as below (summary.json and the page
  // name the study file and the folder)
  const fs::path out = dir_ / "out";
  const std::string a = (dir_ / "a.yaml").string(), b = (dir_ / "b.yaml").string();
  ASSERT_EQ(run(quote(a) + " --out " + quote(out.string())), 0) << err_;
  fs::copy(out, dir_ / "ref-a");
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_EQ(run(quote(b) + " --out " + quote(out.string())), 0) << err_;
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // the study file's copy differs between the runs too, so every file tells old from new
  const auto old_files = files_of(dir_ / "ref-a");
  const auto new_files = files_of(out);
  ASSERT_EQ(old_files.size(), new_files.size());
  ASSERT_TRUE(new_files.count("report.html") && new_files.count("summary.json"));

  std::mt19937 random(17);
  std::uniform_real_distribution<double> moment(0.0, seconds);
  int killed = 0, partial = 0;
  for (int k = 0; k < 12; ++k) {
    // the old run's files in place, then the new run killed at a random moment
    fs::remove_all(out);
    fs::copy(dir_ / "ref-a", out);
    const pid_t pid = start({b, "--out", out.string()});
    ASSERT_GT(pid, 0);
    std::this_thread::sleep_for(std::chrono::duration<double>(moment(random)));
    ::kill(pid, SIGKILL);
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    killed += WIFSIGNALED(status) ? 1 : 0;
    bool mixed = false;
    for (const auto& e : fs::directory_iterator(out)) {
      const std::string name = e.path().filename().string();
      if (name[0] == '.') {  // a temporary: .<file>.<pid>.<n>.tmp of this run
        EXPECT_NE(name.find("." + std::to_string(pid) + "."), std::string::npos) << name;
        EXPECT_TRUE(name.ends_with(".tmp")) << name;
        continue;
      }
      const std::string bytes = read(e.path());
      const bool is_old = old_files.count(name) && old_files.at(name) == bytes;
      const bool is_new = new_files.count(name) && new_files.at(name) == bytes;
      EXPECT_TRUE(is_old || is_new) << name << " is neither the old nor the new file, after "
                                    << "a kill at try " << k;
      mixed = mixed || is_new;
    }
    // the old summary.json or page never stays beside a new data file
    if (mixed) {
      for (const char* name : {"summary.json", "report.html"}) {
        EXPECT_FALSE(fs::exists(out / name) && read(out / name) == old_files.at(name)) << name;
      }
    }
    partial += mixed && !fs::exists(out / "report.html") ? 1 : 0;
  }
  EXPECT_GT(killed, 0);  // at least one kill landed before the run ended
  // the next run cleans up and writes the new files exactly
  ASSERT_EQ(run(quote(b) + " --out " + quote(out.string())), 0) << err_;
  EXPECT_EQ(files_of(out), new_files);
  for (const auto& e : fs::directory_iterator(out)) {
    EXPECT_NE(e.path().filename().string()[0], '.') << e.path();
  }
  RecordProperty("kills_during_the_run", killed);
  RecordProperty("kills_between_first_and_last_file", partial);
}

// A full disk (here a file-size limit of 64 KiB, so the timeseries cannot be written whole):
// one line naming the file and the reason, exit 1, no crash by SIGXFSZ, no file cut short, and
// neither the earlier run's summary.json nor its page left beside the new files
TEST_F(ReliabilityCliTest, AFullDiskIsOneLineAndLeavesNoFileCutShort) {
  ::setenv("BD_GNUPLOT", "/nonexistent", 1);
  std::ofstream(dir_ / "s.yaml") << balanced_study(3600, 6.283185307179586);
  ASSERT_EQ(run("s.yaml --out out"), 0) << err_;  // an earlier run in the folder
  ASSERT_GT(fs::file_size(dir_ / "out" / "timeseries.csv"), 200000u);
  EXPECT_EQ(run("s.yaml --out out", "ulimit -f 64; "), 1) << err_;
  expect_one_line();
  EXPECT_NE(err_.find("cannot write out/timeseries.csv: File too large"),
            std::string::npos)
      << err_;
  for (const char* gone : {"summary.json", "report.html", "timeseries.csv", "comparison.csv"}) {
    EXPECT_FALSE(fs::exists(dir_ / "out" / gone)) << gone;
  }
  for (const auto& e : fs::directory_iterator(dir_ / "out")) {
    EXPECT_NE(e.path().filename().string()[0], '.') << e.path();  // the temporary removed
  }
  // `report` on what is left: no run here
  EXPECT_EQ(run("report out"), 2) << err_;
  expect_one_line();
}

// An output folder that cannot be made or written: one line naming it, exit 1, nothing else
TEST_F(ReliabilityCliTest, AnUnwritableOutputFolderIsOneLine) {
  ::setenv("BD_GNUPLOT", "/nonexistent", 1);
  std::ofstream(dir_ / "s.yaml") << balanced_study(36, 6.283185307179586);
  std::ofstream(dir_ / "file") << "x";
  // a file where the folder should be, and a folder below a file
  EXPECT_EQ(run("s.yaml --out file"), 1);
  expect_one_line();
  EXPECT_NE(err_.find("cannot create the output directory file"), std::string::npos) << err_;
  EXPECT_EQ(run("s.yaml --out file/sub"), 1);
  expect_one_line();
  EXPECT_NE(err_.find("file/sub: Not a directory"), std::string::npos) << err_;
  EXPECT_EQ(read(dir_ / "file"), "x");
  // a folder in the way of a data file, beside an earlier run: the earlier summary.json and page
  // go first, so none vouches for what is left
  ASSERT_EQ(run("s.yaml --out out"), 0) << err_;
  fs::remove(dir_ / "out" / "comparison.csv");
  fs::create_directories(dir_ / "out" / "comparison.csv" / "x");
  EXPECT_EQ(run("s.yaml --out out"), 1);
  expect_one_line();
  EXPECT_NE(err_.find("comparison.csv"), std::string::npos) << err_;
  EXPECT_FALSE(fs::exists(dir_ / "out" / "summary.json"));
  EXPECT_FALSE(fs::exists(dir_ / "out" / "report.html"));
  // a folder without write permission (root may write anywhere: not checkable as root)
  if (::geteuid() != 0) {
    fs::create_directories(dir_ / "ro");
    fs::permissions(dir_ / "ro", fs::perms::owner_read | fs::perms::owner_exec);
    EXPECT_EQ(run("s.yaml --out ro"), 1);
    expect_one_line();
    EXPECT_NE(err_.find("Permission denied"), std::string::npos) << err_;
    fs::permissions(dir_ / "ro", fs::perms::owner_all);
  }
}

// A full disk in the middle of a sweep (a file-size limit reached while a row of sweep.csv is
// written): one line, exit 1; sweep.csv ends with whole rows (the cut row taken back) and
// sweep.json says the sweep was interrupted, not running; --resume then completes it to the
// bytes of an uninterrupted sweep
TEST_F(ReliabilityCliTest, AFullDiskInASweepKeepsWholeRowsAndResumes) {
  ::setenv("BD_GNUPLOT", "/nonexistent", 1);
  const std::string example = quote(kExamples + "/paper-fourbar-sweep.yaml");
  ASSERT_EQ(run(example + " --out full --progress none"), 0) << err_;
  const std::string full = read(dir_ / "full" / "sweep.csv");
  ASSERT_GT(full.size(), 100000u);
  EXPECT_EQ(run(example + " --out part --progress none --threads 2", "ulimit -f 64; "), 1);
  expect_one_line();
  EXPECT_NE(err_.find("cannot write part/sweep.csv: File too large"),
            std::string::npos)
      << err_;
  const std::string part = read(dir_ / "part" / "sweep.csv");
  expect_whole_rows(part, "sweep.csv after a full disk");
  EXPECT_LT(part.size(), full.size());
  EXPECT_EQ(full.compare(0, part.size(), part), 0);  // the rows written are the full run's
  const auto json = nlohmann::json::parse(read(dir_ / "part" / "sweep.json"));
  EXPECT_EQ(json["status"], "interrupted");
  EXPECT_EQ(json["done"].get<long>(), count(part, "\n") - 1);
  ASSERT_EQ(run(example + " --out part --resume --progress none"), 0) << err_;
  EXPECT_EQ(read(dir_ / "part" / "sweep.csv"), full);
}

// An allocation failing (std::bad_alloc) in the middle of one point of a sweep, wherever it
// lands (the optimiser's evaluation, the simulation, the synthesis): that point's row is failed
// with the message, every other row is as in a sweep without the fault, and the sweep ends
TEST_F(ReliabilityCliTest, AnAllocationFailingInASweepPointFailsThatPointOnly) {
  ::setenv("BD_GNUPLOT", "/nonexistent", 1);
  const bd::studies::Study study = bd::studies::load_study(kExamples + "/paper-fourbar-sweep.yaml");
  bd::studies::SweepOptions options;
  options.threads = 1;
  bd::studies::run_sweep(study, dir_ / "clean", options);
  const std::string clean = read(dir_ / "clean" / "sweep.csv");
  // armed from the writer (this thread) once 100 rows are written: the worker is in a point
  options.progress = [](const bd::studies::SweepProgress& p) {
    if (p.done == 100 && !p.finished) bd::testing::fail_an_allocation_of_another_thread(200);
  };
  const bd::studies::SweepResult r = bd::studies::run_sweep(study, dir_ / "fault", options);
  EXPECT_EQ(bd::testing::failed_allocations(), 1);
  EXPECT_TRUE(r.complete());
  EXPECT_EQ(r.failed, 1);
  const std::string faulty = read(dir_ / "fault" / "sweep.csv");
  expect_whole_rows(faulty, "sweep.csv");
  std::istringstream a(clean), b(faulty);
  std::string x, y;
  int differing = 0, lines = 0;
  while (std::getline(a, x) && std::getline(b, y)) {
    ++lines;
    if (x == y) continue;
    ++differing;
    const std::vector<std::string> f = bd::studies::csv_fields(y);
    const std::string& status = f[f.size() - 2];
    EXPECT_TRUE(status == "error" || status == "no-optimum") << y;
    EXPECT_NE(f.back().find("bad_alloc"), std::string::npos) << y;
    EXPECT_GT(lines, 101) << "a point before the fault was armed: " << y;
  }
  EXPECT_EQ(differing, 1);
  EXPECT_EQ(lines, 442);
}

// `report DIR` on a folder whose data files are cut short (finding 12): one line naming the
// file, exit 2, the same for summary.json, a timeseries cut in a line or at a line's end, and a
// sweep's sweep.json; the whole folder reports fine
TEST_F(ReliabilityCliTest, ReportOnACutShortFolderIsOneLineExit2) {
  ::setenv("BD_GNUPLOT", "/nonexistent", 1);
  std::ofstream(dir_ / "s.yaml") << balanced_study(360, 6.283185307179586);
  ASSERT_EQ(run("s.yaml --out out"), 0) << err_;
  ASSERT_EQ(run("report out"), 0) << err_;
  const fs::path out = dir_ / "out";
  auto cut = [](const fs::path& file, std::size_t keep) {
    const std::string text = read(file);
    std::ofstream(file, std::ios::binary | std::ios::trunc) << text.substr(0, keep);
    return text;
  };
  const std::string summary = cut(out / "summary.json", read(out / "summary.json").size() / 2);
  EXPECT_EQ(run("report out"), 2);
  expect_one_line();
  EXPECT_NE(err_.find("summary.json: not valid JSON (cut short or damaged)"), std::string::npos)
      << err_;
  std::ofstream(out / "summary.json", std::ios::binary | std::ios::trunc) << summary;

  for (const char* name : {"timeseries.csv", "balanced-timeseries.csv"}) {
    const fs::path file = out / name;
    const std::string whole = read(file);
    cut(file, whole.size() - 7);  // in the last line
    EXPECT_EQ(run("report out"), 2) << name;
    expect_one_line();
    EXPECT_NE(err_.find(std::string(name) + ": its last line is cut short"), std::string::npos)
        << err_;
    cut(file, whole.rfind('\n', whole.size() - 2) + 1);  // the last line dropped whole
    EXPECT_EQ(run("report out"), 2) << name;
    expect_one_line();
    EXPECT_NE(err_.find(std::string(name) + ": 359 rows where summary.json says 360 samples"),
              std::string::npos)
        << err_;
    std::ofstream(file, std::ios::binary | std::ios::trunc) << whole;
  }
  ASSERT_EQ(run("report out"), 0) << err_;

  const std::string example = quote(kExamples + "/paper-fourbar-sweep.yaml");
  ASSERT_EQ(run(example + " --out sweep --progress none"), 0) << err_;
  cut(dir_ / "sweep" / "sweep.json", 40);
  EXPECT_EQ(run("report sweep"), 2);
  expect_one_line();
  EXPECT_NE(err_.find("sweep.json: not valid JSON"), std::string::npos) << err_;
}

// The report's scratch folders in the temporary directory (gnuplot's script and SVGs) are named
// after their process; one left by a killed run (its process gone) is removed by the next
// report, one of a running process is kept (finding 10)
TEST_F(ReliabilityCliTest, AKilledRunsReportFolderIsRemovedByTheNext) {
  ::unsetenv("BD_GNUPLOT");  // set by the tests above
  if (bd::studies::find_gnuplot().empty()) GTEST_SKIP() << "gnuplot not installed: no charts drawn";
  const fs::path tmp = dir_ / "tmp";
  fs::create_directories(tmp);
  const pid_t gone = ::fork();  // a process id that has ended
  if (gone == 0) std::_Exit(0);
  ASSERT_GT(gone, 0);
  ::waitpid(gone, nullptr, 0);
  const fs::path stale = tmp / ("bd-report-" + std::to_string(gone) + "-abc123");
  const fs::path alive = tmp / ("bd-report-" + std::to_string(::getpid()) + "-abc123");
  fs::create_directories(stale);
  fs::create_directories(alive);
  std::ofstream(stale / "report.gp") << "x";
  std::ofstream(dir_ / "s.yaml") << balanced_study(36, 6.283185307179586);
  ASSERT_EQ(run("s.yaml --out out", "export TMPDIR=" + quote(tmp.string()) + "; "), 0) << err_;
  ASSERT_NE(read(dir_ / "out" / "report.html").find("<svg"), std::string::npos);
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_TRUE(fs::exists(alive));
  // and the run's own folder is gone
  std::size_t left = 0;
  for (const auto& e : fs::directory_iterator(tmp)) left += e.path() != alive ? 1 : 0;
  EXPECT_EQ(left, 0u);
}

// The JSON writers' check: a number that is not finite anywhere in a document is an error
// naming its place, an explicit null (a value not computed) is not
TEST(JsonNumbers, ANonFiniteNumberIsRefusedWithItsPlace) {
  nlohmann::ordered_json j = {{"metrics", {{"Fsh_rms", 1.5}, {"Msh_rms", nullptr}}},
                              {"peaks", nlohmann::ordered_json::array({1.0, 2.0})}};
  EXPECT_NO_THROW(bd::studies::check_json_numbers(j, "summary.json"));
  j["peaks"][1] = std::numeric_limits<double>::infinity();
  try {
    bd::studies::check_json_numbers(j, "summary.json");
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("summary.json would hold a number that is not finite at "
                                         "peaks[1]"),
              std::string::npos)
        << e.what();
  }
  j["peaks"][1] = 2.0;
  j["metrics"]["Fsh_rms"] = std::nan("");
  EXPECT_THROW(bd::studies::check_json_numbers(j, "summary.json"), std::runtime_error);
}

}  // namespace
