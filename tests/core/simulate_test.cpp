#include "core/fourbar/simulate.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <string>

#include "core/fourbar/energy.hpp"
#include "core/fourbar/kinematics.hpp"
#include "core/fourbar/metrics.hpp"
#include "core/fourbar/samples.hpp"
#include "core/input_error.hpp"

namespace bd::core {
namespace {

constexpr double kPi = std::numbers::pi;

// The paper's free simulation: from rest at theta1 = 1 rad for 5 s, 501 samples.
constexpr FreeScene kPaperFree{.theta1 = 1.0, .omega1 = 0.0, .duration = 5.0, .samples = 501};

double energy(const FourBar& model, const DynamicsSample& s) {
  return kinetic_energy(model, s.state) + load_potential(model, pose_of(s.state));
}

double max_kinetic_energy(const FourBar& model, const Trajectory& trajectory) {
  double T = 0.0;
  for (const auto& s : trajectory.samples) T = std::max(T, kinetic_energy(model, s.state));
  return T;
}

// Throws bd::InputError whose message is exactly `text`.
void expect_input_error(const std::function<void()>& call, const std::string& text) {
  try {
    call();
    ADD_FAILURE() << "no bd::InputError; expected \"" << text << "\"";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), text);
  }
}

TEST(SimulateFree, KineticEnergyChangeEqualsWorkOfLoads) {
  const FourBar model = samples::paper_fourbar();
  // The balance T + V = const holds exactly for the exact motion; what remains is the
  // integrator's global error, δ(T + V) ≈ J ω1 δω1 + Q δθ1. CVODE controls the local error per
  // step to the tolerance, and over the ~250-350 steps of this run the global error grows to a
  // few times it: measured |Δ(T + V)| ≈ 1.1e-9 J at tolerance 1e-10 (4e-9 of ΔT = 0.279 J) and
  // ≈ 1.4e-11 J at 1e-12, following the tolerance. So the 1e-9 check runs at tolerance 1e-12
  // (absolute 1e-14, so the relative tolerance governs the O(1) states), where it has a margin
  // of about 20.
  SimulateOptions options;
  options.tolerance = 1e-12;
  options.absolute_tolerance = 1e-14;
  const Trajectory trajectory = simulate_free(model, kPaperFree, options);
  ASSERT_TRUE(trajectory.ok()) << trajectory.message;
  ASSERT_EQ(trajectory.samples.size(), 501u);
  EXPECT_DOUBLE_EQ(trajectory.t.back(), 5.0);

  // work of the constant loads from t = 0 to 5 s is -ΔV (continuous angles)
  const DynamicsSample& first = trajectory.samples.front();
  const DynamicsSample& last = trajectory.samples.back();
  const double dT = kinetic_energy(model, last.state) - kinetic_energy(model, first.state);
  const double work =
      -(load_potential(model, pose_of(last.state)) - load_potential(model, pose_of(first.state)));
  ASSERT_GT(std::abs(dT), 0.1);  // the motion is not trivial
  EXPECT_NEAR(dT, work, 1e-9 * std::abs(dT));

  // T + V at every sample, relative to the scale of T over the run
  const double scale = max_kinetic_energy(model, trajectory);
  const double E0 = energy(model, first);
  for (std::size_t j = 0; j < trajectory.samples.size(); ++j) {
    EXPECT_NEAR(energy(model, trajectory.samples[j]), E0, 1e-9 * scale)
        << "t = " << trajectory.t[j];
  }
}

