// Self-tests of the planar referee against closed forms, power balances and convergence.
#include <gtest/gtest.h>

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

std::vector<double> linspace(double a, double b, int n) {
  std::vector<double> t(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) t[static_cast<std::size_t>(i)] = a + (b - a) * i / (n - 1);
  return t;
}

// Piston position, velocity and acceleration of the crank-driven slider-crank against
//   x = r cos th + D,  D = sqrt(l^2 - s^2),  s = r sin th - e,  s' = r cos th, s'' = -r sin th
//   x'  = -r sin th - s s' / D
//   x'' = -r cos th - (s'^2 + s s'') / D - s^2 s'^2 / D^3
// with th = th0 + w t: dx/dt = x' w, d2x/dt2 = x'' w^2.
TEST(PlanarReferee, SliderCrankPistonMatchesClosedForm) {
  const SliderCrank sc;
  const Mechanism m = sc.build();
  const double w = 37.0;
  const auto samples = driven(m, {w}, 0.0, linspace(0, 2 * std::acos(-1.0) / w, 361));
  double worst = 0;
  for (const Sample& s : samples) {
    const double th = sc.theta0 + w * s.t;
    const double sn = sc.r * std::sin(th) - sc.e, sp = sc.r * std::cos(th),
                 spp = -sc.r * std::sin(th);
    const double D = std::sqrt(sc.l * sc.l - sn * sn);
    const double x = sc.r * std::cos(th) + D;
    const double x1 = -sc.r * std::sin(th) - sn * sp / D;
    const double x2 =
        -sc.r * std::cos(th) - (sp * sp + sn * spp) / D - sn * sn * sp * sp / (D * D * D);
    const PointMotion B = point_motion(m, s, 1, sc.B());
    // 1e-12 relative to the scales r, r w, r w^2 (the closed form itself is good to ~1e-15)
    EXPECT_NEAR(B.p.x(), x, 1e-12 * sc.r);
    EXPECT_NEAR(B.p.y(), sc.e, 1e-12 * sc.r);
    EXPECT_NEAR(B.v.x(), x1 * w, 1e-12 * sc.r * w);
    EXPECT_NEAR(B.a.x(), x2 * w * w, 1e-12 * sc.r * w * w);
    EXPECT_NEAR(B.a.y(), 0, 1e-12 * sc.r * w * w);
    worst = std::max(worst, std::abs(B.a.x() - x2 * w * w) / (sc.r * w * w));
  }
  RecordProperty("worst_relative_acceleration_error", std::to_string(worst));
}

// The four-bar with every kind of load: gravity, a time-varying force on the coupler, a moment
// on the rocker, a spring-damper from the frame to the rocker and one between crank and coupler.
Mechanism loaded_four_bar(const FourBar& fb) {
  Mechanism m = fb.build();
  m.gravity = {0.3, -9.81};
  m.forces = {{1, fb.A1() + 0.3 * (fb.A2() - fb.A1()) + Vec2(0, 0.05),
               [](double t) { return Vec2(3 * std::cos(5 * t), 2 + std::sin(3 * t)); }}};
  m.moments = {{2, [](double t) { return 0.4 * std::sin(2 * t); }}};
  m.springs = {{kGround, 2, {0.05, 0.3}, fb.A3() + 0.8 * (fb.A2() - fb.A3()), 300, 0.12, 1.5},
               {0, 1, fb.A1(), fb.A1() + 0.5 * (fb.A2() - fb.A1()), 150, 0.1, 0.7}};
  return m;
}

