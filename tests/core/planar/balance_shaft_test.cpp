// Balance shafts (core/planar/model.hpp BalanceShaft) checked from the physics, not from the
// engine's own bookkeeping:
//
//  * A shaft on its link's pivot turning with the link (ratio 1) is part of the link: every
//    output equals that of the linkage whose link carries the shaft's mass and inertia (merged
//    here by the parallel-axis sum), the pivot's reaction split between the pin and the shaft.
//  * Eccentric shafts geared at -2, -1, 2 and 3 to a crank, on shafts away from its pivot (a gear
//    pair) or on it (a pure torque): at random states the drive's power equals dT/dt minus the
//    power of gravity; the shaking force and moment equal the weights and their moments minus
//    the rates of change of the whole machine's linear and angular momentum (the drive's torque
//    on the crank and its stator's on the frame cancel), T and H summed body by body with each
//    shaft turned by ratio × the link's turn; and each shaft's bearing force leaves a tooth force
//    normal to the line of centres that, at the pair's pitch point, turns the shaft as its own
//    moment balance asks.
//  * A free run of such a linkage keeps its energy (kinetic + gravity) to the integrator's
//    tolerance.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/planar/dynamics.hpp"
#include "core/planar/simulate.hpp"
#include "tests/support/planar_mechanisms.hpp"