TEST(SimulateFree, EnergyErrorFollowsDefaultTolerance) {
  // at the default tolerance the same balance holds to the integrator's global error, a modest
  // multiple of the tolerance (measured ≈ 2.3e-9 of max T at 1e-10; bound 1e-8 = 100·tol)
  const FourBar model = samples::paper_fourbar();
  const SimulateOptions options;
  const Trajectory trajectory = simulate_free(model, kPaperFree, options);
  ASSERT_TRUE(trajectory.ok()) << trajectory.message;
  const double scale = max_kinetic_energy(model, trajectory);
  const double E0 = energy(model, trajectory.samples.front());
  for (std::size_t j = 0; j < trajectory.samples.size(); ++j) {
    EXPECT_NEAR(energy(model, trajectory.samples[j]), E0, 100 * options.tolerance * scale)
        << "t = " << trajectory.t[j];
  }
  EXPECT_GT(trajectory.steps, 0);
  EXPECT_GT(trajectory.rhs_evaluations, trajectory.steps);
}

TEST(SimulateFree, HalvingToleranceChangesResultWithinTolerance) {
  // CVODE keeps each step's local error within tol·|y| + atol. For this stable, non-chaotic
  // swing the global error e(tol) stays a modest multiple C of tol times the size of the state
  // (measured C ≈ 1 for theta1 at 1e-10), and it scales with tol. Then
  // |theta1(tol) - theta1(tol/2)| ≈ |e(tol) - e(tol/2)| <= 1.5·C·tol·scale; C <= 10 is what the
  // tolerance may fairly be said to promise over ~250 steps. Both runs must also lie within that
  // of a tight reference (tolerance 1e-13).
  const FourBar model = samples::paper_fourbar();
  SimulateOptions coarse;  // defaults: 1e-10, absolute 1e-12
  SimulateOptions fine = coarse;
  fine.tolerance = coarse.tolerance / 2;
  fine.absolute_tolerance = coarse.absolute_tolerance / 2;
  SimulateOptions reference;
  reference.tolerance = 1e-13;
  reference.absolute_tolerance = 1e-15;
  const Trajectory a = simulate_free(model, kPaperFree, coarse);
  const Trajectory b = simulate_free(model, kPaperFree, fine);
  const Trajectory r = simulate_free(model, kPaperFree, reference);
  ASSERT_TRUE(a.ok() && b.ok() && r.ok());

  double scale = 0.0;  // size of theta1 over the run [rad]
  for (const auto& s : r.samples) scale = std::max(scale, std::abs(s.state.theta1));
  const double theta_a = a.samples.back().state.theta1, theta_b = b.samples.back().state.theta1,
               theta_r = r.samples.back().state.theta1;
  const double promise = 10 * coarse.tolerance * scale;
  EXPECT_LT(std::abs(theta_a - theta_b), promise);
  EXPECT_LT(std::abs(theta_a - theta_r), promise);
  EXPECT_LT(std::abs(theta_b - theta_r), promise / 2);
}

TEST(SimulateFree, OutputInstantsAreTheRequestedOnes) {
  const FourBar model = samples::paper_fourbar();
  const FreeScene scene{.theta1 = 1.0, .omega1 = 0.5, .duration = 0.3, .samples = 7};
  const Trajectory trajectory = simulate_free(model, scene);
  ASSERT_TRUE(trajectory.ok()) << trajectory.message;
  ASSERT_EQ(trajectory.t.size(), 7u);
  for (std::size_t j = 0; j < 7; ++j) {
    EXPECT_DOUBLE_EQ(trajectory.t[j], 0.3 * static_cast<double>(j) / 6.0);
  }
  // the first sample is the initial state
  EXPECT_EQ(trajectory.samples[0].state.theta1, 1.0);
  EXPECT_EQ(trajectory.samples[0].state.omega1, 0.5);
}

