#pragma once
/// How a study is computed: the equations and, in free scenes, the integrator, with the reason
/// in an engineer's words. "Model no more than a scene needs": `auto` takes the leanest exact
/// model that follows the motion (docs/failure-domains.md "What auto must avoid" and
/// docs/performance.md "Recommendation" have the measurements behind each rule).
#include <string>

#include "core/planar/simulate.hpp"
#include "core/simulation.hpp"
#include "studies/study/study.hpp"

namespace bd::studies {

/// The method a run uses, and why (for the console and summary.json).
struct MethodChoice {
  Method method = Method::kMassMatrix;  // never kAuto
  /// The four-bar formulation (four-bar methods); the general engine's studies leave it at its
  /// default (an optimiser on a four-bar study evaluates with it).
  core::Formulation formulation = core::Formulation::kMassMatrix;
  /// Free scenes: the integrator; unused in driven scenes.
  core::Integrator integrator = core::Integrator::kCvodeAdams;
  /// What the run follows the motion in and why, in an engineer's words (one line).
  std::string reason;
  /// How it is computed numerically: the integrator and how it keeps the joints together (the
  /// detail behind `reason`, for summary.json and the report).
  std::string numerics;
  /// True when the general planar engine computes the run (truss, truss-dae).
  bool general_engine() const { return method == Method::kTruss || method == Method::kTrussDae; }
  /// The general engine's route of a free scene.
  core::planar::Route route() const {
    return method == Method::kTrussDae ? core::planar::Route::kDae : core::planar::Route::kReduced;
  }
};

/// Resolves `auto`, and the integrator of a free scene:
/// - a four-bar, driven: mass-matrix, the cheapest exact closed form, kinetostatics per sample;
/// - a four-bar, free, crank turning fully: mass-matrix, one equation in theta1, CVODE Adams;
/// - a four-bar, free, crank reaching limit positions: opened-loop, whose equations in
///   theta1..theta3 pass through them, by an explicit Runge-Kutta pair (order 8 below tolerance
///   1e-8, order 5 above);
/// - a planar linkage: truss (its driven inputs by inverse dynamics per sample; free motion by
///   the equations reduced to its inputs, CVODE Adams; the runner repeats a free run on
///   truss-dae when a limit position stops it).
/// An explicit method is used as asked, with the integrator auto would give it; the reason then
/// says what auto would do differently where that matters.
/// @throws bd::InputError if a four-bar formulation is asked for a planar linkage.
MethodChoice choose_method(const Study& study);

/// The method of a planar linkage's free run on `auto` that is repeated on truss-dae because the
/// reduced equations (`reduced`) stopped at a limit position, as the run's message `stop` says.
MethodChoice through_limits(const MethodChoice& reduced, const std::string& stop);

}  // namespace bd::studies
