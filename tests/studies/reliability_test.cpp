// Hostile input (issue 17): each family of study text that once hung, crashed, passed validation
// but failed the run, or gave a message that was not one located line, is a regression here.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include <unistd.h>
#include <string>

#include "core/fourbar/model.hpp"
#include "core/metrics.hpp"
#include "studies/run/files.hpp"
#include "studies/run/simulation.hpp"
#include "studies/study/load_study.hpp"
#include "tests/support/study_errors.hpp"

namespace bd::studies {
namespace {

using bd::testing::expect_study_error;
using bd::testing::study_error_of;

// a valid driven four-bar; line numbers below refer to this text
const std::string kDriven =
    "name: t\n"                                                               // 1
    "linkage:\n"                                                              // 2
    "  type: fourbar\n"                                                       // 3
    "  frame: 3.2\n"                                                          // 4
    "  branch: 1\n"                                                           // 5
    "  crank: {length: 1, mass: 2, e: 0.5, f: 0.1, inertia: 1}\n"             // 6
    "  coupler: {length: 3, mass: 3, e: 1.5, f: 0.2, inertia: 3}\n"           // 7
    "  rocker: {length: 2, mass: 2, e: 1.5, f: -0.3, inertia: 2}\n"           // 8
    "scene: {type: driven, theta1: 0, omega1: 6.283185307179586, samples: 36}\n";  // 9

std::string edited(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// Finding 1: yaml-cpp 0.7's LoadAll never consumes a ',' outside brackets and returned an endless
// list of empty documents (17 GB in a minute). The loader asks for two documents at most.
TEST(HostileStudyText, StrayFlowEntryIsAnErrorNotAnEndlessLoop) {
  expect_study_error(",", "s.yaml", 1, 1, "unexpected ','");
  expect_study_error(", a", "s.yaml", 1, 1, "unexpected ','");
  expect_study_error("[a], b", "s.yaml", 1, 4, "unexpected ','");
  expect_study_error("{a: 1}, b", "s.yaml", 1, 7, "unexpected ','");
  expect_study_error(kDriven + ",\n", "s.yaml", 10, 1, "");
}

// Finding 9: text the first document cannot take is not "a second document (after '---')"
TEST(HostileStudyText, OnlyADocumentMarkerStartsASecondDocument) {
  const StudyError e = study_error_of("x, a\n# c\nname: t\n", "s.yaml");
  EXPECT_EQ(e.message().find("---"), std::string::npos) << e.what();
  EXPECT_EQ(e.line(), 3) << e.what();
  expect_study_error(kDriven + "---\nname: u\n", "s.yaml", 10, 1,
                     "a study file holds one YAML document; found a second one (after '---')");
  // a document end marker alone is one document
  EXPECT_NO_THROW(parse_study(kDriven + "...\n", "s.yaml"));
}

// Found by the long fuzz run: a text starting with '"' and a NUL byte is read by yaml-cpp as
// UTF-16, its marks count decoded characters, and one of them, past the text's end, made the
// loader's look at the text throw std::out_of_range (a crash). A study file is UTF-8 text: a NUL
// byte or a UTF-16/UTF-32 byte order mark is refused where it is.
TEST(HostileStudyText, NulBytesAndUtf16AreRefusedWhereTheyAre) {
  expect_study_error(std::string("\"\0act: 1\n", 10), "s.yaml", 1, 2, "not UTF-8 text");
  expect_study_error(edited(kDriven, "frame: 3.2", std::string("frame: 3\0.2", 11)), "s.yaml", 4,
                     11, "holds a NUL byte here");
  expect_study_error("\xFF\xFEn\0a\0", "s.yaml", 1, 1, "byte order mark");
  expect_study_error("\xFE\xFF\0n\0a", "s.yaml", 1, 1, "byte order mark");
  // UTF-8, its byte order mark included, is read as before
  EXPECT_NO_THROW(parse_study("\xEF\xBB\xBF" + kDriven, "s.yaml"));
  EXPECT_NO_THROW(parse_study("# M\xC3\xBChle\n" + kDriven, "s.yaml"));
}

// Finding 7: a key or value holding a newline or a NUL is escaped, the message stays one line
TEST(HostileStudyText, ControlCharactersInKeysAndValuesKeepTheMessageOnOneLine) {
  expect_study_error(kDriven + "\"col\\nour\": red\n", "s.yaml", 10, 1,
                     "unknown key 'col\\nour' at the top level");
  expect_study_error(kDriven + "\"a\\0b\": red\n", "s.yaml", 10, 1, "unknown key 'a\\0b'");
  expect_study_error(edited(kDriven, "name: t", "name: \"x\\ty\""), "s.yaml", 1, 7,
                     "got 'x\\ty'");
  expect_study_error(edited(kDriven, "type: fourbar", "type: \"four\\x1bbar\""), "s.yaml", 3, 9,
                     "linkage.type 'four\\x1bbar' is not supported");
  // the file's own name too
  const StudyError e = study_error_of(",", "a\nb.yaml");
  EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
}

// the error of `text` is at `line` of s.yaml, names `message`, and is one line
void expect_error_at_line(const std::string& text, int line, const std::string& message) {
  const StudyError e = study_error_of(text, "s.yaml");
  EXPECT_EQ(e.line(), line) << e.what();
  EXPECT_GT(e.column(), 0) << e.what();
  EXPECT_NE(e.message().find(message), std::string::npos) << e.what();
  EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
}

// Findings 2, 5, 6: numbers whose products leave double's range (a crank of 1e308 m, a disc
// 1e-320 m thick, a subnormal speed, bounds of 1e300) passed `validate` and failed the run
// with -nan, inf or an unlocated internal name. Every number is refused where it is written.
TEST(HostileStudyNumbers, NumbersBeyondTheComputableRangeAreRefusedWhereTheyAre) {
  const std::string range = "must be 0 or of magnitude 1e-100 to 1e15";
  expect_error_at_line(edited(kDriven, "length: 1,", "length: 1e308,"), 6,
                       "linkage.crank.length " + range + " in m");
  expect_error_at_line(edited(kDriven, "omega1: 6.283185307179586", "omega1: 4.9e-324"), 9,
                       "scene.omega1 " + range + " in rad/s");
  expect_error_at_line(edited(kDriven, "f: 0.1,", "f: -1e-300,"), 6, "linkage.crank.f " + range);
  expect_error_at_line(edited(kDriven, "mass: 3,", "mass: 1e16,"), 7, "linkage.coupler.mass");
  const std::string disc =
      kDriven + "balance:\n  counterweights:\n    rocker: {shape: disc, thickness: 1e-320}\n";
  expect_error_at_line(disc, 12, "balance.counterweights.rocker.thickness " + range);
  const std::string opt =
      kDriven +
      "optimize:\n  objective: {Msh_rms: 1}\n  variables:\n    counterweights:\n"
      "      crank: {mass_max: 1e300, distance_max: 1e308}\n";
  expect_error_at_line(opt, 14, "mass_max " + range);
  // the range's ends are valid: a round-off residue and a heavy linkage still load
  EXPECT_NO_THROW(parse_study(edited(kDriven, "f: 0.1,", "f: 1.2246467991473532e-16,"), "s"));
  EXPECT_NO_THROW(parse_study(edited(kDriven, "mass: 3,", "mass: 1e12,"), "s"));
}

// Finding 11: a relative tolerance below what double precision carries is refused up front
TEST(HostileStudyNumbers, ToleranceBelowDoublePrecisionIsRefused) {
  const std::string free_scene =
      edited(kDriven, "scene: {type: driven, theta1: 0, omega1: 6.283185307179586, samples: 36}",
             "scene: {type: free, theta1: 1, duration: 0.1}");
  expect_error_at_line(free_scene + "tolerance: 1e-20\n", 10, "tolerance must be >= 1e-14");
  EXPECT_NO_THROW(parse_study(free_scene + "tolerance: 1e-14\n", "s"));
}

// Finding 4: magnitudes and RMS values of large forces overflowed to inf (summary.json had
// null, the console "inf N", while the CSV held 1e200)
TEST(HostileNumbers, MagnitudesAndRmsDoNotOverflow) {
  EXPECT_DOUBLE_EQ(core::magnitude(3e200, 4e200), 5e200);
  EXPECT_DOUBLE_EQ(core::magnitude(3e-200, 4e-200), 5e-200);
  EXPECT_EQ(core::magnitude(0, 0), 0.0);
  EXPECT_EQ(core::magnitude(3, 4), 5.0);
  core::RmsAccumulator big;
  for (double x : {1e200, -1e200, 1e200, 1e200}) big.add(x);
  EXPECT_DOUBLE_EQ(big.rms(), 1e200);
  // ordinary values: bit for bit the plain formula
  core::RmsAccumulator plain;
  double sum = 0;
  for (double x : {0.1, 2.5, -3.75, 1e-3}) {
    plain.add(x);
    sum += x * x;
  }
  EXPECT_EQ(plain.rms(), std::sqrt(sum / 4));
  core::RmsAccumulator none;
  EXPECT_EQ(none.rms(), 0.0);
  core::RmsAccumulator nan;
  nan.add(1);
  nan.add(std::numeric_limits<double>::quiet_NaN());
  EXPECT_TRUE(std::isnan(nan.rms()));
}

// Deliverable 4: no NaN or infinity is data. Loads at the edge of double's range make the
// shaking force (their sum) overflow: the run stops at the first such sample, keeps the ones
// before and says so, instead of writing inf.
TEST(HostileNumbers, ANonFiniteSampleStopsTheRunThere) {
  Study study = parse_study(kDriven, "s.yaml");
  core::FourBar fb = study.fourbar();
  fb.loads.crank.force = {1.5e308, 0};
  fb.loads.rocker.force = {1.5e308, 0};
  study.linkage = core::make_fourbar(fb);
  const Simulation sim = simulate(study);
  EXPECT_FALSE(sim.status().ok());
  for (const core::DynamicsSample& s : sim.fourbar.samples) {
    ASSERT_TRUE(std::isfinite(s.Fsh.x()) && std::isfinite(s.Fsh.y()) && std::isfinite(s.Msh));
  }
  // the engine's own check or the run's guard (studies/run/simulation.cpp) says it
  EXPECT_NE(sim.status().message.find("finite"), std::string::npos) << sim.status().message;
}

// Finding 10: a run killed before its commit left '.timeseries.csv.<pid>.0.tmp' (up to 477 MB)
// that no later run removed. A run into the folder removes those of processes that are gone.
TEST(FaultLeftovers, TemporariesOfDeadProcessesAreRemovedOthersKept) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("bd-stale-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  auto touch = [&](const std::string& name) { std::ofstream(dir / name) << "x"; };
  const std::string dead = ".timeseries.csv.999999999.0.tmp";  // above any pid_max
  const std::string alive = ".timeseries.csv." + std::to_string(::getpid()) + ".3.tmp";
  touch(dead);
  touch(alive);
  touch("timeseries.csv");
  touch(".notes.tmp");
  remove_stale_temporaries(dir);
  EXPECT_FALSE(std::filesystem::exists(dir / dead));
  EXPECT_TRUE(std::filesystem::exists(dir / alive));
  EXPECT_TRUE(std::filesystem::exists(dir / "timeseries.csv"));
  EXPECT_TRUE(std::filesystem::exists(dir / ".notes.tmp"));
  std::filesystem::remove_all(dir);
}

// Deliverable 1: every input of the fuzz corpus (tests/fuzz/corpus/: each regression the fuzzer
// or the findings turned up) is run by the ordinary suite too, so the sanitizer job sees them:
// it loads, or it is one StudyError, located, on one line.
TEST(FuzzCorpus, EveryInputLoadsOrIsOneLocatedLine) {
  int inputs = 0;
  for (const auto& entry :
       std::filesystem::directory_iterator(std::string(BD_SOURCE_DIR) + "/tests/fuzz/corpus")) {
    std::ifstream in(entry.path(), std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    ++inputs;
    try {
      (void)parse_study(text.str(), "fuzz.yaml");
    } catch (const StudyError& e) {
      const std::string what = e.what();
      EXPECT_GE(e.line(), 1) << entry.path() << ": " << what;
      EXPECT_GE(e.column(), 1) << entry.path() << ": " << what;
      for (const char c : what) {
        EXPECT_GE(static_cast<unsigned char>(c), 0x20) << entry.path() << ": " << what;
      }
    }
  }
  EXPECT_GE(inputs, 4);
}

}  // namespace
}  // namespace bd::studies
