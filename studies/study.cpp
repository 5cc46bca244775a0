#include "studies/study.hpp"

#include <cassert>

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
    choice.reason = limits + "; the opened-loop DAE (projected onto the loop closure) passes "
                             "through them, the reduced equation in theta1 would stop at the first";
  } else {
    choice.formulation = core::Formulation::kMassMatrix;
    choice.reason =
        "the cheapest exact formulation per evaluation (about 2.1k instructions against 2.6k "
        "for complex-masses and 3.9k for opened-loop, docs/performance.md); all three agree to "
        "round-off";
  }
  if (!free) {
    choice.reason += "; no integrator: kinetostatics per sample";
  } else if (choice.formulation == core::Formulation::kOpenedLoop) {
    choice.reason += "; DAE in theta1..theta3 integrated by CVODE (BDF with projection)";
  } else {
    choice.reason += "; reduced equation in theta1 integrated by CVODE (Adams)";
  }
  return choice;
}

}  // namespace bd::studies
