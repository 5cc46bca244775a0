// The design problem as a nonlinear program (optimize/nlp.hpp): the driven regressor against
// core's inverse dynamics, the metrics against core's, the analytic gradients against central
// differences, the force-balance equalities against balance::force_balance, the free scene
// against core::simulate_free.
//
// Tolerances.
// - Regressor and metrics (driven): 1e-12 of the quantity's scale over the revolution (the peak
//   reaction for forces, the peak moment or l4 times the peak reaction for moments). Both sides
//   are exact; the regressor's columns are difference quotients with step 1 of an affine map, so
//   only the round-off of the inverse dynamics (a few eps of the reactions) and of A q separates
//   them.
// - Gradients: central differences with h = 1e-6 (times max(1, |x_j|)): truncation ~ h^2 |f'''|
//   ~ 1e-11, round-off ~ eps |f| / h ~ 1e-10 for values of order one (measured: <= 1e-9 of the
//   row's scale), so 1e-6 of the row's largest gradient entry (at least 1e-2, as the values are
//   of order one) leaves three orders of margin while a wrong term shows at order one.
// - Regressor: measured within 1e-14 of the scales, so 1e-12 leaves two orders of margin.
// - Force balance: the equalities are linear in the inertial parameters, evaluated to a few eps
//   of the masses over the total mass: 1e-13.
// - Objective against its definition: the same formula evaluated two ways (|R q| against the
//   regressor's samples summarised by core::metrics), 1e-12 relative.
#include "optimize/nlp.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "balance/conditions.hpp"
#include "balance/counterweight.hpp"
#include "core/fourbar/dynamics.hpp"
#include "core/input_error.hpp"
#include "core/fourbar/metrics.hpp"
#include "core/fourbar/model.hpp"
#include "core/fourbar/samples.hpp"
#include "core/fourbar/simulate.hpp"

