#pragma once
/// A study: one linkage with its loads, one scene, and how to compute it
/// (docs/study-format.md). Built by load_study()/parse_study() from a study.yaml, or in code.
///
/// The linkage is of one of two types, and the scene is of that type:
/// - `fourbar`: the planar 4R four-bar (core/fourbar/), with its closed-form formulations;
/// - `planar`: any planar linkage on the paper's truss elements (core/planar/).
/// Each type has its own balance and optimize sections (a four-bar's are read into `balance` and
/// `optimize`, a planar linkage's into `planar_balance` and `planar_optimize`).
#include <optional>
#include <string>
#include <variant>

#include "balance/planar.hpp"
#include "balance/synthesis.hpp"
#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/model.hpp"
#include "core/fourbar/simulate.hpp"
#include "core/planar/model.hpp"
#include "core/planar/simulate.hpp"
#include "optimize/problem.hpp"
#include "studies/study/optimize_request.hpp"
#include "studies/study/sweep_request.hpp"

namespace bd::studies {

/// The study's linkage: a four-bar or a general planar linkage.
using Linkage = std::variant<core::FourBar, core::planar::Linkage>;

/// The scene to simulate: the four-bar's free or driven scene, or a planar linkage's.
using Scene = std::variant<core::FreeScene, core::DrivenScene, core::planar::FreeScene,
                           core::planar::DrivenScene>;

/// "free" or "driven".
const char* scene_type(const Scene& scene);
/// True for a free scene (of either linkage type).
bool is_free(const Scene& scene);
/// The initial crank angle of a four-bar's scene [rad] (precondition: a four-bar scene).
double crank_angle_at_start(const Scene& scene);

/// How a study is computed: `auto`, one of the four-bar's formulations, or the general engine
/// (`truss`: the reduced equations in the inputs; `truss-dae`: every node coordinate, the
/// constraints as a stabilised DAE).
enum class Method { kAuto, kMassMatrix, kOpenedLoop, kComplexMasses, kTruss, kTrussDae };
/// "auto", "opened-loop", "complex-masses", "mass-matrix", "truss", "truss-dae".
const char* to_string(Method method);
/// Every method, in the order the docs list them.
inline constexpr Method kMethods[] = {Method::kAuto,          Method::kOpenedLoop,
                                      Method::kComplexMasses, Method::kMassMatrix,
                                      Method::kTruss,         Method::kTrussDae};
/// The method named `name`, else nothing.
std::optional<Method> method_named(const std::string& name);
/// The four-bar formulation of a method (mass-matrix, opened-loop, complex-masses), else nothing.
std::optional<core::Formulation> formulation_of(Method method);

/// A counterweight carried by a link as a part of its own (`linkage.counterweights` in a study
/// file, as balanced.yaml and optimized.yaml write the designs' counterweights).
struct CounterweightPart {
  int link{};   // a four-bar's: 1 crank or 3 rocker; a planar linkage's: its index in links
  int pivot{};  // a planar linkage's node its position is measured from (a four-bar's: unused,
                // the crank's is A0 and the rocker's A3)
  balance::Counterweight counterweight;  // mass [kg], position [m] in link axes from the pivot,
                                         // inertia about its own centre [kg m^2]
};

/// The linkage without its counterweight parts, and the parts; the study's linkage is `bare`
/// with each part merged into its link in order (with_counterweights()).
struct LinkageParts {
  Linkage bare;
  std::vector<CounterweightPart> counterweights;
};

/// `parts.bare` with each counterweight merged into its link in order (parallel axes,
/// balance::merged(), the same arithmetic as the balance synthesis and the optimisers use), not
/// yet checked by make_fourbar() or make_linkage().
Linkage with_counterweights(const LinkageParts& parts);

struct Study {
  std::string name;  // used in output names: [A-Za-z0-9._-], not starting with '.'
  Linkage linkage;   // with its loads, checked by core::make_fourbar() or make_linkage()
  Scene scene;       // of the linkage's type
  Method method = Method::kAuto;  // auto: the runner picks, and says why
  double tolerance = 1e-10;       // integrator relative tolerance (free scenes) [-]
  std::string source;             // the study file as named by the user ("" when built in code)
  /// The values the file gives with a unit of their own, as read and in SI, e.g. "scene.theta1:
  /// 90 deg = 1.5707963267948966 rad" (a plain number is SI and is not listed).
  std::vector<std::string> units_read;
  /// The counterweights the file gives as parts of their links (linkage.counterweights), and
  /// the linkage without them; empty when it gives none. `linkage` has them merged in.
  std::optional<LinkageParts> parts;
  /// A four-bar study's `balance:` section, synthesised at load time; empty when absent.
  std::optional<balance::BalancedDesign> balance;
  /// A planar study's `balance:` section, checked at load time; the runner synthesises the design
  /// from the original's run (the balance conditions come from its motion). Empty when absent.
  std::optional<balance::planar::BalanceRequest> planar_balance;
  /// The study file's `optimize:` section, checked at load time and solved by the runner; empty
  /// when absent. A study has a balance section or an optimize section, never both.
  std::optional<OptimizeRequest> optimize;
  /// A planar study's `optimize:` section, checked at load time and solved by the
  /// runner; empty when absent. Never with a balance section.
  std::optional<PlanarOptimizeRequest> planar_optimize;
  /// The study file's `sweep:` section, checked at load time; empty when absent. A study with
  /// a sweep is run point by point (run_sweep() in studies/studies.hpp); its own linkage and
  /// scene are the file's values, valid on their own.
  std::optional<SweepRequest> sweep;

