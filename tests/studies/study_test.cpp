// The method chooser: what `auto` picks for each kind of scene and linkage, and why.
#include "studies/study/method.hpp"
#include "studies/study/study.hpp"

#include <gtest/gtest.h>

#include "core/fourbar/samples.hpp"

namespace bd::studies {
namespace {

Study study_of(const core::FourBar& model, Scene scene) {
  Study s;
  s.name = "t";
  s.fourbar() = model;
  s.scene = scene;
  return s;
}

TEST(ChooseMethod, FreeTurningCrankTakesTheCheapestExactFormulation) {
  const MethodChoice c =
      choose_method(study_of(core::samples::paper_fourbar(), core::FreeScene{1.0, 0.0, 5.0, 501}));
  EXPECT_EQ(c.formulation, core::Formulation::kMassMatrix);
  EXPECT_NE(c.reason.find("the exact equation of motion in the crank angle"), std::string::npos)
      << c.reason;
  EXPECT_NE(c.numerics.find("CVODE Adams"), std::string::npos) << c.numerics;
}

TEST(ChooseMethod, DrivenSceneNeedsNoIntegrator) {
  const MethodChoice c =
      choose_method(study_of(core::samples::paper_fourbar(), core::DrivenScene{0.0, 6.28, 1, 360}));
  EXPECT_EQ(c.formulation, core::Formulation::kMassMatrix);
  EXPECT_NE(c.reason.find("the drive prescribes the motion"), std::string::npos) << c.reason;
  EXPECT_NE(c.reason.find("nothing integrated"), std::string::npos) << c.reason;
  EXPECT_EQ(c.numerics, "none: inverse dynamics at each sample");
}

TEST(ChooseMethod, FreeCrankReachingLimitPositionsTakesTheOpenedLoopDae) {
  const MethodChoice c = choose_method(
      study_of(core::samples::triple_rocker(), core::FreeScene{0.0, 1.0, 20.0, 2001}));
  EXPECT_EQ(c.formulation, core::Formulation::kOpenedLoop);
  EXPECT_NE(c.reason.find("cannot turn fully (non-Grashof)"), std::string::npos) << c.reason;
  EXPECT_NE(c.reason.find("all three link angles"), std::string::npos) << c.reason;
  EXPECT_NE(c.reason.find("through its limit positions"), std::string::npos) << c.reason;
}

TEST(ChooseMethod, RequestedMethodIsUsedAndTheReasonSaysWhatAutoWouldDo) {
  Study s = study_of(core::samples::triple_rocker(), core::FreeScene{0.0, 1.0, 20.0, 2001});
  s.method = Method::kMassMatrix;
  const MethodChoice c = choose_method(s);
  EXPECT_EQ(c.formulation, core::Formulation::kMassMatrix);
  EXPECT_EQ(c.reason.rfind("as the study asks: ", 0), 0u) << c.reason;
  EXPECT_NE(c.reason.find("stops at its first limit position (auto follows it through)"),
            std::string::npos)
      << c.reason;
}

TEST(ChooseMethod, FreeTurningCrankIsIntegratedByCvodeAdams) {
  // the fastest integrator of the reduced equation at every tolerance (docs/performance.md)
  for (double tolerance : {1e-4, 1e-10, 1e-13}) {
    Study s = study_of(core::samples::paper_fourbar(), core::FreeScene{1.0, 0.0, 5.0, 501});
    s.tolerance = tolerance;
    const MethodChoice c = choose_method(s);
    EXPECT_EQ(c.integrator, core::Integrator::kCvodeAdams) << tolerance;
    EXPECT_NE(c.numerics.find("CVODE Adams"), std::string::npos) << c.numerics;
  }
}

TEST(ChooseMethod, OpenedLoopIntegratorFollowsTheTolerance) {
  // through limit positions: the order-8 pair below 1e-8, the order-5 pair from 1e-8 up
  Study s = study_of(core::samples::triple_rocker(), core::FreeScene{0.0, 1.0, 20.0, 2001});
  s.tolerance = 1e-10;
  MethodChoice c = choose_method(s);
  EXPECT_EQ(c.formulation, core::Formulation::kOpenedLoop);
  EXPECT_EQ(c.integrator, core::Integrator::kErk8);
  EXPECT_NE(c.numerics.find("Fehlberg 8(7) Runge-Kutta pair"), std::string::npos) << c.numerics;
  s.tolerance = 1e-8;
  c = choose_method(s);
  EXPECT_EQ(c.integrator, core::Integrator::kErk5);
  EXPECT_NE(c.numerics.find("Dormand-Prince 5(4) Runge-Kutta pair"), std::string::npos)
      << c.numerics;
  // a requested formulation gets the integrator auto would give it
  Study paper = study_of(core::samples::paper_fourbar(), core::FreeScene{1.0, 0.0, 5.0, 501});
  paper.method = Method::kOpenedLoop;
  EXPECT_EQ(choose_method(paper).integrator, core::Integrator::kErk8);
  paper.method = Method::kComplexMasses;
  EXPECT_EQ(choose_method(paper).integrator, core::Integrator::kCvodeAdams);
  // every choice is a valid combination
  for (const Study& t : {s, paper}) {
    core::SimulateOptions o;
    o.formulation = choose_method(t).formulation;
    o.integrator = choose_method(t).integrator;
    EXPECT_EQ(problem_text(o.validate()), "");
  }
}

TEST(ChooseMethod, FormulationNames) {
  EXPECT_EQ(method_named("opened-loop"), Method::kOpenedLoop);
  EXPECT_EQ(method_named("complex-masses"), Method::kComplexMasses);
  EXPECT_EQ(method_named("mass-matrix"), Method::kMassMatrix);
  EXPECT_EQ(method_named("auto"), Method::kAuto);
  EXPECT_EQ(method_named("truss"), Method::kTruss);
  EXPECT_EQ(method_named("truss-dae"), Method::kTrussDae);
  EXPECT_FALSE(method_named("newton-euler").has_value());
  EXPECT_EQ(formulation_of(Method::kOpenedLoop), core::Formulation::kOpenedLoop);
  EXPECT_FALSE(formulation_of(Method::kTruss).has_value());
}

}  // namespace
}  // namespace bd::studies