namespace bd::optimize {
namespace {

using P = LinkParameterVariable::Parameter;

double uniform(std::mt19937_64& rng, double a, double b) {
  return std::uniform_real_distribution<double>(a, b)(rng);
}

core::FourBar with_counter_rotations(core::FourBar m) {
  m.counter_rotations.crank = {0.3, Vec2(-0.5, 0.2)};
  m.counter_rotations.rocker = {0.4, Vec2(m.frame_length + 0.3, -0.4)};
  return core::make_fourbar(m);
}

// Two counterweights (a point on the crank, a light disc on the rocker, so its own inertia
// matters) and link parameters on every link.
DesignProblem driven_problem(const core::FourBar& model, core::Formulation f, int samples = 24) {
  DesignProblem p;
  p.original = model;
  core::DrivenScene scene;
  scene.theta1 = 0.3;
  scene.omega1 = 2.5;
  scene.samples = samples;
  p.scene = scene;
  p.formulation = f;
  CounterweightVariables c1;
  c1.link = 1;
  c1.mass_max = 5.0;
  c1.distance_max = 0.8;
  CounterweightVariables c3;
  c3.link = 3;
  c3.mass_max = 4.0;
  c3.distance_max = 1.0;
  c3.shape = balance::CounterweightShape::kDisc;
  c3.thickness = 0.05;
  c3.density = 500.0;
  p.counterweights = {c1, c3};
  p.link_parameters = {{2, P::kMass, 1.0, 5.0},    {2, P::kE, 0.5, 2.0},
                       {2, P::kF, -0.5, 0.5},      {2, P::kInertia, 0.5, 5.0},
                       {1, P::kInertia, 0.1, 2.0}, {3, P::kMass, 1.0, 4.0},
                       {3, P::kF, -0.3, 0.3}};
  p.objective = {{Metric::kFshRms, 1.0}};
  return p;
}

// Every metric in the objective and in a limit, with force balance: every kind of term and
// constraint.
DesignProblem full_problem(const core::FourBar& model, core::Formulation f) {
  DesignProblem p = driven_problem(model, f, 12);
  p.objective.clear();
  p.limits.clear();
  double w = 0.5;
  for (Metric m : kMetrics) {
    p.objective.push_back({m, w});
    p.limits.push_back({m, m == Metric::kAddedMass ? 3.0 : 1.5});
    w += 0.25;
  }
  p.force_balance = true;
  return p;
}

int design_variables(const DesignProblem& p) {
  return static_cast<int>(3 * p.counterweights.size() + p.link_parameters.size());
}

// A random point of the box; counterweights inside their envelopes; bound variables anywhere in
// [0, 1.5 x their start] (not necessarily feasible: the derivatives do not care).
Eigen::VectorXd random_x(const Nlp& nlp, const DesignProblem& p, std::mt19937_64& rng) {
  Eigen::VectorXd x = nlp.start();
  for (int j = 0; j < nlp.n(); ++j) {
    const bool design = j < design_variables(p);
    x(j) = uniform(rng, design ? nlp.lower()(j) : 0.0, design ? nlp.upper()(j) : 1.5 * x(j));
  }
  for (std::size_t c = 0; c < p.counterweights.size(); ++c) {
    const int j = 3 * static_cast<int>(c);
    const double r = p.counterweights[c].distance_max * std::sqrt(uniform(rng, 0, 1));
    const double phi = uniform(rng, -3.14159, 3.14159);
    x(j + 1) = r * std::cos(phi);
    x(j + 2) = r * std::sin(phi);
  }
  return x;
}

core::SimulateOptions options_of(const DesignProblem& p) {
  core::SimulateOptions o;
  o.formulation = p.formulation;
  o.tolerance = p.tolerance;
  return o;
}

struct Scales {
  double force{}, moment{};
};
Scales scales_of(const core::Trajectory& t, double l4) {
  Scales s;
  for (const core::DynamicsSample& d : t.samples) {
    s.force = std::max({s.force, d.RA0.norm(), d.RA3.norm(), d.Fsh.norm()});
    s.moment = std::max({s.moment, std::abs(d.tau), std::abs(d.Msh)});
  }
  s.moment = std::max(s.moment, l4 * s.force);
  return s;
}

std::vector<core::FourBar> test_models() {
  std::vector<core::FourBar> models = {
      core::samples::with_paper_loads(core::samples::paper_fourbar_unloaded(), Vec2(0, -9.81))};
  std::mt19937_64 rng(7);
  for (int i = 0; i < 3; ++i) models.push_back(core::samples::random_crank_rocker(rng));
  const std::size_t bare = models.size();
  for (std::size_t i = 0; i < bare; ++i) models.push_back(with_counter_rotations(models[i]));
  return models;
}

TEST(Nlp, RegressorReproducesInverseDynamics) {
  std::mt19937_64 rng(11);
  for (const core::FourBar& model : test_models()) {
    for (core::Formulation f : core::kFormulations) {
      const DesignProblem p = driven_problem(model, f);
      const Nlp nlp(p);
      for (int trial = 0; trial < 3; ++trial) {
        const Eigen::VectorXd x = random_x(nlp, p, rng);
        const core::FourBar design = nlp.design(x);
        const core::Trajectory ref =
            core::simulate_driven(design, std::get<core::DrivenScene>(p.scene), options_of(p));
        ASSERT_TRUE(ref.ok()) << ref.message;
        const core::Trajectory got = nlp.trajectory(x);
        ASSERT_EQ(got.samples.size(), ref.samples.size());
        const Scales s = scales_of(ref, model.frame_length);
        for (std::size_t i = 0; i < ref.samples.size(); ++i) {
          const core::DynamicsSample &a = got.samples[i], &b = ref.samples[i];
          const std::string at = std::string(core::to_string(f)) + ", sample " + std::to_string(i);
          EXPECT_EQ(a.state.theta1, b.state.theta1) << at;
          EXPECT_EQ(got.t[i], ref.t[i]) << at;
          EXPECT_LT((a.RA0 - b.RA0).norm(), 1e-12 * s.force) << at;
          EXPECT_LT((a.RA3 - b.RA3).norm(), 1e-12 * s.force) << at;
          EXPECT_LT((a.Fsh - b.Fsh).norm(), 1e-12 * s.force) << at;
          EXPECT_LT(std::abs(a.Msh - b.Msh), 1e-12 * s.moment) << at;
          EXPECT_LT(std::abs(a.tau - b.tau), 1e-12 * s.moment) << at;
        }
      }
    }
  }
}

TEST(Nlp, MetricsMatchCoreMetricsOfTheDrivenDesign) {
  std::mt19937_64 rng(12);
  for (const core::FourBar& model : test_models()) {
    const DesignProblem p = driven_problem(model, core::Formulation::kComplexMasses, 36);
    const Nlp nlp(p);
    for (int trial = 0; trial < 3; ++trial) {
      const Eigen::VectorXd x = random_x(nlp, p, rng);
      const core::Trajectory ref =
          core::simulate_driven(nlp.design(x), std::get<core::DrivenScene>(p.scene), options_of(p));
      ASSERT_TRUE(ref.ok());
      const core::Metrics want = core::metrics(ref);
      const core::Metrics got = nlp.metrics(x);
      const Scales s = scales_of(ref, model.frame_length);
      for (Metric m : kMetrics) {
        if (m == Metric::kAddedMass) continue;
        const double scale = (m == Metric::kMshRms || m == Metric::kMshMax ||
                              m == Metric::kTauRms || m == Metric::kTauMax)
                                 ? s.moment
                                 : s.force;
        // the summary of the regressor's samples, and the fast path (|R q| for an RMS)
        const double* fields[] = {&got.Fsh_rms, &got.Fsh_max, &got.Msh_rms, &got.Msh_max,
                                  &got.tau_rms, &got.tau_max, &got.RA0_rms, &got.RA0_max,
                                  &got.RA3_rms, &got.RA3_max};
        const double* wants[] = {&want.Fsh_rms, &want.Fsh_max, &want.Msh_rms, &want.Msh_max,
                                 &want.tau_rms, &want.tau_max, &want.RA0_rms, &want.RA0_max,
                                 &want.RA3_rms, &want.RA3_max};
        const auto k = static_cast<std::size_t>(m);
        EXPECT_NEAR(*fields[k], *wants[k], 1e-12 * scale) << to_string(m);
        EXPECT_NEAR(nlp.metric(x, m), *wants[k], 1e-12 * scale) << to_string(m);
      }
      // added mass: the design's total mass minus the original's
      EXPECT_NEAR(nlp.metric(x, Metric::kAddedMass),
                  core::total_mass(nlp.design(x)) - core::total_mass(model),
                  1e-13 * core::total_mass(model));
    }
  }
}

TEST(Nlp, OriginalValuesNormaliseTheObjective) {
  // with no counterweight mass and the link parameters at their original values the design is
  // the original: each term is 1 (linear form: sqrt(1 + ε²), ε the smoothing), the added mass 0
  const core::FourBar model = core::samples::paper_fourbar();
  DesignProblem p = driven_problem(model, core::Formulation::kMassMatrix, 36);
  p.link_parameters = {{2, P::kMass, 1.0, 5.0}};
  p.objective = {{Metric::kFshRms, 2.0}, {Metric::kTauRms, 0.5}, {Metric::kAddedMass, 3.0}};
  const Nlp nlp(p);
  Eigen::VectorXd x = nlp.start();
  x(0) = x(3) = 0.0;  // no counterweights
  EXPECT_EQ(x(6), model.coupler.mass);
  EXPECT_EQ(p.objective_form, ObjectiveForm::kLinear);  // the default
  EXPECT_NEAR(nlp.objective(x, nullptr), 2.5 * std::sqrt(1 + std::pow(p.smoothing, 2)), 1e-12);
  p.objective_form = ObjectiveForm::kSquared;
  EXPECT_NEAR(Nlp(p).objective(x, nullptr), 2.5, 1e-12);
  const core::Metrics o = core::metrics(
      core::simulate_driven(model, std::get<core::DrivenScene>(p.scene), options_of(p)));
  EXPECT_EQ(nlp.original(Metric::kFshRms), o.Fsh_rms);
  EXPECT_EQ(nlp.original(Metric::kAddedMass), core::total_mass(model));
}

TEST(Nlp, ObjectiveAndLimitsFollowTheirDefinitions) {
  for (const ObjectiveForm form : {ObjectiveForm::kLinear, ObjectiveForm::kSquared}) {
    SCOPED_TRACE(to_string(form));
    std::mt19937_64 rng(13);
    const core::FourBar model = core::samples::random_crank_rocker(rng);
    DesignProblem p = full_problem(model, core::Formulation::kOpenedLoop);
    p.objective_form = form;
    p.smoothing = 1e-3;  // large enough to show in the values
    const Nlp nlp(p);
    const int samples = std::get<core::DrivenScene>(p.scene).samples;
    const Eigen::VectorXd x = random_x(nlp, p, rng);
    // objective: Σ w s(metric/original) with s(r) = sqrt(r² + ε²) (linear) or r² (squared), a
    // peak through its bound variable (w t/original or w (t/original)²), added mass linear
    const bool linear = form == ObjectiveForm::kLinear;
    double want = 0;
    int t = design_variables(p);
    for (const Term& term : p.objective) {
      const double o = nlp.original(term.metric);
      if (term.metric == Metric::kAddedMass) {
        want += term.weight * nlp.metric(x, term.metric) / core::total_mass(model);
      } else if (is_peak(term.metric)) {
        const double r = x(t++) / o;
        want += term.weight * (linear ? r : r * r);
      } else {
        const double r = nlp.metric(x, term.metric) / o;
        want += term.weight * (linear ? std::sqrt(r * r + 1e-6) : r * r);
      }
    }
    EXPECT_NEAR(nlp.objective(x, nullptr), want, 1e-12 * want);
    // limits: the largest peak-limit constraint over the samples is (peak/limit)² - 1
    Eigen::VectorXd c;
    nlp.inequalities(x, c, nullptr);
    ASSERT_EQ(c.size(), nlp.n_ineq());
    ASSERT_EQ(static_cast<int>(nlp.constraint_names().size()), nlp.n_eq() + nlp.n_ineq());
    int row = 2;  // after the two envelopes
    for (const Limit& l : p.limits) {
      const double v = nlp.metric(x, l.metric);
      if (l.metric == Metric::kAddedMass) {
        EXPECT_NEAR(c(row), (v - l.value) / core::total_mass(model), 1e-14);
        ++row;
      } else if (is_peak(l.metric)) {
        const double worst = c.segment(row, samples).maxCoeff();
        EXPECT_NEAR(worst, std::pow(v / (l.value * nlp.original(l.metric)), 2) - 1, 1e-12);
        row += samples;
      } else {
        EXPECT_NEAR(c(row), std::pow(v / (l.value * nlp.original(l.metric)), 2) - 1, 1e-12);
        ++row;
      }
    }
    // then the five peak bounds' samples: the largest is (sqrt(peak² + (ε o)²) - t) / o (linear)
    // or (peak² - t²) / o² (squared)
    t = design_variables(p);
    for (Metric m : kMetrics) {
      if (!is_peak(m)) continue;
      const double o = nlp.original(m), peak = nlp.metric(x, m), tm = x(t++);
      const double worst = c.segment(row, samples).maxCoeff();
      if (linear) {
        EXPECT_NEAR(worst, (std::hypot(peak, 1e-3 * o) - tm) / o, 1e-12 * peak / o) << to_string(m);
      } else {
        EXPECT_NEAR(worst, (peak * peak - tm * tm) / (o * o), 1e-12 * std::pow(peak / o, 2))
            << to_string(m);
      }
      row += samples;
    }
    EXPECT_EQ(row, nlp.n_ineq());
  }
}

// Central differences of a vector function, column by column.
template <class F>
Eigen::MatrixXd central_differences(const Eigen::VectorXd& x, int rows, F f) {
  Eigen::MatrixXd jac(rows, x.size());
  for (int j = 0; j < x.size(); ++j) {
    const double h = 1e-6 * std::max(1.0, std::abs(x(j)));
    Eigen::VectorXd xp = x, xm = x;
    xp(j) += h;
    xm(j) -= h;
    jac.col(j) = (f(xp) - f(xm)) / (xp(j) - xm(j));
  }
  return jac;
}

void expect_rows_agree(const Eigen::MatrixXd& analytic, const Eigen::MatrixXd& numeric,
                       const Nlp& nlp, const std::string& what, int row_offset) {
  ASSERT_EQ(analytic.rows(), numeric.rows());
  ASSERT_EQ(analytic.cols(), numeric.cols());
  for (int i = 0; i < analytic.rows(); ++i) {
    const double scale = std::max(analytic.row(i).cwiseAbs().maxCoeff(), 1e-2);
    const double error = (analytic.row(i) - numeric.row(i)).cwiseAbs().maxCoeff();
    EXPECT_LT(error, 1e-6 * scale)
        << what << " row " << i << ": "
        << nlp.constraint_names()[static_cast<std::size_t>(i + row_offset)];
  }
}

TEST(Nlp, GradientsMatchCentralDifferences) {
  std::mt19937_64 rng(14);
  for (const core::FourBar& model : test_models()) {
    for (const ObjectiveForm form : {ObjectiveForm::kLinear, ObjectiveForm::kSquared}) {
      SCOPED_TRACE(to_string(form));
      DesignProblem p = full_problem(model, core::Formulation::kMassMatrix);
      p.objective_form = form;
      const Nlp nlp(p);
      ASSERT_TRUE(nlp.has_gradients());
      for (int trial = 0; trial < 2; ++trial) {
        const Eigen::VectorXd x = random_x(nlp, p, rng);
        // objective
        Eigen::VectorXd g;
        nlp.objective(x, &g);
        const Eigen::MatrixXd g_fd = central_differences(x, 1, [&](const Eigen::VectorXd& z) {
          return Eigen::VectorXd::Constant(1, nlp.objective(z, nullptr));
        });
        ASSERT_EQ(g.size(), nlp.n());
        const double scale = g.cwiseAbs().maxCoeff();
        EXPECT_LT((g.transpose() - g_fd).cwiseAbs().maxCoeff(), 1e-6 * scale);
        // equalities
        Eigen::VectorXd c;
        Eigen::MatrixXd jac;
        nlp.equalities(x, c, &jac);
        ASSERT_EQ(nlp.n_eq(), 4);
        expect_rows_agree(jac,
                          central_differences(x, nlp.n_eq(),
                                              [&](const Eigen::VectorXd& z) {
                                                Eigen::VectorXd v;
                                                nlp.equalities(z, v, nullptr);
                                                return v;
                                              }),
                          nlp, "equality", 0);
        // inequalities
        nlp.inequalities(x, c, &jac);
        expect_rows_agree(jac,
                          central_differences(x, nlp.n_ineq(),
                                              [&](const Eigen::VectorXd& z) {
                                                Eigen::VectorXd v;
                                                nlp.inequalities(z, v, nullptr);
                                                return v;
                                              }),
                          nlp, "inequality", nlp.n_eq());
      }
    }
  }
}

TEST(Nlp, EqualitiesAreEquation57OverTheTotalMass) {
  std::mt19937_64 rng(15);
  for (const core::FourBar& model : test_models()) {
    DesignProblem p = driven_problem(model, core::Formulation::kComplexMasses);
    p.force_balance = true;
    const Nlp nlp(p);
    const Eigen::VectorXd x = random_x(nlp, p, rng);
    const balance::ForceBalanceResiduals r = balance::force_balance_residuals(nlp.design(x));
    Eigen::VectorXd c;
    nlp.equalities(x, c, nullptr);
    const double M = core::total_mass(model);
    EXPECT_NEAR(c(0), r.crank.real() / M, 1e-13);
    EXPECT_NEAR(c(1), r.crank.imag() / M, 1e-13);
    EXPECT_NEAR(c(2), r.rocker.real() / M, 1e-13);
    EXPECT_NEAR(c(3), r.rocker.imag() / M, 1e-13);
  }
}

TEST(Nlp, ForceBalanceEqualitiesVanishForForceBalancedDesign) {
  for (const balance::CounterweightShape shape :
       {balance::CounterweightShape::kPoint, balance::CounterweightShape::kDisc}) {
    const core::FourBar model = core::samples::paper_fourbar_unloaded();
    balance::CounterweightSpec spec;
    spec.shape = shape;
    spec.distance = 0.5;
    const balance::ForceBalancedDesign balanced = balance::force_balance(model, spec, spec);
    ASSERT_TRUE(balanced.crank && balanced.rocker);

    DesignProblem p = driven_problem(model, core::Formulation::kComplexMasses, 72);
    p.link_parameters.clear();
    p.force_balance = true;
    for (CounterweightVariables& c : p.counterweights) {
      c.shape = shape;
      c.thickness = spec.thickness;
      c.density = spec.density;
      c.mass_max = 20.0;
    }
    const Nlp nlp(p);
    Eigen::VectorXd x(6);
    x << balanced.crank->mass, balanced.crank->position.x(), balanced.crank->position.y(),
        balanced.rocker->mass, balanced.rocker->position.x(), balanced.rocker->position.y();
    ASSERT_TRUE((x.array() <= nlp.upper().array()).all() &&
                (x.array() >= nlp.lower().array()).all());
    Eigen::VectorXd c;
    nlp.equalities(x, c, nullptr);
    EXPECT_LT(c.cwiseAbs().maxCoeff(), 1e-13) << c.transpose();
    // the same design as balance's (its inertia included), and no shaking force in the scene
    const core::FourBar design = nlp.design(x);
    for (int k = 1; k <= 3; ++k) {
      const core::Link &a = core::link(design, k), &b = core::link(balanced.model, k);
      EXPECT_NEAR(a.mass, b.mass, 1e-13 * b.mass);
      EXPECT_NEAR(a.e, b.e, 1e-13 * b.length);
      EXPECT_NEAR(a.f, b.f, 1e-13 * b.length);
      EXPECT_NEAR(a.inertia, b.inertia, 1e-13 * (b.inertia + b.mass * b.length * b.length));
    }
    EXPECT_LT(nlp.metric(x, Metric::kFshRms), 1e-12 * nlp.metric(x, Metric::kRA0Rms));
    EXPECT_LT(nlp.metrics(x).Fsh_max, 1e-12 * nlp.metrics(x).RA0_max);
    // and not otherwise: the start, and the balanced design with either counterweight moved
    nlp.equalities(nlp.start(), c, nullptr);
    EXPECT_GT(c.cwiseAbs().maxCoeff(), 1e-3);
    for (int j : {0, 1, 2, 3, 4, 5}) {
      Eigen::VectorXd y = x;
      y(j) += 0.05;
      nlp.equalities(y, c, nullptr);
      EXPECT_GT(c.cwiseAbs().maxCoeff(), 1e-4) << "variable " << j;
    }
  }
}

TEST(Nlp, PeakBoundsHoldOverTheBox) {
  // t_max bounds the peak of every design in the box, and the start is feasible
  std::mt19937_64 rng(16);
  for (const core::FourBar& model : test_models()) {
    for (const ObjectiveForm form : {ObjectiveForm::kLinear, ObjectiveForm::kSquared}) {
      DesignProblem p = full_problem(model, core::Formulation::kComplexMasses);
      p.objective_form = form;
      const Nlp nlp(p);
      const Eigen::VectorXd x0 = nlp.start();
      EXPECT_TRUE((x0.array() <= nlp.upper().array()).all());
      EXPECT_TRUE((x0.array() >= nlp.lower().array()).all());
      Eigen::VectorXd c;
      nlp.inequalities(x0, c, nullptr);
      const int samples = std::get<core::DrivenScene>(p.scene).samples;
      EXPECT_LE(c.tail(5 * samples).maxCoeff(), 0.0);  // the peak bounds at the start
      for (int trial = 0; trial < 20; ++trial) {
        const Eigen::VectorXd x = random_x(nlp, p, rng);
        int t = design_variables(p);
        for (Metric m : kMetrics) {
          if (is_peak(m)) {
            EXPECT_LE(nlp.metric(x, m), nlp.upper()(t++)) << to_string(m);
          }
        }
      }
      // the bound variables' boxes: [0, t_max] (squared), [-t_max, t_max] (linear, where the
      // constraints keep t > 0; nlp.hpp says why)
      for (int j = design_variables(p); j < nlp.n(); ++j) {
        EXPECT_EQ(nlp.lower()(j), form == ObjectiveForm::kLinear ? -nlp.upper()(j) : 0.0);
      }
    }
  }
}

TEST(Nlp, SmoothedObjectiveBracketsTheExactWeightedSum) {
  // f <= f~ <= f + ε Σ w (optimize/nlp.hpp) for the exact sum f = Σ w metric/original at any
  // design, with a bound variable at its smallest feasible value sqrt(peak² + (ε o)²); tight
  // where a metric vanishes: at a force-balanced design the Fsh_rms term is ε w exactly
  std::mt19937_64 rng(18);
  for (const double eps : {1e-6, 1e-2}) {
    const core::FourBar model = core::samples::paper_fourbar_unloaded();
    DesignProblem p = driven_problem(model, core::Formulation::kComplexMasses, 36);
    p.link_parameters.clear();
    p.counterweights[1].shape = balance::CounterweightShape::kPoint;
    for (CounterweightVariables& c : p.counterweights) c.mass_max = 20.0;
    p.objective = {{Metric::kFshRms, 2.0}, {Metric::kFshMax, 0.5}, {Metric::kMshRms, 1.0},
                   {Metric::kTauMax, 0.25}, {Metric::kAddedMass, 0.1}};
    p.smoothing = eps;
    const Nlp nlp(p);
    const double sum_w = 2.0 + 0.5 + 1.0 + 0.25;  // the reaction terms' weights
    auto exact = [&](const Eigen::VectorXd& x) {
      double f = 0;
      for (const Term& t : p.objective) {
        f += t.weight * nlp.metric(x, t.metric) / nlp.original(t.metric);
      }
      return f;
    };
    auto at_smallest_bounds = [&](Eigen::VectorXd x) {
      x(6) = std::hypot(nlp.metric(x, Metric::kFshMax), eps * nlp.original(Metric::kFshMax));
      x(7) = std::hypot(nlp.metric(x, Metric::kTauMax), eps * nlp.original(Metric::kTauMax));
      return x;
    };
    for (int trial = 0; trial < 5; ++trial) {
      const Eigen::VectorXd x = at_smallest_bounds(random_x(nlp, p, rng));
      const double f = exact(x), smooth = nlp.objective(x, nullptr);
      EXPECT_GE(smooth, f * (1 - 1e-14));
      EXPECT_LE(smooth, f + eps * sum_w);
    }
    // the force-balanced design of the balance layer: Fsh vanishes (to ~1e-13 of the
    // original's), so the Fsh terms exceed their exact values by ε w each
    balance::CounterweightSpec spec;
    spec.distance = 0.5;
    const balance::ForceBalancedDesign fb = balance::force_balance(model, spec, spec);
    ASSERT_TRUE(fb.crank && fb.rocker);
    DesignProblem q = p;
    q.objective = {{Metric::kFshRms, 2.0}, {Metric::kFshMax, 0.5}, {Metric::kAddedMass, 0.1}};
    const Nlp fsh(q);
    Eigen::VectorXd x(7);
    x << fb.crank->mass, fb.crank->position.x(), fb.crank->position.y(), fb.rocker->mass,
        fb.rocker->position.x(), fb.rocker->position.y(), 0.0;
    x(6) = std::hypot(fsh.metric(x, Metric::kFshMax), eps * fsh.original(Metric::kFshMax));
    ASSERT_LT(fsh.metric(x, Metric::kFshRms), 1e-12 * fsh.original(Metric::kFshRms));
    const double gap = fsh.objective(x, nullptr) -
                       (2.0 * fsh.metric(x, Metric::kFshRms) / fsh.original(Metric::kFshRms) +
                        0.5 * fsh.metric(x, Metric::kFshMax) / fsh.original(Metric::kFshMax) +
                        0.1 * fsh.metric(x, Metric::kAddedMass) / core::total_mass(model));
    EXPECT_NEAR(gap, 2.5 * eps, 1e-11) << "eps " << eps;
  }
}

TEST(Nlp, NamesAndSizes) {
  const DesignProblem p =
      full_problem(core::samples::paper_fourbar(), core::Formulation::kMassMatrix);
  const Nlp nlp(p);
  EXPECT_EQ(nlp.n(), design_variables(p) + 5);
  EXPECT_EQ(nlp.lower().size(), nlp.n());
  ASSERT_EQ(static_cast<int>(nlp.variable_names().size()), nlp.n());
  EXPECT_EQ(nlp.variable_names()[0], "crank counterweight mass [kg]");
  EXPECT_EQ(nlp.variable_names()[4], "rocker counterweight x from A3 in link axes [m]");
  EXPECT_EQ(nlp.variable_names()[6], "coupler mass [kg]");
  EXPECT_EQ(nlp.variable_names()[static_cast<std::size_t>(design_variables(p))],
            "bound on Fsh_max [N]");
  EXPECT_EQ(nlp.constraint_names()[0], "force balance, crank side (real part)");
  EXPECT_EQ(nlp.constraint_names()[4], "crank counterweight within distance_max = 0.8 m of A0");
  EXPECT_EQ(nlp.constraint_names()[6], "Fsh_rms <= 1.5 x original");
  EXPECT_EQ(nlp.constraint_names()[7].rfind("Fsh_max <= 1.5 x original at sample 0", 0), 0u);
  EXPECT_THROW(nlp.objective(Eigen::VectorXd::Zero(3), nullptr), InputError);
  // the counterweights at x, as balance describes them
  const Eigen::VectorXd x = nlp.start();
  const std::vector<PlacedCounterweight> cws = nlp.counterweights(x);
  ASSERT_EQ(cws.size(), 2u);
  EXPECT_EQ(cws[0].link, 1);
  EXPECT_EQ(cws[0].counterweight.mass, 2.5);
  EXPECT_EQ(cws[0].counterweight.position, Vec2(-0.4, 0));
  EXPECT_EQ(cws[1].link, 3);
  EXPECT_EQ(cws[1].counterweight.position, Vec2(0.5, 0));
  const double r2 = 2.0 / (500.0 * 3.141592653589793 * 0.05);
  EXPECT_NEAR(cws[1].counterweight.radius, std::sqrt(r2), 1e-15);
  EXPECT_NEAR(cws[1].counterweight.inertia, 0.5 * 2.0 * r2, 1e-15);
}

TEST(Nlp, ObjectiveNormaliserMustNotVanish) {
  // a force-balanced original has Fsh_rms = 0 to round-off: nothing to normalise by
  const balance::ForceBalancedDesign balanced =
      balance::force_balance(core::samples::paper_fourbar_unloaded(), {}, {});
  DesignProblem p = driven_problem(balanced.model, core::Formulation::kComplexMasses);
  try {
    const Nlp nlp(p);
    ADD_FAILURE() << "no exception";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("objective[0]: the original design's Fsh_rms is"),
              std::string::npos)
        << e.what();
    ASSERT_TRUE(e.field());
    EXPECT_EQ(e.field()->field, "objective");
    EXPECT_EQ(e.field()->index, 0);
  }
  p.objective = {{Metric::kTauRms, 1.0}};
  EXPECT_NO_THROW(Nlp{p});
  p.objective[0].weight = 0;
  p.objective.push_back({Metric::kRA0Max, 1.0});
  p.limits = {{Metric::kFshMax, 0.5}};
  try {
    const Nlp nlp(p);
    ADD_FAILURE() << "no exception";
  } catch (const InputError& e) {
    ASSERT_TRUE(e.field()) << e.what();
    EXPECT_EQ(e.field()->field, "limits");
    EXPECT_EQ(e.field()->index, 0);
    EXPECT_EQ(std::string(e.what()).rfind("limits[0]: the original design's Fsh_max is", 0), 0u)
        << e.what();
  }
}

TEST(Nlp, InvalidProblemThrows) {
  DesignProblem p = driven_problem(core::samples::paper_fourbar(), core::Formulation::kMassMatrix);
  p.counterweights[1].link = 2;
  try {
    const Nlp nlp(p);
    ADD_FAILURE() << "no exception";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "invalid design problem: counterweights[1].link must be 1 (crank) or 3 (rocker), "
              "got 2");
  }
  // a driven crank that cannot turn
  DesignProblem q = driven_problem(core::samples::triple_rocker(), core::Formulation::kMassMatrix);
  EXPECT_THROW(Nlp{q}, InputError);
}

