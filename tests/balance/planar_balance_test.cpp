// Shaking-force balance of any planar linkage (balance/planar.hpp), checked by other routes:
//  - the regressors times the linkage's mass parameters against the general engine's inertial
//    shaking force and moment (computed there from each link's centre-of-mass acceleration),
//    and the momentum regressor against the linear momentum summed body by body;
//  - on four-bars, the counterweights against the four-bar's own synthesis from eq. 57;
//  - balanced six-bars against the independent referee (Newton-Euler in absolute coordinates),
//    driven and free: no inertial shaking force left;
//  - a slider-crank, which counterweights on the crank cannot balance: the message, and the
//    least-squares design against the first Fourier coefficient of the engine's shaking force.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdio>
#include <numbers>
#include <random>
#include <string>

#include "balance/counterweight.hpp"
#include "balance/planar.hpp"
#include "core/fourbar/samples.hpp"
#include "core/input_error.hpp"
#include "core/planar/from_fourbar.hpp"
#include "core/planar/simulate.hpp"
#include "tests/support/balance_motion.hpp"
#include "tests/support/planar_glue.hpp"
#include "tests/support/planar_mechanisms.hpp"

namespace bd::testing::planar {
namespace {

// a driven revolution of the first input (and the others at their own speeds) on the engine
// RMS of the inertial shaking force's magnitude over a table's rows
double rms_inertial_force(const core::Series& t) {
  const std::vector<double> a = t.column_values("Fshx_inertial"),
                            b = t.column_values("Fshy_inertial");
  EXPECT_FALSE(a.empty());
  double s = 0;
  for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * a[i] + b[i] * b[i];
  return std::sqrt(s / static_cast<double>(a.size()));
}

std::vector<bp::LinkCounterweightSpec> on_grounded_links(const cp::Linkage& l) {
  std::vector<bp::LinkCounterweightSpec> out;
  for (std::size_t k = 0; k < l.links.size(); ++k) {
    for (int n : l.links[k].nodes) {
      if (l.nodes[static_cast<std::size_t>(n)].ground) {
        out.push_back({static_cast<int>(k), {}});
        break;
      }
    }
  }
  return out;
}

// The regressors reproduce the engine's inertial parts (-Σ m a from the centres of mass, -dH/dt
// from each link's centre of mass and its inertia) at every sample: round-off apart.
TEST(PlanarBalance, RegressorsReproduceTheEnginesInertialShakingForceAndMoment) {
  Rng rng(301);
  double worst_force = 0, worst_moment = 0, worst_momentum = 0;
  for (int i = 0; i < 24; ++i) {
    const cp::Linkage l = i % 3 == 0   ? slider_crank(rng, coin(rng))
                          : i % 3 == 1 ? six_bar_or_retry(rng, coin(rng))
                                       : quick_return(rng, coin(rng), coin(rng));
    const cp::Trajectory tr = revolution(l, {uniform(rng, 5, 30)}, 60);
    ASSERT_TRUE(tr.ok()) << tr.message;
    const bp::Kinematics k = kinematics_of(l, tr);
    const Eigen::VectorXd theta = bp::Parameters::of(l);
    const Eigen::VectorXd F = bp::shaking_force_regressor(l, k) * theta;
    const Eigen::VectorXd M = bp::shaking_moment_regressor(l, k) * theta;
    const std::vector<double> fx = tr.table.column_values("Fshx_inertial"),
                              fy = tr.table.column_values("Fshy_inertial"),
                              mz = tr.table.column_values("Msh_inertial");
    const double f_scale = rms_inertial_force(tr.table);
    double m_scale = 0;
    for (double v : mz) m_scale = std::max(m_scale, std::abs(v));
    for (std::size_t r = 0; r < fx.size(); ++r) {
      const double df = std::hypot(F[2 * static_cast<Eigen::Index>(r)] - fx[r],
                                   F[2 * static_cast<Eigen::Index>(r) + 1] - fy[r]);
      worst_force = std::max(worst_force, df / f_scale);
      worst_moment =
          std::max(worst_moment, std::abs(M[static_cast<Eigen::Index>(r)] - mz[r]) / m_scale);
    }
    // the momentum per unit input rate, body by body: m (v_p + ω × (c - p)) + point masses
    const Eigen::VectorXd Z = bp::momentum_regressor(l, k) * theta;
    for (std::size_t r = 0; r < k.samples.size(); ++r) {
      const bp::Kinematics::Sample& s = k.samples[r];
      const std::vector<Vec2>& v = s.unit_rate_velocity[0];
      Vec2 L(0, 0);
      double scale = 0;
      for (std::size_t j = 0; j < l.links.size(); ++j) {
        const cp::Link& link = l.links[j];
        const std::size_t p = static_cast<std::size_t>(link.nodes[0]),
                          q = static_cast<std::size_t>(link.nodes[1]);
        const Vec2 d = s.x[q] - s.x[p], dv = v[q] - v[p];
        const double w = cross2(d, dv) / d.squaredNorm();  // the link's rate at unit input rate
        const Vec2 u = d.normalized(), c = link.e * u + link.f * perp_of(u);
        L += link.mass * (v[p] + w * perp_of(c));
        scale += link.mass * (v[p].norm() + std::abs(w) * c.norm());
      }
      for (const cp::PointMass& pm : l.point_masses) {
        L += pm.mass * v[static_cast<std::size_t>(pm.node)];
        scale += pm.mass * v[static_cast<std::size_t>(pm.node)].norm();
      }
      worst_momentum = std::max(
          worst_momentum, (Z.segment<2>(2 * static_cast<Eigen::Index>(r)) - L).norm() / scale);
    }
  }
  std::printf("regressors against the engine: force %.2e, moment %.2e, momentum %.2e\n",
              worst_force, worst_moment, worst_momentum);
  EXPECT_LE(worst_force, 1e-12);
  EXPECT_LE(worst_moment, 1e-12);
  EXPECT_LE(worst_momentum, 1e-13);
}

// On a four-bar the general conditions are eq. 57's two complex equations, and the counterweights
// on crank and rocker are those of the four-bar's own synthesis.
TEST(PlanarBalance, FourBarCounterweightsAreThoseOfEquation57) {
  Rng rng(302);
  double worst = 0;
  for (int i = 0; i < 20; ++i) {
    const core::FourBar fb = random_fourbar(rng);
    balance::CounterweightSpec spec;
    if (i % 3 == 1) spec.mass = uniform(rng, 1, 4);
    if (i % 3 == 2) {
      spec.shape = balance::CounterweightShape::kDisc;
      spec.radius = uniform(rng, 0.05, 0.2);
    }
    const balance::ForceBalancedDesign expected = balance::force_balance(fb, spec, spec);
    const cp::Linkage l = cp::linkage_of(fb, 0.0);
    const bp::Kinematics k = kinematics_of(l, revolution(l, {6.0}, 72));
    const bp::ForceBalance got = bp::force_balance(l, k, {{0, spec}, {2, spec}});
    EXPECT_TRUE(got.full) << got.message;
    EXPECT_EQ(got.conditions, 4);
    ASSERT_EQ(got.added.size(), 2u);
    const balance::Counterweight* want[] = {&*expected.crank, &*expected.rocker};
    for (int s = 0; s < 2; ++s) {
      const balance::Counterweight& a = got.added[static_cast<std::size_t>(s)].counterweight;
      const balance::Counterweight& b = *want[s];
      worst = std::max({worst, std::abs(a.mass - b.mass) / b.mass,
                        (a.position - b.position).norm() / b.distance,
                        std::abs(a.inertia - b.inertia) / std::max(b.inertia, 1e-300 + b.mass)});
    }
    EXPECT_EQ(got.added[0].pivot, 0);  // A0
    EXPECT_EQ(got.added[1].pivot, 3);  // A3, the rocker's second node
  }
  std::printf("four-bar counterweights against eq. 57: %.2e\n", worst);
  EXPECT_LE(worst, 1e-12);
}

// Six-bars balanced by counterweights on their three grounded links: the referee, which shares
// no code with the engine or the balance layer, finds no inertial shaking force left, driven
// and free (the momentum is zero for every motion).
template <class Make>
void balanced_family(const char* family, std::uint64_t seed, Make make) {
  Rng rng(seed);
  double worst_driven = 0, worst_free = 0;
  for (int i = 0; i < 8; ++i) {
    const cp::Linkage l = make(rng);
    const double speed = uniform(rng, 5, 20);
    const cp::Trajectory tr = revolution(l, {speed}, 90);
    ASSERT_TRUE(tr.ok()) << tr.message;
    const bp::ForceBalance b = bp::force_balance(l, kinematics_of(l, tr), on_grounded_links(l));
    EXPECT_TRUE(b.full) << family << " #" << i << ": " << b.message;
    EXPECT_EQ(b.conditions, 6) << family << " #" << i;  // three complex node groups
    const double original = b.Fsh_rms_before;
    ASSERT_GT(original, 0);
    const Glue g = glue_of(b.linkage);
    const std::vector<double> times = tr.table.column_values("t");
    for (const rf::Sample& s : rf::driven(g.mechanism, {speed}, 0.0, times))
      worst_driven = std::max(worst_driven, s.inertial_force.norm() / original);
    const double duration = 0.2;
    std::vector<double> free_times;
    for (int j = 0; j <= 20; ++j) free_times.push_back(duration * j / 20);
    for (const rf::Sample& s : rf::free_run(g.mechanism, {speed}, duration, free_times))
      worst_free = std::max(worst_free, s.inertial_force.norm() / original);
  }
  std::printf(
      "%s balanced: inertial shaking force left (referee) / original RMS: driven %.2e, "
      "free %.2e\n",
      family, worst_driven, worst_free);
  EXPECT_LE(worst_driven, 1e-10);
  EXPECT_LE(worst_free, 1e-10);
}

TEST(PlanarBalance, WattSixBarsBalancedByCounterweightsShakeNoMore) {
  balanced_family("Watt II six-bar", 303, [](Rng& r) { return six_bar_or_retry(r, false); });
}
TEST(PlanarBalance, StephensonSixBarsBalancedByCounterweightsShakeNoMore) {
  balanced_family("Stephenson III six-bar", 304, [](Rng& r) { return six_bar_or_retry(r, true); });
}

// An inline slider-crank cannot be force balanced by a counterweight on its crank: the piston's
// reciprocating mass moves on a line. The least-squares counterweight is the one that cancels
// the first Fourier coefficient of the complex shaking force Fx + i Fy over the revolution (the
// counterweight's force is a rotating vector at crank speed): its residual is the rest of the
// series, by Parseval. Computed here from the engine's samples by a direct DFT.
TEST(PlanarBalance, SliderCrankCannotBeBalancedOnItsCrankAndSaysWhy) {
  Rng rng(305);
  for (int i = 0; i < 6; ++i) {
    const cp::Linkage l = slider_crank(rng, true);
    const double speed = uniform(rng, 5, 30);
    const int n = 180;
    const cp::Trajectory tr = revolution(l, {speed}, n);
    ASSERT_TRUE(tr.ok());
    const bp::ForceBalance b = bp::force_balance(l, kinematics_of(l, tr), on_grounded_links(l));
    EXPECT_FALSE(b.full);
    EXPECT_NE(b.message.find("full force balance cannot be reached with counterweights on crank"),
              std::string::npos)
        << b.message;
    // the independent least squares: |F|² mean minus the first coefficient's share
    const std::vector<double> fx = tr.table.column_values("Fshx_inertial"),
                              fy = tr.table.column_values("Fshy_inertial"),
                              th = tr.table.column_values("theta_crank");
    std::complex<double> c1(0, 0);
    double power = 0;
    for (int j = 0; j < n; ++j) {
      const std::complex<double> F(fx[static_cast<std::size_t>(j)],
                                   fy[static_cast<std::size_t>(j)]);
      c1 += F * std::exp(std::complex<double>(0, -th[static_cast<std::size_t>(j)]));
      power += std::norm(F);
    }
    c1 /= n;
    power /= n;
    const double rms_left = std::sqrt(power - std::norm(c1));
    EXPECT_NEAR(b.Fsh_rms_after, rms_left, 1e-10 * std::sqrt(power)) << i;
    EXPECT_NEAR(b.Fsh_rms_before, std::sqrt(power), 1e-12 * std::sqrt(power)) << i;
    // the design simulated: its RMS is what the regressor promised
    const cp::Trajectory after = revolution(b.linkage, {speed}, n);
    EXPECT_NEAR(rms_inertial_force(after.table), rms_left, 1e-10 * std::sqrt(power));
  }
}

TEST(PlanarBalance, MistakesAreNamedByLink) {
  Rng rng(306);
  const cp::Linkage l = six_bar_or_retry(rng, false);
  const bp::Kinematics k = kinematics_of(l, revolution(l, {6.0}, 36));
  auto message = [&](const std::vector<bp::LinkCounterweightSpec>& cws) -> std::string {
    try {
      bp::force_balance(l, k, cws);
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  };
  // the coupler (link 1) floats: its counterweight's mass must be given
  EXPECT_NE(message({{1, {}}}).find("counterweights.coupler"), std::string::npos);
  EXPECT_NE(message({{1, {}}}).find("give its mass"), std::string::npos);
  balance::CounterweightSpec bad;
  bad.mass = -1.0;
  EXPECT_NE(message({{0, bad}}).find("counterweights.crank.mass must be > 0 kg"), std::string::npos)
      << message({{0, bad}});
  EXPECT_NE(message({{0, {}}, {0, {}}}).find("one counterweight per link"), std::string::npos);
}

}  // namespace
}  // namespace bd::testing::planar
