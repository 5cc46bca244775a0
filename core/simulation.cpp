#include "core/simulation.hpp"

#include <cmath>
#include <string>

#include "core/number_text.hpp"

namespace bd::core {

Problem check_integration(double tolerance, double absolute_tolerance, long max_steps) {
  if (!(tolerance > 0.0 && tolerance < 1.0)) {
    return FieldError{"tolerance", -1, "must be > 0 and < 1, got " + text::digits(tolerance, 10)};
  }
  if (!(absolute_tolerance > 0.0) || !std::isfinite(absolute_tolerance)) {
    return FieldError{"absolute_tolerance", -1,
                      "must be > 0, got " + text::digits(absolute_tolerance, 10)};
  }
  if (max_steps < 1)
    return FieldError{"max_steps", -1, "must be >= 1, got " + std::to_string(max_steps)};
  return std::nullopt;
}

const char* to_string(Integrator integrator) {
  switch (integrator) {
    case Integrator::kCvodeAdams:
      return "cvode-adams";
    case Integrator::kCvodeBdf:
      return "cvode-bdf";
    case Integrator::kErk2:
      return "erk2";
    case Integrator::kErk3:
      return "erk3";
    case Integrator::kErk4:
      return "erk4";
    case Integrator::kErk5:
      return "erk5";
    case Integrator::kErk6:
      return "erk6";
    case Integrator::kErk8:
      return "erk8";
    case Integrator::kIda:
      return "ida";
  }
  return "?";
}

const char* to_string(SimulationStatus s) {
  switch (s) {
    case SimulationStatus::kNotRun:
      return "not-run";
    case SimulationStatus::kCompleted:
      return "completed";
    case SimulationStatus::kAssemblyFailed:
      return "assembly-failed";
    case SimulationStatus::kSingular:
      return "singular";
    case SimulationStatus::kIntegratorFailed:
      return "integrator-failed";
  }
  return "?";
}

}  // namespace bd::core
