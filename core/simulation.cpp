#include "core/simulation.hpp"

namespace bd::core {

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