// Sweeps a driven scene and checks, at every sample: Newton–Euler of every body with the
// reported forces, the power balance, and the inertial + static split of the shaking force and
// moment. The referee solves these equations to rounding (condition numbers of ~1e2..1e3
// times 1e-16), so 1e-10 relative to the largest term leaves a wide margin.
void check_driven_balances(const Mechanism& m, const std::vector<Sample>& samples) {
  double ne = 0, power = 0, split = 0;
  for (const Sample& s : samples) {
    ne = std::max(ne, newton_euler_violation(m, s));
    power = std::max(power, power_balance_violation(m, s));
    split = std::max(split, shaking_split_violation(m, s));
  }
  EXPECT_LT(ne, 1e-10);
  EXPECT_LT(power, 1e-10);
  EXPECT_LT(split, 1e-10);
  std::printf("    Newton-Euler %.1e, power balance %.1e, shaking split %.1e\n", ne, power, split);
}

TEST(PlanarReferee, DrivenFourBarBalances) {
  const FourBar fb;
  const Mechanism m = loaded_four_bar(fb);
  const double w = 12.0;
  const auto samples = driven(m, {w}, 0.1, linspace(0, 2 * std::acos(-1.0) / w, 361));
  check_driven_balances(m, samples);
  // the drive torque from the power balance alone
  for (const Sample& s : samples) {
    const double tau =
        (kinetic_energy_rate(m, s) - s.applied_power - s.gravity_power - s.spring_power) / w;
    EXPECT_NEAR(s.input_efforts[0], tau, 1e-10 * std::max(1.0, std::abs(tau)));
  }
}

TEST(PlanarReferee, DrivenFourBarMatchesLoopClosure) {
  const FourBar fb;
  const Mechanism m = fb.build();
  const double w = 5.0;
  for (const Sample& s : driven(m, {w}, 0.0, linspace(-0.3, 1.0, 53))) {
    const double th = fb.theta0 + w * s.t;
    const Vec2 A1 = polar(fb.a, th), A2 = circle_intersection(A1, fb.b, fb.A3(), fb.c, 1);
    EXPECT_LT((point_motion(m, s, 1, fb.A1()).p - A1).norm(), 1e-13);
    EXPECT_LT((point_motion(m, s, 1, fb.A2()).p - A2).norm(), 1e-13);
    EXPECT_LT((point_motion(m, s, 2, fb.A2()).p - A2).norm(), 1e-13);
    EXPECT_NEAR(s.input_values[0], w * s.t, 1e-14);
    EXPECT_NEAR(s.input_rates[0], w, 1e-13);
    EXPECT_NEAR(s.input_accelerations[0], 0, 1e-11);
  }
}

// Quick return: rocker angle psi = atan2(r sin th + h, r cos th) about Q = (0, -h). With
// rho^2 = r^2 + h^2 + 2 r h sin th:  psi' = (r^2 + r h sin th) / rho^2,
// psi'' = r h cos th (h^2 - r^2) / rho^4 (derivatives in th; d/dt = w d/dth, w constant).
TEST(PlanarReferee, QuickReturnRockerMatchesClosedForm) {
  const QuickReturn qr;
  const Mechanism m = qr.build();
  const double w = 9.0;
  const double psi0 = std::atan2(qr.r * std::sin(qr.theta0) + qr.h, qr.r * std::cos(qr.theta0));
  double unwrap = 0, last = psi0;
  for (const Sample& s : driven(m, {w}, 0.0, linspace(0, 2 * std::acos(-1.0) / w, 181))) {
    const double th = qr.theta0 + w * s.t;
    const double rho2 = qr.r * qr.r + qr.h * qr.h + 2 * qr.r * qr.h * std::sin(th);
    double psi = std::atan2(qr.r * std::sin(th) + qr.h, qr.r * std::cos(th)) + unwrap;
    if (psi - last > 3) psi -= 2 * std::acos(-1.0), unwrap -= 2 * std::acos(-1.0);
    if (psi - last < -3) psi += 2 * std::acos(-1.0), unwrap += 2 * std::acos(-1.0);
    last = psi;
    const double d1 = (qr.r * qr.r + qr.r * qr.h * std::sin(th)) / rho2;
    const double d2 = qr.r * qr.h * std::cos(th) * (qr.h * qr.h - qr.r * qr.r) / (rho2 * rho2);
    EXPECT_NEAR(s.bodies[1].angle, psi - psi0, 1e-12);
    EXPECT_NEAR(s.bodies[1].omega, d1 * w, 1e-12 * w);
    EXPECT_NEAR(s.bodies[1].alpha, d2 * w * w, 1e-12 * w * w);
  }
  check_driven_balances(m, driven(m, {w}, 0.0, linspace(0, 1, 50)));
}

