#include "core/fourbar/sensitivity.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <optional>
#include <string>
#include <utility>

#include "core/detail/sensitivity.hpp"
#include "core/fourbar/detail/free_motion.hpp"
#include "core/input_error.hpp"
#include "core/number_text.hpp"

namespace bd::core {

namespace {

// the numbers of a sample, by kind: angles (differences taken modulo 2π, as the dynamics
// returns theta2 and theta3 wrapped while a trajectory continues them), other scalars, vectors
constexpr double FourBarState::*kAngles[] = {&FourBarState::theta2, &FourBarState::theta3};
constexpr double FourBarState::*kStateScalars[] = {
    &FourBarState::theta1, &FourBarState::omega1, &FourBarState::alpha1, &FourBarState::omega2,
    &FourBarState::omega3, &FourBarState::alpha2, &FourBarState::alpha3};
constexpr double DynamicsSample::*kScalars[] = {&DynamicsSample::Msh, &DynamicsSample::tau,
                                                &DynamicsSample::Msh_inertial,
                                                &DynamicsSample::Msh_static};
constexpr Vec2 DynamicsSample::*kVectors[] = {
    &DynamicsSample::RA0, &DynamicsSample::RA3,          &DynamicsSample::RC1,
    &DynamicsSample::RC3, &DynamicsSample::Fsh,          &DynamicsSample::FA1,
    &DynamicsSample::FA2, &DynamicsSample::Fsh_inertial, &DynamicsSample::Fsh_static};

// (a - b) / step, number by number
DynamicsSample difference_quotient(const DynamicsSample& a, const DynamicsSample& b, double step) {
  constexpr double kTwoPi = 2 * std::numbers::pi;
  DynamicsSample d;
  for (auto f : kAngles) {
    d.state.*f = std::remainder(a.state.*f - b.state.*f, kTwoPi) / step;
  }
  for (auto f : kStateScalars) d.state.*f = (a.state.*f - b.state.*f) / step;
  for (auto f : kScalars) d.*f = (a.*f - b.*f) / step;
  for (auto f : kVectors) d.*f = (a.*f - b.*f) / step;
  return d;
}

// the typical magnitude of a parameter (CVODES' pbar, and the scale of the difference step)
double scale_of(const FourBar& model, const LinkParameter& p) {
  const Link& l = link(model, p.link);
  switch (p.kind) {
    case LinkParameter::Kind::kMass:
      return l.mass;  // > 0 in a checked model
    case LinkParameter::Kind::kE:
    case LinkParameter::Kind::kF:
      return l.length;
    case LinkParameter::Kind::kInertia:
      break;
  }
  return l.inertia + l.mass * l.length * l.length / 12;  // a rod's, at least
}

void check(const std::vector<LinkParameter>& parameters, const SimulateOptions& options) {
  if (options.formulation == Formulation::kOpenedLoop) {
    throw InputError(FieldError{"formulation", -1,
                                ": forward sensitivities need the reduced equation in theta1 "
                                "(mass-matrix or complex-masses), got opened-loop"});
  }
  detail::require_sensitivity_integrator(options.integrator);
  std::vector<bool> seen(detail::kLinkParameters, false);
  for (std::size_t j = 0; j < parameters.size(); ++j) {
    const LinkParameter& p = parameters[j];
    if (p.link < 1 || p.link > 3) {
      throw InputError(FieldError{"parameters", static_cast<int>(j),
                                  ".link must be 1, 2 or 3, got " + std::to_string(p.link)});
    }
    const auto i = static_cast<std::size_t>(4 * (p.link - 1) + static_cast<int>(p.kind));
    if (seen[i]) {
      throw InputError(FieldError{"parameters", static_cast<int>(j), "is listed twice"});
    }
    seen[i] = true;
  }
}

// the run's sensitivity set-up: the parameters' entries and scales, the error test's tolerance
detail::StateSensitivities sensitivity_setup(const FourBar& model,
                                             const std::vector<LinkParameter>& parameters,
                                             const SimulateOptions& options) {
  detail::StateSensitivities state;
  state.tolerance = std::max(options.tolerance, detail::kSensitivityTolerance);
  for (const LinkParameter& p : parameters) {
    state.which.push_back(4 * (p.link - 1) + static_cast<int>(p.kind));
    state.scales.push_back(scale_of(model, p));
  }
  return state;
}

// The derivatives of the sample at state s, whose state derivatives are ds[j], along (ds_j, e_j):
// the dynamics at the state and parameters moved by ±h along it, h = kSensitivityStep · scale_j.
// The error of the first evaluation that fails (within h of a position where the dynamics
// refuses), else none.
std::optional<DynamicsError> sample_derivatives(const FourBar& model,
                                                const detail::StateSensitivities& state,
                                                Formulation formulation, const FourBarState& s,
                                                const std::vector<Vec2>& ds,
                                                std::vector<DynamicsSample>& out,
                                                long& evaluations) {
  out.resize(ds.size());
  for (std::size_t j = 0; j < ds.size(); ++j) {
    const double h = detail::kSensitivityStep * state.scales[j];
    auto at = [&](double step) {
      detail::LinkParameters p = state.parameters;
      p[static_cast<std::size_t>(state.which[j])] += step;
      ++evaluations;
      return forward_dynamics(detail::with_link_parameters(model, p.data()),
                              s.theta1 + step * ds[j].x(), s.omega1 + step * ds[j].y(),
                              formulation);
    };
    const auto plus = at(h), minus = at(-h);
    if (!plus) return plus.error();
    if (!minus) return minus.error();
    out[j] = difference_quotient(*plus, *minus, 2 * h);
  }
  return std::nullopt;
}

}  // namespace

FreeSensitivities simulate_free_sensitivities(const FourBar& model, const FreeScene& scene,
                                              const std::vector<LinkParameter>& parameters,
                                              const SimulateOptions& options) {
  throw_if(options.validate());
  validate_scene(scene);
  check(parameters, options);
  FreeSensitivities out;
  out.parameters = parameters;
  detail::StateSensitivities state = sensitivity_setup(model, parameters, options);
  out.trajectory = detail::simulate_free_reduced(model, scene, options, &state);
  if (!out.trajectory.ok()) return out;

  // each sample's derivatives along (s_j, e_j)
  const std::size_t n = out.trajectory.samples.size();
  out.derivative.assign(parameters.size(), std::vector<DynamicsSample>(n));
  std::vector<DynamicsSample> d;
  for (std::size_t i = 0; i < n; ++i) {
    const FourBarState& s = out.trajectory.samples[i].state;
    if (const std::optional<DynamicsError> e = sample_derivatives(
            model, state, options.formulation, s, state.state[i], d, out.sensitivity_evaluations)) {
      // within h of a position where the dynamics refuses: the run's derivatives are not to be
      // had there
      out.trajectory.status = status_of(e->kind);
      out.trajectory.message = "sensitivity at t = " + text::digits(out.trajectory.t[i], 10) +
                               " s, theta1 = " + text::digits(s.theta1, 10) + " rad: " + e->what();
      out.derivative.clear();
      return out;
    }
    for (std::size_t j = 0; j < parameters.size(); ++j) out.derivative[j][i] = d[j];
  }
  out.state_derivative = std::move(state.state);
  return out;
}

std::optional<std::vector<DynamicsSample>> free_derivatives_at(const FourBar& model,
                                                               const FreeSensitivities& run,
                                                               const SimulateOptions& options,
                                                               double t, DynamicsSample* sample) {
  const std::vector<double>& times = run.trajectory.t;
  const std::size_t n = run.trajectory.samples.size();
  if (n == 0 || times.size() != n || run.derivative.size() != run.parameters.size() ||
      run.state_derivative.size() != n || !(t >= times.front() && t <= times.back())) {
    return std::nullopt;
  }
  // the latest sample at or before t
  const auto i =
      static_cast<std::size_t>(std::upper_bound(times.begin(), times.end(), t) - times.begin()) - 1;
  const DynamicsSample& from = run.trajectory.samples[i];
  std::vector<DynamicsSample> d(run.parameters.size());
  if (t == times[i]) {
    for (std::size_t j = 0; j < d.size(); ++j) d[j] = run.derivative[j][i];
    if (sample) *sample = from;
    return d;
  }
  detail::StateSensitivities state = sensitivity_setup(model, run.parameters, options);
  state.initial = run.state_derivative[i];
  FreeScene step;
  step.theta1 = from.state.theta1;
  step.omega1 = from.state.omega1;
  step.duration = t - times[i];
  step.samples = 2;
  const Trajectory to = detail::simulate_free_reduced(model, step, options, &state);
  if (!to.ok() || to.samples.size() != 2 || state.state.size() != 2) return std::nullopt;
  long evaluations = 0;
  if (sample_derivatives(model, state, options.formulation, to.samples.back().state,
                         state.state.back(), d, evaluations)) {
    return std::nullopt;
  }
  if (sample) *sample = to.samples.back();
  return d;
}

namespace {

// a quantity of a sample as a vector (a moment's or torque's second component 0)
Vec2 components(const DynamicsSample& s, Quantity q) {
  switch (q) {
    case Quantity::kShakingForce:
      return s.Fsh_inertial;
    case Quantity::kShakingMoment:
      return {s.Msh_inertial, 0.0};
    case Quantity::kDriveTorque:
      return {s.tau, 0.0};
    case Quantity::kReactionA0:
      return s.RA0;
    case Quantity::kReactionA3:
      return s.RA3;
  }
  return Vec2::Zero();
}

}  // namespace

Eigen::MatrixXd metric_gradients(const FourBar& model, const FreeSensitivities& run,
                                 const SimulateOptions& options, const PeakList& peaks) {
  Eigen::MatrixXd g = metric_gradients(run);
  if (run.trajectory.samples.empty() || run.derivative.size() != run.parameters.size() ||
      peaks.table.size() != kMetricCount) {
    return g;
  }
  for (std::size_t k = 0; k < kMetricCount; ++k) {
    const MetricInfo& info = kMetricTable[k];
    if (info.statistic != Statistic::kMax || !(peaks.table[k].value > 0)) continue;
    DynamicsSample at;
    const auto d = free_derivatives_at(model, run, options, peaks.table[k].t, &at);
    if (!d) continue;  // the largest sample's, as metric_gradients(run) has it
    const Vec2 v = components(at, info.quantity);
    const double size = magnitude(v.x(), v.y());
    if (!(size > 0)) continue;
    for (std::size_t j = 0; j < d->size(); ++j) {
      g(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(j)) =
          v.dot(components((*d)[j], info.quantity)) / size;
    }
  }
  return g;
}

Eigen::MatrixXd metric_gradients(const FreeSensitivities& run) {
  const std::vector<DynamicsSample>& samples = run.trajectory.samples;
  const auto m = static_cast<Eigen::Index>(run.parameters.size());
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(kMetricCount), m);
  if (samples.empty() || run.derivative.size() != run.parameters.size()) return g;
  const Metrics values = metrics(run.trajectory);
  for (std::size_t k = 0; k < kMetricCount; ++k) {
    const MetricInfo& info = kMetricTable[k];
    const auto v = [&](std::size_t i) { return components(samples[i], info.quantity); };
    const std::size_t at = detail::peak_sample(samples.size(), v);
    for (Eigen::Index j = 0; j < m; ++j) {
      const auto& d = run.derivative[static_cast<std::size_t>(j)];
      g(static_cast<Eigen::Index>(k), j) = detail::metric_derivative(
          info.statistic, samples.size(), values.*info.field, at, v,
          [&](std::size_t i) { return components(d[i], info.quantity); });
    }
  }
  return g;
}

}  // namespace bd::core
