#include "core/fourbar/sensitivity.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "core/fourbar/metrics.hpp"
#include "core/fourbar/samples.hpp"
#include "core/input_error.hpp"

namespace bd::core {
namespace {

// The referee: central differences of full simulations (simulate_free) at a tighter
// tolerance, the parameter moved by ±h with h = 1e-4 of its scale. Truncation ~h² ~ 1e-8 of the
// derivative; the runs' own errors (global ~1e-11 relative at tolerance 1e-12) divided by 2h
// give ~1e-7. The sensitivities under test are in the error test at 1e-7 (measured: within
// 1e-6 of their size). So each derivative is held to 1e-5 of its largest magnitude over the
// run: above both routes' errors, far below what a wrong formula (an O(1) error) gives.
constexpr double kRelativeStep = 1e-4;
constexpr double kTolerance = 1e-5;

const std::vector<LinkParameter>& all_parameters() {
  static const std::vector<LinkParameter> all = [] {
    std::vector<LinkParameter> out;
    for (int k = 1; k <= 3; ++k) {
      for (auto kind : {LinkParameter::Kind::kMass, LinkParameter::Kind::kE,
                        LinkParameter::Kind::kF, LinkParameter::Kind::kInertia}) {
        out.push_back({k, kind});
      }
    }
    return out;
  }();
  return all;
}

double& value(FourBar& m, const LinkParameter& p) {
  Link& l = p.link == 1 ? m.crank : p.link == 2 ? m.coupler : m.rocker;
  switch (p.kind) {
    case LinkParameter::Kind::kMass:
      return l.mass;
    case LinkParameter::Kind::kE:
      return l.e;
    case LinkParameter::Kind::kF:
      return l.f;
    case LinkParameter::Kind::kInertia:
      break;
  }
  return l.inertia;
}

// a step size on the scale of the parameter (its magnitude, or the link's length for an
// offset)
double step(const FourBar& m, const LinkParameter& p) {
  const Link& l = link(m, p.link);
  const double scale = p.kind == LinkParameter::Kind::kE || p.kind == LinkParameter::Kind::kF
                           ? l.length
                       : p.kind == LinkParameter::Kind::kMass ? l.mass
                                                              : l.inertia;
  return kRelativeStep * scale;
}

Trajectory run(FourBar m, const FreeScene& scene, double tolerance, Formulation f) {
  SimulateOptions o;
  o.formulation = f;
  o.tolerance = tolerance;
  o.absolute_tolerance = 1e-2 * tolerance;
  return simulate_free(make_fourbar(m), scene, o);
}

// the quantities compared sample by sample
std::vector<double> numbers(const DynamicsSample& s) {
  return {s.state.theta1,     s.state.omega1, s.state.alpha1, s.RA0.x(),
          s.RA0.y(),          s.RA3.x(),      s.RA3.y(),      s.Fsh_inertial.x(),
          s.Fsh_inertial.y(), s.Msh_inertial, s.Fsh.x(),      s.Msh};
}
const char* const kNames[] = {"theta1",         "omega1",       "alpha1", "RA0x",
                              "RA0y",           "RA3x",         "RA3y",   "Fsh_inertial_x",
                              "Fsh_inertial_y", "Msh_inertial", "Fshx",   "Msh"};

struct Case {
  std::string name;
  FourBar model;
  FreeScene scene;
  Formulation formulation;
};

std::vector<Case> cases() {
  std::mt19937_64 rng(15);
  return {
      {"paper four-bar with gravity",
       samples::with_paper_loads(samples::paper_fourbar_unloaded(), Vec2(0, -9.81)),
       FreeScene{.theta1 = 1.0, .omega1 = 3.0, .duration = 1.0, .samples = 41},
       Formulation::kComplexMasses},
      {"random crank-rocker", samples::random_crank_rocker(rng),
       FreeScene{.theta1 = 0.3, .omega1 = 8.0, .duration = 0.8, .samples = 33},
       Formulation::kMassMatrix},
  };
}

// A case's sensitivity run (at the default tolerance) and the referee's runs: the nominal one
// and, per parameter, the runs at ±h (tolerance 1e-12).
struct Runs {
  FreeSensitivities sensitivities;
  Trajectory nominal;
  std::vector<Trajectory> plus, minus;
};

Runs runs_of(const Case& c) {
  SimulateOptions options;
  options.formulation = c.formulation;
  Runs r;
  r.sensitivities = simulate_free_sensitivities(c.model, c.scene, all_parameters(), options);
  r.nominal = run(c.model, c.scene, 1e-12, c.formulation);
  for (const LinkParameter& p : all_parameters()) {
    FourBar plus = c.model, minus = c.model;
    value(plus, p) += step(c.model, p);
    value(minus, p) -= step(c.model, p);
    r.plus.push_back(run(plus, c.scene, 1e-12, c.formulation));
    r.minus.push_back(run(minus, c.scene, 1e-12, c.formulation));
  }
  return r;
}

// a metric of run t: an RMS over its samples; a peak as the magnitude at the sample where
// `nominal` has its largest
double metric(const Trajectory& t, const Trajectory& nominal, const MetricInfo& info) {
  if (info.statistic == Statistic::kRms) return metrics(t).*info.field;
  std::size_t at = 0;
  for (std::size_t i = 0; i < nominal.samples.size(); ++i) {
    if (magnitude(nominal.samples[i], info.quantity) >
        magnitude(nominal.samples[at], info.quantity)) {
      at = i;
    }
  }
  return magnitude(t.samples[at], info.quantity);
}

TEST(Sensitivity, SamplesAndMetricsMatchCentralDifferencesOfFullRuns) {
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.name);
    const Runs r = runs_of(c);
    const FreeSensitivities& s = r.sensitivities;
    ASSERT_TRUE(s.trajectory.ok()) << s.trajectory.message;
    ASSERT_EQ(s.derivative.size(), all_parameters().size());
    for (std::size_t j = 0; j < all_parameters().size(); ++j) {
      const LinkParameter& p = all_parameters()[j];
      SCOPED_TRACE("link " + std::to_string(p.link) + " parameter " +
                   std::to_string(static_cast<int>(p.kind)));
      const double h = step(c.model, p);
      const Trajectory& a = r.plus[j];
      const Trajectory& b = r.minus[j];
      ASSERT_TRUE(a.ok() && b.ok());
      ASSERT_EQ(a.samples.size(), s.trajectory.samples.size());
      const std::size_t count = std::size(kNames);
      // the largest magnitude of each derivative over the run: its scale
      std::vector<double> scale(count, 0.0);
      std::vector<std::vector<double>> referee;
      for (std::size_t i = 0; i < a.samples.size(); ++i) {
        const std::vector<double> na = numbers(a.samples[i]), nb = numbers(b.samples[i]);
        std::vector<double> d(count);
        for (std::size_t q = 0; q < count; ++q) {
          d[q] = (na[q] - nb[q]) / (2 * h);
          scale[q] = std::max(scale[q], std::abs(d[q]));
        }
        referee.push_back(d);
      }
      for (std::size_t i = 0; i < a.samples.size(); ++i) {
        const std::vector<double> got = numbers(s.derivative[j][i]);
        for (std::size_t q = 0; q < count; ++q) {
          EXPECT_NEAR(got[q], referee[i][q], kTolerance * scale[q] + 1e-12)
              << kNames[q] << " at sample " << i;
        }
      }
    }

