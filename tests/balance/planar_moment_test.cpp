// Shaking-moment balance of planar linkages by counter-rotations (balance/planar_moment.hpp),
// checked by other routes:
//  - the angular momentum regressor against the angular momentum summed body by body from
//    each link's centre of mass (and eccentric balance shafts and point masses);
//  - on four-bars with a Berkof coupler, the discs' inertias against the four-bar's own
//    synthesis (Berkof's reduced inertias), and the moment-balanced design in the independent
//    referee (Newton-Euler in absolute coordinates, the discs as bodies meshing with their links
//    by spur gears): no inertial shaking force or moment left, driven and free;
//  - where full moment balance cannot be reached (a coupler that is not a Berkof coupler, a
//    six-bar), the message names the link, and the least-squares discs against an independent
//    least-squares fit of the engine's simulated shaking moment by the links' angular
//    accelerations; the design simulated has the RMS the synthesis promised.
#include "balance/planar_moment.hpp"

#include <gtest/gtest.h>

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "balance/counter_rotation.hpp"
#include "balance/counterweight.hpp"
#include "core/fourbar/samples.hpp"
#include "core/input_error.hpp"
#include "core/planar/from_fourbar.hpp"
#include "core/planar/simulate.hpp"
#include "tests/support/balance_motion.hpp"
#include "tests/support/planar_glue.hpp"
#include "tests/support/planar_mechanisms.hpp"

