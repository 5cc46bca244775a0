#pragma once
/// Internal to core, not part of its API (core/detail/xy.hpp says what the detail folders hold).
///
/// What the two integrations of free motion share: the reduced equation in theta1
/// (core/fourbar/simulate.cpp) and the opened loop's DAE (core/fourbar/opened_loop_dae.cpp) output
/// at the same instants and report an integrator that stops short in the same words.
#include <array>
#include <cstddef>
#include <string>
#include <vector>

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

/// The links' mass parameters a free run's sensitivities are taken with respect to: per link
/// k = 1, 2, 3 at 4(k-1) its mass [kg], e [m], f [m] and inertia about the centre of mass
/// [kg m^2] (core/fourbar/sensitivity.hpp, LinkParameter, in this order).
inline constexpr int kLinkParameters = 12;
using LinkParameters = std::array<double, kLinkParameters>;

inline LinkParameters link_parameters(const FourBar& model) {
  LinkParameters p{};
  for (int k = 1; k <= 3; ++k) {
    const Link& l = link(model, k);
    const auto b = static_cast<std::size_t>(4 * (k - 1));
    p[b] = l.mass, p[b + 1] = l.e, p[b + 2] = l.f, p[b + 3] = l.inertia;
  }
  return p;
}

/// The model with its links' mass parameters replaced by p (LinkParameters' layout).
inline FourBar with_link_parameters(const FourBar& model, const double* p) {
  FourBar out = model;
  Link* links[3] = {&out.crank, &out.coupler, &out.rocker};
  for (int k = 0; k < 3; ++k) {
    links[k]->mass = p[4 * k];
    links[k]->e = p[4 * k + 1];
    links[k]->f = p[4 * k + 2];
    links[k]->inertia = p[4 * k + 3];
  }
  return out;
}

/// What simulate_free_reduced() takes and gives for forward sensitivities.
struct StateSensitivities {
  std::vector<int> which;       // the entries of LinkParameters differentiated
  std::vector<double> scales;   // their typical magnitudes, > 0 (CVODES' pbar)
  double tolerance{};           // relative, of the sensitivities' error test
  /// d(theta1, omega1)/dp at the start, per entry of `which`; empty: 0 (a run from the scene's
  /// start), else those of the instant a run is continued from
  std::vector<Vec2> initial;
  LinkParameters parameters{};  // set by the run: the model's
  /// set by the run: per sample, per entry of `which`, d(theta1, omega1)/dp [rad/unit],
  /// [rad/s/unit]
  std::vector<std::vector<Vec2>> state;
};

/// simulate_free() on the reduced equation in theta1 (Formulation::kMassMatrix or
/// kComplexMasses; the scene and options already validated), with CVODES' forward
/// sensitivities of (theta1, omega1) when `sensitivities` is not null (options.integrator
/// kCvodeAdams or kCvodeBdf).
Trajectory simulate_free_reduced(const FourBar& model, const FreeScene& scene,
                                 const SimulateOptions& options, StateSensitivities* sensitivities);

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
