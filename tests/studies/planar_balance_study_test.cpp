// A planar linkage's balance section, from the study file to the files a run writes: the loader
// places every mistake at its file:line:column; the runner synthesises the counterweights from
// the original's motion, simulates the balanced design and writes it as a study that runs by
// itself. The balanced six-bars are checked by the independent referee (tests/reference/planar,
// Newton-Euler per body, sharing no code with the engine or the balance layer), the engine's
// least-squares design by the engine's own simulation of it (regressors against kinetostatics).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>
#include <vector>

#include "core/number_text.hpp"
#include "studies/run/runner.hpp"
#include "studies/studies.hpp"
#include "studies/study/load_study.hpp"
#include "tests/support/planar_glue.hpp"
#include "tests/support/studies.hpp"
#include "tests/support/study_errors.hpp"
#include "tests/support/text.hpp"

namespace bd::studies {
namespace {

namespace fs = std::filesystem;
namespace bp = balance::planar;

// a slider-crank driven by its crank; line numbers below refer to it
const std::string kEngine = bd::testing::engine_study(72);

void expect_error(const std::string& text, int line, int column, const std::string& message) {
  bd::testing::expect_study_error(text, "e.yaml", line, column, message);
}

using bd::testing::example_path;
using bd::testing::rms_norm;

// the column `name` of a planar run's table
std::vector<double> column(const core::planar::Trajectory& t, const std::string& name) {
  return t.table.column_values(name);
}

TEST(PlanarBalanceStudy, MistakesAreOneLineAtTheirPlace) {
  expect_error(kEngine + "balance: {moment: full, balancing_factor: 0.5}\n", 20, 19,
               "balance.moment: full needs full force balance, which a balancing factor does not "
               "give");
  expect_error(kEngine + "balance:\n  moment: full\n  counter_rotations:\n    piston: {}\n", 23, 5,
               "balance.counter_rotations.piston: no link of that name");
  expect_error(kEngine + "balance:\n  moment: full\n  counter_rotations:\n    rod: {}\n", 23, 5,
               "balance.counter_rotations.rod: the link does not turn about one ground node");
  expect_error(kEngine + "balance:\n  moment: full\n  counter_rotations:\n    crank: {at: [1]}\n",
               23, 17, "balance.counter_rotations.crank.at");
  expect_error(kEngine + "balance:\n  moment: full\n  counter_rotations:\n    crank: {on: 1}\n", 23,
               13, "on");
  expect_error(kEngine + "balance: {force: none}\n", 20, 18,
               "balance.force: none leaves nothing to balance");
  expect_error(kEngine + "balance:\n  counterweights:\n    piston: {}\n", 22, 5,
               "balance.counterweights.piston: no link of that name (links: crank, rod)");
  expect_error(kEngine + "balance:\n  counterweights:\n    crank: {mass: -1}\n", 22, 19,
               "balance.counterweights.crank.mass must be > 0 kg, got -1");
  expect_error(kEngine + "balance:\n  counterweights:\n    rod: {distance: 0.05}\n", 22, 5,
               "balance.counterweights.rod: the link does not turn about the frame");
  expect_error(kEngine + "balance:\n  counterweights:\n    crank: {colour: red}\n", 22, 13,
               "colour");
  expect_error(kEngine + "balance: {counter_rotations: {}}\n", 20, 11,
               "balance.counter_rotations are used only with balance.moment: full");
  expect_error(kEngine + "balance: {balancing_factor: -1}\n", 20, 29,
               "balance.balancing_factor must be >= 0");
  expect_error(kEngine + "balance:\n  counterweights: {rod: {mass: 1}}\n  balancing_factor: 0.5\n",
               22, 21, "balance.balancing_factor: applies to one counterweight, on a crank");
  expect_error(kEngine + "balance:\n  shafts: {orders: [1, 0]}\n", 21, 24,
               "balance.shafts.orders[1] must be a whole number from 1 to 100, got 0");
  expect_error(kEngine + "balance:\n  shafts: {orders: 2}\n", 21, 20,
               "balance.shafts.orders must be a list of whole numbers >= 1");
  expect_error(kEngine + "balance:\n  shafts: {orders: [2], radius: 0}\n", 21, 33,
               "balance.shafts.radius must be > 0 m, got 0");
  expect_error(kEngine + "balance:\n  shafts: {orders: [1, 1]}\n", 21, 24,
               "balance.shafts.orders[1] repeats order 1 (orders[0])");
  expect_error(kEngine + "balance:\n  shafts: {orders: [2], at: {shaft_3: [0, 1]}}\n", 21, 30,
               "balance.shafts.at.shaft_3: no such shaft (the orders give shaft_2, shaft_-2)");
}

// The Lanchester example: the crank counterweight by balancing factor 0.5, then shafts at -1, 2
// and -2 times crank speed; the balanced run's orders 1 and 2 (harmonics, from its own samples)
// vanish to round-off, order 4 stays, and its balanced.yaml runs by itself to the same samples.
TEST(PlanarBalanceStudy, TheLanchesterEngineLosesOrdersOneAndTwoAndItsStudyRunsByItself) {
  const fs::path dir = fs::path(BD_BINARY_DIR) / "test-output" / "planar-balance" / "lanchester";
  fs::remove_all(dir);
  const Study study = load_study(example_path("engine-lanchester.yaml"));
  RunResult r = compute_study(study);
  write_run(study, r, dir);
  ASSERT_TRUE(r.ok() && r.balanced && r.balanced->ok() && r.balanced->shafts);
  const bp::ShaftBalance& sh = *r.balanced->shafts;
  ASSERT_EQ(sh.added.size(), 3u);  // the counterweight took the forward half of order 1
  ASSERT_TRUE(r.harmonics && r.balanced->harmonics);
  const Harmonics& before = *r.harmonics;
  const Harmonics& after = *r.balanced->harmonics;
  auto x = [](const Harmonics& h, int n) {
    return h.orders[static_cast<std::size_t>(n)].Fshx.amplitude;
  };
  auto y = [](const Harmonics& h, int n) {
    return h.orders[static_cast<std::size_t>(n)].Fshy.amplitude;
  };
  const double size = x(before, 1);
  for (int n : {1, 2, 3}) {
    EXPECT_LT(x(after, n), 1e-12 * size) << n;
    EXPECT_LT(y(after, n), 1e-12 * size) << n;
  }
  EXPECT_NEAR(x(after, 4), x(before, 4), 1e-12 * size);
  EXPECT_GT(x(before, 4), 1e-4 * size);
  const Study again = load_study((dir / "balanced.yaml").string());
  ASSERT_EQ(again.planar().shafts.size(), 3u);
  // what the design reports, against the design read back and its own simulation (no gravity:
  // the shaking force is all inertial)
  const bp::ForceBalance& d = *r.balanced->design;
  EXPECT_NEAR(d.added_mass,
              core::planar::total_mass(again.planar()) - core::planar::total_mass(study.planar()),
              1e-12 * core::planar::total_mass(study.planar()));
  const core::planar::Trajectory& t = r.balanced->planar;
  EXPECT_NEAR(d.Fsh_rms_after, rms_norm(column(t, "Fshx"), column(t, "Fshy")),
              1e-12 * d.Fsh_rms_before);
  EXPECT_LT(d.Fsh_rms_after, 3e-3 * d.Fsh_rms_before);
  const RunResult r2 = compute_study(again);
  ASSERT_TRUE(r2.ok());
  const std::vector<double> a = column(r.balanced->planar, "Fshx"), b = column(r2.planar, "Fshx");
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_NEAR(a[i], b[i], 1e-12 * size);
  // summary.json's ratios pair the metrics by name: the shafts' bearings are metrics the original
  // lacks, so an index pairing would shift every ratio after them
  const nlohmann::json summary = nlohmann::json::parse(bd::testing::read(dir / "summary.json"));
  const nlohmann::json& original = summary.at("metrics");
  const nlohmann::json& balanced = summary.at("balanced_metrics");
  ASSERT_GT(balanced.size(), original.size());
  for (const auto& [name, ratio] : summary.at("reduction").items()) {
    SCOPED_TRACE(name);
    ASSERT_TRUE(balanced.contains(name));
    if (!original.contains(name) || original.at(name).get<double>() == 0) {
      EXPECT_TRUE(ratio.is_null());
    } else {
      EXPECT_EQ(ratio.get<double>(),
                balanced.at(name).get<double>() / original.at(name).get<double>());
    }
  }
  EXPECT_EQ(summary.at("reduction").size(), balanced.size());
  EXPECT_EQ(summary.at("reduction").at("FA_max").get<double>(),
            balanced.at("FA_max").get<double>() / original.at("FA_max").get<double>());
}

// The Berkof inline four-bar of berkof-inline-moment-balanced.yaml written as a planar linkage
// (crank A0-A1, coupler A1-A2, rocker A2-A3): balance.moment: full finds the four-bar's
// counter-rotations (Berkof's reduced inertias, from the four-bar's own synthesis of that
// example), the balanced run has neither shaking force nor shaking moment left, and its
// balanced.yaml, with the discs as balance shafts, runs by itself to the same samples.
TEST(PlanarBalanceStudy, ABerkofFourBarOnTrussElementsIsForceAndMomentBalanced) {
  // A2 where the coupler (3 m from A1 = (1, 0)) meets the rocker (2 m from A3 = (3.2, 0))
  const double a = (9.0 - 4.0 + 2.2 * 2.2) / (2 * 2.2), h = std::sqrt(9.0 - a * a);
  const std::string text =
      "name: berkof-planar\n"
      "linkage:\n"
      "  type: planar\n"
      "  nodes:\n"
      "    A0: {at: [0, 0], ground: true}\n"
      "    A3: {at: [3.2, 0], ground: true}\n"
      "    A1: [1, 0]\n"
      "    A2: [" +
      text::exact(1 + a) + ", " + text::exact(h) +
      "]\n"
      "  links:\n"
      "    crank: {nodes: [A0, A1], mass: 2.0, e: 0.5, f: 0, inertia: 0.2}\n"
      "    coupler: {nodes: [A1, A2], mass: 3.0, e: 1.2, f: 0, inertia: 6.48}\n"
      "    rocker: {nodes: [A2, A3], mass: 2.2, e: 1.0, f: 0, inertia: 0.8}\n"
      "  inputs:\n"
      "    crank: {link: crank}\n"
      "scene:\n"
      "  type: driven\n"
      "  speeds: [6.283185307179586]\n"
      "  samples: 360\n"
      "balance:\n"
      "  moment: full\n"
      "  counter_rotations:\n"
      "    crank: {at: [0.0, -1.0]}\n"
      "    rocker: {at: [3.2, -2.0]}\n";
  const Study study = parse_study(text, "berkof-planar.yaml");
  ASSERT_TRUE(study.planar_balance && study.planar_balance->counter_rotations);
  const fs::path out = fs::path(BD_BINARY_DIR) / "test-output" / "planar-balance" / "berkof";
  fs::remove_all(out);
  RunResult r = compute_study(study);
  write_run(study, r, out);
  ASSERT_TRUE(r.ok() && r.balanced && r.balanced->ok() && r.balanced->moment);
  const bp::MomentBalance& m = *r.balanced->moment;
  EXPECT_TRUE(m.full) << m.message;

  const Study fourbar = load_study(example_path("berkof-inline-moment-balanced.yaml"));
  const core::CounterRotations& want = fourbar.balance->model.counter_rotations;
  ASSERT_EQ(m.added.size(), 2u);
  const core::planar::BalanceShaft& c = m.linkage.shafts[static_cast<std::size_t>(m.added[0])];
  const core::planar::BalanceShaft& k = m.linkage.shafts[static_cast<std::size_t>(m.added[1])];
  EXPECT_NEAR(c.inertia, want.crank.inertia, 1e-12 * want.crank.inertia);
  EXPECT_NEAR(k.inertia, want.rocker.inertia, 1e-12 * want.rocker.inertia);

  // the balanced run: no inertial shaking force or moment (no gravity) against the original's
  const core::planar::Trajectory& b = r.balanced->planar;
  const double force = rms_norm(column(r.planar, "Fshx"), column(r.planar, "Fshy"));
  const std::vector<double> msh0 = column(r.planar, "Msh"), zero(msh0.size(), 0.0);
  const double moment = rms_norm(msh0, zero);
  EXPECT_LE(rms_norm(column(b, "Fshx"), column(b, "Fshy")), 1e-12 * force);
  EXPECT_LE(rms_norm(column(b, "Msh"), zero), 1e-12 * moment);

  const nlohmann::json j = nlohmann::json::parse(bd::testing::read(out / "summary.json"));
  EXPECT_EQ(j["balance"]["moment"], "full");
  EXPECT_EQ(j["balance"]["moment_balanced"], true);
  EXPECT_EQ(j["balance"]["counter_rotations"].size(), 2u);
  EXPECT_EQ(j["balance"]["counter_rotations"][1]["name"], "counter_rocker");
  EXPECT_EQ(j["balance"]["counter_rotations"][1]["ratio"], -1);
  EXPECT_EQ(j["balance"]["counter_rotations"][1]["inertia"].get<double>(), k.inertia);

  const Study again = load_study((out / "balanced.yaml").string());
  ASSERT_EQ(again.planar().shafts.size(), 2u);
  EXPECT_EQ(again.planar().shafts[0].inertia, c.inertia);
  const RunResult rerun = compute_study(again);
  ASSERT_TRUE(rerun.ok());
  const std::vector<double> m1 = column(b, "Msh"), m2 = column(rerun.planar, "Msh");
  ASSERT_EQ(m1.size(), m2.size());
  for (std::size_t i = 0; i < m1.size(); ++i) EXPECT_EQ(m1[i], m2[i]);
}

// An engine cannot be fully force balanced by its crank counterweight, so a moment balance has
// nothing to start from: no discs are added, and the message and summary.json say why.
TEST(PlanarBalanceStudy, NoCounterRotationsWithoutFullForceBalance) {
  const Study study = parse_study(kEngine + "balance:\n  moment: full\n", "e.yaml");
  ASSERT_TRUE(study.planar_balance && study.planar_balance->counter_rotations);
  const fs::path out = fs::path(BD_BINARY_DIR) / "test-output" / "planar-balance" / "no-discs";
  fs::remove_all(out);
  RunResult r = compute_study(study);
  write_run(study, r, out);
  ASSERT_TRUE(r.ok() && r.balanced && r.balanced->design);
  EXPECT_FALSE(r.balanced->moment.has_value());
  EXPECT_TRUE(r.balanced->design->linkage.shafts.empty());
  const nlohmann::json j = nlohmann::json::parse(bd::testing::read(out / "summary.json"));
  EXPECT_EQ(j["balance"]["moment"], "full");
  EXPECT_EQ(j["balance"]["moment_balanced"], false);
  EXPECT_FALSE(j["balance"].contains("counter_rotations"));
  EXPECT_NE(j["balance"]["message"].get<std::string>().find(
                "no counter-rotations: a moment balance starts from full force balance, which "
                "is not reached"),
            std::string::npos);
}

TEST(PlanarBalanceStudy, CounterweightsDefaultToTheLinksThatTurnAboutTheFrame) {
  const Study s = parse_study(kEngine + "balance:\n", "e.yaml");
  ASSERT_TRUE(s.planar_balance.has_value());
  ASSERT_EQ(s.planar_balance->counterweights.size(), 1u);
  EXPECT_EQ(s.planar_balance->counterweights[0].link, 0);  // the crank, not the rod

  const Study w = load_study(example_path("watt-sixbar-balanced.yaml"));
  ASSERT_TRUE(w.planar_balance.has_value());
  std::vector<std::string> links;
  for (const bp::LinkCounterweightSpec& c : w.planar_balance->counterweights) {
    links.push_back(w.planar().links[static_cast<std::size_t>(c.link)].name);
    EXPECT_EQ(c.spec.shape, balance::CounterweightShape::kDisc);
  }
  EXPECT_EQ(links, (std::vector<std::string>{"crank", "rocker", "output"}));
}

// The example six-bar: fully force balanced; the balanced design's own simulation, and the
// referee's of the design read back from balanced.yaml, find no inertial shaking force left; the
// files say what was added and the balanced study runs by itself to the same numbers.
TEST(PlanarBalanceStudy, TheExampleSixBarIsFullyForceBalancedAndItsStudyRunsByItself) {
  const Study study = load_study(example_path("watt-sixbar-balanced.yaml"));
  const fs::path out = fs::path(BD_BINARY_DIR) / "test-output" / "planar-balance" / "watt";
  fs::remove_all(out);
  RunResult r = compute_study(study);
  write_run(study, r, out);
  ASSERT_TRUE(r.ok());
  ASSERT_TRUE(r.balanced && r.balanced->design);
  const bp::ForceBalance& design = *r.balanced->design;
  EXPECT_TRUE(design.full) << design.message;
  EXPECT_EQ(design.conditions, 6);
  ASSERT_EQ(design.added.size(), 3u);

  // the engine's balanced run: the shaking force is inertial (no gravity) and gone
  const double before = r.metric_list.front().value;  // Fsh_rms
  ASSERT_EQ(r.metric_list.front().name, "Fsh_rms");
  ASSERT_GT(before, 1.0);
  const core::planar::Trajectory& b = r.balanced->planar;
  const std::vector<double> fx = column(b, "Fshx"), fy = column(b, "Fshy");
  double worst = 0;
  for (std::size_t i = 0; i < fx.size(); ++i) worst = std::max(worst, std::hypot(fx[i], fy[i]));
  EXPECT_LE(worst / before, 1e-13);

  // balanced.yaml is the design to the last digit, and runs by itself to the same samples
  const Study again = load_study((out / "balanced.yaml").string());
  ASSERT_FALSE(again.is_fourbar());
  EXPECT_FALSE(again.planar_balance.has_value());
  for (std::size_t k = 0; k < design.linkage.links.size(); ++k) {
    const core::planar::Link& x = again.planar().links[k];
    const core::planar::Link& y = design.linkage.links[k];
    EXPECT_EQ(x.mass, y.mass);
    EXPECT_EQ(x.e, y.e);
    EXPECT_EQ(x.f, y.f);
    EXPECT_EQ(x.inertia, y.inertia);
  }
  const RunResult rerun = compute_study(again);
  ASSERT_EQ(rerun.metric_list.size(), r.balanced->metric_list.size());
  for (std::size_t k = 0; k < rerun.metric_list.size(); ++k) {
    EXPECT_EQ(rerun.metric_list[k].value, r.balanced->metric_list[k].value)
        << rerun.metric_list[k].name;
  }

  // each counterweight as reported (mass, position from its pivot, disc of the radius given) is
  // what the link in balanced.yaml carries: the merged link rebuilt here by the parallel-axis
  // sum from the original link and the reported counterweight (every pivot here is the link's
  // first node, so link axes and pivot axes share their origin)
  double inertia_added = 0;
  for (const bp::LinkCounterweight& c : design.added) {
    const core::planar::Link& before_link = study.planar().links[static_cast<std::size_t>(c.link)];
    const core::planar::Link& after_link = again.planar().links[static_cast<std::size_t>(c.link)];
    ASSERT_EQ(c.pivot, before_link.nodes[0]);
    const balance::Counterweight& w = c.counterweight;
    EXPECT_NEAR(w.distance, w.position.norm(), 1e-15 * w.distance);
    EXPECT_NEAR(w.inertia, 0.5 * w.mass * w.radius * w.radius, 1e-15 * w.inertia);  // a disc
    EXPECT_NEAR(w.mass, 0.02 * 7850 * std::numbers::pi * w.radius * w.radius, 1e-13 * w.mass);
    const double m = before_link.mass + w.mass;
    const Vec2 g0(before_link.e, before_link.f),
        g = (before_link.mass * g0 + w.mass * w.position) / m;
    const double inertia = before_link.inertia + before_link.mass * (g0 - g).squaredNorm() +
                           w.inertia + w.mass * (w.position - g).squaredNorm();
    EXPECT_NEAR(after_link.mass, m, 1e-15 * m) << after_link.name;
    EXPECT_NEAR(after_link.e, g.x(), 1e-15 * g.norm()) << after_link.name;
    EXPECT_NEAR(after_link.f, g.y(), 1e-15 * g.norm()) << after_link.name;
    EXPECT_NEAR(after_link.inertia, inertia, 1e-14 * inertia) << after_link.name;
    inertia_added += w.inertia + w.mass * w.position.squaredNorm();  // about the pivot
  }
  EXPECT_NEAR(design.added_inertia, inertia_added, 1e-14 * inertia_added);
  EXPECT_LE(design.momentum_left, 1e-12);

  // the referee on the design as written: no inertial shaking force at any sample
  const bd::testing::planar::Glue g = bd::testing::planar::glue_of(again.planar());
  const auto& scene = std::get<core::planar::DrivenScene>(study.scene);
  const std::vector<double> times = column(b, "t");
  double referee_worst = 0;
  for (const referee::Sample& s : referee::driven(g.mechanism, scene.speeds, 0.0, times)) {
    referee_worst = std::max(referee_worst, s.inertial_force.norm() / before);
  }
  EXPECT_LE(referee_worst, 1e-10);

  // the mass added is the balanced linkage's total mass less the original's
  const double added =
      core::planar::total_mass(again.planar()) - core::planar::total_mass(study.planar());
  EXPECT_NEAR(design.added_mass, added, 1e-14 * added);
  const std::string csv = bd::testing::read(out / "comparison.csv");
  EXPECT_NE(csv.find("\nFsh_rms," + text::exact(before) + ","), std::string::npos) << csv;
  EXPECT_NE(csv.find("\nFD_max,"), std::string::npos) << csv;  // every metric of the six-bar
  EXPECT_NE(csv.find("\nadded_mass,0," + text::exact(design.added_mass) + ",\n"), std::string::npos)
      << csv;
  const std::string summary = bd::testing::read(out / "summary.json");
  EXPECT_NE(summary.find("\"force_balanced\": true"), std::string::npos);
  EXPECT_NE(summary.find("\"balanced_metrics\""), std::string::npos);
  EXPECT_NE(summary.find("\"from_node\": \"O4\""), std::string::npos);
}

// A slider-crank's piston cannot be balanced by a counterweight on the crank: the message says
// so, and the least-squares design's RMS shaking force, computed by the balance layer from its
// regressor, is what the engine's simulation of the design finds.
TEST(PlanarBalanceStudy, AnEnginesCrankCounterweightLeavesWhatTheMessageSays) {
  const Study study =
      parse_study(kEngine + "balance:\n  counterweights:\n    crank: {}\n", "e.yaml");
  const RunResult r = compute_study(study);
  ASSERT_TRUE(r.ok());
  ASSERT_TRUE(r.balanced && r.balanced->design);
  const bp::ForceBalance& d = *r.balanced->design;
  EXPECT_FALSE(d.full);
  EXPECT_NE(d.message.find("cannot"), std::string::npos) << d.message;
  // what is left is named as the piston's reciprocating mass (the crank pin's equivalent mass
  // is left on purpose: it cancels half the piston's first order)
  EXPECT_NE(d.message.find("the reciprocating mass at B"), std::string::npos) << d.message;
  const core::planar::Trajectory& b = r.balanced->planar;
  const double simulated = rms_norm(column(b, "Fshx"), column(b, "Fshy"));
  EXPECT_NEAR(d.Fsh_rms_after, simulated, 1e-12 * d.Fsh_rms_before);
  EXPECT_NEAR(d.Fsh_rms_before, r.metric_list.front().value, 1e-12 * d.Fsh_rms_before);
  EXPECT_LT(d.Fsh_rms_after, d.Fsh_rms_before);
}

// A floating link's counterweight has its mass given and its place solved: a rod counterweight
// of 1 g that balances the engine's piston must sit some 65 m out (the moment it must carry over
// its mass), and the message says so; with 1 kg it sits within the linkage and nothing is said.
TEST(PlanarBalanceStudy, AFloatingCounterweightFarOutsideTheLinkageIsSaid) {
  auto balance = [](const std::string& mass) {
    const Study study = parse_study(
        kEngine + "balance:\n  counterweights:\n    crank: {}\n    rod: {mass: " + mass + "}\n",
        "e.yaml");
    const RunResult r = compute_study(study);
    EXPECT_TRUE(r.ok() && r.balanced && r.balanced->design);
    return *r.balanced->design;
  };
  const bp::ForceBalance light = balance("0.001"), heavy = balance("1");
  EXPECT_TRUE(light.full && heavy.full);
  ASSERT_EQ(light.added.size(), 2u);
  EXPECT_GT(light.added[1].counterweight.distance, 3 * 0.14);
  EXPECT_NE(light.message.find("the counterweight on rod sits"), std::string::npos)
      << light.message;
  EXPECT_NE(light.message.find("give it more mass"), std::string::npos) << light.message;
  EXPECT_LT(heavy.added[1].counterweight.distance, 3 * 0.14);
  EXPECT_EQ(heavy.message.find("sits"), std::string::npos) << heavy.message;
}

// momentum_left of a least-squares design (the engine: a piston no counterweight balances)
// against a second route: the linear momentum of each design from its simulated node positions
// alone (every body's centre of mass from the link's nodes and its e, f; the point masses at
// their nodes), differentiated in time by central differences over the periodic revolution
// (error ~ (ω h)² / 6 = 5e-7 at 3600 samples a revolution), RMS over the samples, design over original.
TEST(PlanarBalanceStudy, TheLeastSquaresMomentumLeftIsTheDesignsMomentumOverTheOriginals) {
  const Study study = parse_study(bd::testing::engine_study(3600) +
                                      "balance:\n  counterweights:\n    crank: {}\n",
                                  "e.yaml");
  const RunResult r = compute_study(study);
  ASSERT_TRUE(r.ok() && r.balanced && r.balanced->design);
  const bp::ForceBalance& d = *r.balanced->design;
  ASSERT_FALSE(d.full);
  // Σ m c over the bodies at each sample of a run's table
  auto first_moment = [](const core::planar::Linkage& l, const core::planar::Trajectory& t) {
    const std::size_t n = t.table.column_values("t").size();
    std::vector<std::vector<Vec2>> at(l.nodes.size(), std::vector<Vec2>(n));
    for (std::size_t k = 0; k < l.nodes.size(); ++k) {
      const auto& node = l.nodes[k];
      if (node.ground) {
        std::fill(at[k].begin(), at[k].end(), node.position);
        continue;
      }
      const std::vector<double> x = column(t, "x_" + node.name), y = column(t, "y_" + node.name);
      for (std::size_t i = 0; i < n; ++i) at[k][i] = Vec2(x[i], y[i]);
    }
    std::vector<Vec2> S(n, Vec2(0, 0));
    for (std::size_t i = 0; i < n; ++i) {
      for (const core::planar::Link& link : l.links) {
        const Vec2 p = at[static_cast<std::size_t>(link.nodes[0])][i],
                   q = at[static_cast<std::size_t>(link.nodes[1])][i];
        const Vec2 u = (q - p) / (q - p).norm();
        S[i] += link.mass * (p + link.e * u + link.f * Vec2(-u.y(), u.x()));
      }
      for (const core::planar::PointMass& pm : l.point_masses)
        S[i] += pm.mass * at[static_cast<std::size_t>(pm.node)][i];
    }
    return S;
  };
  // the RMS of dS/dt over one revolution, periodic central differences
  auto rms_momentum = [](const std::vector<Vec2>& S, double dt) {
    const std::size_t n = S.size();
    double sum = 0;
    for (std::size_t i = 0; i < n; ++i) {
      sum += ((S[(i + 1) % n] - S[(i + n - 1) % n]) / (2 * dt)).squaredNorm();
    }
    return std::sqrt(sum / static_cast<double>(n));
  };
  const std::vector<double> time = column(r.planar, "t");
  const std::vector<double> angle = column(r.planar, "theta_crank");
  // one revolution without its repeated end point, if the table has one
  std::size_t n = angle.size();
  if (std::abs(std::abs(angle.back() - angle.front()) - 2 * std::numbers::pi) < 1e-9) --n;
  // the samples left span one period exactly, so the differences wrap around
  ASSERT_NEAR(angle[n - 1] + (angle[1] - angle[0]) - angle[0], 2 * std::numbers::pi, 1e-9);
  const double dt = time[1] - time[0];
  auto head = [n](std::vector<Vec2> v) {
    v.resize(n);
    return v;
  };
  const double before = rms_momentum(head(first_moment(study.planar(), r.planar)), dt);
  const double after = rms_momentum(head(first_moment(d.linkage, r.balanced->planar)), dt);
  ASSERT_GT(before, 0);
  EXPECT_NEAR(d.momentum_left, after / before, 1e-5 * after / before);
}

// A free run: the counterweights come from the configurations the original swung through, and
// the balanced design, released alike, shakes its frame with no inertial force whatever motion
// the spring and motor give it (its linear momentum is zero in every configuration).
TEST(PlanarBalanceStudy, AFreeSixBarBalancedFromItsSwingShakesNoMoreInItsOwnSwing) {
  std::string text = bd::testing::read(example_path("stephenson-sixbar-free.yaml"));
  const std::string gravity = "loads:\n  gravity: [0, -9.81]\n";
  ASSERT_NE(text.find(gravity), std::string::npos);
  text.replace(text.find(gravity), gravity.size(), "");
  text.replace(text.find("samples: 3001"), 13, "samples: 301");
  const Study study = parse_study(text + "balance:\n", "free.yaml");
  const RunResult r = compute_study(study);
  ASSERT_TRUE(r.ok()) << r.balanced->status().message;
  ASSERT_TRUE(r.balanced->design);
  EXPECT_TRUE(r.balanced->design->full) << r.balanced->design->message;
  const double before = r.metric_list.front().value;
  const core::planar::Trajectory& b = r.balanced->planar;
  const std::vector<double> fx = column(b, "Fshx"), fy = column(b, "Fshy");
  double worst = 0;
  for (std::size_t i = 0; i < fx.size(); ++i) worst = std::max(worst, std::hypot(fx[i], fy[i]));
  EXPECT_LE(worst / before, 1e-10);
  // the balanced design moves otherwise than the original (heavier links, same loads)
  EXPECT_NE(column(b, "theta_crank").back(), column(r.planar, "theta_crank").back());
}

// The balance conditions are the linkage's, not the scene's: a six-bar at rest in a free scene
// passes through one configuration, which shows 2 of its 6 conditions; the runner takes them
// from a full revolution of the crank instead (and says so), so the design is the one its driven
// study finds (the example, checked by the referee), not one balanced in a single position.
TEST(PlanarBalanceStudy, ALinkageAtRestIsBalancedInEveryConfiguration) {
  const std::string driven = bd::testing::read(example_path("watt-sixbar-balanced.yaml"));
  std::string still = driven;
  const std::size_t from = still.find("scene:"), to = still.find("balance:");
  ASSERT_NE(from, std::string::npos);
  still.replace(from, to - from,
                "scene: {type: free, rates: [0.0], duration: 0.2, samples: 21}\n\n");
  const RunResult moving = compute_study(parse_study(driven, "driven.yaml"));
  const RunResult r = compute_study(parse_study(still, "still.yaml"));
  ASSERT_TRUE(moving.ok() && r.ok());
  const bp::ForceBalance& a = *moving.balanced->design;
  const bp::ForceBalance& b = *r.balanced->design;
  EXPECT_TRUE(b.full) << b.message;
  EXPECT_EQ(b.conditions, 6);
  EXPECT_NE(b.message.find("the scene's motion shows 2 of the 6 conditions"), std::string::npos)
      << b.message;
  ASSERT_EQ(a.added.size(), b.added.size());
  for (std::size_t i = 0; i < a.added.size(); ++i) {
    const balance::Counterweight &x = a.added[i].counterweight,
                                 &y = b.added[i].counterweight;
    EXPECT_NEAR(y.mass, x.mass, 1e-10 * x.mass) << i;
    EXPECT_NEAR((y.position - x.position).norm(), 0.0, 1e-10 * x.position.norm()) << i;
  }
}

// A driven revolution sampled too coarsely to show every condition (1 or 2 samples per turn)
// is balanced as a fine one: the conditions come from a full revolution of the crank, not from
// its samples. (A designer's check: at 1 sample the design met that sample's conditions only,
// said "force balanced", and Fsh_rms rose from 3.81 to 5.03 N.)
TEST(PlanarBalanceStudy, ACoarselySampledRevolutionIsBalancedInEveryConfiguration) {
  const RunResult fine = compute_study(load_study(example_path("watt-sixbar-balanced.yaml")));
  ASSERT_TRUE(fine.ok() && fine.balanced && fine.balanced->design);
  const bp::ForceBalance& a = *fine.balanced->design;
  ASSERT_TRUE(a.full);
  for (const char* samples : {"1", "2"}) {
    SCOPED_TRACE(samples);
    const RunResult r = compute_study(parse_study(
        bd::testing::edited_example("watt-sixbar-balanced.yaml",
                                    {{"  samples: 360", std::string("  samples: ") + samples}}),
        "coarse.yaml"));
    ASSERT_TRUE(r.ok() && r.balanced && r.balanced->design);
    const bp::ForceBalance& b = *r.balanced->design;
    EXPECT_TRUE(b.full) << b.message;
    EXPECT_NE(b.message.find("of the 6 conditions of force balance, so they are taken from a "
                             "full revolution"),
              std::string::npos)
        << b.message;
    ASSERT_EQ(a.added.size(), b.added.size());
    for (std::size_t i = 0; i < a.added.size(); ++i) {
      const balance::Counterweight &x = a.added[i].counterweight, &y = b.added[i].counterweight;
      EXPECT_NEAR(y.mass, x.mass, 1e-10 * x.mass) << i;
      EXPECT_NEAR((y.position - x.position).norm(), 0.0, 1e-10 * x.position.norm()) << i;
    }
  }
}

// After full force balance no rotating part of the shaking force is left for a balance shaft:
// none is added (their masses were round-off, 3e-16 kg, before the threshold took the linkage's
// own scale instead of its balanced force's).
TEST(PlanarBalanceStudy, NoBalanceShaftForARoundOffRotatingPart) {
  std::string text = bd::testing::read(example_path("watt-sixbar-balanced.yaml"));
  text += "  shafts: {orders: [1, 2]}\n";
  const RunResult r = compute_study(parse_study(text, "shafts.yaml"));
  ASSERT_TRUE(r.ok() && r.balanced && r.balanced->shafts);
  EXPECT_TRUE(r.balanced->shafts->added.empty());
  EXPECT_TRUE(r.balanced->design->linkage.shafts.empty());
}

// A Lanchester pair placed either side of the cylinder axis (balance.shafts.at by shaft): the
// order-2 shafts of an inline engine cancel the secondary force along the axis, and their
// forces are mirror images (F_-2 the conjugate of F_2), so their moments about the crank,
// h (F_-2,x - F_2,x), cancel: the inertial shaking moment is the one with both shafts on the
// crank's axis, to round-off. Both at the same point above the axis it is not.
TEST(PlanarBalanceStudy, ALanchesterPairEitherSideOfTheAxisAddsNoShakingMoment) {
  const std::string text = bd::testing::read(example_path("engine-lanchester.yaml"));
  const std::string radius = "    radius: 0.02";
  ASSERT_NE(text.find(radius), std::string::npos);
  auto run = [&](const std::string& at) {
    std::string t = text;
    t.insert(t.find(radius), at);
    const RunResult r = compute_study(parse_study(t, "lanchester.yaml"));
    EXPECT_TRUE(r.ok() && r.balanced && r.balanced->shafts);
    return r;
  };
  const RunResult axis = run("");
  const RunResult pair = run("    at: {shaft_2: [0, 0.1], shaft_-2: [0, -0.1]}\n");
  const RunResult above = run("    at: {shaft_2: [0, 0.1], shaft_-2: [0, 0.1]}\n");
  // the shafts sit where they were asked to, the others on the crank's axis
  for (const core::planar::BalanceShaft& b : pair.balanced->design->linkage.shafts) {
    const double y = b.ratio == 2 ? 0.1 : b.ratio == -2 ? -0.1 : 0.0;
    EXPECT_EQ(b.at, Vec2(0, y)) << b.name;
  }
  const std::vector<double> m0 = column(axis.balanced->planar, "Msh_inertial"),
                            m1 = column(pair.balanced->planar, "Msh_inertial"),
                            m2 = column(above.balanced->planar, "Msh_inertial");
  const double size = rms_norm(m0, std::vector<double>(m0.size(), 0.0));
  double pair_worst = 0, above_worst = 0;
  for (std::size_t i = 0; i < m0.size(); ++i) {
    pair_worst = std::max(pair_worst, std::abs(m1[i] - m0[i]));
    above_worst = std::max(above_worst, std::abs(m2[i] - m0[i]));
  }
  EXPECT_LE(pair_worst, 1e-10 * size);
  EXPECT_GT(above_worst, 0.1 * size);
  // the shaking force is the same wherever the shafts sit
  const double f0 = axis.balanced->design->Fsh_rms_after;
  EXPECT_NEAR(pair.balanced->design->Fsh_rms_after, f0, 1e-12 * axis.balanced->design->Fsh_rms_before);
  EXPECT_NEAR(above.balanced->design->Fsh_rms_after, f0, 1e-12 * axis.balanced->design->Fsh_rms_before);
}

// When the original stops early there is no motion to balance over: nothing is synthesised, the
// summary says why, no balanced file is written, and the run reports the early stop.
TEST(PlanarBalanceStudy, NoBalancedDesignWhenTheOriginalStopsEarly) {
  // the piston driven past its top dead centre: the loader refuses that scene (the run would
  // stop there), so it is lengthened after loading, as the library takes any scene
  Study study =
      parse_study(bd::testing::piston_driven_slider_crank(0.5, 31) + "balance:\n", "p.yaml");
  std::get<core::planar::DrivenScene>(study.scene).duration = 1.5;
  const fs::path out = fs::path(BD_BINARY_DIR) / "test-output" / "planar-balance" / "stopped";
  fs::remove_all(out);
  RunResult r = compute_study(study);
  write_run(study, r, out);
  EXPECT_TRUE(r.stopped_early());
  ASSERT_TRUE(r.balanced);
  EXPECT_FALSE(r.balanced->design);
  EXPECT_EQ(r.balanced->status().message.rfind("not run: the original design's simulation", 0), 0u)
      << r.balanced->status().message;
  EXPECT_TRUE(fs::exists(out / "timeseries.csv"));
  EXPECT_FALSE(fs::exists(out / "balanced.yaml"));
  EXPECT_FALSE(fs::exists(out / "comparison.csv"));
  const std::string summary = bd::testing::read(out / "summary.json");
  EXPECT_NE(summary.find("\"message\": \"not run: the original design's simulation stopped"),
            std::string::npos)
      << summary;
}

}  // namespace
}  // namespace bd::studies