  bool is_fourbar() const { return std::holds_alternative<core::FourBar>(linkage); }
  /// The four-bar of a four-bar study (precondition: is_fourbar()).
  const core::FourBar& fourbar() const { return std::get<core::FourBar>(linkage); }
  core::FourBar& fourbar() { return std::get<core::FourBar>(linkage); }
  /// The linkage of a planar study (precondition: !is_fourbar()).
  const core::planar::Linkage& planar() const { return std::get<core::planar::Linkage>(linkage); }
  /// True when the study has an optimize section (of either linkage type).
  bool optimizes() const { return optimize.has_value() || planar_optimize.has_value(); }
  /// "auto" or the requested method's name.
  std::string method_name() const { return to_string(method); }
};

/// The linkage's size [m], the natural scale of its positions: a four-bar's longest link or
/// frame, a planar linkage's largest distance between two of its nodes as drawn.
double linkage_size(const Study& study);
double linkage_size(const core::FourBar& fourbar);
double linkage_size(const core::planar::Linkage& linkage);

/// The study of the balanced design: name `<name>-balanced`, the balanced model, the same scene,
/// method and tolerance, no balance section, no source. Precondition: study.balance is set.
Study balanced_study(const Study& study);

/// The study of a planar linkage's balanced design: name `<name>-balanced`, the linkage
/// `balanced`, the same scene, method and tolerance, no balance section, no source.
Study planar_balanced_study(const Study& study, const core::planar::Linkage& balanced);

/// The study of an optimised design: name `<name>-optimized`, model `design`, the same scene,
/// method and tolerance, no balance or optimize section, no source.
Study optimized_study(const Study& study, const core::FourBar& design);

/// The study of a planar linkage's optimised design: name `<name>-optimized`, the linkage
/// `design`, the same scene, method and tolerance, no sections, no source.
Study planar_optimized_study(const Study& study, const core::planar::Linkage& design);

/// The design problem of a planar study's optimize section: its variables, objective and
/// constraints, with the study's linkage as the original, its scene and (a free scene) its
/// tolerance. Precondition: study.planar_optimize is set.
optimize::planar::DesignProblem planar_design_problem(const Study& study);

/// The design problem of an optimize study: the request's variables, objective, constraints,
/// with the study's model as the original, its scene and tolerance, and the formulation its run
/// uses (choose_method(study), studies/run/method.hpp). Precondition: study.optimize is set.
optimize::DesignProblem design_problem(const Study& study);

}  // namespace bd::studies
