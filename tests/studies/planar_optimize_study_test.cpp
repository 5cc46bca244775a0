// A planar linkage's optimize section, from the study file to the files a run writes: the loader
// places every mistake at its file:line:column; the runner solves the design problem in the
// driven scene, simulates the optimum and writes it as a study that runs by itself.
//
// The optimum is checked against an independent route: the paper's four-bar optimisation of
// berkof-lowen-min-shaking-moment.yaml (the four-bar's closed-form kinematics and dynamics, its
// own problem with eq. 57 as the force balance) written as a planar linkage on truss elements
// (the general engine, the regressor from its runs, the momentum conditions) must reach the same
// optimum.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>
#include <vector>

#include "core/number_text.hpp"
#include "core/planar/metrics.hpp"
#include "core/planar/simulate.hpp"
#include "optimize/planar.hpp"
#include "studies/report/report.hpp"
#include "studies/run/runner.hpp"
#include "studies/studies.hpp"
#include "studies/study/load_study.hpp"
#include "tests/support/studies.hpp"
#include "tests/support/study_errors.hpp"
#include "tests/support/text.hpp"

namespace bd::studies {
namespace {

namespace fs = std::filesystem;
namespace cp = bd::core::planar;

// a slider-crank driven by its crank; line numbers below refer to it (the section starts at 20)
const std::string kEngine = bd::testing::engine_study(72);

void expect_error(const std::string& text, int line, int column, const std::string& message) {
  bd::testing::expect_study_error(text, "e.yaml", line, column, message);
}

using bd::testing::example_path;
using bd::testing::rms_norm;

// the optimize section with `objective`, `constraints` and `variables` lines after its key
std::string section(const std::string& body) { return kEngine + "optimize:\n" + body; }

const std::string kObjective = "  objective: {Msh_rms: 1}\n";                           // line 21
const std::string kVariables = "  variables:\n    counterweights:\n      crank: {}\n";  // 22-24

TEST(PlanarOptimizeStudy, MistakesAreOneLineAtTheirPlace) {
  // the section's own keys
  expect_error(section(kObjective), 20, 1,
               "optimize: missing required key 'variables' (what may change");
  expect_error(section(kObjective + kVariables + "  pareto: {first: Fsh_rms, second: Fsh}\n"), 25,
               36, "unknown metric 'Fsh' in optimize.pareto.second");
  expect_error(section(kObjective + kVariables + "  pareto: {first: Fsh_rms, second: Fsh_rms}\n"),
               25, 36, "optimize.pareto.second must differ from first (both are Fsh_rms)");
  expect_error(
      section(kObjective + kVariables + "  pareto: {first: Fsh_rms, second: Msh_rms, points: 1}\n"),
      25, 53, "optimize.pareto.points must be >= 2");
  expect_error(section(kObjective + kVariables + "  colour: red\n"), 25, 3, "colour");
  expect_error(section("  algorithm: newton\n" + kObjective + kVariables), 21, 14,
               "unknown algorithm 'newton' in optimize.algorithm");
  expect_error(section(kObjective + kVariables + "  tolerance: 2\n"), 25, 14,
               "optimize.tolerance must be > 0 and < 1");
  // the peaks: resolved (the default in a driven scene) or sampled (always in a free one, below)
  EXPECT_TRUE(parse_study(section(kObjective + kVariables + "  peaks: resolved\n"), "e.yaml")
                  .planar_optimize->resolve_peaks);
  EXPECT_TRUE(
      parse_study(section(kObjective + kVariables), "e.yaml").planar_optimize->resolve_peaks);
  EXPECT_FALSE(parse_study(section(kObjective + kVariables + "  peaks: sampled\n"), "e.yaml")
                   .planar_optimize->resolve_peaks);
  expect_error(section(kObjective + kVariables + "  peaks: every\n"), 25, 10,
               "optimize.peaks must be resolved or sampled, got 'every'");
  EXPECT_NO_THROW(parse_study(section(kObjective + kVariables + "  peaks: sampled\n"), "e.yaml"));
  // objective and constraints: the linkage's metrics by name
  expect_error(section("  objective: {Msh: 1}\n" + kVariables), 21, 15,
               "unknown metric 'Msh' in optimize.objective; expected one of Fsh_rms, Fsh_max, "
               "Msh_rms");
  expect_error(section("  objective: {Msh_rms: 0}\n" + kVariables), 21, 3,
               "optimize.objective needs at least one metric with a weight > 0");
  expect_error(section(kObjective + "  constraints: {RO_max: -1}\n" + kVariables), 22, 25,
               "optimize.constraints.RO_max must be > 0 (a fraction of the original design's");
  expect_error(section(kObjective + "  constraints: {torque: 1}\n" + kVariables), 22, 17,
               "unknown constraint 'torque' in optimize.constraints; expected force_balance or "
               "one of Fsh_rms");
  expect_error(section(kObjective + "  constraints: {force_balance: maybe}\n" + kVariables), 22, 32,
               "optimize.constraints.force_balance must be true or false");
  // variables: links by name, their envelopes and bounds
  expect_error(section(kObjective + "  variables:\n    counterweights:\n      piston: {}\n"), 24, 7,
               "optimize.variables.counterweights.piston: no link of that name (links: crank, "
               "rod)");
  expect_error(
      section(kObjective + "  variables:\n    counterweights:\n      crank: {mass_max: 0}\n"), 24,
      25, "optimize.variables.counterweights.crank.mass_max must be > 0 kg, got 0");
  expect_error(section(kObjective + "  variables:\n    links:\n      rod: {mass: [0, 1]}\n"), 24,
               20, "optimize.variables.links.rod.mass lower bound must be > 0 kg");
  expect_error(section(kObjective + "  variables:\n    links:\n      rod: {}\n"), 24, 7,
               "optimize.variables.links.rod: give at least one of mass, e, f, inertia");
  expect_error(section(kObjective + "  variables: {}\n"), 22, 3,
               "optimize.variables: no design variable");
  // what the optimize layer refuses, at the key it names
  expect_error(section("  algorithm: mma\n" + kObjective +
                       "  constraints: {force_balance: true}\n" + kVariables),
               21, 14, "optimize.algorithm: algorithm 'mma' takes inequality constraints only");
  // full force balance that no counterweight on the crank can give (the piston): said at the key
  expect_error(section(kObjective + "  constraints: {force_balance: true}\n" + kVariables), 22, 17,
               "optimize.constraints.force_balance: full force balance cannot be reached with "
               "counterweights on crank: the reciprocating mass at B (");
  // an added-mass limit that no design can meet: counterweights add mass, only a link's own
  // mass variable can take some away (here none): at the limit
  expect_error(section(kObjective + "  constraints: {added_mass: -5}\n" + kVariables), 22, 17,
               "optimize.constraints.added_mass: added_mass <= -5 kg cannot be met: the least the "
               "variables allow is 0 kg");
  // a force at a centre of mass that a variable moves: at the variable
  expect_error(kEngine + "loads:\n  links:\n    rod: {force: [0, -1]}\noptimize:\n" + kObjective +
                   "  variables:\n    links:\n      rod: {mass: [0.3, 0.6]}\n",
               27, 7,
               "optimize.variables.links.rod.mass: link rod carries a force at its centre of mass, "
               "which this variable moves");
  // a free scene: every evaluation a simulation, its gradients by forward sensitivities of the
  // reduced route, so a gradient method is taken there (tests/optimize/planar_free_test.cpp)
  std::string free = kEngine;
  free.replace(free.find("  type: driven\n"), 15, "  type: free\n  duration: 0.1\n");
  free.erase(free.find("  speeds:"), free.find("  samples:") - free.find("  speeds:"));
  free.insert(free.find("  samples:"), "  rates: [20.0]\n");  // set in motion: Msh_rms > 0
  // its peaks resolved between the samples, as a driven scene's, unless the study says sampled
  EXPECT_TRUE(
      parse_study(free + "optimize:\n  algorithm: slsqp\n" + kObjective + kVariables, "e.yaml")
          .planar_optimize->resolve_peaks);
  EXPECT_FALSE(
      parse_study(free + "optimize:\n" + kObjective + kVariables + "  peaks: sampled\n", "e.yaml")
          .planar_optimize->resolve_peaks);
  // a balance section beside it
  expect_error(kEngine + "balance: {}\noptimize:\n" + kObjective + kVariables, 21, 1,
               "a study has a balance section or an optimize section, not both");
}

// The four-bar of berkof-lowen-min-shaking-moment.yaml on truss elements (crank A0-A1, coupler
// A1-A2, rocker A2-A3 as the four-bar's links, centres of mass from their first joints) with
// the same optimize section: least RMS shaking moment among force-balanced designs, with
// counterweights on crank and rocker and the coupler's mass and inertia as variables.
std::string berkof_lowen_planar(const std::string& scene =
                                    "scene:\n"
                                    "  type: driven\n"
                                    "  speeds: [6.283185307179586]\n"
                                    "  samples: 360\n") {
  const double l1 = 1, l2 = 3, l3 = 2, l4 = 3.2;
  // A2 where the coupler (l2 from A1 = (l1, 0)) meets the rocker (l3 from A3 = (l4, 0)), above
  // the frame (branch 1: the original's metrics below must agree)
  const double d = l4 - l1, a = (l2 * l2 - l3 * l3 + d * d) / (2 * d);
  const double h = std::sqrt(l2 * l2 - a * a);
  auto link = [](const std::string& name, const std::string& nodes, double mass, double s,
                 double sigma, double inertia) {
    return "    " + name + ": {nodes: [" + nodes + "], mass: " + text::exact(mass) +
           ", e: " + text::exact(s * std::cos(sigma)) + ", f: " + text::exact(s * std::sin(sigma)) +
           ", inertia: " + text::exact(inertia) + "}\n";
  };
  return "name: berkof-lowen-planar\n"
         "linkage:\n"
         "  type: planar\n"
         "  nodes:\n"
         "    A0: {at: [0, 0], ground: true}\n"
         "    A3: {at: [3.2, 0], ground: true}\n"
         "    A1: [1, 0]\n"
         "    A2: [" +
         text::exact(l1 + a) + ", " + text::exact(h) +
         "]\n"
         "  links:\n" +
         link("crank", "A0, A1", 2.1, 0.6, 0.3, 1.1) +
         link("coupler", "A1, A2", 3.0, 1.45, 0.4, 3.1) +
         link("rocker", "A2, A3", 2.2, 1.66, -0.4, 2.1) +
         "  inputs:\n"
         "    crank: {link: crank}\n" +
         scene +
         "optimize:\n"
         "  algorithm: slsqp\n"
         "  objective: {Msh_rms: 1.0}\n"
         "  constraints: {force_balance: true}\n"
         "  variables:\n"
         "    counterweights:\n"
         "      crank:  {mass_max: 10.0, distance_max: 1.0}\n"
         "      rocker: {mass_max: 10.0, distance_max: 2.0}\n"
         "    links:\n"
         "      coupler: {mass: [2.0, 4.0], inertia: [1.0, 8.0]}\n"
         "  max_evaluations: 2000\n"
         "  tolerance: 1.0e-10\n";
}

double metric(const MetricList& list, const std::string& name) {
  for (const MetricValue& m : list)
    if (m.name == name) return m.value;
  ADD_FAILURE() << "no metric " << name;
  return std::nan("");
}

TEST(PlanarOptimizeStudy, TheFourBarsOptimumIsReachedOnTrussElements) {
  const Study planar = parse_study(berkof_lowen_planar(), "berkof-lowen-planar.yaml");
  ASSERT_TRUE(planar.planar_optimize.has_value());
  const fs::path out = fs::path(BD_BINARY_DIR) / "test-output" / "planar-optimize" / "berkof";
  fs::remove_all(out);
  RunResult r = compute_study(planar);
  write_run(planar, r, out);
  ASSERT_TRUE(r.ok() && r.optimized && r.optimized->found()) << r.optimized->message();

  const Study fourbar = load_study(example_path("berkof-lowen-min-shaking-moment.yaml"));
  const RunResult f = compute_study(fourbar);
  ASSERT_TRUE(f.ok() && f.optimized && f.optimized->found());

  // the same linkage and motion: the originals agree to round-off
  for (const char* m : {"Fsh_rms", "Msh_rms", "tau_rms"}) {
    EXPECT_NEAR(metric(r.metric_list, m), metric(f.metric_list, m),
                1e-12 * metric(f.metric_list, m))
        << m;
  }
  // the same optimum: objective (Msh_rms / original) to the solvers' tolerance, the coupler's
  // parameters, the counterweights' masses and distances from their pivots
  const optimize::planar::Result& p = r.optimized->planar_result;
  const optimize::OptimizeResult& q = f.optimized->result;
  EXPECT_NEAR(p.objective, q.objective, 1e-7 * q.objective);
  EXPECT_NEAR(p.design.links[1].mass, q.design.coupler.mass, 1e-6);
  EXPECT_NEAR(p.design.links[1].inertia, q.design.coupler.inertia, 1e-6);
  ASSERT_EQ(p.counterweights.size(), 2u);
  ASSERT_EQ(q.counterweights.size(), 2u);
  // the crank turns at constant speed about the origin: its counterweight's angular momentum is
  // constant, so only its mass moment m r (fixed by the force balance) is determined, not m and r
  // apart; the rocker's counterweight is determined
  const balance::Counterweight &pc = p.counterweights[0].counterweight,
                               &qc = q.counterweights[0].counterweight;
  EXPECT_NEAR(pc.mass * pc.distance, qc.mass * qc.distance, 1e-6 * qc.mass * qc.distance);
  const balance::Counterweight &pr = p.counterweights[1].counterweight,
                               &qr = q.counterweights[1].counterweight;
  EXPECT_NEAR(pr.mass, qr.mass, 1e-6);
  EXPECT_NEAR(pr.distance, qr.distance, 1e-6);
  // the optimum simulated: force balanced (no gravity), its shaking moment the four-bar's
  const core::planar::Trajectory& t = r.optimized->planar;
  const double fsh0 = metric(r.metric_list, "Fsh_rms");
  EXPECT_LE(rms_norm(t.table.column_values("Fshx"), t.table.column_values("Fshy")), 1e-10 * fsh0);
  EXPECT_NEAR(metric(r.optimized->metric_list, "Msh_rms"),
              metric(f.optimized->metric_list, "Msh_rms"),
              1e-6 * metric(f.optimized->metric_list, "Msh_rms"));

  // the files: summary.json's optimum, comparison.csv, and optimized.yaml running by itself to
  // the same samples
  const nlohmann::json j = nlohmann::json::parse(bd::testing::read(out / "summary.json"));
  EXPECT_EQ(j["optimize"]["termination"], "converged");
  EXPECT_EQ(j["optimize"]["force_balance"], true);
  EXPECT_EQ(j["optimize"]["counterweights"].size(), 2u);
  EXPECT_EQ(j["optimize"]["counterweights"][1]["from_node"], "A3");
  EXPECT_LE(j["optimize"]["verification_error"].get<double>(), 1e-9);
  // the second route: the bodies' accelerations give the engine's inertial shaking force and
  // moment to round-off
  EXPECT_LE(j["optimize"]["inertial_verification_error"].get<double>(), 1e-12);
  EXPECT_EQ(j["optimize"]["added_mass"].get<double>(), p.added_mass);
  EXPECT_EQ(j["optimized_run"]["study"], "berkof-lowen-planar-optimized");
  EXPECT_EQ(j["optimized_metrics"]["Msh_rms"].get<double>(),
            metric(r.optimized->metric_list, "Msh_rms"));
  EXPECT_TRUE(fs::exists(out / "comparison.csv"));
  EXPECT_NE(bd::testing::read(out / "comparison.csv").find("added_mass,0,"), std::string::npos);
  const Study again = load_study((out / "optimized.yaml").string());
  EXPECT_FALSE(again.optimizes());
  const RunResult rerun = compute_study(again);
  ASSERT_TRUE(rerun.ok());
  const std::vector<double> m1 = t.table.column_values("Msh"),
                            m2 = rerun.planar.table.column_values("Msh");
  ASSERT_EQ(m1.size(), m2.size());
  for (std::size_t i = 0; i < m1.size(); ++i) EXPECT_EQ(m1[i], m2[i]);
}

// peaks: resolved in a study: the objective (a peak over the original's peak) is the ratio the
// tables show, both resolved between the samples (with peaks: sampled the objective was the
// samples' and the tables the motion's: 0.2446 against 0.2462 here), and summary.json says how
// the peaks were bounded and at which added instants.
TEST(PlanarOptimizeStudy, ResolvedPeaksAreWhatTheTablesShow) {
  const std::string body =
      "optimize:\n  objective: {Fsh_max: 1}\n  variables:\n    counterweights:\n"
      "      crank: {mass_max: 1.0, distance_max: 0.05}\n";
  for (const bool resolved : {true, false}) {
    SCOPED_TRACE(resolved ? "resolved" : "sampled");
    const Study study = parse_study(
        bd::testing::engine_study(24) + body + (resolved ? "" : "  peaks: sampled\n"), "e.yaml");
    const fs::path out = fs::path(BD_BINARY_DIR) / "test-output" / "planar-optimize" /
                         (resolved ? "resolved" : "sampled");
    fs::remove_all(out);
    RunResult r = compute_study(study);
    write_run(study, r, out);
    ASSERT_TRUE(r.ok() && r.optimized && r.optimized->found()) << r.optimized->message();
    const optimize::planar::Result& p = r.optimized->planar_result;
    const double ratio =
        metric(r.optimized->metric_list, "Fsh_max") / metric(r.metric_list, "Fsh_max");
    const nlohmann::json j = nlohmann::json::parse(bd::testing::read(out / "summary.json"));
    EXPECT_EQ(j["optimize"]["peaks"], resolved ? "resolved" : "sampled");
    EXPECT_EQ(j["optimize"]["peak_times"].size(), p.peak_times.size());
    // every metric's unit, from the linkage's table: the slider's guide force is in N (the
    // report's tables read them; by the name alone 'Rpiston' had none)
    EXPECT_EQ(j["metric_units"]["Rpiston_max"], "N");
    EXPECT_EQ(j["metric_units"]["Msh_rms"], "N m");
    EXPECT_EQ(j["metric_units"].size(), j["metrics"].size());
    if (resolved) {
      // the default; the lean program's instants: each peak of the optimum with its two
      // neighbours on the exchange's grid (whose rounds held 256), each once, listed on the page
      ASSERT_FALSE(p.peak_times.empty());
      EXPECT_LE(p.peak_times.size(), 6u);
      write_report(study, out);
      const std::string page = bd::testing::read(out / "report.html");
      EXPECT_NE(page.find("<tr><th>peak_times"), std::string::npos);
      std::vector<double> times = p.peak_times;  // each once
      std::sort(times.begin(), times.end());
      EXPECT_EQ(std::adjacent_find(times.begin(), times.end()), times.end());
      EXPECT_EQ(j["optimize"]["peak_times"][0].get<double>(), p.peak_times[0]);
      // the smoothed peak: sqrt(r² + ε²) with ε = 1e-6
      EXPECT_NEAR(p.objective, ratio, 1e-9);
    } else {
      EXPECT_GT(std::abs(p.objective - ratio), 1e-4) << "24 samples held the peaks";
    }
  }
}

// A counterweight that changes nothing the problem reads is left out (the four-bar's test in
// tests/optimize/optimize_test.cpp): the engine's crank turns at constant speed about the origin,
// so a crank counterweight changes no shaking moment about it; the solver used to leave it at its
// start (half its mass_max). Checked against the engine's own runs with and without it.
TEST(PlanarOptimizeStudy, ACounterweightThatChangesNothingIsLeftOut) {
  const Study study = parse_study(bd::testing::engine_study(24) +
                                      "optimize:\n  objective: {Msh_rms: 1}\n  variables:\n"
                                      "    counterweights:\n"
                                      "      crank: {mass_max: 1.0, distance_max: 0.05}\n",
                                  "e.yaml");
  const RunResult r = compute_study(study);
  ASSERT_TRUE(r.ok() && r.optimized && r.optimized->found()) << r.optimized->message();
  const optimize::planar::Result& p = r.optimized->planar_result;
  EXPECT_EQ(p.added_mass, 0.0);
  EXPECT_NE(p.message.find("the crank counterweight changed nothing the problem reads"),
            std::string::npos)
      << p.message;
  EXPECT_NEAR(p.objective, 1.0, 1e-12);
  // the start's counterweight (0.5 kg at 25 mm) changes the engine's Msh_rms by round-off only
  const optimize::planar::DesignProblem problem = planar_design_problem(study);
  optimize::planar::PlanarNlp nlp(problem);
  Eigen::VectorXd with = nlp.start();
  Eigen::VectorXd without = with;
  without.head(3).setZero();
  const auto msh = [&](const Eigen::VectorXd& x) {
    const cp::Model model(nlp.design(x));
    const cp::Trajectory run = cp::simulate_driven(model, std::get<cp::DrivenScene>(problem.scene));
    EXPECT_TRUE(run.ok()) << run.message;
    return cp::metric_values(nlp.metric_table(), run.table)[static_cast<std::size_t>(
        std::find_if(nlp.metric_table().begin(), nlp.metric_table().end(),
                     [](const cp::ColumnMetric& m) { return m.name == "Msh_rms"; }) -
        nlp.metric_table().begin())];
  };
  EXPECT_GT(with(0), 0.4);
  EXPECT_NEAR(msh(with), msh(without), 1e-12 * msh(without));
}

// A user's front on the Stephenson six-bar (counterweights on all five links, force balance, a
// bearing-force peak limit): SLSQP found no design at its tightest point (4.822 kg, 0.003 kg
// above the least mass any force-balanced design needs) from the lone starts. Each point now
// starts from its neighbour or from the least-mass design, which meets every bound of the front:
// every point is found, within its bound, and the front is monotone.
TEST(PlanarOptimizeStudy, EveryPointOfATightFrontIsFound) {
  const std::string text = bd::testing::read(example_path("stephenson-sixbar.yaml")) +
                           "optimize:\n"
                           "  algorithm: slsqp\n"
                           "  objective: {Msh_rms: 1.0, tau_rms: 0.5, added_mass: 0.01}\n"
                           "  constraints: {force_balance: true, added_mass: 8, RO4_max: 3.0}\n"
                           "  variables:\n"
                           "    counterweights:\n"
                           "      crank:   {mass_max: 4, distance_max: 0.1}\n"
                           "      rocker:  {mass_max: 4, distance_max: 0.3}\n"
                           "      output:  {mass_max: 4, distance_max: 0.25}\n"
                           "      coupler: {mass_max: 2, distance_max: 0.3}\n"
                           "      link:    {mass_max: 2, distance_max: 0.3}\n"
                           "  pareto: {first: Msh_rms, second: added_mass, points: 6}\n";
  const RunResult r = compute_study(parse_study(text, "steph.yaml"));
  ASSERT_TRUE(r.ok() && r.optimized);
  const std::vector<optimize::planar::ParetoPoint>& p = r.optimized->planar_pareto;
  ASSERT_EQ(p.size(), 6u);
  for (std::size_t i = 0; i < p.size(); ++i) {
    SCOPED_TRACE(std::to_string(i) + ": " + p[i].result.message);
    ASSERT_TRUE(p[i].result.ok());
    EXPECT_LE(p[i].result.added_mass, p[i].epsilon + 1e-6);
    if (i > 0) {
      EXPECT_GE(p[i].result.objective, p[i - 1].result.objective - 1e-9);
    }
  }
}

// The four-bar's Pareto front (least RMS shaking moment for each bound on the added mass, among
// force-balanced designs) and the same front of the four-bar on truss elements: the same bounds
// and the same designs, point by point.
TEST(PlanarOptimizeStudy, TheFourBarsParetoFrontIsReachedOnTrussElements) {
  const std::string pareto = "  pareto: {first: Msh_rms, second: added_mass, points: 4}\n";
  const Study planar = parse_study(berkof_lowen_planar() + pareto, "berkof-lowen-planar.yaml");
  ASSERT_TRUE(planar.planar_optimize && planar.planar_optimize->pareto);
  const fs::path out = fs::path(BD_BINARY_DIR) / "test-output" / "planar-optimize" / "pareto";
  fs::remove_all(out);
  RunResult r = compute_study(planar);
  write_run(planar, r, out);
  ASSERT_TRUE(r.ok()) << r.optimized->message();
  const Study fourbar = parse_study(
      bd::testing::read(example_path("berkof-lowen-min-shaking-moment.yaml")) + pareto, "b.yaml");
  const RunResult f = compute_study(fourbar);
  ASSERT_TRUE(f.ok());
  const std::vector<optimize::planar::ParetoPoint>& p = r.optimized->planar_pareto;
  const std::vector<optimize::ParetoPoint>& q = f.optimized->pareto;
  ASSERT_EQ(p.size(), 4u);
  ASSERT_EQ(q.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    SCOPED_TRACE(i);
    ASSERT_TRUE(p[i].result.ok() && q[i].result.ok());
    EXPECT_NEAR(p[i].epsilon, q[i].epsilon, 1e-6 * std::abs(q[i].epsilon));
    EXPECT_NEAR(p[i].result.objective, q[i].result.objective, 1e-6 * q[i].result.objective);
    EXPECT_NEAR(p[i].result.added_mass, added_mass(fourbar.fourbar(), q[i].result.design), 1e-6);
    EXPECT_LE(p[i].result.added_mass, p[i].epsilon + 1e-9);
  }
  // along the front, a larger mass allowance buys a smaller shaking moment
  for (std::size_t i = 1; i < 4; ++i)
    EXPECT_GE(p[i].result.objective, p[i - 1].result.objective - 1e-9);
  const std::string csv = bd::testing::read(out / "pareto.csv");
  EXPECT_EQ(csv.substr(0, csv.find('\n')),
            "epsilon,Msh_rms,added_mass,termination,verification_error,crank counterweight mass "
            "[kg],crank counterweight x from A0 in link axes [m],crank counterweight y from A0 in "
            "link axes [m],rocker counterweight mass [kg],rocker counterweight x from A3 in link "
            "axes [m],rocker counterweight y from A3 in link axes [m],coupler mass [kg],coupler "
            "inertia [kg m²]");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 5);
  const nlohmann::json j = nlohmann::json::parse(bd::testing::read(out / "summary.json"));
  EXPECT_EQ(j["optimize"]["pareto"]["points"], 4);

