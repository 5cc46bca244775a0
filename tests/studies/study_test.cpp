// The method chooser: what `auto` picks for each kind of scene and linkage, and why.
#include "studies/study.hpp"

#include <gtest/gtest.h>

#include "core/samples.hpp"

namespace bd::studies {
namespace {

Study study_of(const core::FourBar& model, Scene scene) {
  Study s;
  s.name = "t";
  s.model = model;
  s.scene = scene;
  return s;
}

TEST(ChooseMethod, FreeTurningCrankTakesTheCheapestExactFormulation) {
  const MethodChoice c = choose_method(
      study_of(core::samples::paper_fourbar(), core::FreeScene{1.0, 0.0, 5.0, 501}));
  EXPECT_EQ(c.formulation, core::Formulation::kMassMatrix);
  EXPECT_NE(c.reason.find("cheapest exact formulation"), std::string::npos) << c.reason;
  EXPECT_NE(c.reason.find("reduced equation in theta1"), std::string::npos) << c.reason;
}

TEST(ChooseMethod, DrivenSceneNeedsNoIntegrator) {
  const MethodChoice c = choose_method(
      study_of(core::samples::paper_fourbar(), core::DrivenScene{0.0, 6.28, 1, 360}));
  EXPECT_EQ(c.formulation, core::Formulation::kMassMatrix);
  EXPECT_NE(c.reason.find("no integrator"), std::string::npos) << c.reason;
}

TEST(ChooseMethod, FreeCrankReachingLimitPositionsTakesTheOpenedLoopDae) {
  const MethodChoice c = choose_method(
      study_of(core::samples::triple_rocker(), core::FreeScene{0.0, 1.0, 20.0, 2001}));
  EXPECT_EQ(c.formulation, core::Formulation::kOpenedLoop);
  EXPECT_NE(c.reason.find("cannot turn fully (non-Grashof)"), std::string::npos) << c.reason;
  EXPECT_NE(c.reason.find("DAE"), std::string::npos) << c.reason;
}

TEST(ChooseMethod, RequestedMethodIsUsedAndTheReasonSaysWhatAutoWouldDo) {
  Study s = study_of(core::samples::triple_rocker(), core::FreeScene{0.0, 1.0, 20.0, 2001});
  s.formulation = core::Formulation::kMassMatrix;
  const MethodChoice c = choose_method(s);
  EXPECT_EQ(c.formulation, core::Formulation::kMassMatrix);
  EXPECT_NE(c.reason.find("requested in the study file"), std::string::npos) << c.reason;
  EXPECT_NE(c.reason.find("auto would take the opened-loop DAE"), std::string::npos) << c.reason;
}

TEST(ChooseMethod, FormulationNames) {
  EXPECT_EQ(formulation_named("opened-loop"), core::Formulation::kOpenedLoop);
  EXPECT_EQ(formulation_named("complex-masses"), core::Formulation::kComplexMasses);
  EXPECT_EQ(formulation_named("mass-matrix"), core::Formulation::kMassMatrix);
  EXPECT_FALSE(formulation_named("auto").has_value());
  EXPECT_FALSE(formulation_named("newton-euler").has_value());
}

}  // namespace
}  // namespace bd::studies