TEST(SimulateDriven, DrivePowerOverRevolutionEqualsKineticEnergyChange) {
  // Without loads tau·omega1 = dT/dt, whose integral over a period vanishes. The trapezoid rule
  // on a smooth periodic integrand is spectrally accurate, so with 360 samples only round-off
  // of the sum remains (~1e-14 of the scale max|tau|·|omega1|·T).
  const FourBar model = samples::paper_fourbar_unloaded();
  const double omega1 = 2 * kPi;
  const DrivenScene scene{.theta1 = 0.0, .omega1 = omega1, .revolutions = 1, .samples = 360};
  const Trajectory trajectory = simulate_driven(model, scene);
  ASSERT_TRUE(trajectory.ok()) << trajectory.message;
  ASSERT_EQ(trajectory.samples.size(), 360u);
  const double period = 2 * kPi / std::abs(omega1);
  const double dt = period / 360;
  EXPECT_NEAR(trajectory.t[1] - trajectory.t[0], dt, 1e-15);

  double work = 0.0, tau_max = 0.0;
  for (const auto& s : trajectory.samples) {
    work += s.tau * s.state.omega1 * dt;  // periodic trapezoid: every sample has weight dt
    tau_max = std::max(tau_max, std::abs(s.tau));
    EXPECT_EQ(s.state.alpha1, 0.0);
  }
  ASSERT_GT(tau_max, 1.0);  // the torque is not trivially zero
  const double dT = 0.0;    // periodic motion: T(T_period) = T(0)
  EXPECT_NEAR(work, dT, 1e-10 * tau_max * std::abs(omega1) * period);

  // and the kinetic energy does come back
  const double T0 = kinetic_energy(model, trajectory.samples.front().state);
  const auto end = inverse_dynamics(model, 2 * kPi, omega1, 0.0);
  ASSERT_TRUE(end.has_value());
  EXPECT_NEAR(kinetic_energy(model, end->state), T0, 1e-13 * T0);
}

// Σ m_k r̄_k [kg m] at crank angle theta1.
Vec2 first_moment(const FourBar& model, double theta1) {
  const auto pose = solve_position(model, theta1);
  EXPECT_TRUE(pose.has_value()) << "theta1 = " << theta1;
  return total_mass(model) * system_centre_of_mass(model, *pose);
}

// Checks Fsh = Σ m_k ḡ - dp/dt along a driven revolution, dp/dt = d²(Σ m_k r̄_k)/dt² by the
// fourth-order central difference [-S(t+2h) + 16 S(t+h) - 30 S(t) + 16 S(t-h) - S(t-2h)]/(12h²).
// h = 2e-3/|omega1| (crank step 2e-3 rad): truncation (ωh)⁴/90 ~ 2e-13 of ω²|S| per harmonic
// (k⁶ times that for the k-th, whose amplitude falls fast); round-off ~ (64/12) eps |S| / h²
// ~ 3e-10 of ω²|S|. With |S| of the order of M·l and Fsh ~ ω² M l, 1e-8·max|Fsh| leaves a margin.
void check_shaking_force_is_momentum_rate(const FourBar& model) {
  const double omega1 = 2 * kPi;
  const DrivenScene scene{.theta1 = 0.3, .omega1 = omega1, .revolutions = 1, .samples = 72};
  const Trajectory trajectory = simulate_driven(model, scene);
  ASSERT_TRUE(trajectory.ok()) << trajectory.message;
  const double h = 2e-3 / std::abs(omega1);
  const Vec2 weight = total_mass(model) * model.loads.gravity;
  double Fsh_max = 0.0;
  for (const auto& s : trajectory.samples) Fsh_max = std::max(Fsh_max, s.Fsh.norm());
  ASSERT_GT(Fsh_max, 1.0);
  for (std::size_t j = 0; j < trajectory.samples.size(); ++j) {
    const double t = trajectory.t[j];
    const auto S = [&](double dt_) {
      return first_moment(model, scene.theta1 + omega1 * (t + dt_));
    };
    const Vec2 dp_dt = (-S(2 * h) + 16 * S(h) - 30 * S(0) + 16 * S(-h) - S(-2 * h)) / (12 * h * h);
    const Vec2 expected = weight - dp_dt;
    EXPECT_LT((trajectory.samples[j].Fsh - expected).norm(), 1e-8 * Fsh_max) << "t = " << t;
    // RA0 + RA3 is the shaking force as stored
    EXPECT_LT(
        (trajectory.samples[j].RA0 + trajectory.samples[j].RA3 - trajectory.samples[j].Fsh).norm(),
        1e-14 * Fsh_max);
  }
}

