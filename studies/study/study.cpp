#include "studies/study/study.hpp"

#include <cassert>
#include <string>
#include <utility>

namespace bd::studies {

const char* scene_type(const Scene& scene) {
  return std::holds_alternative<core::FreeScene>(scene) ? "free" : "driven";
}

std::optional<core::Formulation> formulation_named(const std::string& name) {
  for (core::Formulation f : core::kFormulations) {
    if (name == core::to_string(f)) return f;
  }
  return std::nullopt;
}

std::string Study::method_name() const {
  return formulation ? std::string(core::to_string(*formulation)) : std::string("auto");
}

Study balanced_study(const Study& study) {
  assert(study.balance.has_value());
  Study b;
  b.name = study.name + "-balanced";
  b.model = study.balance->model;
  b.scene = study.scene;
  b.formulation = study.formulation;
  b.tolerance = study.tolerance;
  return b;
}

Study optimized_study(const Study& study, const core::FourBar& design) {
  Study o;
  o.name = study.name + "-optimized";
  o.model = design;
  o.scene = study.scene;
  o.formulation = study.formulation;
  o.tolerance = study.tolerance;
  return o;
}

optimize::DesignProblem design_problem(const Study& study) {
  assert(study.optimize.has_value());
  const OptimizeRequest& r = *study.optimize;
  optimize::DesignProblem p;
  p.original = study.model;
  p.scene = study.scene;
  p.formulation = choose_method(study).formulation;
  p.tolerance = study.tolerance;
  p.counterweights = r.counterweights;
  p.link_parameters = r.link_parameters;
  p.objective = r.objective;
  p.limits = r.limits;
  p.force_balance = r.force_balance;
  return p;
}

namespace {

// Below this tolerance the opened loop is integrated by the order-8 pair, above it by the
// order-5 pair (docs/performance.md "Recommendation"). Through the triple rocker's limit
// positions (20 s, 2001 samples): Dormand-Prince 5(4) gives 7.9 correct digits in 8.6 ms at
// tolerance 1e-8, but no more at 1e-9 (12 ms) and 8.6 at 1e-10 (17 ms); Fehlberg 8(7), its steps
// ending at every sample, 12 digits in 15 ms at any tolerance from 1e-3 to 1e-11. CVODE Adams
// (Baumgarte) gives 4.1 / 5.0 / 6.3 digits in 5.8 / 7.0 / 9.5 ms at 1e-8 / 1e-9 / 1e-10, BDF
// with projection 3.7 / 7.3 / 6.5 digits in 12 / 16 / 21 ms: both lie above the pairs' front.
constexpr double kOpenedLoopErk8Below = 1e-8;

// the integrator of formulation f at a tolerance, and why
std::pair<core::Integrator, std::string> integrator_for(core::Formulation f, double tolerance) {
  if (f != core::Formulation::kOpenedLoop) {
    return {core::Integrator::kCvodeAdams,
            "reduced equation in theta1 integrated by CVODE Adams, on the front of the "
            "work-precision chart at every tolerance (paper example: 10.9 correct digits in "
            "0.56 ms at tolerance 1e-12, docs/performance.md)"};
  }
  if (tolerance < kOpenedLoopErk8Below) {
    return {core::Integrator::kErk8,
            "DAE in theta1..theta3 integrated by the Fehlberg 8(7) Runge-Kutta pair (Baumgarte "
            "stabilisation, steps ending at every sample): below tolerance 1e-8 the most "
            "correct digits per CPU time through limit positions (docs/performance.md)"};
  }
  return {core::Integrator::kErk5,
          "DAE in theta1..theta3 integrated by the Dormand-Prince 5(4) Runge-Kutta pair "
          "(Baumgarte stabilisation): from tolerance 1e-8 up the most correct digits per CPU "
          "time (docs/performance.md)"};
}

}  // namespace

MethodChoice choose_method(const Study& study) {
  const bool free = std::holds_alternative<core::FreeScene>(study.scene);
  // a free crank that cannot turn fully reaches limit positions, where theta1 stops being a
  // coordinate: only the opened loop's DAE goes through them
  const bool reaches_limits = free && !core::crank_turns_fully(study.model);
  const std::string limits = std::string("the crank cannot turn fully (") +
                             core::to_string(core::classify_grashof(study.model)) +
                             ") and reaches limit positions";

  MethodChoice choice;
  if (study.formulation) {
    choice.formulation = *study.formulation;
    choice.reason = "requested in the study file";
    if (reaches_limits && choice.formulation != core::Formulation::kOpenedLoop) {
      choice.reason += "; " + limits +
                       ", where this reduced equation in theta1 stops (auto would take the "
                       "opened-loop DAE through them)";
    }
  } else if (reaches_limits) {
    choice.formulation = core::Formulation::kOpenedLoop;
    choice.reason = limits +
                    "; the opened-loop DAE passes through them, the reduced equation "
                    "in theta1 would stop at the first";
  } else {
    choice.formulation = core::Formulation::kMassMatrix;
    choice.reason =
        "the cheapest exact formulation per evaluation (about 1.2k instructions against 1.6k "
        "for complex-masses and 1.85k for opened-loop, docs/performance.md); all three agree to "
        "round-off";
  }
  if (!free) {
    choice.reason += "; no integrator: kinetostatics per sample";
  } else {
    const auto [integrator, why] = integrator_for(choice.formulation, study.tolerance);
    choice.integrator = integrator;
    choice.reason += "; " + why;
  }
  return choice;
}

}  // namespace bd::studies