namespace bd::testing::planar {
namespace {

double rms(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x * x;
  return std::sqrt(s / static_cast<double>(v.size()));
}

// the four-bar as a planar linkage, force balanced by counterweights on crank and rocker
bp::ForceBalance force_balanced(const core::FourBar& fb, const bp::Kinematics& k) {
  const cp::Linkage l = cp::linkage_of(fb, 0.0);
  bp::ForceBalance b = bp::force_balance(l, k, {{0, {}}, {2, {}}});
  EXPECT_TRUE(b.full) << b.message;
  return b;
}

// The angular momentum per unit input rate about the origin, body by body: each link's
// m c × v_c + I ω from its centre of mass, point masses m x × v, eccentric shafts as bodies.
TEST(PlanarMomentBalance, AngularMomentumRegressorIsTheBodiesAngularMomentum) {
  Rng rng(401);
  double worst = 0;
  for (int i = 0; i < 18; ++i) {
    cp::Linkage l = i % 3 == 0 ? slider_crank(rng, coin(rng)) : six_bar_or_retry(rng, coin(rng));
    const int crank = l.inputs[0].link;
    const int pivot = cp::pivot_of(l, crank);
    for (int ratio : {-2, 1}) {  // eccentric shafts, off the pivot
      cp::BalanceShaft b;
      b.name = "S" + std::to_string(ratio + 3);
      b.link = crank;
      b.ratio = ratio;
      b.at = l.nodes[static_cast<std::size_t>(pivot)].position + polar(uniform(rng, 0.1, 0.5), 1.0);
      b.mass = uniform(rng, 0.2, 2);
      b.eccentricity = polar(uniform(rng, 0.01, 0.1), uniform(rng, -kPi, kPi));
      b.inertia = uniform(rng, 0.001, 0.01);
      l.shafts.push_back(b);
    }
    l = cp::make_linkage(l);
    const bp::Kinematics k = kinematics_of(l, revolution(l, {7.0}, 24));
    const Eigen::VectorXd H = bp::angular_momentum_regressor(l, k) * bp::Parameters::of(l) +
                              bp::shaft_series(l, k).angular_momentum;
    ASSERT_EQ(H.size(), static_cast<Eigen::Index>(k.samples.size()));
    const double drawn = std::atan2(
        l.nodes[static_cast<std::size_t>(l.links[static_cast<std::size_t>(crank)].nodes[1])]
                .position.y() -
            l.nodes[static_cast<std::size_t>(l.links[static_cast<std::size_t>(crank)].nodes[0])]
                .position.y(),
        l.nodes[static_cast<std::size_t>(l.links[static_cast<std::size_t>(crank)].nodes[1])]
                .position.x() -
            l.nodes[static_cast<std::size_t>(l.links[static_cast<std::size_t>(crank)].nodes[0])]
                .position.x());
    for (std::size_t r = 0; r < k.samples.size(); ++r) {
      const bp::Kinematics::Sample& s = k.samples[r];
      const std::vector<Vec2>& v = s.unit_rate_velocity[0];
      double h = 0, scale = 0;
      std::vector<double> w(l.links.size());
      std::vector<double> angle(l.links.size());
      for (std::size_t j = 0; j < l.links.size(); ++j) {
        const cp::Link& link = l.links[j];
        const std::size_t p = static_cast<std::size_t>(link.nodes[0]),
                          q = static_cast<std::size_t>(link.nodes[1]);
        const Vec2 d = s.x[q] - s.x[p], dv = v[q] - v[p];
        w[j] = cross2(d, dv) / d.squaredNorm();
        angle[j] = std::atan2(d.y(), d.x());
        const Vec2 u = d.normalized(), rc = link.e * u + link.f * perp_of(u);
        const Vec2 c = s.x[p] + rc, vc = v[p] + w[j] * perp_of(rc);
        h += link.mass * cross2(c, vc) + link.inertia * w[j];
        scale += link.mass * c.norm() * vc.norm() + link.inertia * std::abs(w[j]);
      }
      for (const cp::PointMass& pm : l.point_masses) {
        const std::size_t n = static_cast<std::size_t>(pm.node);
        h += pm.mass * cross2(s.x[n], v[n]);
        scale += pm.mass * s.x[n].norm() * v[n].norm();
      }
      for (const cp::BalanceShaft& b : l.shafts) {
        const double turn = angle[static_cast<std::size_t>(b.link)] - drawn;
        const double spin = b.ratio * w[static_cast<std::size_t>(b.link)];
        const Vec2 e = Eigen::Rotation2Dd(b.ratio * turn) * b.eccentricity;
        const Vec2 c = b.at + e, vc = spin * perp_of(e);
        h += b.mass * cross2(c, vc) + b.inertia * spin;
        scale += b.mass * c.norm() * vc.norm() + b.inertia * std::abs(spin);
      }
      worst = std::max(worst, std::abs(H[static_cast<Eigen::Index>(r)] - h) / scale);
    }
  }
  std::printf("angular momentum regressor against the bodies: %.2e\n", worst);
  EXPECT_LE(worst, 1e-13);
}

// The moment-balanced design in the referee: its links (counterweights merged) and each
// counter-rotating disc as a body on a frame pin, meshing with its link by a spur gear whose
// pitch point is midway (ratio -1).
Glue referee_of(const cp::Linkage& l) {
  Glue g = glue_of(l);
  for (const cp::BalanceShaft& b : l.shafts) {
    EXPECT_EQ(b.ratio, -1);
    EXPECT_EQ(b.mass, 0.0);
    const int disc = static_cast<int>(g.mechanism.bodies.size());
    // a disc's own mass sits on its fixed axis: it adds no inertial force or moment
    g.mechanism.bodies.push_back(rf::Body{b.name, 1.0, b.inertia, b.at, {}});
    g.mechanism.pins.push_back(rf::Pin{b.name, rf::kGround, disc, b.at});
    const Vec2 pivot = l.nodes[static_cast<std::size_t>(cp::pivot_of(l, b.link))].position;
    g.mechanism.gears.push_back(rf::Gear{b.name, b.link, disc, pivot, b.at, 0.5 * (pivot + b.at)});
  }
  return g;
}

// On a four-bar with a Berkof coupler the general synthesis gives Berkof's reduced inertias (the
// four-bar's own moment_balance), and the referee finds neither shaking force nor shaking moment
// left, driven and free.
TEST(PlanarMomentBalance, FourBarDiscsAreBerkofsAndShakeNothing) {
  Rng rng(402);
  double worst_j = 0, worst_driven = 0, worst_free = 0;
  for (int i = 0; i < 10; ++i) {
    const core::FourBar fb = random_fourbar(rng, true);
    const double speed = uniform(rng, 4, 12);
    const cp::Linkage l0 = cp::linkage_of(fb, 0.0);
    const bp::Kinematics k = kinematics_of(l0, revolution(l0, {speed}, 72));
    const bp::ForceBalance fbal = force_balanced(fb, k);
    const Vec2 crank_at = polar(uniform(rng, 0.3, 1.0), uniform(rng, -kPi, kPi));
    const Vec2 rocker_at = Vec2(fb.frame_length, 0) + polar(uniform(rng, 0.3, 1.0), 2.0);
    const bp::MomentBalance m =
        bp::moment_balance(fbal.linkage, k, {{0, crank_at}, {2, rocker_at}});
    EXPECT_TRUE(m.full) << m.message;
    EXPECT_TRUE(m.message.empty());
    ASSERT_EQ(m.added.size(), 2u);

    const balance::ForceBalancedDesign dedicated =
        balance::force_balance(fb, balance::CounterweightSpec{}, balance::CounterweightSpec{});
    const balance::MomentBalancedDesign want =
        balance::moment_balance(dedicated.model, crank_at, rocker_at);
    const cp::BalanceShaft& c = m.linkage.shafts[static_cast<std::size_t>(m.added[0])];
    const cp::BalanceShaft& r = m.linkage.shafts[static_cast<std::size_t>(m.added[1])];
    EXPECT_EQ(c.name, "counter_crank");
    EXPECT_EQ(r.name, "counter_rocker");
    EXPECT_EQ(c.ratio, -1);
    EXPECT_EQ(r.ratio, -1);
    EXPECT_EQ(c.at, crank_at);
    worst_j = std::max({worst_j, std::abs(c.inertia - want.crank_inertia) / want.crank_inertia,
                        std::abs(r.inertia - want.rocker_inertia) / want.rocker_inertia});
    EXPECT_NEAR(m.added_inertia, want.crank_inertia + want.rocker_inertia, 1e-12 * m.added_inertia);
    EXPECT_LE(m.Msh_rms_after, 1e-10 * m.Msh_rms_before);

    // the referee, which shares no code with the engine or the balance layer
    const Glue g = referee_of(m.linkage);
    const Glue g0 = glue_of(l0);
    std::vector<double> times;
    for (int j = 0; j < 36; ++j) times.push_back(2 * kPi / speed * j / 36);
    double force0 = 0, moment0 = 0;
    for (const rf::Sample& s : rf::driven(g0.mechanism, {speed}, 0.0, times)) {
      force0 = std::max(force0, s.inertial_force.norm());
      moment0 = std::max(moment0, std::abs(s.inertial_moment));
    }
    for (const rf::Sample& s : rf::driven(g.mechanism, {speed}, 0.0, times)) {
      worst_driven = std::max(
          {worst_driven, s.inertial_force.norm() / force0, std::abs(s.inertial_moment) / moment0});
    }
    std::vector<double> free_times;
    for (int j = 0; j <= 10; ++j) free_times.push_back(0.3 * j / 10);
    for (const rf::Sample& s : rf::free_run(g.mechanism, {speed}, 0.3, free_times)) {
      worst_free = std::max(
          {worst_free, s.inertial_force.norm() / force0, std::abs(s.inertial_moment) / moment0});
    }
  }
  std::printf(
      "four-bar discs against Berkof's inertias: %.2e; shaking left (referee) / "
      "original peak: driven %.2e, free %.2e\n",
      worst_j, worst_driven, worst_free);
  EXPECT_LE(worst_j, 1e-12);
  EXPECT_LE(worst_driven, 1e-10);
  EXPECT_LE(worst_free, 1e-10);
}

// Where the counter-rotations cannot cancel the angular momentum (a coupler that is not a Berkof
// coupler; a six-bar's floating links) the message names the link, and the discs are the
// least-squares fit of the force-balanced design's simulated shaking moment by its links'
// angular accelerations (an independent solve on the engine's time series); the design
// simulated has the RMS shaking moment the synthesis promised.
TEST(PlanarMomentBalance, WhatCannotBeCancelledIsNamedAndLeastSquares) {
  Rng rng(403);
  for (int i = 0; i < 8; ++i) {
    cp::Linkage l0;
    std::vector<bp::CounterRotationRequest> asks;
    const bool fourbar = i % 2 == 0;
    if (fourbar) {
      l0 = cp::linkage_of(random_fourbar(rng, false), 0.0);
    } else {
      l0 = six_bar_or_retry(rng, coin(rng));
    }
    const double speed = uniform(rng, 4, 12);
    const int n = 120;
    const cp::Trajectory tr0 = revolution(l0, {speed}, n);
    ASSERT_TRUE(tr0.ok()) << tr0.message;
    const bp::Kinematics k = kinematics_of(l0, tr0);
    const bp::ForceBalance fbal = bp::force_balance(l0, k, bp::grounded_links(l0));
    ASSERT_TRUE(fbal.full) << fbal.message;
    asks = bp::default_counter_rotations(fbal.linkage);
    const bp::MomentBalance m = bp::moment_balance(fbal.linkage, k, asks);
    EXPECT_FALSE(m.full);
    const std::string expect = fourbar ? "the largest part of the angular momentum they cannot "
                                         "cancel is link coupler's"
                                       : "full moment balance cannot be reached with "
                                         "counter-rotations on ";
    EXPECT_NE(m.message.find(expect), std::string::npos) << m.message;

    // the independent least squares on the force-balanced design's simulated series, over the
    // links whose angular acceleration is not zero in the scene
    const cp::Trajectory tr = revolution(fbal.linkage, {speed}, n);
    ASSERT_TRUE(tr.ok());
    const std::vector<double> msh = tr.table.column_values("Msh_inertial");
    std::vector<std::string> names;
    std::vector<double> size;
    for (const bp::CounterRotationRequest& ask : asks) {
      names.push_back(fbal.linkage.links[static_cast<std::size_t>(ask.link)].name);
      size.push_back(rms(tr.table.column_values("alpha_" + names.back())));
    }
    // a driven crank's angular acceleration is 0 to round-off
    std::vector<std::size_t> moving, still;
    const double largest = *std::max_element(size.begin(), size.end());
    for (std::size_t c = 0; c < asks.size(); ++c)
      (size[c] > 1e-9 * largest ? moving : still).push_back(c);
    Eigen::MatrixXd A(n, static_cast<Eigen::Index>(moving.size()));
    Eigen::VectorXd b(n);
    for (int j = 0; j < n; ++j) {
      b[j] = -msh[static_cast<std::size_t>(j)];
      for (std::size_t c = 0; c < moving.size(); ++c) {
        A(j, static_cast<Eigen::Index>(c)) =
            -tr.table.column_values("alpha_" + names[moving[c]])[static_cast<std::size_t>(j)];
      }
    }
    const Eigen::VectorXd fitted = A.colPivHouseholderQr().solve(b);
    Eigen::VectorXd c = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(asks.size()));
    for (std::size_t s = 0; s < moving.size(); ++s)
      c[static_cast<Eigen::Index>(moving[s])] = fitted[static_cast<Eigen::Index>(s)];
    // a link at constant speed (the crank): its disc cancels the mean of what is left of the
    // angular momentum per unit crank rate (the referee's, over the same configurations)
    const std::vector<double> times = tr.table.column_values("t");
    const std::vector<rf::Sample> ref =
        rf::driven(glue_of(fbal.linkage).mechanism, {speed}, 0.0, times);
    for (std::size_t s : still) {
      double mean = 0;
      for (int j = 0; j < n; ++j) {
        double h = ref[static_cast<std::size_t>(j)].angular_momentum / speed;
        for (std::size_t o : moving) {
          h += c[static_cast<Eigen::Index>(o)] *
               tr.table.column_values("omega_" + names[o])[static_cast<std::size_t>(j)] / speed;
        }
        mean += h / n;
      }
      // the still link turns with the crank: its rate per unit crank rate is 1
      EXPECT_EQ(fbal.linkage.links[static_cast<std::size_t>(asks[s].link)].name, "crank");
      c[static_cast<Eigen::Index>(s)] = -mean;
    }
    const double before = rms(msh);
    EXPECT_NEAR(m.Msh_rms_before, before, 1e-12 * before);
    ASSERT_EQ(m.added.size(), asks.size());
    for (std::size_t s = 0; s < asks.size(); ++s) {
      const cp::BalanceShaft& d = m.linkage.shafts[static_cast<std::size_t>(m.added[s])];
      EXPECT_EQ(d.link, asks[s].link);
      EXPECT_NEAR(d.ratio * d.inertia, c[static_cast<Eigen::Index>(s)],
                  1e-9 * c.cwiseAbs().maxCoeff())
          << i << " " << d.name;
    }
    // the angular momentum left, per unit crank rate: the referee's with the discs' c ω
    double h2 = 0, left2 = 0;
    for (int j = 0; j < n; ++j) {
      const double h = ref[static_cast<std::size_t>(j)].angular_momentum / speed;
      double left = h;
      for (std::size_t s = 0; s < asks.size(); ++s) {
        left += c[static_cast<Eigen::Index>(s)] *
                tr.table.column_values("omega_" + names[s])[static_cast<std::size_t>(j)] / speed;
      }
      h2 += h * h;
      left2 += left * left;
    }
    EXPECT_NEAR(m.angular_momentum_left, std::sqrt(left2 / h2), 1e-9) << i;
    EXPECT_GT(m.angular_momentum_left, 1e-3) << i;
    const double fit = std::sqrt((A * fitted - b).squaredNorm() / n);
    EXPECT_NEAR(m.Msh_rms_after, fit, 1e-10 * before);
    EXPECT_LT(m.Msh_rms_after, before);
    const cp::Trajectory after = revolution(m.linkage, {speed}, n);
    ASSERT_TRUE(after.ok()) << after.message;
    EXPECT_NEAR(rms(after.table.column_values("Msh_inertial")), fit, 1e-10 * before);
    EXPECT_LE(rms(after.table.column_values("Fshx_inertial")), 1e-10 * fbal.Fsh_rms_before);
  }
}

TEST(PlanarMomentBalance, RefusesWhatItCannotDo) {
  Rng rng(404);
  const cp::Linkage l = cp::linkage_of(random_fourbar(rng, true), 0.0);
  const bp::Kinematics k = kinematics_of(l, revolution(l, {6.0}, 36));
  // not force balanced
  try {
    (void)bp::moment_balance(l, k, {{0, std::nullopt}});
    ADD_FAILURE() << "an unbalanced design was moment balanced";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("starts from a fully force-balanced design"),
              std::string::npos)
        << e.what();
  }
  auto field_of = [&](const std::vector<bp::CounterRotationRequest>& asks) {
    try {
      bp::check_counter_rotations(l, asks);
    } catch (const InputError& e) {
      return e.field() ? e.field()->field + ": " + e.what() : std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(field_of({{0, std::nullopt}, {2, Vec2(1, 1)}}), "accepted");
  EXPECT_NE(field_of({{1, std::nullopt}}).find("counter_rotations.coupler: "), std::string::npos);
  EXPECT_NE(field_of({{1, std::nullopt}}).find("does not turn about one ground node"),
            std::string::npos);
  EXPECT_NE(field_of({{0, std::nullopt}, {0, std::nullopt}}).find("one counter-rotation per link"),
            std::string::npos);
  EXPECT_NE(field_of({{2, Vec2(NAN, 0)}}).find("at must be finite"), std::string::npos);
  // the default shaft: below the pivot by the link's length, as a four-bar's (0, -l1)
  const Vec2 at = bp::shaft_position(l, {0, std::nullopt});
  EXPECT_NEAR(at.x(), 0.0, 1e-15);
  EXPECT_NEAR(at.y(), -cp::element_length(l, 0), 1e-15);
}

}  // namespace
}  // namespace bd::testing::planar