TEST(SimulateDriven, ShakingForceIsMinusMomentumRate) {
  check_shaking_force_is_momentum_rate(samples::paper_fourbar_unloaded());
}

TEST(SimulateDriven, ShakingForceIsWeightMinusMomentumRateWithGravity) {
  FourBar model = samples::paper_fourbar_unloaded();
  model.loads.gravity = Vec2(0.0, -9.81);
  check_shaking_force_is_momentum_rate(make_fourbar(model));
}

TEST(SimulateDriven, AnglesAreContinuousOverRevolutionsOfDoubleCrank) {
  const FourBar model = samples::double_crank();
  ASSERT_EQ(classify_grashof(model), GrashofClass::kDoubleCrank);
  const double omega1 = -3.0;  // clockwise, so all angles decrease
  const DrivenScene scene{.theta1 = 0.5, .omega1 = omega1, .revolutions = 3, .samples = 72};
  const Trajectory fine = simulate_driven(model, scene);
  ASSERT_TRUE(fine.ok()) << fine.message;
  ASSERT_EQ(fine.samples.size(), 216u);
  for (std::size_t j = 1; j < fine.samples.size(); ++j) {
    const FourBarState &a = fine.samples[j - 1].state, &b = fine.samples[j].state;
    EXPECT_LT(std::abs(b.theta1 - a.theta1), kPi);
    EXPECT_LT(std::abs(b.theta2 - a.theta2), kPi) << "t = " << fine.t[j];
    EXPECT_LT(std::abs(b.theta3 - a.theta3), kPi) << "t = " << fine.t[j];
  }
  // coupler and rocker turn once per crank turn, in the crank's sense
  for (std::size_t j = 0; j + 72 < fine.samples.size(); ++j) {
    const FourBarState &a = fine.samples[j].state, &b = fine.samples[j + 72].state;
    EXPECT_NEAR(b.theta2 - a.theta2, -2 * kPi, 1e-9);
    EXPECT_NEAR(b.theta3 - a.theta3, -2 * kPi, 1e-9);
  }

  // three samples per revolution (120° apart): the angles still count the turns
  DrivenScene coarse_scene = scene;
  coarse_scene.samples = 3;
  const Trajectory coarse = simulate_driven(model, coarse_scene);
  ASSERT_TRUE(coarse.ok()) << coarse.message;
  ASSERT_EQ(coarse.samples.size(), 9u);
  for (std::size_t j = 0; j < coarse.samples.size(); ++j) {
    EXPECT_NEAR(coarse.samples[j].state.theta2, fine.samples[24 * j].state.theta2, 1e-9);
    EXPECT_NEAR(coarse.samples[j].state.theta3, fine.samples[24 * j].state.theta3, 1e-9);
  }
}

TEST(SimulateDriven, CrankRockerAnglesArePeriodic) {
  const FourBar model = samples::paper_fourbar_unloaded();
  ASSERT_EQ(classify_grashof(model), GrashofClass::kCrankRocker);
  const DrivenScene scene{.theta1 = 0.0, .omega1 = 2 * kPi, .revolutions = 4, .samples = 90};
  const Trajectory trajectory = simulate_driven(model, scene);
  ASSERT_TRUE(trajectory.ok()) << trajectory.message;
  for (std::size_t j = 0; j + 90 < trajectory.samples.size(); ++j) {
    const FourBarState &a = trajectory.samples[j].state, &b = trajectory.samples[j + 90].state;
    EXPECT_NEAR(b.theta1 - a.theta1, 2 * kPi, 1e-12);
    EXPECT_NEAR(b.theta2, a.theta2, 1e-9);  // the coupler does not turn relative to the frame
    EXPECT_NEAR(b.theta3, a.theta3, 1e-9);  // the rocker rocks
  }
}