namespace bd::studies {
namespace {

// added_inertia of a planar design (studies::added_inertia: each link's inertia about its pivot,
// before and after, from the merged link parameters) against the balance layer's own sum of the
// counterweights' inertias about their pivots.
TEST(PlanarBalanceStudy, AddedInertiaIsTheCounterweightsInertiaAboutTheirPivots) {
  const Study study = load_study(bd::testing::example_path("watt-sixbar-balanced.yaml"));
  const RunResult r = compute_study(study);
  ASSERT_TRUE(r.ok() && r.balanced && r.balanced->design);
  const bp::ForceBalance& b = *r.balanced->design;
  ASSERT_GT(b.added_inertia, 0);
  EXPECT_NEAR(added_inertia(study.planar(), b.linkage), b.added_inertia, 1e-12 * b.added_inertia);
}

// A sweep over the balancing factor of an engine with a Lanchester balancer: each point's
// synthesis adds its own shafts (their bearing forces are metrics of that point's balanced
// design), yet every row of sweep.csv has the header's columns, the balanced_ ones by name.
TEST(PlanarBalanceStudy, ASweepWithBalanceShaftsKeepsItsColumns) {
  const std::string text = bd::testing::read(bd::testing::example_path("engine-lanchester.yaml")) +
                           "sweep:\n  design: grid\n  parameters:\n"
                           "    - {path: balance.balancing_factor, values: [0, 0.5, 1.0]}\n";
  const Study study = parse_study(text, "sweep.yaml");
  const fs::path out = fs::path(BD_BINARY_DIR) / "test-output" / "planar-balance" / "sweep";
  fs::remove_all(out);
  SweepOptions options;
  options.threads = 1;

  const SweepResult r = run_sweep(study, out, options);
  ASSERT_TRUE(r.complete());
  EXPECT_EQ(r.failed, 0);
  const std::string csv = bd::testing::read(out / "sweep.csv");
  std::vector<std::string> lines;
  for (std::size_t a = 0, b; (b = csv.find('\n', a)) != std::string::npos; a = b + 1)
    lines.push_back(csv.substr(a, b - a));
  ASSERT_EQ(lines.size(), 4u);
  const auto fields = [](const std::string& line) {
    return std::count(line.begin(), line.end(), ',');
  };
  for (std::size_t i = 1; i < lines.size(); ++i) EXPECT_EQ(fields(lines[i]), fields(lines[0])) << i;
  // the point at 0.5 is the example itself: its balanced shaking force in its column
  const Study example = load_study(bd::testing::example_path("engine-lanchester.yaml"));
  const RunResult e = compute_study(example);
  ASSERT_TRUE(e.ok() && e.balanced);
  double want = 0;
  for (const MetricValue& m : e.balanced->metric_list)
    if (m.name == "Fsh_rms") want = m.value;
  std::vector<std::string> header, row;
  for (const auto& [line, cells] : {std::pair{lines[0], &header}, std::pair{lines[2], &row}}) {
    std::size_t a = 0;
    for (std::size_t b; (b = line.find(',', a)) != std::string::npos; a = b + 1)
      cells->push_back(line.substr(a, b - a));
    cells->push_back(line.substr(a));
  }
  const auto column = std::find(header.begin(), header.end(), "balanced_Fsh_rms") - header.begin();
  ASSERT_LT(static_cast<std::size_t>(column), row.size());
  EXPECT_EQ(std::stod(row[static_cast<std::size_t>(column)]), want);
}

}  // namespace
}  // namespace bd::studies
