// The design problem (optimize/problem.hpp): metric names and DesignProblem::validate()'s
// messages, one per mistake.
#include "optimize/problem.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "core/fourbar/samples.hpp"

namespace bd::optimize {
namespace {

using P = LinkParameterVariable::Parameter;

TEST(Problem, MetricNamesRoundTrip) {
  const char* names[] = {"Fsh_rms", "Fsh_max", "Msh_rms", "Msh_max", "tau_rms",   "tau_max",
                         "RA0_rms", "RA0_max", "RA3_rms", "RA3_max", "added_mass"};
  ASSERT_EQ(std::size(kMetrics), std::size(names));
  for (std::size_t i = 0; i < std::size(kMetrics); ++i) {
    EXPECT_STREQ(to_string(kMetrics[i]), names[i]);
    EXPECT_EQ(metric_named(names[i]), kMetrics[i]);
    EXPECT_EQ(is_peak(kMetrics[i]), std::string(names[i]).ends_with("_max")) << names[i];
  }
  EXPECT_FALSE(metric_named("Fsh_RMS"));
  EXPECT_FALSE(metric_named(""));
}

TEST(Problem, ObjectiveFormNamesRoundTripAndTheDefaultIsLinear) {
  for (ObjectiveForm f : {ObjectiveForm::kLinear, ObjectiveForm::kSquared}) {
    EXPECT_EQ(objective_form_named(to_string(f)), f);
  }
  EXPECT_STREQ(to_string(ObjectiveForm::kLinear), "linear");
  EXPECT_STREQ(to_string(ObjectiveForm::kSquared), "squared");
  EXPECT_FALSE(objective_form_named("Linear"));
  EXPECT_EQ(DesignProblem{}.objective_form, ObjectiveForm::kLinear);  // the weighted sum
  EXPECT_EQ(DesignProblem{}.smoothing, kDefaultSmoothing);
}

DesignProblem valid_problem() {
  DesignProblem p;
  p.original = core::samples::paper_fourbar();
  core::DrivenScene scene;
  scene.omega1 = 2.0;
  scene.samples = 36;
  p.scene = scene;
  CounterweightVariables c1;
  c1.link = 1;
  CounterweightVariables c3;
  c3.link = 3;
  c3.shape = balance::CounterweightShape::kDisc;
  p.counterweights = {c1, c3};
  p.link_parameters = {{2, P::kMass, 1.0, 5.0}, {2, P::kInertia, 0.0, 4.0}, {3, P::kE, -1, 2}};
  p.objective = {{Metric::kFshRms, 1.0}, {Metric::kMshMax, 0.0}};
  p.limits = {{Metric::kTauMax, 1.2}, {Metric::kAddedMass, 0.0}};
  return p;
}

// validate()'s problem after a change of the valid problem: its text, "" when there is none
template <class Change>
std::string message_after(Change change) {
  DesignProblem p = valid_problem();
  change(p);
  const Problem e = p.validate();
  return e ? e->text() : "";
}

// the field and index of validate()'s problem after a change
template <class Change>
std::pair<std::string, int> field_after(Change change) {
  DesignProblem p = valid_problem();
  change(p);
  const Problem e = p.validate();
  return e ? std::pair{e->field, e->index} : std::pair{std::string("none"), -1};
}

TEST(Problem, ValidProblemsPass) {
  EXPECT_FALSE(valid_problem().validate());
  // link parameters alone, a free scene, an added-mass limit below zero (remove mass)
  EXPECT_EQ(message_after([](DesignProblem& p) {
              p.counterweights.clear();
              p.scene = core::FreeScene{0.0, 1.0, 2.0, 11};
              p.limits = {{Metric::kAddedMass, -0.5}};
            }),
            "");
}

TEST(Problem, ValidateNamesEachMistake) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(message_after([](DesignProblem& p) { p.original.coupler.mass = -1.2; }),
            "original design: coupler.mass must be > 0 kg, got -1.2");
  EXPECT_EQ(message_after([](DesignProblem& p) {
              p.counterweights.clear();
              p.link_parameters.clear();
            }),
            "no design variables: give at least one counterweight or link parameter");
  EXPECT_EQ(message_after([](DesignProblem& p) { p.counterweights[1].link = 2; }),
            "counterweights[1].link must be 1 (crank) or 3 (rocker), got 2");
  EXPECT_EQ(message_after([](DesignProblem& p) { p.counterweights[1].link = 1; }),
            "counterweights[1]: a second counterweight on the crank (counterweights[0] is there "
            "already); at most one per link");
  EXPECT_EQ(message_after([](DesignProblem& p) { p.counterweights[0].mass_max = 0; }),
            "counterweights[0].mass_max must be > 0 kg, got 0");
  EXPECT_EQ(message_after([](DesignProblem& p) { p.counterweights[0].distance_max = -1; }),
            "counterweights[0].distance_max must be > 0 m, got -1");
  EXPECT_EQ(message_after([](DesignProblem& p) { p.counterweights[1].thickness = 0; }),
            "counterweights[1].thickness must be > 0 m, got 0");
  EXPECT_EQ(message_after([nan](DesignProblem& p) { p.counterweights[1].density = nan; }),
            "counterweights[1].density must be > 0 kg/m^3, got nan");
  // a point counterweight ignores thickness and density
  EXPECT_EQ(message_after([](DesignProblem& p) { p.counterweights[0].density = 0; }), "");
  EXPECT_EQ(message_after([](DesignProblem& p) { p.link_parameters[0].link = 4; }),
            "link_parameters[0].link must be 1, 2 or 3, got 4");
  EXPECT_EQ(message_after([](DesignProblem& p) {
              p.link_parameters[2] = {2, P::kMass, 1, 2};
            }),
            "link_parameters[2] (coupler.mass) appears twice");
  EXPECT_EQ(message_after([](DesignProblem& p) { p.link_parameters[0].lower = 0; }),
            "link_parameters[0] (coupler.mass).lower must be > 0 kg, got 0");
  EXPECT_EQ(
      message_after([](DesignProblem& p) { p.link_parameters[1].lower = -0.1; }),
      "link_parameters[1] (coupler.inertia).lower must be >= 0 kg m², got -0.10000000000000001");
  EXPECT_EQ(message_after([](DesignProblem& p) { p.link_parameters[2].upper = -2; }),
            "link_parameters[2] (rocker.e).upper must be >= lower = -1 m, got -2");
  EXPECT_EQ(message_after([nan](DesignProblem& p) { p.link_parameters[2].lower = nan; }),
            "link_parameters[2] (rocker.e).lower must be finite m, got nan");
  EXPECT_EQ(message_after([](DesignProblem& p) { p.objective.clear(); }),
            "objective: give at least one term");
  EXPECT_EQ(message_after([](DesignProblem& p) { p.objective[1].weight = -1; }),
            "objective[1].weight (Msh_max) must be >= 0, got -1");
  EXPECT_EQ(message_after([](DesignProblem& p) { p.objective[0].weight = 0; }),
            "objective: at least one term needs a weight > 0, all are 0");
  EXPECT_EQ(message_after([](DesignProblem& p) { p.smoothing = 0; }),
            "smoothing must be in (0, 0.1], got 0");
  EXPECT_EQ(message_after([](DesignProblem& p) { p.smoothing = 0.5; }),
            "smoothing must be in (0, 0.1], got 0.5");
  EXPECT_EQ(message_after([nan](DesignProblem& p) { p.smoothing = nan; }),
            "smoothing must be in (0, 0.1], got nan");
  EXPECT_EQ(message_after([](DesignProblem& p) { p.objective_form = ObjectiveForm{7}; }),
            "objective_form must be linear or squared");
  EXPECT_EQ(message_after([](DesignProblem& p) {
              p.objective_form = ObjectiveForm::kSquared;
              p.smoothing = 1e-3;
            }),
            "");
  EXPECT_EQ(message_after([](DesignProblem& p) { p.limits[0].value = 0; }),
            "limits[0].value (tau_max) must be > 0 (a fraction of the original), got 0");
  EXPECT_EQ(message_after([](DesignProblem& p) {
              p.limits[1].value = std::numeric_limits<double>::infinity();
            }),
            "limits[1].value (added_mass) must be finite kg, got inf");
  EXPECT_EQ(message_after([](DesignProblem& p) {
              p.scene = core::DrivenScene{0.0, 0.0, 1, 36};
            }),
            "scene.omega1 must be finite and != 0 rad/s, got 0");
  EXPECT_EQ(message_after([](DesignProblem& p) {
              p.scene = core::DrivenScene{0.0, 1.0, 0, 36};
            }),
            "scene.revolutions must be >= 1, got 0");
  EXPECT_EQ(message_after([](DesignProblem& p) {
              p.scene = core::FreeScene{0.0, 1.0, 0.0, 11};
            }),
            "scene.duration must be > 0 s, got 0");
  EXPECT_EQ(message_after([](DesignProblem& p) {
              p.scene = core::FreeScene{0.0, 1.0, 1.0, 1};
            }),
            "scene.samples must be >= 2, got 1");
  EXPECT_EQ(message_after([](DesignProblem& p) {
              p.scene = core::FreeScene{0.0, 1.0, 1.0, 11};
              p.tolerance = 0;
            }),
            "tolerance must be > 0, got 0");
  // free motion has no drive torque
  EXPECT_EQ(message_after([](DesignProblem& p) {
              p.scene = core::FreeScene{0.0, 1.0, 1.0, 11};
              p.objective[1] = {Metric::kTauRms, 1.0};
            }),
            "objective[1]: tau_rms is 0 in a free scene (no drive torque)");
  EXPECT_EQ(message_after([](DesignProblem& p) {
              p.scene = core::FreeScene{0.0, 1.0, 1.0, 11};
            }),
            "limits[0]: tau_max is 0 in a free scene (no drive torque)");
}

TEST(Problem, ValidateNamesTheFieldOfEachMistake) {
  using Field = std::pair<std::string, int>;
  EXPECT_EQ(field_after([](DesignProblem& p) { p.original.coupler.mass = -1.2; }),
            Field("original", -1));
  EXPECT_EQ(field_after([](DesignProblem& p) {
              p.scene = core::DrivenScene{0.0, 0.0, 1, 36};
            }),
            Field("scene.omega1", -1));
  EXPECT_EQ(field_after([](DesignProblem& p) {
              p.counterweights.clear();
              p.link_parameters.clear();
            }),
            Field("", -1));
  // an element as a whole: the list and the index; one field of an element: its path
  EXPECT_EQ(field_after([](DesignProblem& p) { p.counterweights[1].link = 1; }),
            Field("counterweights", 1));
  EXPECT_EQ(field_after([](DesignProblem& p) { p.counterweights[1].link = 2; }),
            Field("counterweights[1].link", -1));
  EXPECT_EQ(field_after([](DesignProblem& p) { p.link_parameters[0].lower = 0; }),
            Field("link_parameters", 0));
  EXPECT_EQ(field_after([](DesignProblem& p) { p.objective.clear(); }), Field("objective", -1));
  EXPECT_EQ(field_after([](DesignProblem& p) { p.objective[1].weight = -1; }),
            Field("objective[1].weight", -1));
  EXPECT_EQ(field_after([](DesignProblem& p) {
              p.scene = core::FreeScene{0.0, 1.0, 1.0, 11};
              p.objective[1] = {Metric::kTauRms, 1.0};
            }),
            Field("objective", 1));
  EXPECT_EQ(field_after([](DesignProblem& p) {
              p.scene = core::FreeScene{0.0, 1.0, 1.0, 11};
            }),
            Field("limits", 0));
  EXPECT_EQ(field_after([](DesignProblem& p) { p.limits[0].value = 0; }),
            Field("limits[0].value", -1));
  EXPECT_EQ(field_after([](DesignProblem& p) { p.smoothing = 0; }), Field("smoothing", -1));
}

}  // namespace
}  // namespace bd::optimize