  // a plain run into the same folder leaves no file of the optimisation behind
  Study plain = planar;
  plain.planar_optimize.reset();
  RunResult again = compute_study(plain);
  write_run(plain, again, out);
  for (const char* file :
       {"pareto.csv", "optimized.yaml", "optimized-timeseries.csv", "comparison.csv"}) {
    EXPECT_FALSE(fs::exists(out / file)) << file;
  }
  EXPECT_TRUE(fs::exists(out / "timeseries.csv"));
  EXPECT_TRUE(fs::exists(out / "summary.json"));
}

// A free scene: every evaluation a simulation (the four-bar's closed form against the truss
// engine's reduced route), derivative-free (cobyla); the same linkage coasting from 2π rad/s
// reaches the same optimum of Fsh_rms + Msh_rms, and the planar optimum is verified by the dae
// route.
TEST(PlanarOptimizeStudy, AFreeSceneReachesTheFourBarsOptimum) {
  const std::string optimize =
      "optimize:\n"
      "  algorithm: cobyla\n"
      "  objective: {Fsh_rms: 1.0, Msh_rms: 1.0}\n"
      "  variables:\n"
      "    counterweights:\n"
      "      crank:  {mass_max: 10.0, distance_max: 1.0}\n"
      "      rocker: {mass_max: 10.0, distance_max: 2.0}\n"
      "  max_evaluations: 3000\n"
      "  tolerance: 1.0e-10\n";
  std::string planar_text = berkof_lowen_planar(
      "scene: {type: free, rates: [6.283185307179586], duration: 1.0, samples: 101}\n");
  planar_text = planar_text.substr(0, planar_text.find("optimize:\n")) + optimize;
  const Study planar = parse_study(planar_text, "p.yaml");
  std::string fourbar_text =
      bd::testing::read(example_path("berkof-lowen-min-shaking-moment.yaml"));
  fourbar_text = fourbar_text.substr(0, fourbar_text.find("scene:")) +
                 "scene: {type: free, theta1: 0.0, omega1: 6.283185307179586, duration: 1.0, "
                 "samples: 101}\n" +
                 optimize;
  const Study fourbar = parse_study(fourbar_text, "f.yaml");
  const RunResult r = compute_study(planar);
  const RunResult f = compute_study(fourbar);
  ASSERT_TRUE(r.ok()) << r.optimized->message();
  ASSERT_TRUE(f.ok()) << f.optimized->message();
  const optimize::planar::Result& p = r.optimized->planar_result;
  const optimize::OptimizeResult& q = f.optimized->result;
  // cobyla's optimum: the objective to 1e-7, the variables to 1e-3 (the objective is flat along
  // the crank's counterweight to within its tolerance)
  EXPECT_NEAR(p.objective, q.objective, 1e-7 * q.objective);
  ASSERT_EQ(p.counterweights.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_NEAR(p.counterweights[k].counterweight.mass, q.counterweights[k].counterweight.mass,
                1e-3 * q.counterweights[k].counterweight.mass)
        << k;
  }
  // verified by the other route: two integrations at tolerance 1e-10
  EXPECT_LE(p.verification_error, 1e-6);
  EXPECT_EQ(p.verified.size(), p.metrics.size());
  EXPECT_LE(p.inertial_error, 1e-10);
  EXPECT_NEAR(metric(r.optimized->metric_list, "Msh_rms"),
              metric(f.optimized->metric_list, "Msh_rms"),
              1e-4 * metric(f.optimized->metric_list, "Msh_rms"));
}

// The six-bar example: least RMS shaking moment among the force-balanced designs is below the
// shaking moment of the balance section's design with the same counterweights, and the
// optimum is force balanced when simulated.
TEST(PlanarOptimizeStudy, TheSixBarExampleHasLessShakingMomentThanTheBalanceSections) {
  const Study study = load_study(example_path("watt-sixbar-optimized.yaml"));
  const RunResult r = compute_study(study);
  ASSERT_TRUE(r.ok() && r.optimized && r.optimized->found()) << r.optimized->message();
  const Study balanced = load_study(example_path("watt-sixbar-balanced.yaml"));
  const RunResult b = compute_study(balanced);
  ASSERT_TRUE(b.ok() && b.balanced && b.balanced->design && b.balanced->design->full);
  // force balanced to the solver's feasibility: the momentum conditions hold to its constraint
  // violation (scaled by the linkage's mass times its longest link), so the shaking force left
  // is at most ω² times that momentum, ~1e-8 N here
  const optimize::planar::Result& o = r.optimized->planar_result;
  EXPECT_LE(o.constraint_violation, 1e-9);
  const double omega = 2 * std::numbers::pi, mass = core::planar::total_mass(study.planar());
  EXPECT_LE(metric(r.optimized->metric_list, "Fsh_rms"),
            10 * omega * omega * mass * 0.5 * std::max(o.constraint_violation, 1e-13));
  EXPECT_LT(metric(r.optimized->metric_list, "Msh_rms"),
            0.6 * metric(b.balanced->metric_list, "Msh_rms"));
  EXPECT_LE(r.optimized->planar_result.added_mass, 12 + 1e-9);
}

}  // namespace
}  // namespace bd::studies

