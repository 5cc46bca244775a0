// Planar linkages in study files (linkage.type: planar): the example loads to the model it
// describes, writes back as itself, and runs on the general engine; every mistake in its
// sections is one line at the place of the value that is wrong.
#include <gtest/gtest.h>

#include <string>

#include "studies/studies.hpp"
#include "studies/study/load_study.hpp"
#include "studies/study/method.hpp"
#include "studies/study/study_yaml.hpp"
#include "tests/support/studies.hpp"
#include "tests/support/study_errors.hpp"

namespace bd::studies {
namespace {

// a slider-crank driven by its crank; line numbers below refer to it
const std::string kEngine = bd::testing::engine_study(36);

std::string edit(const std::string& from, const std::string& to) {
  std::string t = kEngine;
  const std::size_t at = t.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return t.replace(at, from.size(), to);
}

void expect_error(const std::string& text, int line, int column, const std::string& message) {
  bd::testing::expect_study_error(text, "e.yaml", line, column, message);
}

TEST(PlanarStudy, LoadsTheLinkageItDescribes) {
  const Study s = parse_study(kEngine, "e.yaml");
  ASSERT_FALSE(s.is_fourbar());
  const core::planar::Linkage& l = s.planar();
  ASSERT_EQ(l.nodes.size(), 3u);
  EXPECT_TRUE(l.nodes[0].ground);
  EXPECT_EQ(l.nodes[2].position, Vec2(0.18, 0));
  ASSERT_EQ(l.links.size(), 2u);
  EXPECT_EQ(l.links[1].nodes, (std::vector<int>{1, 2}));
  EXPECT_EQ(l.links[1].e, 0.035);
  ASSERT_EQ(l.point_masses.size(), 1u);
  EXPECT_EQ(l.point_masses[0].mass, 0.35);
  ASSERT_EQ(l.sliders.size(), 1u);
  EXPECT_EQ(l.sliders[0].link, -1);
  EXPECT_EQ(l.sliders[0].to, Vec2(1, 0));
  ASSERT_EQ(l.inputs.size(), 1u);
  EXPECT_EQ(l.inputs[0].kind, core::planar::Input::Kind::kAngle);
  const auto& scene = std::get<core::planar::DrivenScene>(s.scene);
  EXPECT_EQ(scene.speeds, std::vector<double>{314.1592653589793});
  EXPECT_EQ(scene.samples, 36);
  EXPECT_EQ(choose_method(s).method, Method::kTruss);
}

TEST(PlanarStudy, RunsOnTheGeneralEngine) {
  const Study s = parse_study(kEngine, "e.yaml");
  const RunResult r = compute_study(s);
  ASSERT_TRUE(r.ok()) << r.status().message;
  EXPECT_EQ(r.planar.table.rows(), 36u);
  // the piston's acceleration at top dead centre: -r ω² (1 + r/l), the exact slider-crank value
  const double w = 314.1592653589793, rr = 0.04, ll = 0.14;
  EXPECT_NEAR(r.planar.table.column_values("a_piston")[0], -rr * w * w * (1 + rr / ll),
              1e-12 * rr * w * w);
  ASSERT_FALSE(r.metric_list.empty());
  EXPECT_EQ(r.metric_list.front().name, "Fsh_rms");
}

TEST(PlanarStudy, MistakesAreOneLineAtTheirPlace) {
  expect_error(edit("rod: {nodes: [A, B]", "rod: {nodes: [A, C]"), 10, 22,
               "linkage.links.rod.nodes[1]: unknown node 'C'; the nodes are O, A, B");
  expect_error(edit("rod: {nodes: [A, B]", "rod: {nodes: [A]"), 10, 18,
               "linkage.links.rod.nodes must be a list of two or more node names");
  expect_error(edit("rod: {nodes: [A, B]", "rod: {nodes: [A, A]"), 10, 22,
               "linkage.links.rod.nodes names A twice");
  expect_error(edit("    B: [0.18, 0]\n", "    B: [0.04, 0]\n"), 10, 18,
               "linkage.links.rod: its first two nodes A and B are drawn at the same point");
  expect_error(edit("[[0, 0], [1, 0]]", "[[1, 0], [1, 0]]"), 13, 30,
               "linkage.sliders.piston.guide: its two points coincide");
  expect_error(edit("[[0, 0], [1, 0]]", "[[0, 0.01], [1, 0.01]]"), 2, 1,
               "linkage: the drawn positions do not close slider piston (node B on its guide): "
               "off by 0.01 m");
  expect_error(edit("    crank: {link: crank}\n",
                    "    crank: {link: crank}\n    stroke: {slider: piston}\n"),
               14, 3, "the linkage has 1 degree of freedom and 2 inputs");
  expect_error(edit("{link: crank}", "{link: shaft}"), 15, 19,
               "linkage.inputs.crank.link: unknown link 'shaft'; the links are crank, rod");
  expect_error(edit("{link: crank}", "{slider: ram}"), 15, 21,
               "linkage.inputs.crank.slider: unknown slider 'ram'; the sliders are piston");
  expect_error(edit("{link: crank}", "{link: rod}"), 15, 5,
               "link rod has no ground node to turn about");
  expect_error(edit("  point_masses: {B: 0.35}\n", "  point_masses: {B: -1}\n"), 11, 21,
               "linkage.point_masses.B must be > 0 kg, got -1");
  expect_error(edit("mass: 0.45", "mass: -0.45"), 10, 32,
               "linkage.links.rod.mass must be >= 0 kg, got -0.45");
  expect_error(edit("speeds: [314.1592653589793]", "speeds: [1, 2]"), 18, 11,
               "scene.speeds must be a list of 1 number (one per input");
  expect_error(kEngine + "method: mass-matrix\n", 20, 9,
               "method mass-matrix is one of the four-bar's formulations");
  expect_error(edit("  type: planar\n", "  type: sixbar\n"), 3, 9,
               "linkage.type 'sixbar' is not supported; expected fourbar or planar");
  // the centre of mass: one complete pair, {e, f} or {s, sigma} (the four-bar's reader's check)
  const std::string crank = "e: 0.012, f: 0, inertia";
  expect_error(edit(crank, "e: 0.012, inertia"), 9, 39,
               "linkage.links.crank.e is given without f; give both e and f");
  expect_error(edit(crank, "e: 0.012, f: 0, s: 0.1, inertia"), 9, 55,
               "linkage.links.crank gives its centre of mass both as {s, sigma} and as {e, f}");
  expect_error(edit(crank, "inertia"), 9, 5, "linkage.links.crank: missing the centre of mass");
  // a slider-crank drawn at its outer dead centre and driven from the piston: the drawing is
  // where the piston does not fix the crank, so no start can be reached from it (a designer saw
  // "cannot be assembled at stroke = 0.1775 m: input stroke does not close" for a start of 0.17,
  // and "reciprocal condition nan" for 0.18)
  const std::string from_piston =
      edit("    crank: {link: crank}\n", "    stroke: {slider: piston}\n");
  for (const char* start : {"0.3", "0.17", "0.12"}) {
    std::string beyond = from_piston;
    beyond.replace(beyond.find("  speeds: [314.1592653589793]\n"), 30,
                   "  speeds: [0.1]\n  duration: 1\n  start: [" + std::string(start) + "]\n");
    expect_error(beyond, 16, 1,
                 "scene: the linkage cannot be moved from its drawing (stroke = 0.18 m) to stroke "
                 "= " +
                     std::string(start) +
                     " m: the drawing is a dead centre of the inputs (they do not fix the "
                     "linkage's position there); draw the linkage away from it");
  }
  // a scene by duration that drives the piston past its inner dead centre (rod - crank =
  // 0.10 m from O) is refused at scene.type, at the first sample beyond it, as a scene over
  // whole revolutions is where the linkage cannot turn (the run would stop there)
  std::string past = from_piston;  // drawn with the crank upright, away from the dead centres
  auto replace = [](std::string& text, const std::string& from, const std::string& to) {
    text.replace(text.find(from), from.size(), to);
  };
  replace(past, "    A: [0.04, 0]\n", "    A: [0, 0.04]\n");
  replace(past, "    B: [0.18, 0]\n", "    B: [0.13416407864998739, 0]\n");
  replace(past, "  speeds: [314.1592653589793]\n",
          "  speeds: [-0.1]\n  duration: 1\n  start: [0.13]\n");
  expect_error(past, 17, 9,
               "scene.type: driven moves the inputs at their speeds for the whole duration, but "
               "the linkage cannot be assembled at stroke = ");
  const std::string message = bd::testing::study_error_of(past, "e.yaml").message();
  const double stroke = std::stod(message.substr(message.find("stroke = ") + 9));
  const double step = 0.1 / 35;  // 36 samples over 1 s at 0.1 m/s
  EXPECT_LT(stroke, 0.10) << message;
  EXPECT_GE(stroke, 0.10 - step) << message;
  // within its reach it runs
  std::string within = past;  // (the stroke ends at 0.105 m)
  replace(within, "duration: 1\n", "duration: 0.25\n");
  EXPECT_NO_THROW(parse_study(within, "e.yaml"));
}

TEST(PlanarStudy, ExamplesWriteBackAsThemselves) {
  const Study s = load_study(BD_SOURCE_DIR "/studies/examples/stephenson-sixbar-free.yaml");
  const Study back = parse_study(study_yaml(s, ""), "copy.yaml");
  EXPECT_EQ(study_yaml(back, ""), study_yaml(s, ""));
  EXPECT_EQ(back.planar().springs.size(), 1u);
  EXPECT_EQ(back.planar().inputs[0].effort(0.0), 2.0);
}

}  // namespace
}  // namespace bd::studies