    // every metric: the referee's gradient over every parameter, each entry in the metric's
    // unit per the parameter's step (so that entries compare on one footing). A peak is the
    // largest sample's magnitude: where two samples come within the step of each other the runs
    // at ±h may take different ones, so the referee differentiates the magnitude at the nominal
    // run's largest sample (the derivative the peak has wherever it is differentiable)
    const Eigen::MatrixXd g = metric_gradients(s);
    ASSERT_EQ(g.rows(), static_cast<Eigen::Index>(kMetricCount));
    ASSERT_EQ(g.cols(), static_cast<Eigen::Index>(all_parameters().size()));
    for (std::size_t k = 0; k < kMetricCount; ++k) {
      const MetricInfo& info = kMetricTable[k];
      if (info.quantity == Quantity::kDriveTorque) {
        // no drive in free motion: tau is 0 at every sample, and so is its gradient
        EXPECT_EQ(g.row(static_cast<Eigen::Index>(k)).norm(), 0.0);
        continue;
      }
      std::vector<double> got, referee;
      double largest = 0;
      for (std::size_t j = 0; j < all_parameters().size(); ++j) {
        const double h = step(c.model, all_parameters()[j]);
        const double d =
            (metric(r.plus[j], r.nominal, info) - metric(r.minus[j], r.nominal, info)) / 2;
        referee.push_back(d);
        got.push_back(g(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(j)) * h);
        largest = std::max(largest, std::abs(d));
      }
      ASSERT_GT(largest, 0.0) << info.name;
      for (std::size_t j = 0; j < got.size(); ++j) {
        EXPECT_NEAR(got[j], referee[j], kTolerance * largest) << info.name << " by parameter " << j;
      }
    }
  }
}

