// Self-tests of the referee's free runs: exact references (a pendulum by a very fine RK4 in long
// double, a gear pair in closed form), energy-work balances, Newton–Euler of every body with the
// reported forces, and convergence with the tolerance.
//
// Accuracy claimed for free runs at the default tolerance (1e-15): samples correct to 1e-11
// relative (positions and angles to the mechanism's size and 1 rad, velocities and
// accelerations to their largest magnitude over the run). The tests below bound the error by
// that claim; what they actually measure is printed (typically 1e-13 .. 1e-12).
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "tests/reference/planar/referee.hpp"
#include "tests/reference/planar/selftest_checks.hpp"
#include "tests/reference/planar/selftest_mechanisms.hpp"

namespace bd::referee {
namespace {

using namespace selftest;

constexpr double kClaim = 1e-11;  // the accuracy claimed for free runs (see the top)

std::vector<double> linspace(double a, double b, int n) {
  std::vector<double> t(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) t[static_cast<std::size_t>(i)] = a + (b - a) * i / (n - 1);
  return t;
}

// Largest difference between two runs, each quantity relative to its scale over run b:
// positions to the largest |com|, angles to max(1 rad, largest |angle|), velocities, angular
// velocities, accelerations and angular accelerations to their largest magnitudes.
double state_difference(const std::vector<Sample>& a, const std::vector<Sample>& b) {
  double pos = 0, ang = 1, vel = 0, w = 0, acc = 0, al = 0;
  for (const Sample& s : b)
    for (const BodyState& x : s.bodies) {
      pos = std::max(pos, x.com.norm());
      ang = std::max(ang, std::abs(x.angle));
      vel = std::max(vel, x.velocity.norm());
      w = std::max(w, std::abs(x.omega));
      acc = std::max(acc, x.acceleration.norm());
      al = std::max(al, std::abs(x.alpha));
    }
  double d = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    for (std::size_t k = 0; k < a[i].bodies.size(); ++k) {
      const BodyState &x = a[i].bodies[k], &y = b[i].bodies[k];
      d = std::max({d, (x.com - y.com).norm() / pos, std::abs(x.angle - y.angle) / ang,
                    (x.velocity - y.velocity).norm() / vel, std::abs(x.omega - y.omega) / w,
                    (x.acceleration - y.acceleration).norm() / acc,
                    std::abs(x.alpha - y.alpha) / al});
    }
  return d;
}

double energy_scale(const std::vector<Sample>& run) {
  double scale = 0;
  for (const Sample& s : run)
    scale = std::max({scale, std::abs(total_energy(s)), s.kinetic_energy, std::abs(s.input_work),
                      s.damper_work, std::abs(s.applied_work)});
  return scale;
}

// E(t) - E(0) against the integrated work W_in - W_damp + W_app, relative to the largest of
// |E|, the kinetic energy and the works along the run.
double energy_work_violation(const std::vector<Sample>& run) {
  const double e0 = total_energy(run.front()), scale = energy_scale(run);
  double worst = 0;
  for (const Sample& s : run) {
    const double balance = total_energy(s) - e0 - (s.input_work - s.damper_work + s.applied_work);
    worst = std::max(worst, std::abs(balance) / scale);
  }
  return worst;
}

// The same balance with the work from the samples' powers by the composite Boole rule (equally
// spaced samples, count = 4k + 1; error ~ (omega h)^6 relative): independent of the
// integrator's quadratures.
double energy_boole_violation(const std::vector<Sample>& run) {
  const double scale = energy_scale(run);
  auto p = [&](std::size_t i) {
    return run[i].input_power - run[i].damper_power + run[i].applied_power;
  };
  double work = 0, worst = 0;
  for (std::size_t i = 4; i < run.size(); i += 4) {
    const double h = run[i].t - run[i - 1].t;
    work += 2 * h / 45 * (7 * p(i - 4) + 32 * p(i - 3) + 12 * p(i - 2) + 32 * p(i - 1) + 7 * p(i));
    const double balance = total_energy(run[i]) - total_energy(run[0]) - work;
    worst = std::max(worst, std::abs(balance) / scale);
  }
  return worst;
}

// Newton–Euler, power balance and shaking split at every sample (see selftest_checks.hpp);
// the forces of a free run are recovered to rounding, as in driven scenes.
void check_balances(const Mechanism& m, const std::vector<Sample>& run) {
  double ne = 0, power = 0, split = 0;
  for (const Sample& s : run) {
    ne = std::max(ne, newton_euler_violation(m, s));
    power = std::max(power, power_balance_violation(m, s));
    split = std::max(split, shaking_split_violation(m, s));
  }
  EXPECT_LT(ne, 1e-10);
  EXPECT_LT(power, 1e-10);
  EXPECT_LT(split, 1e-10);
}

// Runs at the default tolerance, at half of it and at a tenth (the reference); checks the
// claimed accuracy on both differences and prints them.
std::vector<Sample> check_convergence(const char* name, const Mechanism& m,
                                      const std::vector<double>& rates, double duration,
                                      const std::vector<double>& times) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto run = free_run(m, rates, duration, times);
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const FreeRunStats stats = last_free_run_stats();
  const auto half = free_run(m, rates, duration, times, 0.5e-15);
  const auto reference = free_run(m, rates, duration, times, 1e-16);
  const double d_half = state_difference(run, half), d_ref = state_difference(run, reference);
  EXPECT_LT(d_half, kClaim) << name;
  EXPECT_LT(d_ref, kClaim) << name;
  std::printf(
      "    %s: tol/2 %.1e, tol/10 %.1e; %ld steps, %ld rejected, %ld evaluations, %.0f ms\n", name,
      d_half, d_ref, stats.steps, stats.rejected, stats.evaluations, 1e3 * secs);
  return run;
}

// Pendulum: body pinned at the origin, centre of mass at distance d, theta from the downward
// vertical: I_O theta'' = -m g d sin theta, I_O = I + m d^2. Reference: classical RK4 in long
// double with h = 1e-4 s (local error ~ (omega_n h)^5 / 120 ~ 1e-19, global ~ 1e-15).
TEST(PlanarRefereeFree, PendulumMatchesFineRk4) {
  const double m = 1.3, I = 0.02, d = 0.25, g = 9.81, th0 = 1.0, w0 = 2.0;
  Mechanism mech;
  mech.bodies = {Body{"bob", m, I, polar(d, th0 - std::acos(-1.0) / 2), {}}};
  mech.pins = {{"O", kGround, 0, {0, 0}}};
  mech.inputs = {AngleInput{0}};
  mech.gravity = {0, -g};
  const auto times = linspace(0, 2, 41);
  const auto run = free_run(mech, {w0}, 2.0, times);
  using LD = long double;
  const LD k = LD(m) * g * d / (LD(I) + LD(m) * d * d);
  auto f = [&](LD th, LD w) { return std::pair<LD, LD>{w, -k * std::sin(th)}; };
  LD th = th0, w = w0;
  const LD h = 1e-4L;
  double worst = 0;
  for (std::size_t i = 0; i < times.size(); ++i) {
    if (i > 0) {
      for (int s = 0; s < 500; ++s) {  // 0.05 s between samples
        const auto [a1, b1] = f(th, w);
        const auto [a2, b2] = f(th + h / 2 * a1, w + h / 2 * b1);
        const auto [a3, b3] = f(th + h / 2 * a2, w + h / 2 * b2);
        const auto [a4, b4] = f(th + h * a3, w + h * b3);
        th += h / 6 * (a1 + 2 * a2 + 2 * a3 + a4);
        w += h / 6 * (b1 + 2 * b2 + 2 * b3 + b4);
      }
    }
    const BodyState& b = run[i].bodies[0];
    worst = std::max({worst, std::abs(b.angle - static_cast<double>(th - th0)),
                      std::abs(b.omega - static_cast<double>(w)) / 10,
                      std::abs(b.alpha + static_cast<double>(k * std::sin(th))) / 50});
  }
  // relative to 1 rad, 10 rad/s and 50 rad/s^2 (the motion's scales)
  EXPECT_LT(worst, kClaim);
  std::printf("    pendulum vs RK4: %.1e\n", worst);
  check_balances(mech, run);
}

// Gear pair under a torque tau(t) = 0.3 + 0.1 sin 4t on disc a: with I_eff = I_a + I_b (ra/rb)^2,
// omega_a = w0 + (0.3 t + 0.025 (1 - cos 4t)) / I_eff,
// phi_a = w0 t + (0.15 t^2 + 0.025 (t - sin(4t) / 4)) / I_eff, omega_b = -(ra/rb) omega_a; the
// mesh force on b turns it: (pitch - pivot_b) x F = I_b alpha_b.
TEST(PlanarRefereeFree, GearPairMatchesClosedForm) {
  const double ra = 0.03, rb = 0.05, Ia = 2e-3, Ib = 7e-3, w0 = 5;
  Mechanism m = gear_pair(ra, rb, Ia, Ib);
  m.input_efforts = {[](double t) { return 0.3 + 0.1 * std::sin(4 * t); }};
  const double Ieff = Ia + Ib * (ra / rb) * (ra / rb);
  const auto run = free_run(m, {w0}, 1.5, linspace(0, 1.5, 31));
  for (const Sample& s : run) {
    const double t = s.t;
    const double w = w0 + (0.3 * t + 0.025 * (1 - std::cos(4 * t))) / Ieff;
    const double phi = w0 * t + (0.15 * t * t + 0.025 * (t - std::sin(4 * t) / 4)) / Ieff;
    EXPECT_NEAR(s.bodies[0].angle, phi, 1e-12 * std::max(1.0, std::abs(phi)));
    EXPECT_NEAR(s.bodies[0].omega, w, 1e-12 * std::abs(w));
    EXPECT_NEAR(s.bodies[1].omega, -ra / rb * w, 1e-12 * std::abs(w));
    const double torque_b =
        cross(s.gear_forces[0].point - Vec2(ra + rb, 0), s.gear_forces[0].force);
    EXPECT_NEAR(torque_b, Ib * s.bodies[1].alpha, 1e-12);
    EXPECT_NEAR(s.input_efforts[0], 0.3 + 0.1 * std::sin(4 * t), 1e-15);
  }
  check_balances(m, run);
}

Mechanism motor_four_bar() {
  const FourBar fb;
  Mechanism m = fb.build();
  m.gravity = {0, -9.81};
  m.springs = {{kGround, 2, {0.05, 0.3}, fb.A3() + 0.8 * (fb.A2() - fb.A3()), 300, 0.12, 3.0}};
  m.forces = {{1, fb.A1() + 0.3 * (fb.A2() - fb.A1()),
               [](double t) { return Vec2(3 * std::cos(5 * t), 2 + std::sin(3 * t)); }}};
  m.moments = {{2, [](double t) { return 0.4 * std::sin(2 * t); }}};
  m.input_efforts = {[](double) { return 0.5; }};
  return m;
}

TEST(PlanarRefereeFree, FourBarWithMotorSpringDamper) {
  const Mechanism m = motor_four_bar();
  const auto run = check_convergence("four-bar", m, {10.0}, 1.0, linspace(0, 1, 201));
  EXPECT_LT(energy_work_violation(run), 1e-10);  // the works are integrated with the state
  check_balances(m, run);
  // the balance with the work from the sampled powers needs dense samples: up to 0.4 s the
  // links turn at < 40 rad/s, so with h = 2.5e-4 s Boole's error is ~ (omega h)^6 ~ 1e-12
  const auto dense = free_run(m, {10.0}, 0.4, linspace(0, 0.4, 1601));
  const double integrated = energy_work_violation(dense), boole = energy_boole_violation(dense);
  EXPECT_LT(integrated, 1e-10);
  EXPECT_LT(boole, 1e-9);
  std::printf("    energy-work balance: integrated %.1e, Boole %.1e\n", integrated, boole);
}

// A violent case (torque 2 N m, light damping: the crank reaches 100 rad/s, other links 200).
TEST(PlanarRefereeFree, FourBarSpinningUp) {
  Mechanism m = motor_four_bar();
  m.input_efforts = {[](double) { return 2.0; }};
  m.springs[0].damping = 1.5;
  const auto run = check_convergence("four-bar spinning up", m, {10.0}, 1.0, linspace(0, 1, 101));
  EXPECT_LT(energy_work_violation(run), 1e-10);
}

TEST(PlanarRefereeFree, SliderCrankConservesEnergy) {
  Mechanism m = SliderCrank().build();
  m.gravity = {0, -9.81};
  const auto run = check_convergence("slider-crank", m, {30.0}, 1.0, linspace(0, 1, 201));
  const double e = energy_work_violation(run);
  EXPECT_LT(e, 1e-12);  // conservative: E constant; observed ~1e-14
  std::printf("    energy drift %.1e\n", e);
  check_balances(m, run);
}

// The block slides on the rotating rocker (a moving line).
TEST(PlanarRefereeFree, QuickReturnConservesEnergy) {
  Mechanism m = QuickReturn().build();
  m.gravity = {0, -9.81};
  const auto run = check_convergence("quick return", m, {15.0}, 1.0, linspace(0, 1, 201));
  const double e = energy_work_violation(run);
  EXPECT_LT(e, 1e-12);
  std::printf("    energy drift %.1e\n", e);
  check_balances(m, run);
}

// 2 degrees of freedom: both ground links are inputs with efforts; spring-damper and gravity.
TEST(PlanarRefereeFree, FiveBarTwoInputs) {
  const FiveBar fv;
  Mechanism m = fv.build();
  m.gravity = {0, -9.81};
  m.springs = {{kGround, 1, {0.1, 0.45}, fv.A2(), 400, 0.1, 0.5}};
  m.input_efforts = {[](double t) { return 0.05 * std::sin(3 * t); }, [](double) { return -0.02; }};
  const auto run = check_convergence("five-bar", m, {2.0, -1.0}, 1.0, linspace(0, 1, 401));
  const double integrated = energy_work_violation(run), boole = energy_boole_violation(run);
  EXPECT_LT(integrated, 1e-10);
  EXPECT_LT(boole, 1e-9);
  std::printf("    energy-work balance: integrated %.1e, Boole %.1e\n", integrated, boole);
  check_balances(m, run);
}

// A slider driven by a force: the slide input with a piston force as its effort.
TEST(PlanarRefereeFree, SliderCrankDrivenByPistonForce) {
  Mechanism m = SliderCrank().build(true);
  m.gravity = {0, -9.81};
  m.input_efforts = {[](double t) { return -40.0 * (1 + t); }};  // pushes towards the crank
  const auto run = check_convergence("piston force", m, {-0.3}, 0.04, linspace(0, 0.04, 81));
  EXPECT_LT(energy_work_violation(run), 1e-10);
  EXPECT_NEAR(run.back().input_efforts[0], -40.0 * 1.04, 1e-12);
  check_balances(m, run);
}

// Free with the slide as the coordinate, the piston reaches dead centre: reported with the time.
TEST(PlanarRefereeFree, SingularPositionIsReported) {
  SliderCrank sc;
  sc.e = 0;
  const Mechanism m = sc.build(true);
  try {
    free_run(m, {1.0}, 0.5, {0.5});
    FAIL() << "no exception";
  } catch (const std::domain_error& e) {
    EXPECT_NE(std::string(e.what()).find("t = "), std::string::npos) << e.what();
    std::printf("    %s\n", e.what());
  }
}

// A whole second of a sprung six-bar under gravity and a drive torque: energy and work balance,
// and every body's momentum balance. (How long it takes is a benchmark's business, not a test's:
// a time limit here failed under the sanitizers, 6 s against 0.2 s in the Release build.)
TEST(PlanarRefereeFree, SixBarSecondBalancesEnergyAndMomentum) {
  const SixBar sb;
  Mechanism m = sb.build();
  m.gravity = {0, -9.81};
  m.springs = {{kGround, 4, {0.6, 0.0}, sb.D(), 200, 0.2, 0.5}};
  m.input_efforts = {[](double) { return 0.3; }};
  const auto run = free_run(m, {8.0}, 1.0, linspace(0, 1, 201));
  EXPECT_LT(energy_work_violation(run), 1e-10);
  check_balances(m, run);
}

}  // namespace
}  // namespace bd::referee
