#pragma once
/// The optimisation problem: design variables on a four-bar, an objective and constraints built
/// from the metrics of its simulated reactions. Solver-agnostic: NLopt and Ipopt stay behind
/// optimize() (optimize/optimize.hpp).
#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "balance/counterweight.hpp"
#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/metrics.hpp"
#include "core/fourbar/model.hpp"
#include "core/fourbar/simulate.hpp"
#include "core/input_error.hpp"

namespace bd::optimize {

/// Metrics of a design in the scene: the rows of core's metric table (core/metrics.hpp, in its
/// order), then the added mass.
// clang-format off
enum class Metric {
  kFshRms, kFshMax,  // |F̄sh| [N]
  kMshRms, kMshMax,  // |Msh| [N m]
  kTauRms, kTauMax,  // |tau| [N m]
  kRA0Rms, kRA0Max,  // |R̄A0| [N]
  kRA3Rms, kRA3Max,  // |R̄A3| [N]
  kAddedMass,        // Σ (design mass - original mass) over the links [kg]
};
// clang-format on
static_assert(static_cast<std::size_t>(Metric::kAddedMass) == core::kMetricCount,
              "the reaction metrics are core::kMetricTable's rows, in its order");

/// The row of core's metric table of a reaction metric (any but kAddedMass).
const core::MetricInfo& info(Metric m);

/// "Fsh_rms", "Fsh_max", ..., "added_mass" (the names of summary.json and comparison.csv).
const char* to_string(Metric m);
std::optional<Metric> metric_named(const std::string& name);
/// "N", "N m" or "kg".
const char* metric_unit(Metric m);
/// True for the metrics of moments [N m] (the shaking moment and the drive torque).
bool is_moment(Metric m);
/// The value of a reaction metric (any but kAddedMass) in `metrics`.
double value(const core::Metrics& metrics, Metric m);

/// Every metric, in the table's order, added_mass last.
inline constexpr Metric kMetrics[] = {Metric::kFshRms, Metric::kFshMax,   Metric::kMshRms,
                                      Metric::kMshMax, Metric::kTauRms,   Metric::kTauMax,
                                      Metric::kRA0Rms, Metric::kRA0Max,   Metric::kRA3Rms,
                                      Metric::kRA3Max, Metric::kAddedMass};

/// True for the peak metrics (handled by a bound variable, never by a non-smooth max).
bool is_peak(Metric m);

/// How the objective sums its terms (optimize/nlp.hpp has the exact formulas).
enum class ObjectiveForm {
  /// Σ w · metric(design) / metric(original): the weighted sum of the normalised metrics, each
  /// magnitude smoothed where it reaches 0 (DesignProblem::smoothing). The default.
  kLinear,
  /// Σ w · (metric(design) / metric(original))² over the reaction metrics: smooth everywhere,
  /// the same minimiser for a single term, but weighing a term's large ratios more.
  kSquared,
};
/// "linear", "squared".
const char* to_string(ObjectiveForm f);
std::optional<ObjectiveForm> objective_form_named(const std::string& name);

/// The default smoothing ε of the linear form's magnitudes (DesignProblem::smoothing), chosen
/// from measurements (docs/performance.md, "The objective's form"): every gradient solver
/// converges on optima where a metric vanishes, and the objective is within 1e-6 per unit of
/// weight of the exact sum. With much smaller values Ipopt runs out of its budget where a metric
/// vanishes.
inline constexpr double kDefaultSmoothing = 1e-6;

/// One term of the objective: weight · metric(design) / metric(original) for the reaction
/// metrics (squared in ObjectiveForm::kSquared), weight · added_mass / (original total mass)
/// for added_mass (linear in both forms).
struct Term {
  Metric metric = Metric::kFshRms;
  double weight = 1.0;  // >= 0
};

/// An upper limit on a metric: metric(design) <= fraction · metric(original); for added_mass
/// the limit is in kg: added_mass <= value (any finite value: 0 or less keeps or removes mass).
struct Limit {
  Metric metric = Metric::kFshRms;
  double value = 1.0;  // fraction of the original [-], or kg for added_mass
};

/// A counterweight as design variables: its mass and its centre (x, y) in the link frame (from
/// A0 for the crank, from A3 for the rocker: link == 1 or 3) within distance_max of the pivot.
/// Its inertia follows from the shape (disc: thickness and density fix the radius from the mass,
/// so its inertia m²/(2 density pi thickness) is smooth in m).
struct CounterweightVariables {
  int link = 1;               // 1 crank, 3 rocker
  double mass_max = 10.0;     // [kg], mass in [0, mass_max], > 0
  double distance_max = 1.0;  // [m], |(x, y)| <= distance_max (the envelope), > 0
  balance::CounterweightShape shape = balance::CounterweightShape::kPoint;
  double thickness = 0.02;  // disc [m], > 0
  double density = 7850.0;  // disc [kg/m^3], > 0
};

/// One of the link's own mass parameters as a design variable, within bounds.
struct LinkParameterVariable {
  int link = 2;  // 1, 2, 3
  enum class Parameter { kMass, kE, kF, kInertia } parameter = Parameter::kMass;
  double lower{}, upper{};  // [kg], [m], [m], [kg m^2]; mass lower > 0, inertia lower >= 0
};
/// "mass", "e", "f", "inertia".
const char* parameter_name(LinkParameterVariable::Parameter p);
/// "kg", "m", "m", "kg m²".
const char* parameter_unit(LinkParameterVariable::Parameter p);

/// What to optimise, on which design, in which scene.
struct DesignProblem {
  core::FourBar original;  // the starting design (geometry, loads, counter-rotations)
  std::variant<core::FreeScene, core::DrivenScene> scene;
  core::Formulation formulation = core::Formulation::kComplexMasses;  // for the evaluations
  double tolerance = 1e-10;                                           // free scenes
  std::vector<CounterweightVariables> counterweights;
  std::vector<LinkParameterVariable> link_parameters;
  std::vector<Term> objective;  // at least one term
  std::vector<Limit> limits;
  bool force_balance = false;  // the two complex conditions of eq. 57 as four equalities
  ObjectiveForm objective_form = ObjectiveForm::kLinear;
  /// Linear form: each normalised magnitude r = |y| / original (an RMS, or one sample of a peak)
  /// enters as sqrt(r² + ε²) with ε = smoothing, in (0, 0.1]: smooth where r = 0, and within
  /// min(ε, ε²/(2r)) above r, so the objective is within ε · Σ weights above the exact sum
  /// (optimize/nlp.hpp has the bound on the optimum).
  double smoothing = kDefaultSmoothing;
  /// Bound the motion's peaks, not the samples' (the default; off: the samples', as the
  /// metrics of a run without resolved peaks). The original's peaks that normalise the objective
  /// and the limits ("x original") are then its resolved ones.
  /// - Driven scenes: optimize() runs exchange steps: where a peak of the objective or of a
  ///   limit, resolved between the samples at the optimum, rises above the peak the program
  ///   bounded (by more than 1e-9 of the original's), crank angles around it are added to
  ///   peak_angles and the problem is solved again from that optimum; once bounded, the result
  ///   is the lean program's (the samples and the angles around each peak of that design),
  ///   which is the one certified.
  /// - Free scenes: each evaluation's simulation has the peaks of the objective and the limits
  ///   resolved between its samples (core::metrics(model, trajectory, options, resolve)), and
  ///   their gradients are taken at the peaks' instants (core::free_derivatives_at()); the
  ///   other peaks stay the samples' (resolved_peak_rows()).
  bool resolve_peaks = true;
  /// Driven scenes: crank angles [rad] at which the peaks (of the objective and of the limits)
  /// are bounded besides the scene's samples (the exchange steps add to them). The RMS metrics
  /// stay the scene's samples'.
  std::vector<double> peak_angles;
  /// Empty when valid, else the first problem; text() says it in words, e.g.
  /// "counterweights[1].link must be 1 (crank) or 3 (rocker), got 2". Its field:
  /// - "original" (core's complaint about the design in the message), "scene.omega1" and the
  ///   scene's other fields, "formulation", "tolerance", "objective_form", "smoothing",
///   "peak_angles" (index: the angle that is not finite, or any in a free scene);
  /// - no field when there is no design variable; "objective" (no index) when the objective as
  ///   a whole is wrong (no term, no positive weight);
  /// - a list field with the element's index when the element is wrong as a whole: a second
  ///   counterweight on a link ("counterweights", i), a link parameter twice or with bad bounds
  ///   ("link_parameters", i: "(coupler.mass).lower must be > 0 kg, got 0"), a torque metric in
  ///   a free scene ("objective" or "limits", i);
  /// - the path of one field of an element, index -1: "counterweights[i].link" (.mass_max,
  ///   .distance_max, .shape, .thickness, .density), "link_parameters[i].link" (.parameter),
  ///   "objective[i].metric" (.weight), "limits[i].metric" (.value).
  bd::Problem validate() const;
};

/// The rows of core::kMetricTable whose peaks a free scene's program resolves between the
/// samples (with resolve_peaks): the peak metrics of the objective (positive weight) and of the
/// limits. Its other peaks are the largest samples'; the optimum's verification evaluates them
/// alike.
core::MetricMask resolved_peak_rows(const DesignProblem& problem);

}  // namespace bd::optimize