// A slide input on a moving line (the block sliding along the rocker): the drive force and
// all joint forces satisfy every body's Newton–Euler equations and the power balance.
TEST(PlanarReferee, QuickReturnDrivenBySlideBalances) {
  const QuickReturn qr;
  Mechanism m = qr.build(true);
  m.gravity = {0, -9.81};
  m.moments = {{0, [](double t) { return 0.1 + 0.05 * t; }}};
  const auto samples = driven(m, {0.05}, 0.0, linspace(-0.3, 0.6, 91));
  check_driven_balances(m, samples);
  for (const Sample& s : samples) {
    const double rho = (point_motion(m, s, 0, qr.A()).p - qr.Q()).norm();
    EXPECT_NEAR(rho - (qr.A() - qr.Q()).norm(), 0.05 * s.t, 1e-14);
  }
}

// Driving the slider-crank from the piston: the crank follows x(th(t)) = x0 + v t, and the
// crank rate is v / x'(th).
TEST(PlanarReferee, SliderCrankDrivenFromPiston) {
  const SliderCrank sc;
  Mechanism m = sc.build(true);
  m.gravity = {0, -9.81};
  const double v = -0.4;
  const auto samples = driven(m, {v}, 0.0, linspace(0, 0.15, 61));
  check_driven_balances(m, samples);
  for (const Sample& s : samples) {
    const double th = sc.theta0 + s.bodies[0].angle;
    EXPECT_NEAR(sc.x(th), sc.B().x() + v * s.t, 1e-13);
    const double sn = sc.r * std::sin(th) - sc.e;
    const double x1 =
        -sc.r * std::sin(th) - sn * sc.r * std::cos(th) / std::sqrt(sc.l * sc.l - sn * sn);
    EXPECT_NEAR(s.bodies[0].omega, v / x1, 1e-11 * std::abs(v / x1));
  }
}

// Dead centre (crank and rod aligned, x = r + l with e = 0) cannot be driven from the piston:
// the referee names the time.
TEST(PlanarReferee, SingularPositionIsReported) {
  SliderCrank sc;
  sc.e = 0;
  const Mechanism m = sc.build(true);
  const double v = 0.2, t_dead = (sc.r + sc.l - sc.B().x()) / v;
  try {
    driven(m, {v}, 0.0, {0.0, 0.5 * t_dead, t_dead});
    FAIL() << "no exception";
  } catch (const std::domain_error& e) {
    EXPECT_NE(std::string(e.what()).find("t = "), std::string::npos) << e.what();
    std::printf("    %s\n", e.what());
  }
  EXPECT_THROW(driven(m, {v}, 0.0, {1.2 * t_dead}), std::domain_error);  // beyond: no closure
}

TEST(PlanarReferee, AssembleFourBar) {
  const FourBar fb;
  const Mechanism m = fb.build();
  for (double v : {-2.0, 0.3, 3.5}) {
    const auto poses = assemble(m, {v});
    const Vec2 A1 = polar(fb.a, fb.theta0 + v),
               A2 = circle_intersection(A1, fb.b, fb.A3(), fb.c, 1);
    const double coupler0 = std::atan2((fb.A2() - fb.A1()).y(), (fb.A2() - fb.A1()).x());
    const double rocker0 = std::atan2((fb.A2() - fb.A3()).y(), (fb.A2() - fb.A3()).x());
    EXPECT_NEAR(poses[0].angle, v, 1e-15);
    EXPECT_NEAR(
        std::remainder(poses[1].angle - (std::atan2((A2 - A1).y(), (A2 - A1).x()) - coupler0),
                       2 * std::acos(-1.0)),
        0, 1e-13);
    EXPECT_NEAR(std::remainder(
                    poses[2].angle - (std::atan2((A2 - fb.A3()).y(), (A2 - fb.A3()).x()) - rocker0),
                    2 * std::acos(-1.0)),
                0, 1e-13);
  }
}

