// The balance-design executable running sweeps across the ranks of an MPI job (`mpirun -np 2`):
// the same sweep.csv bytes as the threaded run for grid, random and Latin-hypercube designs; a
// rank killed mid-sweep (SIGKILL from outside) and the sweep resumed, with another number of
// processes, to the bytes of an uninterrupted run. Skipped, with the reason, where the program
// was built without MPI or mpirun is not installed.
#include <dirent.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include "tests/support/studies.hpp"
#include "tests/support/spawn.hpp"
#include "tests/support/text.hpp"

namespace {

namespace fs = std::filesystem;

const std::string kExe = BD_BINARY_DIR "/bin/balance-design";
const std::string kMpirun = BD_MPIEXEC;  // empty where CMake found no MPI
const std::string kExamples = BD_SOURCE_DIR "/studies/examples";

using bd::testing::quote;
using bd::testing::read;
const auto rows = bd::testing::sweep_rows;


// mpirun's options for two ranks on this machine, whatever its cores, as root too
std::vector<std::string> mpirun_args() {
  std::vector<std::string> a = {kMpirun, "-np", "2", "--oversubscribe"};
  if (::getuid() == 0) a.push_back("--allow-run-as-root");
  return a;
}

// a driven random sweep of the paper's four-bar over coupler mass and crank speed: microseconds
// a point, so both ranks take many chunks
std::string random_sweep(int points) {
  std::string text = read(kExamples + "/paper-fourbar-sweep.yaml");
  const std::size_t at = text.find("sweep:");
  text.resize(at);
  return text + "sweep:\n  design: random\n  points: " + std::to_string(points) +
         "\n  seed: 11\n  parameters:\n"
         "    - {path: linkage.coupler.mass, from: 1.0, to: 5.0}\n"
         "    - {path: scene.omega1, from: 1.0, to: 20.0, scale: log}\n";
}

class MpiSweepCli : public ::testing::Test {
 public:
  void SetUp() override {
    ASSERT_TRUE(fs::exists(kExe)) << kExe << " not built";
#ifndef BD_WITH_MPI
    GTEST_SKIP() << "balance-design was built without MPI (libopenmpi-dev was not found): "
                    "nothing to test across ranks";
#endif
    if (kMpirun.empty() || ::access(kMpirun.c_str(), X_OK) != 0) {
      GTEST_SKIP() << "mpirun not found (install openmpi-bin): the MPI sweeps are not tested";
    }
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("bd_mpi_sweep_test_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    ::setenv("BD_GNUPLOT", "/nonexistent", 1);  // the page without charts: not tested here
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }

  // runs `command` in dir_ (stdout and stderr kept); returns the exit code
  int shell(const std::string& command) {
    const std::string cmd = "cd " + quote(dir_.string()) + " && " + command + " >" +
                            quote((dir_ / "stdout.txt").string()) + " 2>" +
                            quote((dir_ / "stderr.txt").string()) + " </dev/null";
    const int status = std::system(cmd.c_str());
    out_ = read(dir_ / "stdout.txt");
    err_ = read(dir_ / "stderr.txt");
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  }
  int run(const std::string& args) { return shell(quote(kExe) + " " + args); }
  int mpirun(const std::string& args) {
    std::string cmd;
    for (const std::string& a : mpirun_args()) cmd += quote(a) + " ";
    return shell(cmd + quote(kExe) + " " + args);
  }

  // starts mpirun -np 2 balance-design ARGS in the background
  pid_t start_mpirun(const std::vector<std::string>& args) {
    std::vector<std::string> all = mpirun_args();
    all.push_back(kExe);
    all.insert(all.end(), args.begin(), args.end());
    const pid_t pid = bd::testing::spawn_to_files(all, (dir_ / "child-stdout.txt").string(),
                                                  (dir_ / "child-stderr.txt").string());
    EXPECT_GT(pid, 0) << "posix_spawn failed";
    return pid;
  }

  // the parent of process `pid` (field 4 of /proc/PID/stat), or -1
  static pid_t parent_of(pid_t pid) {
    const std::string stat = read(fs::path("/proc") / std::to_string(pid) / "stat");
    const std::size_t name_end = stat.rfind(')');  // the command's name may hold ") "
    if (name_end == std::string::npos) return -1;
    std::istringstream fields(stat.substr(name_end + 1));
    char state = 0;
    pid_t parent = -1;
    fields >> state >> parent;
    return fields ? parent : -1;
  }

  static bool descends_from(pid_t pid, pid_t ancestor) {
    for (int depth = 0; pid > 1 && depth < 32; ++depth) {
      pid = parent_of(pid);
      if (pid == ancestor) return true;
    }
    return false;
  }

  // the pid of the process that mpirun `job` started as rank `rank` (its environment says so),
  // or -1: only job's descendants are looked at, so another MPI job on the machine (another
  // test, or someone else's run) is never taken for it
  static pid_t rank_pid(pid_t job, int rank) {
    const std::string wanted = "OMPI_COMM_WORLD_RANK=" + std::to_string(rank);
    for (const fs::directory_entry& e : fs::directory_iterator("/proc")) {
      const std::string name = e.path().filename().string();
      if (name.find_first_not_of("0123456789") != std::string::npos) continue;
      const pid_t pid = std::stoi(name);
      if (!descends_from(pid, job)) continue;
      std::string env = read(e.path() / "environ");
      std::replace(env.begin(), env.end(), '\0', '\n');
      if (env.find("\n" + wanted + "\n") != std::string::npos || env.rfind(wanted + "\n", 0) == 0)
        return pid;
    }
    return -1;
  }

  fs::path dir_;
  std::string out_, err_;
};

// the sweep run on threads, then by two ranks of one thread each: the same bytes
void expect_same_rows(MpiSweepCli& t, const std::string& study, long points,
                      const fs::path& dir) {
  ASSERT_EQ(t.run(study + " --out threaded --progress none"), 0);
  const std::string threaded = read(dir / "threaded" / "sweep.csv");
  ASSERT_EQ(rows(dir / "threaded" / "sweep.csv"), points);
  ASSERT_EQ(t.mpirun(study + " --out ranks --threads 1 --progress none"), 0);
  EXPECT_EQ(read(dir / "ranks" / "sweep.csv"), threaded) << study;
}

TEST_F(MpiSweepCli, GridSweepMatchesTheThreadedRunByteForByte) {
  const std::string example = quote(kExamples + "/paper-fourbar-sweep.yaml");
  expect_same_rows(*this, example, 441, dir_);
  // rank 0 alone speaks: one summary line on stdout, the ranks' threads in sweep.json
  EXPECT_EQ(std::count(out_.begin(), out_.end(), '\n'), 1) << out_;
  EXPECT_NE(out_.find("paper-fourbar-sweep: sweep complete, 441 of 441 points, 0 failed, "),
            std::string::npos)
      << out_;
  EXPECT_NE(read(dir_ / "ranks" / "sweep.json").find("\"threads\": 2,"), std::string::npos);
  EXPECT_TRUE(fs::exists(dir_ / "ranks" / "report.html"));
}

TEST_F(MpiSweepCli, RandomSweepMatchesTheThreadedRunByteForByte) {
  std::ofstream(dir_ / "random.yaml") << random_sweep(1500);
  expect_same_rows(*this, "random.yaml", 1500, dir_);
}

TEST_F(MpiSweepCli, LatinHypercubeSweepMatchesTheThreadedRunByteForByte) {
  std::ofstream(dir_ / "free.yaml") << bd::testing::paper_free_lhs_sweep(120, "  seed: 3\n");
  expect_same_rows(*this, "free.yaml", 120, dir_);
}

TEST_F(MpiSweepCli, RankKilledMidSweepThenResumedGivesTheSameBytes) {
  std::ofstream(dir_ / "free.yaml") << bd::testing::paper_free_lhs_sweep(300, "");
  ASSERT_EQ(run("free.yaml --out full --progress none"), 0) << err_;
  const std::string full = read(dir_ / "full" / "sweep.csv");
  ASSERT_EQ(rows(dir_ / "full" / "sweep.csv"), 300);

  // two ranks of one thread each; rank 1 killed (SIGKILL: nothing of it runs after) once ten
  // rows are written: mpirun ends the job
  const fs::path csv = dir_ / "killed" / "sweep.csv";
  const pid_t job = start_mpirun({(dir_ / "free.yaml").string(), "--out",
                                  (dir_ / "killed").string(), "--threads", "1", "--progress",
                                  "none"});
  ASSERT_GT(job, 0);
  bool killed = false;
  int status = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (std::chrono::steady_clock::now() < deadline) {
    if (::waitpid(job, &status, WNOHANG) == job) break;
    if (!killed && rows(csv) >= 10) {
      const pid_t rank1 = rank_pid(job, 1);
      if (rank1 > 0) killed = ::kill(rank1, SIGKILL) == 0;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ASSERT_TRUE(killed) << "the sweep ended before rank 1 was killed";
  ASSERT_FALSE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "mpirun reported success";
  const long kept = rows(csv);
  EXPECT_GE(kept, 10);
  EXPECT_LT(kept, 300);
  // whole rows, in point order: the first rows of the sweep (a last line may be cut short)
  const std::string text = read(csv);
  const std::string whole = text.substr(0, text.rfind('\n') + 1);
  EXPECT_EQ(full.compare(0, whole.size(), whole), 0) << "the rows kept are not the sweep's first";

  // resumed without MPI (another number of processes): every row once, the same bytes
  ASSERT_EQ(run("free.yaml --out killed --resume --threads 2 --progress none"), 0) << err_;
  EXPECT_NE(out_.find("free: sweep complete, 300 of 300 points ("), std::string::npos) << out_;
  EXPECT_EQ(read(csv), full);
}

TEST_F(MpiSweepCli, ThreadedSweepInterruptedThenResumedOnTwoRanks) {
  std::ofstream(dir_ / "random.yaml") << random_sweep(2000);
  ASSERT_EQ(run("random.yaml --out full --progress none"), 0) << err_;
  const std::string full = read(dir_ / "full" / "sweep.csv");
  // the first 700 rows, as a killed run leaves them (its last line cut short), and its sweep.json
  ASSERT_EQ(run("random.yaml --out part --progress none"), 0) << err_;
  std::size_t cut = 0;
  for (int line = 0; line < 701; ++line) cut = full.find('\n', cut) + 1;
  std::ofstream(dir_ / "part" / "sweep.csv", std::ios::trunc) << full.substr(0, cut + 17);
  std::string json = read(dir_ / "part" / "sweep.json");
  const std::size_t s = json.find("\"status\": \"complete\"");
  ASSERT_NE(s, std::string::npos);
  json.replace(s, 20, "\"status\": \"running\"");
  std::ofstream(dir_ / "part" / "sweep.json", std::ios::trunc) << json;

  ASSERT_EQ(mpirun("random.yaml --out part --resume --threads 1 --progress none"), 0) << err_;
  EXPECT_NE(out_.find("2000 of 2000 points (700 resumed)"), std::string::npos) << out_;
  EXPECT_EQ(read(dir_ / "part" / "sweep.csv"), full);
}

// summary.json without the lines that hold a wall time (they differ from run to run): the
// solver's seconds, and its one-line report that states them
std::string without_times(const std::string& json) {
  std::istringstream in(json);
  std::string kept;
  for (std::string line; std::getline(in, line);) {
    if (line.find("\"seconds\"") == std::string::npos &&
        line.find("\"brief_report\"") == std::string::npos) {
      kept += line + "\n";
    }
  }
  return kept;
}

// A multistart (mlsl, six starts) over the driven paper four-bar's counterweights, its local
// runs shared between two ranks: the optimum's files are the bytes of the run in one process,
// and the summary reports every start and how many reached the best value.
TEST_F(MpiSweepCli, MultistartSharedAmongRanksGivesTheSameOptimum) {
  std::string study = read(kExamples + "/weighted-counterweights.yaml");
  study = bd::testing::edited(study, "algorithm: slsqp", "algorithm: mlsl\n  starts: 6");
  study = bd::testing::edited(study, "max_evaluations: 2000", "max_evaluations: 1200");
  std::ofstream(dir_ / "mlsl.yaml") << study;
  ASSERT_EQ(run("mlsl.yaml --out alone"), 0) << err_;
  const std::string alone_out = out_;
  // the console says how many local runs reached the best value (the README's promise)
  EXPECT_TRUE(std::regex_search(
      out_, std::regex("\n           multistart: 6 local runs, [1-6] of them reaching the best "
                       "value\n")))
      << out_;
  ASSERT_EQ(mpirun("mlsl.yaml --out ranks"), 0) << err_;
  // rank 0 alone speaks: the summary of the run in one process, line for line
  EXPECT_EQ(std::count(out_.begin(), out_.end(), '\n'),
            std::count(alone_out.begin(), alone_out.end(), '\n'))
      << out_;
  for (const char* file : {"optimized.yaml", "comparison.csv", "optimized-timeseries.csv"}) {
    const std::string alone = read(dir_ / "alone" / file);
    EXPECT_FALSE(alone.empty()) << file;
    EXPECT_EQ(read(dir_ / "ranks" / file), alone) << file;
  }
  const std::string summary = without_times(read(dir_ / "alone" / "summary.json"));
  EXPECT_EQ(without_times(read(dir_ / "ranks" / "summary.json")), summary);
  EXPECT_NE(summary.find("6 local runs"), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"starts\": 6"), std::string::npos) << summary;
}

#ifndef BD_WITH_MPI
// The program built without MPI, started as one of two ranks (the environment mpirun gives its
// ranks; no mpirun needed): it refuses with one line that says why, and writes nothing, rather
// than letting every rank run the whole study into the same folder.
TEST(MpiSweepCliWithoutMpi, RefusesToRunAsOneOfSeveralRanks) {
  ASSERT_TRUE(fs::exists(kExe)) << kExe << " not built";
  const fs::path dir = fs::temp_directory_path() /
                       ("bd_mpi_none_test_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string cmd = "cd " + quote(dir.string()) + " && OMPI_COMM_WORLD_SIZE=2 " +
                          quote(kExe) + " run " + quote(kExamples + "/paper-fourbar-sweep.yaml") +
                          " --out out --progress none >stdout.txt 2>stderr.txt </dev/null";
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 1);
  const std::string err = read(dir / "stderr.txt");
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  EXPECT_NE(err.find("built without MPI"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(dir / "out"));
  // alone, the same program runs the sweep
  const std::string alone = "cd " + quote(dir.string()) + " && " + quote(kExe) + " run " +
                            quote(kExamples + "/paper-fourbar-sweep.yaml") +
                            " --out out --progress none >stdout.txt 2>stderr.txt </dev/null";
  EXPECT_EQ(std::system(alone.c_str()), 0) << read(dir / "stderr.txt");
  EXPECT_EQ(rows(dir / "out" / "sweep.csv"), 441);
  fs::remove_all(dir);
}
#endif

}  // namespace