TEST(SimulateFree, AnglesAreContinuousOverRevolutionsOfDoubleCrank) {
  // free spin of a drag link without loads: several crank turns in 3 s
  const FourBar model = samples::double_crank();
  const FreeScene scene{.theta1 = 0.0, .omega1 = 12.0, .duration = 3.0, .samples = 301};
  const Trajectory trajectory = simulate_free(model, scene);
  ASSERT_TRUE(trajectory.ok()) << trajectory.message;
  const FourBarState& s0 = trajectory.samples.front().state;
  EXPECT_GT(trajectory.samples.back().state.theta1 - s0.theta1, 4 * kPi);
  for (std::size_t j = 1; j < trajectory.samples.size(); ++j) {
    const FourBarState &a = trajectory.samples[j - 1].state, &b = trajectory.samples[j].state;
    EXPECT_LT(std::abs(b.theta2 - a.theta2), kPi) << "t = " << trajectory.t[j];
    EXPECT_LT(std::abs(b.theta3 - a.theta3), kPi) << "t = " << trajectory.t[j];
    // on a drag link every link turns with the crank: the relative angles stay bounded
    EXPECT_LT(std::abs((b.theta2 - b.theta1) - (s0.theta2 - s0.theta1)), 2 * kPi);
    EXPECT_LT(std::abs((b.theta3 - b.theta1) - (s0.theta3 - s0.theta1)), 2 * kPi);
  }
  // No loads: kinetic energy is conserved to the integrator's global error. CVODE bounds the
  // error of each step by the tolerance relative to |y|, and over ~1100 steps of a fast,
  // strongly non-uniform spin (omega1 between 11.6 and 22.1 rad/s; theta1 grows to 50 rad, so
  // its relative tolerance loosens with every turn) those add up: measured 1.9e-8 of T at
  // tolerance 1e-10, 1.1e-9 at 1e-11. The bound is the worst case of steps x tolerance (δT/T ≈
  // 2 δomega1/omega1).
  const double T0 = kinetic_energy(model, s0);
  const double bound = 2.0 * static_cast<double>(trajectory.steps) * SimulateOptions{}.tolerance;
  for (const auto& s : trajectory.samples) {
    EXPECT_NEAR(kinetic_energy(model, s.state), T0, bound * T0);
  }
}

TEST(SimulateFree, NonGrashofCrankStopsAtLimitPositionKeepingSamples) {
  // The crank of this triple rocker cannot pass theta1 = acos(0.25/14) = 1.5529 rad, where the
  // coupler and rocker stretch into one line. Started at 0 with 5 rad/s and no loads it reaches
  // that limit (its reduced inertia grows without bound there, so omega1 -> 0 like the square
  // root of the remaining angle, reached in finite time); beyond it the loop cannot close.
  const FourBar model = samples::triple_rocker();
  ASSERT_EQ(classify_grashof(model), GrashofClass::kNonGrashof);
  const double limit = std::acos(0.25 / 14.0);
  const FreeScene scene{.theta1 = 0.0, .omega1 = 5.0, .duration = 5.0, .samples = 501};
  const Trajectory trajectory = simulate_free(model, scene);
  EXPECT_TRUE(trajectory.status == SimulationStatus::kSingular ||
              trajectory.status == SimulationStatus::kAssemblyFailed)
      << to_string(trajectory.status) << ": " << trajectory.message;
  EXPECT_FALSE(trajectory.ok());
  EXPECT_NE(trajectory.message.find("t = "), std::string::npos) << trajectory.message;
  EXPECT_NE(trajectory.message.find("theta1 = "), std::string::npos) << trajectory.message;
  EXPECT_EQ(trajectory.message.find('\n'), std::string::npos) << trajectory.message;
  EXPECT_EQ(trajectory.t.size(), trajectory.samples.size());
  EXPECT_GT(trajectory.samples.size(), 0u);
  EXPECT_LT(trajectory.samples.size(), 501u);
  // the samples kept lie before the limit and were reached moving towards it
  for (std::size_t j = 0; j < trajectory.samples.size(); ++j) {
    EXPECT_LT(trajectory.samples[j].state.theta1, limit);
    EXPECT_GE(trajectory.samples[j].state.omega1, 0.0);
  }
  EXPECT_GT(trajectory.samples.back().state.theta1, limit - 0.05);
}

