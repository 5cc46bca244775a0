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

// the integrator of a four-bar formulation at a tolerance, and its numerics in words
std::pair<core::Integrator, std::string> integrator_for(core::Formulation f, double tolerance) {
  if (f != core::Formulation::kOpenedLoop) {
    return {core::Integrator::kCvodeAdams, "CVODE Adams-Moulton, variable order"};
  }
  if (tolerance < kOpenedLoopErk8Below) {
    return {core::Integrator::kErk8,
            "Fehlberg 8(7) Runge-Kutta pair, the loop closure held by Baumgarte stabilisation, "
            "steps ending at every sample"};
  }
  return {core::Integrator::kErk5,
          "Dormand-Prince 5(4) Runge-Kutta pair, the loop closure held by Baumgarte "
          "stabilisation"};
}

// what a four-bar formulation follows a free motion in, in words
std::string formulation_words(core::Formulation f) {
  switch (f) {
    case core::Formulation::kMassMatrix:
      return "the exact equation of motion in the crank angle (the links' constant mass matrix)";
    case core::Formulation::kComplexMasses:
      return "the exact equation of motion in the crank angle (complex equivalent masses)";
    case core::Formulation::kOpenedLoop:
      return "the motion followed in all three link angles, the loop kept closed";
  }
  return "";
}

constexpr const char* kAsked = "as the study asks: ";
constexpr const char* kDriven =
    "the drive prescribes the motion: each sample's loads from the exact equations, nothing "
    "integrated";
constexpr const char* kDrivenNumerics = "none: inverse dynamics at each sample";
constexpr const char* kEveryJoint =
    "the motion followed in every joint's coordinates, the links kept joined, through limit "
    "positions";
constexpr const char* kEveryJointNumerics =
    "CVODE Adams-Moulton, variable order, on the node coordinates, the constraints held by "
    "Baumgarte stabilisation and each sample projected onto them";

MethodChoice fourbar_choice(const Study& study) {
  const bool free = is_free(study.scene);
  const core::FourBar& model = study.fourbar();
  // a free crank that cannot turn fully reaches limit positions, where theta1 stops being a
  // coordinate: only the opened loop's equations go through them
  const bool reaches_limits = free && !core::crank_turns_fully(model);
  const std::string cannot_turn = std::string("the crank cannot turn fully (") +
                                  core::to_string(core::classify_grashof(model)) + ")";
  const std::string stops =
      "; " + cannot_turn +
      ", so the run stops at its first limit position (auto follows it through)";
  MethodChoice c;
  if (study.method == Method::kAuto) {
    c.method = reaches_limits ? Method::kOpenedLoop : Method::kMassMatrix;
  } else {
    c.method = study.method;
  }
  const std::string asked = study.method == Method::kAuto ? "" : kAsked;
  if (c.general_engine()) {
    c.reason = asked + "the general planar engine, the links as truss elements; ";
    if (!free) {
      c.reason += kDriven;
      c.numerics = kDrivenNumerics;
    } else if (c.method == Method::kTrussDae) {
      c.reason += kEveryJoint;
      c.numerics = kEveryJointNumerics;
    } else {
      c.reason += "the motion in the crank angle";
      if (reaches_limits) c.reason += stops;
      c.numerics = "CVODE Adams-Moulton, variable order";
    }
    return c;
  }
  c.formulation = *formulation_of(c.method);
  if (!free) {
    c.reason = asked + kDriven;
    c.numerics = kDrivenNumerics;
    return c;
  }
  if (study.method == Method::kAuto && reaches_limits) {
    c.reason = cannot_turn + ": " + formulation_words(c.formulation) +
               ", which carries it through its limit positions";
  } else {
    c.reason = asked + formulation_words(c.formulation);
    if (reaches_limits && c.formulation != core::Formulation::kOpenedLoop) c.reason += stops;
  }
  const auto [integrator, numerics] = integrator_for(c.formulation, study.tolerance);
  c.integrator = integrator;
  c.numerics = numerics;
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
  MethodChoice c;
  c.method = study.method == Method::kAuto ? Method::kTruss : study.method;
  c.reason = study.method == Method::kAuto ? "" : kAsked;
  if (!is_free(study.scene)) {
    c.reason += kDriven;
    c.numerics = kDrivenNumerics;
  } else if (c.method == Method::kTrussDae) {
    c.reason += kEveryJoint;
    c.numerics = kEveryJointNumerics;
  } else {
    const bool one = inputs == 1;
    c.reason += std::string("the motion in its ") + (one ? "input" : "inputs");
    c.reason += study.method == Method::kAuto
                    ? std::string("; at a limit position, where ") +
                          (one ? "it stops" : "they stop") +
                          " describing the motion, the run starts again in every joint's "
                          "coordinates, which pass through it"
                    : std::string("; the run stops at a limit position, where ") +
                          (one ? "it stops" : "they stop") + " describing the motion";
    c.numerics = "CVODE Adams-Moulton, variable order, on the inputs and their rates";
  }
  return c;
}

}  // namespace

MethodChoice choose_method(const Study& study) {
  return study.is_fourbar() ? fourbar_choice(study) : planar_choice(study);
}

MethodChoice through_limits(const MethodChoice& reduced, const std::string& stop) {
  MethodChoice c = reduced;
  c.method = Method::kTrussDae;
  // the stop's place: its message up to the first colon
  c.reason = std::string(kEveryJoint) + "; in the inputs alone the run stopped (" +
             stop.substr(0, stop.find(':')) + ")";
  c.numerics = kEveryJointNumerics;
  return c;
}

}  // namespace bd::studies