namespace bd::studies {
namespace {

// Force balance asked for with counterweights far from balancing at the start (half of
// mass_max = 10 kg each, half their envelopes out): the start is moved onto the balance
// conditions, so SLSQP finds a force-balanced design (it ended "infeasible" from the plain
// start, a feasible problem that ipopt, cobyla and mlsl solve).
TEST(PlanarOptimizeStudy, ForceBalanceFromAFarStartIsFound) {
  const std::string text =
      bd::testing::read(bd::testing::example_path("watt-sixbar.yaml")) +
      "optimize: {objective: {Msh_rms: 1}, constraints: {force_balance: true}, variables: "
      "{counterweights: {crank: {}, rocker: {}, output: {}}}}\n";
  const Study study = parse_study(text, "w.yaml");
  const RunResult r = compute_study(study);
  ASSERT_TRUE(r.optimized && r.optimized->found()) << r.optimized->message();
  const optimize::planar::Result& o = r.optimized->planar_result;
  EXPECT_LE(o.constraint_violation, 1e-9);
  // the inertial shaking force (the linkage's weight, with gravity, is no counterweight's to
  // cancel), against the original's
  auto inertial = [](const core::planar::Trajectory& t) {
    return rms_norm(t.table.column_values("Fshx_inertial"), t.table.column_values("Fshy_inertial"));
  };
  EXPECT_LE(inertial(r.optimized->planar), 1e-8 * inertial(r.planar));
}

}  // namespace
}  // namespace bd::studies
