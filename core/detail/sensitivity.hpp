#pragma once
/// Internal to core, not part of its API (core/detail/xy.hpp says what the detail folders hold).
///
/// What the forward sensitivities of both linkage types' free scenes share
/// (core/fourbar/sensitivity.hpp, core/planar/simulate.hpp simulate_free_sensitivities()): the
/// tolerance of the sensitivities' error test, the step of a sample's directional difference,
/// and a metric's gradient from its samples' derivatives.
#include <cstddef>
#include <string>

#include "core/input_error.hpp"
#include "core/metrics.hpp"
#include "core/simulation.hpp"
#include "core/types.hpp"

namespace bd::core::detail {

/// The sensitivities' relative tolerance, at most as tight as this: their right-hand side is
/// CVODES' difference quotient of the dynamics, whose round-off (that of the loop closure and the
/// solve, over an increment ~sqrt(rtol)) leaves a noise floor near 1e-9 of the derivatives. The
/// error test cannot see below it and only shrinks the step: measured on the paper's four-bar
/// (1 s, gravity), 1e-9 takes ~3000 steps, 1e-8 ~650, 1e-7 ~330 against 158 for the state alone,
/// and with 1e-7 every sample's derivative and every metric's gradient agrees with central
/// differences of full runs to 1e-6 of its size (tests/core/sensitivity_test.cpp).
inline constexpr double kSensitivityTolerance = 1e-7;

/// The step of a sample's directional difference along (s_j, e_j), relative to the parameter's
/// scale: truncation ~h² ~ 1e-10, round-off ~eps/h ~ 1e-11, both below the integration's error.
inline constexpr double kSensitivityStep = 1e-5;

/// Throws unless `integrator` is CVODE's (CVODES has the sensitivities): field "integrator".
inline void require_sensitivity_integrator(Integrator integrator) {
  if (integrator != Integrator::kCvodeAdams && integrator != Integrator::kCvodeBdf) {
    throw InputError(FieldError{"integrator", -1,
                                std::string(": forward sensitivities need cvode-adams or "
                                            "cvode-bdf (CVODES), got ") +
                                    to_string(integrator)});
  }
}

/// d(metric)/dp_j for one parameter, from the samples' vectors v(i) and their derivatives dv(i)
/// (i < n; a scalar quantity as (x, 0)): an RMS's is Σ_i v_i · dv_i / (n · RMS) (0 where the RMS
/// is 0); a peak's that of the largest sample's magnitude, v · dv / |v| at the sample `peak_at`.
template <class Value, class Derivative>
double metric_derivative(Statistic statistic, std::size_t n, double value, std::size_t peak_at,
                         Value v, Derivative dv) {
  if (!(value > 0)) return 0.0;
  if (statistic == Statistic::kMax) return v(peak_at).dot(dv(peak_at)) / value;
  double sum = 0;
  for (std::size_t i = 0; i < n; ++i) sum += v(i).dot(dv(i));
  return sum / (static_cast<double>(n) * value);
}

/// The sample metrics() takes as a peak: the first of the largest magnitudes |v(i)|, i < n.
template <class Value>
std::size_t peak_sample(std::size_t n, Value v) {
  std::size_t at = 0;
  double peak = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 x = v(i);
    const double m = magnitude(x.x(), x.y());
    if (m > peak) peak = m, at = i;
  }
  return at;
}

}  // namespace bd::core::detail
