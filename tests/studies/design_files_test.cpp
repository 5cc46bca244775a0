// The designs' study files (balanced.yaml, optimized.yaml) carry their counterweights as data:
// a linkage.counterweights section of parts (mass, centre in the link's axes from its pivot,
// own inertia) on the links as they were before the counterweights. The loader merges them back;
// re-running the written file gives the design's samples to the last bit (the same inputs
// through the same code: every number in the file is written exactly), for either linkage type,
// balanced and optimised, with link parameters set by the optimiser on a link that also carries
// a counterweight. The part itself is checked against an independent route: the centre of mass
// and the parallel-axis inertia of link plus part, summed here by hand.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "studies/run/runner.hpp"
#include "studies/studies.hpp"
#include "studies/study/load_study.hpp"
#include "studies/study/study_yaml.hpp"
#include "tests/support/studies.hpp"
#include "tests/support/study_errors.hpp"
#include "tests/support/text.hpp"

namespace bd::studies {
namespace {

namespace fs = std::filesystem;
using bd::testing::read;

class DesignFilesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("bd_design_files_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

// the design's study file loads back with its parts; re-running it writes the design's samples
// byte for byte
void expect_reproduced(const fs::path& yaml, const fs::path& samples, const fs::path& again_dir,
                       std::size_t parts) {
  const std::string text = read(yaml);
  EXPECT_NE(text.find("  counterweights:"), std::string::npos) << text;
  const Study back = load_study(yaml.string());
  ASSERT_TRUE(back.parts.has_value()) << text;
  EXPECT_EQ(back.parts->counterweights.size(), parts) << text;
  const RunResult again = run_study(back, again_dir);
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(read(again.timeseries), read(samples))
      << "the re-run's samples differ from " << samples;
}

// the independent route: link + part summed by hand (centre of mass and parallel axes) give the
// design's link; `r` is the part's centre from the link's first node in link axes [m]
template <class L>
void expect_link_with_part(const L& bare, const balance::Counterweight& cw, const Vec2& r,
                           const L& design) {
  const double M = bare.mass + cw.mass;
  const double e = (bare.mass * bare.e + cw.mass * r.x()) / M;
  const double f = (bare.mass * bare.f + cw.mass * r.y()) / M;
  const double I = bare.inertia + bare.mass * (std::pow(bare.e - e, 2) + std::pow(bare.f - f, 2)) +
                   cw.inertia + cw.mass * (std::pow(r.x() - e, 2) + std::pow(r.y() - f, 2));
  // a few roundings apart: 1e-14 of the link's size
  EXPECT_NEAR(design.mass, M, 1e-14 * M);
  EXPECT_NEAR(design.e, e, 1e-14 * (std::abs(e) + std::abs(r.x()) + std::abs(bare.e)));
  EXPECT_NEAR(design.f, f, 1e-14 * (std::abs(f) + std::abs(r.y()) + std::abs(bare.f) + 1e-3));
  EXPECT_NEAR(design.inertia, I, 1e-13 * I);
}

TEST_F(DesignFilesTest, FourBarBalancedDesignCarriesItsCounterweightsAndReproducesItsRun) {
  const Study study =
      load_study(bd::testing::example_path("paper-fourbar-driven-force-balanced.yaml"));
  const RunResult r = run_study(study, dir_);
  ASSERT_TRUE(r.ok());
  const Study back = load_study(r.balanced->study_file.string());
  ASSERT_TRUE(back.parts.has_value());
  // the parts are the synthesis's counterweights, the bare links the original's
  const balance::BalancedDesign& b = *study.balance;
  ASSERT_TRUE(b.crank_counterweight && b.rocker_counterweight);
  ASSERT_EQ(back.parts->counterweights.size(), 2u);
  const CounterweightPart& crank = back.parts->counterweights[0];
  const CounterweightPart& rocker = back.parts->counterweights[1];
  EXPECT_EQ(crank.link, 1);
  EXPECT_EQ(rocker.link, 3);
  EXPECT_EQ(crank.counterweight.mass, b.crank_counterweight->mass);
  EXPECT_EQ(crank.counterweight.position, b.crank_counterweight->position);
  EXPECT_EQ(rocker.counterweight.mass, b.rocker_counterweight->mass);
  const core::FourBar& bare = std::get<core::FourBar>(back.parts->bare);
  EXPECT_EQ(bare.crank.mass, study.fourbar().crank.mass);
  EXPECT_EQ(bare.rocker.e, study.fourbar().rocker.e);
  // crank: from A0, the first joint; rocker: from A3, (l3, 0) in its axes from A2
  expect_link_with_part(bare.crank, crank.counterweight, crank.counterweight.position,
                        back.fourbar().crank);
  expect_link_with_part(bare.rocker, rocker.counterweight,
                        Vec2(bare.rocker.length, 0) + rocker.counterweight.position,
                        back.fourbar().rocker);
  expect_reproduced(r.balanced->study_file, r.balanced->timeseries, dir_ / "again", 2);
}

TEST_F(DesignFilesTest, FourBarOptimumWithALinkParameterOnItsCounterweightsLinkReproducesItsRun) {
  // the crank's own mass is a variable beside its counterweight: the file gives the crank with
  // the optimiser's mass and, as a part, the counterweight
  const std::string text = bd::testing::edited(
      read(bd::testing::example_path("berkof-lowen-min-shaking-moment.yaml")),
      "      coupler: {mass: [2.0, 4.0], inertia: [1.0, 8.0]}",
      "      coupler: {mass: [2.0, 4.0], inertia: [1.0, 8.0]}\n      crank: {mass: [1.5, 3.0]}");
  const Study study = parse_study(text, "berkof.yaml");
  const RunResult r = run_study(study, dir_);
  ASSERT_TRUE(r.ok()) << r.optimized->result.message;
  const OptimizedRun& o = *r.optimized;
  expect_reproduced(o.study_file, o.timeseries, dir_ / "again", o.result.counterweights.size());
  const Study back = load_study(o.study_file.string());
  const core::FourBar& bare = std::get<core::FourBar>(back.parts->bare);
  // the crank's mass is the optimiser's variable (the last one), its other values the study's
  EXPECT_EQ(bare.crank.mass, o.result.x[o.result.x.size() - 1]);
  EXPECT_EQ(bare.crank.e, study.fourbar().crank.e);
  EXPECT_EQ(bare.coupler.mass, o.result.design.coupler.mass);
}

TEST_F(DesignFilesTest, PlanarBalancedDesignCarriesItsCounterweightsAndReproducesItsRun) {
  const Study study = load_study(bd::testing::example_path("watt-sixbar-balanced.yaml"));
  const RunResult r = run_study(study, dir_);
  ASSERT_TRUE(r.ok());
  const BalancedRun& b = *r.balanced;
  ASSERT_TRUE(b.design.has_value());
  const std::string text = read(b.study_file);
  const Study back = load_study(b.study_file.string());
  ASSERT_TRUE(back.parts.has_value()) << text;
  ASSERT_EQ(back.parts->counterweights.size(), b.design->added.size());
  const auto& bare = std::get<core::planar::Linkage>(back.parts->bare);
  for (std::size_t i = 0; i < b.design->added.size(); ++i) {
    const balance::planar::LinkCounterweight& added = b.design->added[i];
    const CounterweightPart& part = back.parts->counterweights[i];
    EXPECT_EQ(part.link, added.link);
    EXPECT_EQ(part.pivot, added.pivot);
    EXPECT_EQ(part.counterweight.mass, added.counterweight.mass);
    EXPECT_EQ(part.counterweight.position, added.counterweight.position);
    // each link here turns about its ground node; that node in the link's axes from its first
    const core::planar::Link& link = bare.links[static_cast<std::size_t>(part.link)];
    const Vec2 p = bare.nodes[static_cast<std::size_t>(link.nodes[0])].position;
    const Vec2 q = bare.nodes[static_cast<std::size_t>(link.nodes[1])].position;
    const Vec2 u = (q - p).normalized(), v(-u.y(), u.x());
    const Vec2 pivot = bare.nodes[static_cast<std::size_t>(part.pivot)].position - p;
    const Vec2 r_first = Vec2(pivot.dot(u), pivot.dot(v)) + part.counterweight.position;
    EXPECT_EQ(link.mass, study.planar().links[static_cast<std::size_t>(part.link)].mass);
    expect_link_with_part(link, part.counterweight, r_first,
                          back.planar().links[static_cast<std::size_t>(part.link)]);
  }
  expect_reproduced(b.study_file, b.timeseries, dir_ / "again", b.design->added.size());
}

TEST_F(DesignFilesTest, PlanarOptimumCarriesItsCounterweightsAndReproducesItsRun) {
  std::string text = read(bd::testing::example_path("watt-sixbar-optimized.yaml"));
  text = text.substr(0, text.find("  pareto:"));  // the optimum alone
  const Study study = parse_study(text, "watt.yaml");
  const RunResult r = run_study(study, dir_);
  ASSERT_TRUE(r.ok()) << r.optimized->planar_result.message;
  const OptimizedRun& o = *r.optimized;
  std::size_t placed = 0;
  for (const auto& c : o.planar_result.counterweights) placed += c.counterweight.mass > 0;
  ASSERT_GT(placed, 0u);
  expect_reproduced(o.study_file, o.timeseries, dir_ / "again", placed);
}

TEST_F(DesignFilesTest, AStudyWithCounterweightPartsWritesThemBackExactly) {
  // a part given by hand: study_yaml() writes it back, and reading that gives the same study
  const std::string study_text =
      bd::testing::edited(bd::testing::engine_study(36), "  inputs:\n",
                          "  counterweights:\n"
                          "    crank: {mass: 0.3, at: [-0.01, 0.002], inertia: 1.0e-5}\n"
                          "  inputs:\n");
  const Study study = parse_study(study_text, "e.yaml");
  ASSERT_TRUE(study.parts.has_value());
  const CounterweightPart& p = study.parts->counterweights.at(0);
  EXPECT_EQ(p.pivot, 0);  // default: the crank's ground node O
  const auto& bare = std::get<core::planar::Linkage>(study.parts->bare);
  expect_link_with_part(bare.links[0], p.counterweight, p.counterweight.position,
                        study.planar().links[0]);
  const Study again = parse_study(study_yaml(study, ""), "again.yaml");
  ASSERT_TRUE(again.parts.has_value());
  EXPECT_EQ(again.planar().links[0].mass, study.planar().links[0].mass);
  EXPECT_EQ(again.planar().links[0].e, study.planar().links[0].e);
  EXPECT_EQ(again.planar().links[0].f, study.planar().links[0].f);
  EXPECT_EQ(again.planar().links[0].inertia, study.planar().links[0].inertia);
}

TEST(DesignFiles, CounterweightMistakesAreOneLineAtTheirPlace) {
  const std::string planar = bd::testing::engine_study(36);
  auto with = [&](const std::string& section) {
    return bd::testing::edited(planar, "  inputs:\n", section + "  inputs:\n");
  };
  // lines: the section starts at line 14 (engine_study's inputs line)
  bd::testing::expect_study_error(with("  counterweights:\n    crank: {mass: -1, at: [0, 0]}\n"),
                                  "e.yaml", 15, 19,
                                  "linkage.counterweights.crank.mass must be >= 0 kg");
  bd::testing::expect_study_error(with("  counterweights:\n    crank: {mass: 1, at: [0]}\n"),
                                  "e.yaml", 15, 26,
                                  "linkage.counterweights.crank.at must be a list of 2");
  bd::testing::expect_study_error(with("  counterweights:\n    piston: {mass: 1, at: [0, 0]}\n"),
                                  "e.yaml", 15, 5, "unknown link 'piston'");
  bd::testing::expect_study_error(
      with("  counterweights:\n    crank: {from: B, mass: 1, at: [0, 0]}\n"), "e.yaml", 15, 19,
      "linkage.counterweights.crank.from must be a node of link crank (O, A), got B");
  bd::testing::expect_study_error(with("  counterweights:\n    crank: {mass: 1, where: [0, 0]}\n"),
                                  "e.yaml", 15, 22, "unknown key 'where'");
  bd::testing::expect_study_error(
      with("  counterweights:\n    crank: {mass: 1, at: [0, 0], inertia: -2}\n"), "e.yaml", 15, 43,
      "linkage.counterweights.crank.inertia must be >= 0 kg m²");
  // a four-bar's: crank and rocker only
  const std::string fourbar = read(bd::testing::example_path("paper-fourbar-driven.yaml"));
  const std::string with_coupler = bd::testing::edited(
      fourbar, "\nscene:", "  counterweights:\n    coupler: {mass: 1, at: [0, 0]}\n\nscene:");
  const studies::StudyError e = bd::testing::study_error_of(with_coupler, "f.yaml");
  EXPECT_NE(e.message().find("unknown key 'coupler' in linkage.counterweights"), std::string::npos)
      << e.what();
}

}  // namespace
}  // namespace bd::studies
