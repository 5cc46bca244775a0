// Engine balancing on the general planar engine, checked by the physics of the slider-crank and
// a direct DFT written here (no code shared with balance/planar_shafts.cpp):
//
//  * A Lanchester balancer for orders 1 and 2 (balance_shafts) removes them from the simulated
//    shaking force of random inline and offset slider-cranks at constant crank speed, to
//    round-off, and leaves every other order as it was.
//  * The balancing factor β on an inline slider-crank whose rod has its centre of mass on its
//    axis: the rod is two point masses at its pins, so the order-1 shaking force is the crank
//    pin's rotating vector plus the piston's oscillation m_rec r ω² cos θ; with the rotating mass
//    balanced and β m_rec r added opposite the pin, its forward part is |1/2 - β| m_rec r ω² and
//    its backward part 1/2 m_rec r ω², m_rec the piston with the rod's share at the wrist pin.
#include "balance/planar_shafts.hpp"

#include <gtest/gtest.h>

#include <complex>
#include <numbers>

#include "balance/planar.hpp"
#include "core/planar/simulate.hpp"
#include "tests/support/planar_mechanisms.hpp"

namespace bd::testing::planar {
namespace {

namespace bp = bd::balance::planar;
constexpr double kOmega = 150.0;  // [rad/s]

cp::Linkage bare_engine(Rng& rng, bool inline_guide) {
  cp::Linkage l = slider_crank(rng, inline_guide);
  l.springs.clear();
  l.loads = cp::Loads{};
  for (cp::Input& in : l.inputs) in.effort = cp::TimeFunction{};
  return l;
}

// one constant-speed revolution of the crank: its angles and the shaking force (x + iy)
struct Revolution {
  std::vector<double> angle;
  std::vector<std::complex<double>> force;
};
Revolution revolution(const cp::Linkage& l) {
  const cp::Model model(l);
  const cp::Trajectory tr = cp::simulate_driven(model, cp::DrivenScene{{}, {kOmega}, 1, 0, 360});
  EXPECT_TRUE(tr.ok()) << tr.message;
  Revolution r;
  const std::vector<double> th = tr.table.column_values("theta_crank"),
                            fx = tr.table.column_values("Fshx"),
                            fy = tr.table.column_values("Fshy");
  for (std::size_t j = 0; j < 360 && j < th.size(); ++j) {
    r.angle.push_back(th[j]);
    r.force.emplace_back(fx[j], fy[j]);
  }
  return r;
}

// the coefficient of e^{ikθ} in the force over the revolution
std::complex<double> order(const Revolution& r, int k) {
  std::complex<double> sum = 0;
  for (std::size_t j = 0; j < r.angle.size(); ++j)
    sum += r.force[j] * std::exp(std::complex<double>(0, -k * r.angle[j]));
  return sum / static_cast<double>(r.angle.size());
}

double size_of(const Revolution& r) {
  double s = 0;
  for (const auto& f : r.force) s = std::max(s, std::abs(f));
  return s;
}

TEST(PlanarShafts, LanchesterBalancerRemovesOrdersOneAndTwoAndLeavesTheRest) {
  Rng rng(41);
  for (int i = 0; i < 12; ++i) {
    const cp::Linkage l = bare_engine(rng, i % 2 == 0);
    bp::ShaftRequest ask;
    ask.orders = {1, 2};
    if (i % 3 == 0) ask.at = l.nodes[0].position + Vec2(0.05, -0.02);
    const bp::ShaftBalance b = bp::balance_shafts(l, ask);
    ASSERT_EQ(b.linkage.shafts.size(), 4u);  // an engine has both rotating parts of orders 1, 2
    const Revolution before = revolution(l), after = revolution(b.linkage);
    const double size = size_of(before);
    const std::string what = "engine " + std::to_string(i);
    // both exact; the DFT of 360 samples sums round-off of some 1e-15 of the force
    for (int k : {1, -1, 2, -2})
      EXPECT_LT(std::abs(order(after, k)), 1e-12 * size) << what << " order " << k;
    for (int k : {0, 3, -3, 4, -4, 5, -5, 6, -6}) {
      EXPECT_LT(std::abs(order(after, k) - order(before, k)), 1e-12 * size)
          << what << " order " << k;
    }
    // an inline engine's shaking force has no odd order above the first; an offset one has
    if (i % 2 == 0) {
      EXPECT_LT(std::abs(order(before, 3)) + std::abs(order(before, -3)), 1e-12 * size) << what;
    } else {
      EXPECT_GT(std::abs(order(before, 3)) + std::abs(order(before, -3)), 1e-6 * size) << what;
    }
    // what balance_shafts reports of the orders agrees with the simulated ones per unit ω²
    for (const bp::ShaftBalance::Order& o : b.orders) {
      EXPECT_NEAR(o.forward_before * kOmega * kOmega, std::abs(order(before, o.order)),
                  1e-10 * size);
      EXPECT_NEAR(o.backward_before * kOmega * kOmega, std::abs(order(before, -o.order)),
                  1e-10 * size);
      EXPECT_LT(o.forward_after * kOmega * kOmega, 1e-12 * size);
    }
  }
}

TEST(PlanarShafts, BalancingFactorLeavesTheTextbookPrimaryParts) {
  Rng rng(43);
  for (int i = 0; i < 9; ++i) {
    cp::Linkage l = bare_engine(rng, true);
    cp::Link& rod = l.links[1];
    rod.f = 0;  // its centre of mass on the axis A-B: two point masses at A and B
    const int A = l.links[0].nodes[1], B = l.sliders[0].node;
    const Vec2 a = l.nodes[static_cast<std::size_t>(A)].position,
               bpos = l.nodes[static_cast<std::size_t>(B)].position;
    const Vec2 first = l.nodes[static_cast<std::size_t>(rod.nodes[0])].position,
               second = l.nodes[static_cast<std::size_t>(rod.nodes[1])].position;
    const Vec2 c = first + rod.e * (second - first).normalized();
    const double rod_length = (bpos - a).norm();
    double m_rec = rod.mass * (c - a).norm() / rod_length;  // the rod's share at the wrist pin
    for (const cp::PointMass& pm : l.point_masses) m_rec += pm.node == B ? pm.mass : 0.0;
    const double r = (a - l.nodes[0].position).norm();

    const double beta = 0.5 * (i % 3);
    const cp::Model model(l);
    const cp::Trajectory tr = cp::simulate_driven(model, cp::DrivenScene{{}, {kOmega}, 1, 0, 360});
    ASSERT_TRUE(tr.ok());
    const bp::InputSeries in = bp::input_series(model, tr.table);
    const auto k = bp::kinematics(model, in.values, in.rates, in.accelerations);
    ASSERT_TRUE(k);
    balance::CounterweightSpec spec;
    spec.distance = r;
    const bp::ForceBalance design = bp::force_balance(l, *k, {{0, spec}}, beta);
    EXPECT_FALSE(design.full);
    EXPECT_NE(design.message.find("balancing factor"), std::string::npos);
    const Revolution after = revolution(design.linkage);
    const double primary = m_rec * r * kOmega * kOmega;
    const std::string what = "engine " + std::to_string(i) + ", beta " + std::to_string(beta);
    // the samples' round-off: 1e-12 of the primary force
    EXPECT_NEAR(std::abs(order(after, 1)), std::abs(0.5 - beta) * primary, 1e-12 * primary) << what;
    EXPECT_NEAR(std::abs(order(after, -1)), 0.5 * primary, 1e-12 * primary) << what;
  }
}

TEST(PlanarShafts, BalancingFactorNeedsACrankDrivingAPiston) {
  Rng rng(47);
  cp::Linkage l = bare_engine(rng, true);
  balance::CounterweightSpec spec;
  // a counterweight on the connecting rod: not a crank
  EXPECT_THROW(bp::check_balancing_factor(l, {{1, spec}}, 0.5), InputError);
  EXPECT_THROW(bp::check_balancing_factor(l, {{0, spec}}, -0.1), InputError);
  EXPECT_NO_THROW(bp::check_balancing_factor(l, {{0, spec}}, 0.5));
  l.sliders.clear();  // no piston on a frame guide
  l.inputs = {angle_input("crank", 0)};
  EXPECT_THROW(bp::check_balancing_factor(l, {{0, spec}}, 0.5), InputError);
}

}  // namespace
}  // namespace bd::testing::planar
