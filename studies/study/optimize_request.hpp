#pragma once
/// The optimize section of a study: what to minimise, under which constraints, over which design
/// variables, with which solver (docs/study-format.md "optimize"). The optimisation itself is
/// bd::optimize's (optimize(), pareto_front()); this header holds the study's request and the
/// small helpers the runner and the CLI share to report an optimum.
#include <optional>
#include <string>
#include <vector>

#include "core/fourbar/metrics.hpp"
#include "core/fourbar/model.hpp"
#include "core/planar/model.hpp"
#include "optimize/optimize.hpp"
#include "optimize/planar.hpp"
#include "optimize/problem.hpp"

namespace bd::studies {

/// The ε-constraint trade-off the study asks for (optimize.pareto): minimise `first` subject to
/// second <= ε · second(original) for `points` values of ε.
struct ParetoRequest {
  optimize::Metric first = optimize::Metric::kFshRms;
  optimize::Metric second = optimize::Metric::kMshRms;
  int points = 9;  // >= 2
};

/// The study file's `optimize:` section, defaults in place. The design it starts from, the
/// scene and the formulation are the study's own (design_problem() in studies/study.hpp puts
/// them together).
struct OptimizeRequest {
  std::vector<optimize::CounterweightVariables> counterweights;  // crank first, then rocker
  std::vector<optimize::LinkParameterVariable> link_parameters;  // in the order of the file
  std::vector<optimize::Term> objective;                         // in the order of the file
  std::vector<optimize::Limit> limits;                           // in the order of the file
  bool force_balance = false;  // eq. 57 as equalities (full shaking-force balance)
  /// optimize.peaks: resolved (true, the default) bounds the motion's peaks
  /// (optimize::DesignProblem::resolve_peaks), sampled (false) the samples'
  bool resolve_peaks = true;
  optimize::OptimizeOptions options;
  std::optional<ParetoRequest> pareto;
};

/// A planar study's ε-constraint trade-off (optimize.pareto): minimise `first` (an RMS metric of
/// the linkage's table, or added_mass) subject to second <= ε · second(original) (kg for
/// added_mass) for `points` values of ε.
struct PlanarParetoRequest {
  std::string first = "Fsh_rms";
  std::string second = "Msh_rms";
  int points = 9;  // >= 2
};

/// A planar linkage study's `optimize:` section (docs/study-format.md "optimize"), defaults in
/// place: the variables, objective and constraints of optimize::planar::DesignProblem, whose
/// original and scene are the study's (planar_design_problem() in studies/study.hpp).
struct PlanarOptimizeRequest {
  std::vector<optimize::planar::CounterweightVariables> counterweights;  // in the file's order
  std::vector<optimize::planar::LinkParameterVariable> link_parameters;  // in the file's order
  std::vector<optimize::planar::Term> objective;                         // in the file's order
  std::vector<optimize::planar::Limit> limits;                           // in the file's order
  bool force_balance = false;  // the momentum conditions as equalities (full force balance)
  /// optimize.peaks: resolved (true, the default) bounds the motion's peaks
  /// (optimize::planar::DesignProblem::resolve_peaks), sampled (false) the samples'
  bool resolve_peaks = true;
  optimize::OptimizeOptions options;
  std::optional<PlanarParetoRequest> pareto;
};

/// All algorithms, in the order the docs list them.
inline constexpr optimize::Algorithm kAlgorithms[] = {
    optimize::Algorithm::kSlsqp, optimize::Algorithm::kMma,   optimize::Algorithm::kIpopt,
    optimize::Algorithm::kMlsl,  optimize::Algorithm::kIsres, optimize::Algorithm::kCobyla};

/// "mass", "e", "f", "inertia" (the study file's keys under optimize.variables.links.<link>).
const char* to_string(optimize::LinkParameterVariable::Parameter p);

/// Σ (design mass − original mass) over the links [kg] (negative when mass was taken away).
double added_mass(const core::FourBar& original, const core::FourBar& design);

/// The change of the design's inertia [kg m²]: for each link, the change of its inertia about
/// its pivot (crank about A0, rocker about A3) or, for the coupler, about A1; plus the change of
/// the counter-rotations' J. For counterweights alone this is Σ counterweight inertias about
/// their pivots, as in a balance study.
double added_inertia(const core::FourBar& original, const core::FourBar& design);

/// The value of metric `m` in `metrics`; added_mass is taken from `added` [kg].
double metric_value(const core::Metrics& metrics, optimize::Metric m, double added);

/// The objective in words, e.g. "1 x Msh_rms + 0.5 x tau_rms (each / original)".
std::string objective_text(const OptimizeRequest& request);

/// The constraints in words, e.g. "full force balance; Fsh_rms <= 0.2 x original;
/// added_mass <= 6 kg"; "none" when there are none.
std::string constraints_text(const OptimizeRequest& request);

/// A planar study's objective and constraints in words, as above.
std::string objective_text(const PlanarOptimizeRequest& request);
std::string constraints_text(const PlanarOptimizeRequest& request);

/// The change of a planar design's inertia [kg m²]: for each link, the change of its inertia
/// about its pivot (the ground node it turns about, else its first node), plus the inertias of
/// balance shafts the design has and the original lacks.
double added_inertia(const core::planar::Linkage& original, const core::planar::Linkage& design);

}  // namespace bd::studies
