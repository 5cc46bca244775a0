#pragma once
/// Forward sensitivities of a free scene: the derivatives of every sample, and of every metric,
/// with respect to the links' mass parameters, so that gradient methods can optimise a design
/// whose motion is simulated (optimize/free_nlp.cpp).
///
/// The state y = (theta1, omega1) of the reduced equation y' = f(y, p) has the sensitivities
/// s_j = dy/dp_j, which obey s_j' = (df/dy) s_j + df/dp_j, s_j(0) = 0. CVODES integrates them
/// with the state (staggered corrector, the sensitivities in the error test at the relative
/// tolerance max(options.tolerance, 1e-7): below that the difference quotients' round-off only
/// shrinks the steps), forming the right-hand side (df/dy) s_j + df/dp_j by its own centred
/// difference quotient along (s_j, e_j), so the dynamics needs no derivative code of its own.
/// The derivatives are good to ~1e-6 of their size (measured against central differences of
/// full runs), ample for a gradient whose optimiser stops at a relative tolerance of 1e-8 on the
/// objective: the error moves the optimum by ~1e-6 of the variables' scale only where the
/// objective is flat, so the objective's value there by ~1e-12. An output y_out of a
/// sample (a reaction, the shaking force ...) is a function g(theta1, omega1, p) of the state
/// and the parameters; its total derivative at the sample,
///   d y_out / d p_j = dg/dtheta1 · s_theta1,j + dg/domega1 · s_omega1,j + dg/dp_j,
/// is the derivative of g along the direction (s_j, e_j), taken by a centred difference of the
/// sample's dynamics (no integration) with the step h = 1e-5 relative to the parameter's scale:
/// truncation ~h² ~ 1e-10, round-off ~eps/h ~ 1e-11, both below the integration's error.
#include <Eigen/Core>
#include <optional>
#include <vector>

#include "core/fourbar/metrics.hpp"
#include "core/fourbar/model.hpp"
#include "core/fourbar/simulate.hpp"

namespace bd::core {

/// One mass parameter of a link.
struct LinkParameter {
  int link = 1;  // 1 crank, 2 coupler, 3 rocker
  enum class Kind {
    kMass,     // m_k [kg]
    kE,        // e_k [m]
    kF,        // f_k [m]
    kInertia,  // I_k about the centre of mass [kg m^2]
  } kind = Kind::kMass;
};

/// A free run with the first derivatives of its samples.
struct FreeSensitivities {
  /// The run: the same equations, integrator and tolerances as simulate_free(), with the
  /// sensitivities in the integrator's error test (so its steps, and its samples to within the
  /// integration's error, differ from simulate_free()'s).
  Trajectory trajectory;
  std::vector<LinkParameter> parameters;
  /// derivative[j][i]: every number of trajectory.samples[i] differentiated with respect to
  /// parameters[j] (angles, rates and accelerations, the reactions, the shaking force and moment
  /// and their parts, the joint forces), in their units per the parameter's unit. Empty where
  /// the run failed.
  std::vector<std::vector<DynamicsSample>> derivative;
  /// state_derivative[i][j]: d(theta1, omega1)/d(parameters[j]) at sample i, as the integrator
  /// carried it (what a continuation of the run from sample i starts from). Empty where the run
  /// failed.
  std::vector<std::vector<Vec2>> state_derivative;
  long sensitivity_evaluations{};  // dynamics evaluations for the samples' derivatives
};

/// Simulates the free scene with forward sensitivities with respect to `parameters`.
/// Needs the reduced equation (options.formulation kMassMatrix or kComplexMasses) and a CVODE
/// integrator (kCvodeAdams or kCvodeBdf).
/// @throws bd::InputError as simulate_free() does for an invalid scene or options; also, with
///         field "formulation" or "integrator", for the opened loop or an ERK pair, and with
///         field "parameters" (index: the entry) for a link outside 1..3 or a parameter listed
///         twice.
FreeSensitivities simulate_free_sensitivities(const FourBar& model, const FreeScene& scene,
                                              const std::vector<LinkParameter>& parameters,
                                              const SimulateOptions& options = {});

/// The gradients of the metric table's rows (core::kMetricTable, in its order) over the run:
/// row k, column j is d(metric k)/d(parameters[j]). An RMS's derivative is
/// Σ_i v_i · dv_i / (n · RMS) over the samples' vectors v_i (0 where the RMS is 0); a peak's is
/// that of the largest sample's magnitude, v · dv / |v| (the sample metrics() takes: the first
/// of equal largest ones; 0 where the magnitude is 0). Needs a completed run.
Eigen::MatrixXd metric_gradients(const FreeSensitivities& run);

/// The derivatives with respect to run.parameters of the run's sample at any instant t of its
/// span, not only at its samples: element j is every number of the sample at t differentiated
/// with respect to parameters[j], as FreeSensitivities::derivative holds them at the samples.
/// At a sample's time they are that sample's; between samples the run is continued with its
/// sensitivities from the latest sample before t by `options` (the run's own formulation,
/// integrator and tolerances) in one integration whose last step ends at t, as
/// free_sample_from() continues a plain run. `sample`, when given, receives the sample at t (its
/// link angles as the dynamics gives them, within one turn). None outside the run's span, for a
/// run without derivatives, or where the continuation or a difference fails.
std::optional<std::vector<DynamicsSample>> free_derivatives_at(const FourBar& model,
                                                               const FreeSensitivities& run,
                                                               const SimulateOptions& options,
                                                               double t,
                                                               DynamicsSample* sample = nullptr);

/// The gradients of the metric table's rows over the run with its peaks resolved between the
/// samples: `peaks` as metrics(model, run.trajectory, options, &peaks) locates them (the run's
/// own options). A peak's derivative is v · dv / |v| at the instant of its peak
/// (free_derivatives_at(); where that fails, at the largest sample, as metric_gradients(run));
/// an RMS's as metric_gradients(run) has it. Needs a completed run.
Eigen::MatrixXd metric_gradients(const FourBar& model, const FreeSensitivities& run,
                                 const SimulateOptions& options, const PeakList& peaks);

}  // namespace bd::core
