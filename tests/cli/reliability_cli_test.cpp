// The program against hostile input (issue 17): it ends, with one line and the documented exit
// code, whatever the study file holds.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "tests/support/text.hpp"

namespace {

namespace fs = std::filesystem;
const std::string kExe = BD_BINARY_DIR "/bin/balance-design";
using bd::testing::quote;
using bd::testing::read;

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
  int run(const std::string& args) {
    const std::string cmd = "cd " + quote(dir_.string()) + " && (ulimit -v 2000000; timeout 20 " +
                            quote(kExe) + " " + args + ") >out.txt 2>err.txt";
    const int status = std::system(cmd.c_str());
    err_ = read(dir_ / "err.txt");
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
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

}  // namespace