TEST(PlanarReferee, InvalidMechanismsAreRejected) {
  Mechanism m = FourBar().build();
  m.inputs.push_back(AngleInput{2});  // two inputs on a 1-DOF mechanism
  EXPECT_THROW(assemble(m, {0, 0}), std::domain_error);
  m = SliderCrank().build();
  m.sliders[0].point += Vec2(0, 0.001);  // the described configuration does not close
  EXPECT_THROW(assemble(m, {0}), std::domain_error);
  SliderCrank sc;
  sc.e = 0;
  sc.theta0 = 0;  // described at dead centre, driven from the piston: rank deficient
  EXPECT_THROW(assemble(sc.build(true), {0}), std::domain_error);
}

TEST(PlanarReferee, GearPairDriven) {
  const double ra = 0.03, rb = 0.05;
  const Mechanism m = gear_pair(ra, rb, 2e-3, 7e-3);
  for (const Sample& s : driven(m, {20.0}, 0.0, linspace(0, 1, 11))) {
    EXPECT_NEAR(s.bodies[1].omega, -20.0 * ra / rb, 1e-13);
    EXPECT_NEAR(s.bodies[1].angle, -20.0 * s.t * ra / rb, 1e-13);
  }
  const Mechanism equal = gear_pair(0.04, 0.04, 2e-3, 7e-3);
  for (const Sample& s : driven(equal, {20.0}, 0.0, linspace(0, 1, 11)))
    EXPECT_NEAR(s.bodies[1].omega, -s.bodies[0].omega, 1e-13);
}

// A counter-rotating disc (as in shaking-moment balancing) on a frame shaft at C, geared to the
// crank with ratio -1 (pitch point midway between A0 and C): the gear's mesh force, the shaft and
// crank bearing forces satisfy every body's Newton–Euler equations, and the disc turns at -omega.
TEST(PlanarReferee, DrivenFourBarWithCounterRotatingDisc) {
  const FourBar fb;
  Mechanism m = loaded_four_bar(fb);
  const Vec2 C{-0.06, -0.08};
  m.bodies.push_back(Body{"disc", 0.7, 4e-4, C, {}});
  m.pins.push_back({"disc shaft", kGround, 3, C});
  m.gears.push_back({"disc mesh", 0, 3, {0, 0}, C, 0.5 * C});
  const double w = 15.0;
  const auto samples = driven(m, {w}, 0.0, linspace(0, 2 * std::acos(-1.0) / w, 121));
  check_driven_balances(m, samples);
  for (const Sample& s : samples) {
    EXPECT_NEAR(s.bodies[3].omega, -w, 1e-12 * w);
    EXPECT_NEAR(s.bodies[3].angle, -w * s.t, 1e-12);
    EXPECT_NEAR(s.gear_forces[0].force.dot(C), 0, 1e-12 * s.gear_forces[0].force.norm());
  }
}

// A sprung six-bar under gravity driven over a revolution: every body's balances. (How long it
// takes is a benchmark's business, not a test's: a time limit here is the class of check that
// failed under the sanitizers in the free self-test.)
TEST(PlanarReferee, SixBarRevolutionBalances) {
  SixBar sb;
  Mechanism m = sb.build();
  m.gravity = {0, -9.81};
  m.springs = {{kGround, 4, {0.6, 0.0}, sb.D(), 200, 0.2, 0.5}};
  const double w = 10.0;
  const auto samples = driven(m, {w}, 0.0, linspace(0, 2 * std::acos(-1.0) / w, 360));
  check_driven_balances(m, samples);
}

}  // namespace
}  // namespace bd::referee