TEST(SimulateDriven, NonGrashofCrankStopsWhereLoopCannotClose) {
  const FourBar model = samples::triple_rocker();
  const DrivenScene scene{.theta1 = 0.0, .omega1 = 1.0, .revolutions = 1, .samples = 360};
  const Trajectory trajectory = simulate_driven(model, scene);
  EXPECT_EQ(trajectory.status, SimulationStatus::kAssemblyFailed) << trajectory.message;
  // 1° steps from 0: samples up to 88° (1.536 rad) close; 89° (1.553 rad) just does not
  EXPECT_EQ(trajectory.samples.size(), 89u);
  EXPECT_EQ(trajectory.t.size(), 89u);
  EXPECT_NE(trajectory.message.find("loop cannot close at t = "), std::string::npos)
      << trajectory.message;
  EXPECT_NE(trajectory.message.find("theta1 = 1.55"), std::string::npos) << trajectory.message;
}

TEST(Simulate, InvalidScenesThrowInputError) {
  const FourBar model = samples::paper_fourbar();
  expect_input_error(
      [&] { simulate_free(model, {.theta1 = 1.0, .omega1 = 0.0, .duration = -1.0}); },
      "scene.duration must be > 0 s, got -1");
  expect_input_error(
      [&] { simulate_free(model, {.theta1 = 1.0, .omega1 = 0.0, .duration = 1.0, .samples = 1}); },
      "scene.samples must be >= 2 (and <= 1e8), got 1");
  expect_input_error([&] { simulate_free(model, {.theta1 = NAN, .omega1 = 0.0, .duration = 1.0}); },
                     "scene.theta1 must be finite, got nan");
  expect_input_error([&] { simulate_driven(model, {.theta1 = 0.0, .omega1 = 0.0}); },
                     "scene.omega1 must be finite and != 0 rad/s, got 0");
  expect_input_error(
      [&] { simulate_driven(model, {.theta1 = 0.0, .omega1 = 1.0, .revolutions = 0}); },
      "scene.revolutions must be >= 1, got 0");
  expect_input_error([&] { simulate_driven(model, {.theta1 = 0.0, .omega1 = 1.0, .samples = 0}); },
                     "scene.samples must be >= 1, got 0");

  SimulateOptions options;
  options.tolerance = 0.0;
  EXPECT_EQ(problem_text(options.validate()), "tolerance must be > 0 and < 1, got 0");
  expect_input_error([&] { simulate_free(model, kPaperFree, options); },
                     "tolerance must be > 0 and < 1, got 0");
  options = {};
  options.absolute_tolerance = -1e-3;
  EXPECT_EQ(problem_text(options.validate()), "absolute_tolerance must be > 0, got -0.001");
  options = {};
  options.max_steps = 0;
  expect_input_error([&] { simulate_driven(model, {.omega1 = 1.0}, options); },
                     "max_steps must be >= 1, got 0");
  EXPECT_EQ(problem_text(SimulateOptions{}.validate()), "");
}

TEST(Simulate, TooFewStepsStopsWithIntegratorFailure) {
  const FourBar model = samples::paper_fourbar();
  SimulateOptions options;
  options.max_steps = 20;
  const Trajectory trajectory = simulate_free(model, kPaperFree, options);
  EXPECT_EQ(trajectory.status, SimulationStatus::kIntegratorFailed) << trajectory.message;
  EXPECT_GT(trajectory.samples.size(), 0u);
  EXPECT_LT(trajectory.samples.size(), 501u);
  EXPECT_EQ(trajectory.t.size(), trajectory.samples.size());
  EXPECT_NE(trajectory.message.find("theta1 = "), std::string::npos) << trajectory.message;
}

