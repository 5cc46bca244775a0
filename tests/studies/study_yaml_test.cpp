// Writing a study back as YAML: parse_study() of study_yaml() gives back the same model, scene
// and options bit for bit (every number written exactly, links by e, f), for every example and a
// study with loads, counter-rotations and a free scene.
#include "studies/study/study_yaml.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <random>
#include <string>
#include <variant>

#include "core/fourbar/samples.hpp"
#include "studies/study/load_study.hpp"
#include "studies/study/method.hpp"
#include "tests/support/models.hpp"

namespace bd::studies {
namespace {

namespace fs = std::filesystem;

// exact number text reads back to the same double; the check allows e, f a few ulps (it was
// written for the polar form s, sigma; e, f are exact now)
void expect_same_study(const Study& a, const Study& b) {
  EXPECT_EQ(a.name, b.name);
  ASSERT_EQ(a.is_fourbar(), b.is_fourbar());
  if (!a.is_fourbar()) {
    // every number is written "%.17g", which reads back as the same double: the same study
    // writes the same text, and its nodes and links are the same
    EXPECT_EQ(study_yaml(a, ""), study_yaml(b, ""));
    ASSERT_EQ(a.planar().nodes.size(), b.planar().nodes.size());
    for (std::size_t i = 0; i < a.planar().nodes.size(); ++i) {
      EXPECT_EQ(a.planar().nodes[i].position, b.planar().nodes[i].position);
    }
    ASSERT_EQ(a.planar().links.size(), b.planar().links.size());
    for (std::size_t k = 0; k < a.planar().links.size(); ++k) {
      EXPECT_EQ(a.planar().links[k].nodes, b.planar().links[k].nodes);
      EXPECT_EQ(a.planar().links[k].e, b.planar().links[k].e);
      EXPECT_EQ(a.planar().links[k].inertia, b.planar().links[k].inertia);
    }
    EXPECT_EQ(a.method, b.method);
    return;
  }
  bd::testing::expect_same_model(a.fourbar(), b.fourbar());
  ASSERT_EQ(a.scene.index(), b.scene.index());
  if (const auto* fa = std::get_if<core::FreeScene>(&a.scene)) {
    const auto& fb = std::get<core::FreeScene>(b.scene);
    EXPECT_EQ(fa->theta1, fb.theta1);
    EXPECT_EQ(fa->omega1, fb.omega1);
    EXPECT_EQ(fa->duration, fb.duration);
    EXPECT_EQ(fa->samples, fb.samples);
  } else {
    const auto& da = std::get<core::DrivenScene>(a.scene);
    const auto& db = std::get<core::DrivenScene>(b.scene);
    EXPECT_EQ(da.theta1, db.theta1);
    EXPECT_EQ(da.omega1, db.omega1);
    EXPECT_EQ(da.revolutions, db.revolutions);
    EXPECT_EQ(da.samples, db.samples);
  }
  EXPECT_EQ(a.method, b.method);
  EXPECT_EQ(a.tolerance, b.tolerance);
  EXPECT_FALSE(b.balance.has_value());
}

TEST(StudyYaml, EveryExampleRoundTrips) {
  int count = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(BD_SOURCE_DIR) / "studies/examples")) {
    if (entry.path().extension() != ".yaml") continue;
    ++count;
    SCOPED_TRACE(entry.path().string());
    const Study study = load_study(entry.path().string());
    expect_same_study(study, parse_study(study_yaml(study, ""), "copy.yaml"));
    if (study.balance) {
      const Study balanced = balanced_study(study);
      expect_same_study(balanced, parse_study(study_yaml(balanced, "a header"), "balanced.yaml"));
    }
  }
  EXPECT_GE(count, 5);
}

TEST(StudyYaml, LoadsCounterRotationsAndAnExplicitMethodRoundTrip) {
  std::mt19937_64 rng(7);
  Study s;
  s.name = "odd-numbers_1.0";
  s.fourbar() =
      core::samples::with_paper_loads(core::samples::random_crank_rocker(rng), Vec2(0.1, -9.81));
  s.fourbar().counter_rotations.crank = {0.1 / 3.0, Vec2(-0.25, -1.0 / 7.0)};
  s.fourbar().counter_rotations.rocker = {2.0 / 3.0, Vec2(s.fourbar().frame_length, 1.0 / 3e5)};
  s.fourbar() = core::make_fourbar(s.fourbar());
  s.scene = core::FreeScene{-0.1 / 3.0, 2.0 / 3.0, 1.0 / 7.0, 17};
  s.method = Method::kOpenedLoop;
  s.tolerance = 1.0 / 3.0 * 1e-9;
  const std::string text = study_yaml(s, "line one\n\nline three");
  EXPECT_EQ(text.rfind("# line one\n#\n# line three\n", 0), 0u) << text;
  expect_same_study(s, parse_study(text, "copy.yaml"));
}

}  // namespace
}  // namespace bd::studies