namespace bd::testing::planar {
namespace {

// a random slider-crank or six-bar under gravity only, driven by its crank (input 0, link 0)
cp::Linkage gravity_only(Rng& rng, int i) {
  cp::Linkage l = i % 2 ? slider_crank(rng, i % 4 == 1) : six_bar_or_retry(rng, i % 4 == 2);
  l.springs.clear();
  l.loads.node_forces.clear();
  l.loads.link_loads.clear();
  l.loads.gravity = polar(9.81, uniform(rng, -kPi, kPi));
  for (cp::Input& in : l.inputs) in.effort = cp::TimeFunction{};
  return l;
}

int pivot(const cp::Linkage& l, int link) {
  for (int n : l.links[static_cast<std::size_t>(link)].nodes) {
    if (l.nodes[static_cast<std::size_t>(n)].ground) return n;
  }
  return -1;
}

Vec2 node_position(const cp::Linkage& l, int n) {
  return l.nodes[static_cast<std::size_t>(n)].position;
}

// a random eccentric shaft geared to link 0 with the given ratio, at `at`
cp::BalanceShaft shaft(Rng& rng, const cp::Linkage& l, const std::string& name, int ratio,
                       Vec2 at) {
  const double size = size_of(l);
  const double m = uniform(rng, 0.2, 2.0);
  return {name,
          0,
          ratio,
          at,
          m,
          polar(uniform(rng, 0.1, 0.5) * size, uniform(rng, -kPi, kPi)),
          m * size * size * uniform(rng, 0.01, 0.05)};
}

// at the instant: per shaft its centre of mass from the shaft, its rate and acceleration, from
// its link's turn since the drawn configuration
struct ShaftState {
  Vec2 r, v, a;
  double omega, alpha;
};
ShaftState state_of(const cp::Linkage& l, const cp::BalanceShaft& b, const cp::Instant& in) {
  const auto& nodes = l.links[static_cast<std::size_t>(b.link)].nodes;
  const Vec2 d0 = node_position(l, nodes[1]) - node_position(l, nodes[0]);
  const double turn =
      b.ratio * (in.angle[static_cast<std::size_t>(b.link)] - std::atan2(d0.y(), d0.x()));
  ShaftState s;
  s.r = Vec2(std::cos(turn) * b.eccentricity.x() - std::sin(turn) * b.eccentricity.y(),
             std::sin(turn) * b.eccentricity.x() + std::cos(turn) * b.eccentricity.y());
  s.omega = b.ratio * in.omega[static_cast<std::size_t>(b.link)];
  s.alpha = b.ratio * in.alpha[static_cast<std::size_t>(b.link)];
  s.v = s.omega * perp_of(s.r);
  s.a = s.alpha * perp_of(s.r) - s.omega * s.omega * s.r;
  return s;
}

// the rates of change of the machine's momentum and kinetic energy, and gravity's force, moment
// and power, body by body
struct Balances {
  Vec2 dL{0, 0}, weight{0, 0};
  double dH{}, dT{}, weight_moment{}, weight_power{};
};
Balances balances(const cp::Linkage& l, const cp::Instant& in) {
  Balances b;
  const Vec2 g = l.loads.gravity;
  auto body = [&](double m, double J, const Vec2& c, const Vec2& v, const Vec2& a, double w,
                  double al) {
    b.dL += m * a;
    b.dH += J * al + m * cross2(c, a);
    b.dT += m * v.dot(a) + J * w * al;
    b.weight += m * g;
    b.weight_moment += cross2(c, m * g);
    b.weight_power += m * g.dot(v);
  };
  for (std::size_t k = 0; k < l.links.size(); ++k) {
    const cp::Link& link = l.links[k];
    const std::size_t p = static_cast<std::size_t>(link.nodes[0]);
    const Vec2 u(std::cos(in.angle[k]), std::sin(in.angle[k]));
    const Vec2 rc = link.e * u + link.f * perp_of(u);  // centre of mass from the first node
    const double w = in.omega[k], al = in.alpha[k];
    body(link.mass, link.inertia, in.x[p] + rc, in.v[p] + w * perp_of(rc),
         in.a[p] + al * perp_of(rc) - w * w * rc, w, al);
  }
  for (const cp::PointMass& pm : l.point_masses) {
    const std::size_t n = static_cast<std::size_t>(pm.node);
    body(pm.mass, 0, in.x[n], in.v[n], in.a[n], 0, 0);
  }
  for (const cp::BalanceShaft& sh : l.shafts) {
    const ShaftState s = state_of(l, sh, in);
    body(sh.mass, sh.inertia, sh.at + s.r, s.v, s.a, s.omega, s.alpha);
  }
  return b;
}

TEST(BalanceShaft, CoaxialShaftTurningWithItsLinkIsPartOfTheLink) {
  Rng rng(5);
  std::uniform_real_distribution<double> rate(-20, 20), acc(-200, 200);
  for (int i = 0; i < 40; ++i) {
    const cp::Linkage bare = gravity_only(rng, i);
    const int O = pivot(bare, 0);
    cp::Linkage with = bare;
    with.shafts.push_back(shaft(rng, bare, "shaft", 1, node_position(bare, O)));
    const cp::BalanceShaft& b = with.shafts[0];
    // the merged link: the shaft's mass at O + eccentricity, in the link's axes from its first node
    cp::Linkage merged = bare;
    cp::Link& link = merged.links[0];
    const Vec2 first = node_position(bare, link.nodes[0]);
    const Vec2 d = node_position(bare, link.nodes[1]) - first;
    const Vec2 u = d / d.norm(), n = perp_of(u);
    const Vec2 p = node_position(bare, O) + b.eccentricity - first;
    const Vec2 c1(link.e, link.f), c2(p.dot(u), p.dot(n));
    const double m = link.mass + b.mass;
    const Vec2 c = (link.mass * c1 + b.mass * c2) / m;
    link.inertia +=
        b.inertia + link.mass * (c1 - c).squaredNorm() + b.mass * (c2 - c).squaredNorm();
    link.mass = m;
    link.e = c.x();
    link.f = c.y();
    const cp::Model mw(with), mm(merged);
    cp::Workspace ww(mw), wm(mm);
    const double z = uniform(rng, -kPi, kPi), w = rate(rng), al = acc(rng);
    ASSERT_TRUE(cp::assemble(mw, ww, {z}));
    ASSERT_TRUE(cp::assemble(mm, wm, {z}));
    const bool forward = i % 3 == 0;
    ASSERT_TRUE(forward ? cp::forward_dynamics(mw, ww, 0, {w}, {0.0})
                        : cp::inverse_dynamics(mw, ww, 0, {w}, {al}));
    ASSERT_TRUE(forward ? cp::forward_dynamics(mm, wm, 0, {w}, {0.0})
                        : cp::inverse_dynamics(mm, wm, 0, {w}, {al}));
    const cp::Instant &a = ww.instant, &e = wm.instant;
    const double force = std::max({1.0, e.Fsh.norm(), e.ground_reaction[0].norm()});
    const double moment = force * size_of(bare);
    const std::string what = "linkage " + std::to_string(i);
    constexpr double kTol = 1e-12;  // two exact routes, differing by round-off
    EXPECT_NEAR(a.input_acceleration[0], e.input_acceleration[0],
                kTol * std::max(1.0, std::abs(e.input_acceleration[0])))
        << what;
    EXPECT_NEAR(a.effort[0], e.effort[0], kTol * moment) << what;
    EXPECT_LT((a.Fsh - e.Fsh).norm(), kTol * force) << what;
    EXPECT_NEAR(a.Msh, e.Msh, kTol * moment) << what;
    EXPECT_LT((a.Fsh_inertial - e.Fsh_inertial).norm(), kTol * force) << what;
    EXPECT_NEAR(a.Msh_inertial, e.Msh_inertial, kTol * moment) << what;
    for (std::size_t j = 0; j < e.joint_force.size(); ++j) {
      EXPECT_LT((a.joint_force[j] - e.joint_force[j]).norm(), kTol * force) << what;
    }
    for (std::size_t j = 0; j < e.ground_reaction.size(); ++j) {
      const bool at_pivot = mw.ground_nodes()[j] == O;
      const Vec2 r = a.ground_reaction[j] + (at_pivot ? a.shaft_reaction[0] : Vec2(0, 0));
      EXPECT_LT((r - e.ground_reaction[j]).norm(), kTol * force) << what;
    }
  }
}

TEST(BalanceShaft, GearedEccentricShaftsKeepTheMachinesPowerAndMomentumBalances) {
  Rng rng(17);
  std::uniform_real_distribution<double> rate(-20, 20), acc(-200, 200);
  const int ratios[] = {-2, -1, 2, 3};
  for (int i = 0; i < 40; ++i) {
    cp::Linkage l = gravity_only(rng, i);
    const Vec2 O = node_position(l, pivot(l, 0));
    const double size = size_of(l);
    l.shafts.push_back(shaft(rng, l, "S1", ratios[i % 4],
                             O + polar(uniform(rng, 0.3, 1.0) * size, uniform(rng, -kPi, kPi))));
    l.shafts.push_back(shaft(rng, l, "S2", ratios[(i + 1) % 4],
                             O + polar(uniform(rng, 0.3, 1.0) * size, uniform(rng, -kPi, kPi))));
    l.shafts.push_back(shaft(rng, l, "S3", -1, O));  // coaxial: a pure torque
    const cp::Model model(l);
    cp::Workspace ws(model);
    ASSERT_TRUE(cp::assemble(model, ws, {uniform(rng, -kPi, kPi)}));
    ASSERT_TRUE(cp::inverse_dynamics(model, ws, 0, {rate(rng)}, {acc(rng)}));
    const cp::Instant& in = ws.instant;
    const Balances b = balances(l, in);
    const double force = std::max(b.dL.norm(), b.weight.norm());
    const double moment = force * size, power = moment * std::abs(in.omega[0]) + 1e-300;
    const std::string what = "linkage " + std::to_string(i);
    constexpr double kTol = 1e-12;  // exact identities, to round-off
    EXPECT_NEAR(in.effort[0] * in.omega[0], b.dT - b.weight_power, kTol * power) << what;
    EXPECT_LT((in.Fsh - (b.weight - b.dL)).norm(), kTol * force) << what;
    EXPECT_NEAR(in.Msh, b.weight_moment - b.dH, kTol * moment) << what;
    EXPECT_LT((in.Fsh_inertial + b.dL).norm(), kTol * force) << what;
    EXPECT_NEAR(in.Msh_inertial, -b.dH, kTol * moment) << what;
    for (std::size_t k = 0; k < 2; ++k) {  // the geared ones: the tooth force at the pitch point
      const cp::BalanceShaft& sh = l.shafts[k];
      const ShaftState s = state_of(l, sh, in);
      const Vec2 on_shaft = in.shaft_reaction[k] - sh.mass * (l.loads.gravity - s.a);  // -tooth
      const Vec2 pitch = (O - sh.ratio * sh.at) / (1.0 - sh.ratio);
      EXPECT_NEAR(on_shaft.dot(sh.at - O), 0.0, kTol * force * size) << what;
      const double turning = sh.inertia * s.alpha + cross2(s.r, sh.mass * s.a);
      EXPECT_NEAR(turning, cross2(s.r, sh.mass * l.loads.gravity) + cross2(pitch - sh.at, on_shaft),
                  kTol * moment)
          << what;
    }
  }
}

TEST(BalanceShaft, FreeRunWithGearedShaftsKeepsItsEnergy) {
  Rng rng(23);
  for (int i = 0; i < 6; ++i) {
    cp::Linkage l = gravity_only(rng, i);
    const Vec2 O = node_position(l, pivot(l, 0));
    l.shafts.push_back(shaft(rng, l, "S1", i % 2 ? -2 : 2, O + polar(0.5 * size_of(l), 1.0)));
    l.shafts.push_back(shaft(rng, l, "S2", -1, O + polar(0.4 * size_of(l), -2.0)));
    const cp::Model model(l);
    cp::SimulateOptions o;
    o.tolerance = 1e-11;
    o.absolute_tolerance = 1e-13;
    const cp::Trajectory tr =
        cp::simulate_free(model, cp::FreeScene{{cp::drawn_inputs(model)[0]}, {15.0}, 0.3, 61}, o);
    ASSERT_TRUE(tr.ok()) << tr.message;
    // the energy at each sample from the instant re-evaluated at the run's state
    cp::Workspace ws(model);
    double e0 = 0, worst = 0, scale = 0;
    for (std::size_t j = 0; j < tr.table.rows(); ++j) {
      const double z = tr.table.at(j, static_cast<std::size_t>(tr.table.column("theta_crank")));
      const double w = tr.table.at(j, static_cast<std::size_t>(tr.table.column("omega_crank")));
      ASSERT_TRUE(cp::solve_position(model, ws, ws.instant.x, {z}));
      ASSERT_TRUE(cp::forward_dynamics(model, ws, 0, {w}, {0.0}));
      const cp::Instant& in = ws.instant;
      double T = 0, V = 0;
      auto body = [&](double m, double J, const Vec2& c, const Vec2& v, double om) {
        T += 0.5 * (m * v.squaredNorm() + J * om * om);
        V -= m * l.loads.gravity.dot(c);
      };
      for (std::size_t k = 0; k < l.links.size(); ++k) {
        const cp::Link& link = l.links[k];
        const std::size_t p = static_cast<std::size_t>(link.nodes[0]);
        const Vec2 u(std::cos(in.angle[k]), std::sin(in.angle[k]));
        const Vec2 rc = link.e * u + link.f * perp_of(u);
        body(link.mass, link.inertia, in.x[p] + rc, in.v[p] + in.omega[k] * perp_of(rc),
             in.omega[k]);
      }
      for (const cp::PointMass& pm : l.point_masses) {
        const std::size_t n = static_cast<std::size_t>(pm.node);
        body(pm.mass, 0, in.x[n], in.v[n], 0);
      }
      for (const cp::BalanceShaft& sh : l.shafts) {
        const ShaftState s = state_of(l, sh, in);
        body(sh.mass, sh.inertia, sh.at + s.r, s.v, s.omega);
      }
      if (j == 0) e0 = T + V;
      scale = std::max(scale, T);
      worst = std::max(worst, std::abs(T + V - e0));
    }
    // the integrator's tolerance 1e-11 per step, some hundred steps
    EXPECT_LT(worst, 1e-8 * scale) << "linkage " << i;
  }
}

}  // namespace
}  // namespace bd::testing::planar
