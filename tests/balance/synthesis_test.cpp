// The balance section's synthesis: force and moment steps as the request asks, what was added,
// and errors tagged with the step that failed (so the loader can point at its key).
#include "balance/synthesis.hpp"

#include <gtest/gtest.h>

#include "core/fourbar/samples.hpp"

namespace bd::balance {
namespace {

// an inline four-bar with a Berkof coupler: f2 = 0, I2 = m2 e2 (l2 - e2)
core::FourBar berkof_inline() {
  core::FourBar m = core::samples::paper_fourbar_unloaded();
  m.crank = {1.0, 2.0, 0.5, 0.0, 0.2};
  m.coupler = {3.0, 3.0, 1.2, 0.0, 3.0 * 1.2 * 1.8};
  m.rocker = {2.0, 2.2, 1.0, 0.0, 0.8};
  return core::make_fourbar(m);
}

TEST(BalanceDesign, ForceOnlyAddsCounterweightsAndKeepsTheCoupler) {
  const core::FourBar model = core::samples::paper_fourbar_unloaded();
  const BalancedDesign d = balance_design(model, BalanceRequest{});
  EXPECT_TRUE(d.conditions.force_balanced()) << d.conditions.text();
  ASSERT_TRUE(d.crank_counterweight && d.rocker_counterweight);
  EXPECT_EQ(d.added_mass, d.crank_counterweight->mass + d.rocker_counterweight->mass);
  EXPECT_EQ(d.model.coupler.mass, model.coupler.mass);
  EXPECT_EQ(d.model.coupler.inertia, model.coupler.inertia);
  EXPECT_FALSE(core::has_counter_rotations(d.model));
}

TEST(BalanceDesign, NothingAskedLeavesTheDesignAsItIs) {
  BalanceRequest none;
  none.force = false;
  const core::FourBar model = core::samples::paper_fourbar();
  const BalancedDesign d = balance_design(model, none);
  EXPECT_FALSE(d.crank_counterweight.has_value());
  EXPECT_FALSE(d.rocker_counterweight.has_value());
  EXPECT_EQ(d.model.crank.mass, model.crank.mass);
  EXPECT_EQ(d.model.loads.crank.force, model.loads.crank.force);
  EXPECT_EQ(d.added_mass, 0.0);
  EXPECT_EQ(d.added_inertia, 0.0);
}

TEST(BalanceDesign, MomentBalanceAddsReducedInertiasAtTheShafts) {
  BalanceRequest full;
  full.moment = true;
  const BalancedDesign d = balance_design(berkof_inline(), full);
  EXPECT_TRUE(d.conditions.moment_balanced()) << d.conditions.text();
  const core::CounterRotations& c = d.model.counter_rotations;
  EXPECT_EQ(c.crank.at, crank_shaft(full, d.model));
  EXPECT_EQ(c.crank.at, Vec2(0, -1.0));
  EXPECT_EQ(c.rocker.at, Vec2(3.2, -2.0));
  // counterweight inertias about the pivots plus the discs' J
  const BalancedDesign f = balance_design(berkof_inline(), BalanceRequest{});
  EXPECT_DOUBLE_EQ(d.added_inertia, f.added_inertia + c.crank.inertia + c.rocker.inertia);
  EXPECT_EQ(d.added_mass, f.added_mass);

  full.crank_at = Vec2(0.5, 0.5);
  EXPECT_EQ(balance_design(berkof_inline(), full).model.counter_rotations.crank.at, Vec2(0.5, 0.5));
}

TEST(BalanceDesign, ErrorsSayWhichStepFailed) {
  BalanceRequest moment_only;
  moment_only.force = false;
  moment_only.moment = true;
  try {
    balance_design(berkof_inline(), moment_only);
    ADD_FAILURE() << "no error";
  } catch (const SynthesisError& e) {
    EXPECT_EQ(e.step(), SynthesisError::Step::kMoment);
    EXPECT_NE(std::string(e.what()).find("force: full"), std::string::npos) << e.what();
  }

  BalanceRequest full;
  full.moment = true;
  try {
    balance_design(core::samples::paper_fourbar_unloaded(), full);  // not a Berkof coupler
    ADD_FAILURE() << "no error";
  } catch (const SynthesisError& e) {
    EXPECT_EQ(e.step(), SynthesisError::Step::kMoment);
    EXPECT_NE(std::string(e.what()).find("Berkof"), std::string::npos) << e.what();
  }

  BalanceRequest bad;
  bad.crank_counterweight.mass = -1.0;  // the loader checks this first; the balance layer too
  try {
    balance_design(core::samples::paper_fourbar_unloaded(), bad);
    ADD_FAILURE() << "no error";
  } catch (const SynthesisError& e) {
    EXPECT_EQ(e.step(), SynthesisError::Step::kForce);
    EXPECT_NE(std::string(e.what()).find("crank counterweight"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace bd::balance
