// Mobility: a linkage needs exactly one input per degree of freedom. With too many inputs (over-
// constrained: the inputs fight each other) or too few (the motion is not determined), both
// scenes refuse it with a bd::InputError on linkage.inputs that says how many degrees of freedom
// the linkage has and how many inputs it was given.
#include <gtest/gtest.h>

#include <functional>
#include <random>

#include "core/input_error.hpp"
#include "core/planar/simulate.hpp"
#include "tests/support/planar_mechanisms.hpp"

namespace bd::testing::planar {
namespace {

// Expects both scenes to refuse the linkage, the message naming `dof` and `inputs`.
void expect_refused(const cp::Linkage& l, int dof, int inputs, const std::string& label) {
  const cp::Model model(l);
  EXPECT_EQ(cp::mobility(model), dof) << label;
  const std::string expected = "the linkage has " + std::to_string(dof) + " degree" +
                               (dof == 1 ? "" : "s") + " of freedom and " + std::to_string(inputs) +
                               " input" + (inputs == 1 ? "" : "s");
  auto check = [&](const std::function<void()>& run, const char* scene) {
    try {
      run();
      ADD_FAILURE() << label << ": " << scene << " accepted " << inputs << " inputs for " << dof
                    << " degrees of freedom";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos)
          << label << " (" << scene << "): " << e.what() << "\n expected: " << expected;
      ASSERT_TRUE(e.field().has_value()) << label;
      EXPECT_EQ(e.field()->field, "linkage.inputs") << label;
    }
  };
  cp::DrivenScene driven;
  driven.speeds.assign(static_cast<std::size_t>(inputs), 1.0);
  driven.duration = 1.0;  // needed when no input is an angle
  driven.samples = 10;
  check([&] { cp::simulate_driven(model, driven); }, "simulate_driven");
  for (cp::Route route : {cp::Route::kReduced, cp::Route::kDae}) {
    cp::SimulateOptions o;
    o.route = route;
    check([&] { cp::simulate_free(model, cp::FreeScene{{}, {}, 0.1, 11}, o); },
          route == cp::Route::kDae ? "simulate_free (dae)" : "simulate_free (reduced)");
  }
}

TEST(Mobility, TooManyInputsAreRefused) {
  Rng rng(501);
  for (int i = 0; i < 4; ++i) {
    // a slider-crank (1 degree of freedom) driven by its crank and its piston
    cp::Linkage l = slider_crank(rng, coin(rng));
    l.inputs.push_back(slide_input("piston", 0));
    expect_refused(cp::make_linkage(l), 1, 2, "slider-crank, crank and piston");
    // a six-bar (1) driven by its crank and its last link
    l = six_bar_or_retry(rng, coin(rng));
    l.inputs.push_back(angle_input("link6", 4));
    expect_refused(cp::make_linkage(l), 1, 2, "six-bar, crank and link6");
  }
}

TEST(Mobility, TooFewInputsAreRefused) {
  Rng rng(502);
  for (int i = 0; i < 4; ++i) {
    // a five-bar (2 degrees of freedom) driven by one crank
    cp::Linkage l = five_bar(rng);
    l.inputs.pop_back();
    expect_refused(cp::make_linkage(l), 2, 1, "five-bar, one crank");
    // a six-bar (1) without an input
    l = six_bar_or_retry(rng, coin(rng));
    l.inputs.clear();
    expect_refused(cp::make_linkage(l), 1, 0, "six-bar, no input");
  }
}

TEST(Mobility, AStructureWithAnInputIsRefused) {
  // a triangle of two links pinned to the frame and to each other: no degree of freedom
  cp::Linkage l;
  l.nodes = {{"O", Vec2(0, 0), true}, {"P", Vec2(0.3, 0.1), false}, {"Q", Vec2(0.5, 0), true}};
  l.links = {{"a", {0, 1}, 1.0, 0.15, 0, 0.01}, {"b", {2, 1}, 1.0, 0.1, 0, 0.01}};
  l.inputs = {angle_input("a", 0)};
  expect_refused(cp::make_linkage(l), 0, 1, "triangle");
}

TEST(Mobility, OneInputPerDegreeOfFreedomIsAccepted) {
  // the counterpart: the same linkages with the right inputs run
  Rng rng(503);
  const cp::Model five(five_bar(rng));
  EXPECT_EQ(cp::mobility(five), 2);
  cp::DrivenScene scene;
  scene.speeds = {10.0, -7.0};
  scene.samples = 12;
  EXPECT_TRUE(cp::simulate_driven(five, scene).ok());
  const cp::Model six(six_bar_or_retry(rng, false));
  EXPECT_EQ(cp::mobility(six), 1);
  EXPECT_TRUE(cp::simulate_free(six, cp::FreeScene{{}, {10.0}, 0.05, 6}).ok());
}

}  // namespace
}  // namespace bd::testing::planar
