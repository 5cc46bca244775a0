#pragma once
/// Internal to core, not part of its API (core/detail/xy.hpp says what the detail folders hold).
///
/// What the two integrations of free motion share: the reduced equation in theta1
/// (core/fourbar/simulate.cpp) and the opened loop's DAE (core/fourbar/opened_loop_dae.cpp) output
/// at the same instants and report an integrator that stops short in the same words.
#include <cstddef>
#include <string>

#include "core/fourbar/simulate.hpp"
#include "core/integrators.hpp"
#include "core/number_text.hpp"

namespace bd::core::detail {

/// Output instant j [s] of a free scene: scene.samples instants evenly spaced over
/// [0, scene.duration], the last exactly scene.duration.
inline double output_time(const FreeScene& scene, std::size_t j) {
  const auto samples = static_cast<std::size_t>(scene.samples);
  const double last = static_cast<double>(samples - 1);
  return j + 1 == samples ? scene.duration : scene.duration * static_cast<double>(j) / last;
}

/// Sets the status (kIntegratorFailed) and message of a run whose integration stopped short on
/// its own account, the dynamics not having failed: `max_steps` used up (Outcome::kMaxSteps), or
/// the integrator's failure (kFailed). The state's first component is theta1, e.g.
/// "integrator stopped at t = 1.2 s, theta1 = 3.4 rad: max_steps = 1000 reached".
inline void integrator_stopped(Trajectory& out, const integrators::Integration& integration,
                               integrators::Integration::Outcome outcome, long max_steps) {
  const std::string where = "at t = " + text::digits(integration.t(), 10) +
                            " s, theta1 = " + text::digits(integration.y()[0], 10) + " rad: ";
  out.status = SimulationStatus::kIntegratorFailed;
  out.message =
      outcome == integrators::Integration::Outcome::kMaxSteps
          ? "integrator stopped " + where + "max_steps = " + std::to_string(max_steps) + " reached"
          : "integrator failed " + where + integration.failure();
}

}  // namespace bd::core::detail