TEST(Simulate, StatusNames) {
  EXPECT_STREQ(to_string(SimulationStatus::kNotRun), "not-run");
  EXPECT_STREQ(to_string(SimulationStatus::kCompleted), "completed");
  EXPECT_STREQ(to_string(SimulationStatus::kAssemblyFailed), "assembly-failed");
  EXPECT_STREQ(to_string(SimulationStatus::kSingular), "singular");
  EXPECT_STREQ(to_string(SimulationStatus::kIntegratorFailed), "integrator-failed");
  EXPECT_FALSE(Trajectory{}.ok());
}

TEST(Metrics, MatchHandComputation) {
  Trajectory trajectory;
  DynamicsSample a, b, c;
  // the table's Fsh and Msh are the inertial parts; the totals (weights, loads) come after
  a.Fsh_inertial = Vec2(3, 4);   // |Fsh| = 5
  b.Fsh_inertial = Vec2(0, 0);   // 0
  c.Fsh_inertial = Vec2(-1, 0);  // 1
  a.Msh_inertial = -2, b.Msh_inertial = 1, c.Msh_inertial = 2;
  a.Fsh = Vec2(3, -6), b.Fsh = Vec2(0, -10), c.Fsh = Vec2(-1, -10);
  a.Msh = 0, b.Msh = 4, c.Msh = -1;
  a.FA1 = Vec2(0, 2), b.FA2 = Vec2(-4, 0);
  a.tau = 0, b.tau = -3, c.tau = 0;
  a.RA0 = Vec2(1, 0), b.RA0 = Vec2(0, -6), c.RA0 = Vec2(2, 2);
  a.RA3 = Vec2(0, 7), b.RA3 = Vec2(-5, 0), c.RA3 = Vec2(1, 1);
  trajectory.samples = {a, b, c};
  trajectory.t = {0.0, 0.1, 0.2};
  const Metrics m = metrics(trajectory);
  EXPECT_DOUBLE_EQ(m.Fsh_rms, std::sqrt((25.0 + 0.0 + 1.0) / 3.0));
  EXPECT_DOUBLE_EQ(m.Fsh_max, 5.0);
  EXPECT_DOUBLE_EQ(m.Msh_rms, std::sqrt((4.0 + 1.0 + 4.0) / 3.0));
  EXPECT_DOUBLE_EQ(m.Msh_max, 2.0);
  EXPECT_DOUBLE_EQ(m.tau_rms, std::sqrt(9.0 / 3.0));
  EXPECT_DOUBLE_EQ(m.tau_max, 3.0);
  EXPECT_DOUBLE_EQ(m.RA0_max, 6.0);
  EXPECT_DOUBLE_EQ(m.RA3_max, 7.0);
  EXPECT_DOUBLE_EQ(m.Fsh_total_rms, std::sqrt((45.0 + 100.0 + 101.0) / 3.0));
  EXPECT_DOUBLE_EQ(m.Fsh_total_max, std::sqrt(101.0));
  EXPECT_DOUBLE_EQ(m.Msh_total_rms, std::sqrt((0.0 + 16.0 + 1.0) / 3.0));
  EXPECT_DOUBLE_EQ(m.Msh_total_max, 4.0);
  EXPECT_DOUBLE_EQ(m.FA1_max, 2.0);
  EXPECT_DOUBLE_EQ(m.FA2_max, 4.0);

  const Metrics none = metrics(Trajectory{});
  EXPECT_EQ(none.Fsh_rms, 0.0);
  EXPECT_EQ(none.RA3_max, 0.0);
}

}  // namespace
}  // namespace bd::core