TEST(Sensitivity, RunFollowsTheFreeSimulation) {
  // the same equations and tolerances; only the steps differ (the sensitivities take part in
  // the error test), so the samples agree to the integration's accuracy: both runs' global
  // errors at tolerance 1e-10 over the ~5 rad travelled (measured ~1.3e-8 rad)
  const Case c = cases()[0];
  SimulateOptions options;
  options.formulation = c.formulation;
  const FreeSensitivities s = simulate_free_sensitivities(c.model, c.scene, {{1}}, options);
  const Trajectory plain = simulate_free(c.model, c.scene, options);
  ASSERT_TRUE(s.trajectory.ok() && plain.ok());
  ASSERT_EQ(s.trajectory.samples.size(), plain.samples.size());
  for (std::size_t i = 0; i < plain.samples.size(); ++i) {
    EXPECT_NEAR(s.trajectory.samples[i].state.theta1, plain.samples[i].state.theta1, 1e-7);
    EXPECT_NEAR(s.trajectory.samples[i].RA0.x(), plain.samples[i].RA0.x(),
                1e-6 * std::max(1.0, std::abs(plain.samples[i].RA0.x())));
  }
}

TEST(Sensitivity, BdfAgreesWithAdams) {
  const Case c = cases()[1];
  SimulateOptions adams, bdf;
  adams.formulation = bdf.formulation = c.formulation;
  bdf.integrator = Integrator::kCvodeBdf;
  // BDF (orders <= 5) needs far more steps than Adams at this tolerance: two parameters
  const std::vector<LinkParameter> some = {{1, LinkParameter::Kind::kMass},
                                           {3, LinkParameter::Kind::kF}};
  const Eigen::MatrixXd a =
      metric_gradients(simulate_free_sensitivities(c.model, c.scene, some, adams));
  const Eigen::MatrixXd b =
      metric_gradients(simulate_free_sensitivities(c.model, c.scene, some, bdf));
  // two integrators at tolerance 1e-10: their sensitivities differ by ~1e-9 of their size
  EXPECT_LT((a - b).norm(), 1e-6 * a.norm());
  EXPECT_GT(a.norm(), 0.0);
}

void expect_input_error(const std::function<void()>& call, const std::string& field,
                        const std::string& text) {
  try {
    call();
    ADD_FAILURE() << "no bd::InputError; expected \"" << text << "\"";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), text);
    ASSERT_TRUE(e.field());
    EXPECT_EQ(e.field()->field, field);
  }
}

TEST(Sensitivity, RefusesWhatItCannotDifferentiate) {
  const Case c = cases()[0];
  SimulateOptions opened;
  opened.formulation = Formulation::kOpenedLoop;
  expect_input_error([&] { simulate_free_sensitivities(c.model, c.scene, {{1}}, opened); },
                     "formulation",
                     "formulation: forward sensitivities need the reduced equation in theta1 "
                     "(mass-matrix or complex-masses), got opened-loop");
  SimulateOptions erk;
  erk.integrator = Integrator::kErk5;
  expect_input_error([&] { simulate_free_sensitivities(c.model, c.scene, {{1}}, erk); },
                     "integrator",
                     "integrator: forward sensitivities need cvode-adams or cvode-bdf (CVODES), "
                     "got erk5");
  expect_input_error(
      [&] {
        simulate_free_sensitivities(c.model, c.scene, {{1}, {2}, {1}}, {});
      },
      "parameters", "parameters[2] is listed twice");
  expect_input_error([&] { simulate_free_sensitivities(c.model, c.scene, {{4}}, {}); },
                     "parameters", "parameters[0].link must be 1, 2 or 3, got 4");
}

}  // namespace
}  // namespace bd::core
