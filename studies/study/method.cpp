#include "studies/study/method.hpp"

#include <utility>

#include "core/fourbar/model.hpp"
#include "core/input_error.hpp"

namespace bd::studies {

namespace {

// Below this tolerance the opened loop is integrated by the order-8 pair, above it by the
// order-5 pair: the order-5 pair gains no digits below it (docs/performance.md,
// "Recommendation").
constexpr double kOpenedLoopErk8Below = 1e-8;

// the integrator of a four-bar formulation at a tolerance, and why
std::pair<core::Integrator, std::string> integrator_for(core::Formulation f, double tolerance) {
  if (f != core::Formulation::kOpenedLoop) {
    return {core::Integrator::kCvodeAdams,
            "integrated by CVODE Adams (variable order), the most correct digits per CPU time for "
            "this smooth equation at every tolerance"};
  }
  if (tolerance < kOpenedLoopErk8Below) {
    return {core::Integrator::kErk8,
            "integrated by the Fehlberg 8(7) Runge-Kutta pair with Baumgarte stabilisation, its "
            "steps ending at every sample: the most correct digits per CPU time through limit "
            "positions at tolerances below 1e-8"};
  }
  return {core::Integrator::kErk5,
          "integrated by the Dormand-Prince 5(4) Runge-Kutta pair with Baumgarte stabilisation: "
          "the most correct digits per CPU time through limit positions from tolerance 1e-8 up"};
}

// what the four-bar's formulations compute, in words
std::string formulation_words(core::Formulation f) {
  switch (f) {
    case core::Formulation::kMassMatrix:
      return "closed-form four-bar on the constant mass matrix of its three truss elements, as "
             "the reduced equation in theta1 (the cheapest exact formulation)";
    case core::Formulation::kComplexMasses:
      return "closed-form four-bar with complex equivalent masses, as the reduced equation in "
             "theta1";
    case core::Formulation::kOpenedLoop:
      return "closed-form four-bar as an opened loop: a DAE in theta1, theta2, theta3 with the "
             "loop closure as its constraint";
  }
  return "";
}

MethodChoice fourbar_choice(const Study& study) {
  const bool free = is_free(study.scene);
  const core::FourBar& model = study.fourbar();
  // a free crank that cannot turn fully reaches limit positions, where theta1 stops being a
  // coordinate: only the opened loop's equations go through them
  const bool reaches_limits = free && !core::crank_turns_fully(model);
  const std::string limits = std::string("the crank cannot turn fully (") +
                             core::to_string(core::classify_grashof(model)) +
                             ") and reaches limit positions";
  MethodChoice c;
  if (study.method == Method::kAuto) {
    c.method = reaches_limits ? Method::kOpenedLoop : Method::kMassMatrix;
  } else {
    c.method = study.method;
  }
  if (c.general_engine()) {
    c.reason =
        "requested in the study file: the general planar engine on three truss elements, "
        "in the node coordinates of A1 and A2";
    if (!free) {
      c.reason += "; no integrator: kinetostatics per sample";
    } else if (c.method == Method::kTrussDae) {
      c.reason += ", as a stabilised DAE in every node coordinate; integrated by CVODE Adams";
    } else {
      c.reason += ", reduced to theta1; integrated by CVODE Adams";
      if (reaches_limits) c.reason += "; " + limits + ", where this reduced equation stops";
    }
    return c;
  }
  c.formulation = *formulation_of(c.method);
  c.reason = formulation_words(c.formulation);
  if (study.method == Method::kAuto && reaches_limits) {
    c.reason = limits + ", where theta1 stops being a coordinate: " + c.reason +
               ", which passes through them";
  } else if (study.method != Method::kAuto) {
    c.reason = "requested in the study file: " + c.reason;
    if (reaches_limits && c.formulation != core::Formulation::kOpenedLoop) {
      c.reason += "; " + limits +
                  ", where this reduced equation in theta1 stops (auto would take the opened-loop "
                  "DAE through them)";
    }
  }
  if (!free) {
    c.reason += "; no integrator: kinetostatics per sample";
  } else {
    const auto [integrator, why] = integrator_for(c.formulation, study.tolerance);
    c.integrator = integrator;
    c.reason += "; " + why;
  }
  return c;
}

MethodChoice planar_choice(const Study& study) {
  if (formulation_of(study.method)) {
    throw InputError(FieldError{"method", -1,
                                std::string(": ") + to_string(study.method) +
                                    " is one of the four-bar's formulations; a planar linkage "
                                    "is computed by truss or truss-dae"});
  }
  const std::size_t inputs = study.planar().inputs.size();
  const std::string in_words = std::to_string(inputs) + " input" + (inputs == 1 ? "" : "s");
  MethodChoice c;
  c.method = study.method == Method::kAuto ? Method::kTruss : study.method;
  c.reason = std::string(study.method == Method::kAuto ? "" : "requested in the study file: ") +
             "planar linkage on the paper's truss elements, in node coordinates";
  if (!is_free(study.scene)) {
    c.reason += "; no integrator: kinetostatics per sample";
  } else if (c.method == Method::kTrussDae) {
    c.reason +=
        ", as a stabilised DAE in every node coordinate (it passes through limit "
        "positions); integrated by CVODE Adams";
  } else {
    c.reason += ", reduced to its " + in_words + "; integrated by CVODE Adams";
    if (study.method == Method::kAuto) {
      c.reason +=
          " (at a limit position, where the inputs stop being coordinates, the run is "
          "repeated as a stabilised DAE in every node coordinate, which passes through "
          "it)";
    }
  }
  return c;
}

}  // namespace

MethodChoice choose_method(const Study& study) {
  return study.is_fourbar() ? fourbar_choice(study) : planar_choice(study);
}

}  // namespace bd::studies
