#pragma once
/// A study: one linkage with its loads, one scene, and how to compute it (DESIGN.md "Study file
/// (v1)"). Built by load_study()/parse_study() from a study.yaml, or directly in code.
#include <optional>
#include <string>
#include <variant>

#include "balance/synthesis.hpp"
#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/model.hpp"
#include "core/fourbar/simulate.hpp"
#include "optimize/problem.hpp"
#include "studies/study/optimize_request.hpp"
#include "studies/study/sweep_request.hpp"

namespace bd::studies {

/// The scene to simulate: free motion (forward dynamics, integrated) or driven motion (constant
/// crank speed, kinetostatics per sample).
using Scene = std::variant<core::FreeScene, core::DrivenScene>;

/// "free" or "driven".
const char* scene_type(const Scene& scene);

/// Method names accepted by the study file's `method` key, in the order the docs list them.
inline constexpr const char* kMethodNames[] = {"auto", "opened-loop", "complex-masses",
                                               "mass-matrix"};

/// The formulation named `name` ("mass-matrix", "opened-loop", "complex-masses"), else nothing.
std::optional<core::Formulation> formulation_named(const std::string& name);

struct Study {
  std::string name;     // used in output names: [A-Za-z0-9._-], not starting with '.'
  core::FourBar model;  // linkage and loads, checked by core::make_fourbar()
  Scene scene;          // free or driven
  /// The formulation asked for; empty means `auto` (the runner picks, and says why).
  std::optional<core::Formulation> formulation;
  double tolerance = 1e-10;  // integrator relative tolerance (free scenes) [-]
  std::string source;        // the study file as named by the user ("" when built in code)
  /// The study file's `balance:` section, synthesised at load time; empty when absent.
  std::optional<balance::BalancedDesign> balance;
  /// The study file's `optimize:` section, checked at load time and solved by the runner; empty
  /// when absent. A study has a balance section or an optimize section, never both.
  std::optional<OptimizeRequest> optimize;
  /// The study file's `sweep:` section, checked at load time; empty when absent. A study with
  /// a sweep is run point by point (run_sweep() in studies/sweep.hpp); its own model and scene
  /// are the file's values, valid on their own.
  std::optional<SweepRequest> sweep;

  /// "auto" or the requested formulation's name.
  std::string method_name() const;
};

/// The study of the balanced design: name `<name>-balanced`, the balanced model, the same scene,
/// method and tolerance, no balance section, no source. Precondition: study.balance is set.
Study balanced_study(const Study& study);

/// The study of an optimised design: name `<name>-optimized`, model `design`, the same scene,
/// method and tolerance, no balance or optimize section, no source.
Study optimized_study(const Study& study, const core::FourBar& design);

/// The design problem of an optimize study: the request's variables, objective, constraints,
/// with the study's model as the original, its scene and tolerance, and the formulation its run
/// uses (choose_method(study)). Precondition: study.optimize is set.
optimize::DesignProblem design_problem(const Study& study);

/// The formulation and integrator a run uses, and why (for the console and summary.json).
struct MethodChoice {
  core::Formulation formulation = core::Formulation::kMassMatrix;
  /// Free scenes: the integrator of the formulation's equations (core::SimulateOptions);
  /// unused in driven scenes.
  core::Integrator integrator = core::Integrator::kCvodeAdams;
  std::string reason;
};
/// Resolves `auto` (DESIGN.md: the leanest formulation and evaluation path for the outputs,
/// never one inside its failure domain; docs/failure-domains.md "What auto must avoid"), and the
/// integrator of a free scene, as docs/performance.md "Recommendation" measured them:
/// - a free scene whose crank cannot turn fully: opened-loop, whose DAE passes the crank's limit
///   positions (the reduced equation in theta1 would stop at the first one), integrated by
///   kErk8 at tolerances below 1e-8 and by kErk5 from 1e-8 up (Baumgarte stabilisation);
/// - otherwise mass-matrix, the cheapest exact formulation per evaluation, integrated by
///   kCvodeAdams, on the front of the reduced equation's work-precision chart at every
///   tolerance measured.
/// An explicit method is used as asked, with the integrator auto would give that formulation;
/// the reason then notes what auto would do differently.
MethodChoice choose_method(const Study& study);

}  // namespace bd::studies