TEST(Nlp, FreeSceneSimulatesEveryDesign) {
  std::mt19937_64 rng(17);
  DesignProblem p = driven_problem(core::samples::paper_fourbar(), core::Formulation::kMassMatrix);
  core::FreeScene scene;
  scene.theta1 = 0.5;
  scene.omega1 = 3.0;
  scene.duration = 0.4;
  scene.samples = 21;
  p.scene = scene;
  p.tolerance = 1e-9;
  p.objective = {{Metric::kFshRms, 1.0}, {Metric::kMshMax, 0.5}, {Metric::kAddedMass, 0.1}};
  p.limits = {{Metric::kRA0Max, 2.0}, {Metric::kMshRms, 3.0}, {Metric::kAddedMass, 4.0}};
  p.force_balance = true;
  const Nlp nlp(p);
  // gradients by forward sensitivities of the reduced equation (tests/optimize/free_nlp_test.cpp)
  EXPECT_TRUE(nlp.has_gradients());
  EXPECT_EQ(nlp.n(), design_variables(p));  // no bound variables in free scenes
  EXPECT_EQ(nlp.n_ineq(), 2 + 3);
  // the peaks the problem reads (Msh_max, RA0_max) resolved between the samples by core; the
  // original's every peak (the normalisers)
  const core::MetricMask read = resolved_peak_rows(p);
  for (std::size_t k = 0; k < core::kMetricCount; ++k) {
    EXPECT_EQ(read[k], k == static_cast<std::size_t>(Metric::kMshMax) ||
                           k == static_cast<std::size_t>(Metric::kRA0Max))
        << core::kMetricTable[k].name;
  }
  const core::Metrics o = core::metrics(
      p.original, core::simulate_free(p.original, scene, options_of(p)), options_of(p));
  EXPECT_EQ(nlp.original(Metric::kMshMax), o.Msh_max);

  int between = 0;  // designs whose RA0 peaks between two samples
  for (int trial = 0; trial < 3; ++trial) {
    const Eigen::VectorXd x = random_x(nlp, p, rng);
    const core::Trajectory t = core::simulate_free(nlp.design(x), scene, options_of(p));
    ASSERT_TRUE(t.ok()) << t.message;
    const core::Metrics want = core::metrics(nlp.design(x), t, options_of(p), &read);
    const core::Metrics got = nlp.metrics(x);
    // a peak read lies between the samples or at an end of the run (0.4 s), never below the
    // largest sample; the peaks not read are the largest samples
    const core::Metrics samples = core::metrics(t);
    EXPECT_GE(want.RA0_max, samples.RA0_max);
    between += want.RA0_max > samples.RA0_max;
    EXPECT_EQ(want.Fsh_max, samples.Fsh_max);
    EXPECT_EQ(got.Fsh_rms, want.Fsh_rms);
    EXPECT_EQ(got.Fsh_max, want.Fsh_max);
    EXPECT_EQ(got.Msh_rms, want.Msh_rms);
    EXPECT_EQ(got.Msh_max, want.Msh_max);
    EXPECT_EQ(got.tau_rms, want.tau_rms);
    EXPECT_EQ(got.tau_max, want.tau_max);
    EXPECT_EQ(got.RA0_rms, want.RA0_rms);
    EXPECT_EQ(got.RA0_max, want.RA0_max);
    EXPECT_EQ(got.RA3_rms, want.RA3_rms);
    EXPECT_EQ(got.RA3_max, want.RA3_max);
    const double added = core::total_mass(nlp.design(x)) - core::total_mass(p.original);
    EXPECT_NEAR(nlp.metric(x, Metric::kAddedMass), added, 1e-13);
    // the objective and the limits from these metrics
    // (linear form: the RMS smoothed as in driven scenes, the peak exact)
    const double f = std::hypot(want.Fsh_rms / o.Fsh_rms, p.smoothing) +
                     0.5 * want.Msh_max / o.Msh_max + 0.1 * added / core::total_mass(p.original);
    EXPECT_NEAR(nlp.objective(x, nullptr), f, 1e-13 * f);
    Eigen::VectorXd c;
    nlp.inequalities(x, c, nullptr);
    EXPECT_NEAR(c(2), std::pow(want.RA0_max / (2.0 * o.RA0_max), 2) - 1, 1e-13);
    EXPECT_NEAR(c(3), std::pow(want.Msh_rms / (3.0 * o.Msh_rms), 2) - 1, 1e-13);
    EXPECT_NEAR(c(4), (added - 4.0) / core::total_mass(p.original), 1e-13);
    nlp.equalities(x, c, nullptr);
    EXPECT_EQ(c.size(), 4);
  }
  EXPECT_GE(between, 1);  // measured: 1 of the 3
  // on the opened loop's DAE no gradients: asking is a programming error
  p.formulation = core::Formulation::kOpenedLoop;
  const Nlp opened(p);
  EXPECT_FALSE(opened.has_gradients());
  const Eigen::VectorXd x = opened.start();
  Eigen::VectorXd g, c;
  Eigen::MatrixXd jac;
  EXPECT_THROW(opened.objective(x, &g), std::logic_error);
  EXPECT_THROW(opened.equalities(x, c, &jac), std::logic_error);
  EXPECT_THROW(opened.inequalities(x, c, &jac), std::logic_error);
}

}  // namespace
}  // namespace bd::optimize
