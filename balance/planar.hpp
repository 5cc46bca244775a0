#pragma once
/// Shaking-force balance of any planar linkage (paper §4.1, §5.2, generalised): the linkage's
/// linear momentum is carried by its nodes, each link putting the complex equivalent mass
/// m(1 - s̄/l) at its first node and m s̄/l at its second (s̄ = e + i f), so that
///   L = Σ_n μ̄_n v̄_n  over the moving nodes, μ̄_n the node's total equivalent mass.
/// Everything here is linear in the mass parameters of the links (m, m e, m f and the inertia J
/// about the first node) and the point masses: the linear momentum, the inertial shaking force
/// and moment are regressors times the parameter vector. Full force balance is L ≡ 0 for every
/// motion: the momentum per unit rate of each input vanishes at every configuration. Where loops
/// make node velocities dependent (a ternary link's nodes, a node on a frame guide), these
/// conditions are fewer than "every node's equivalent mass zero"; they are taken exactly from the
/// linkage's kinematics at the configurations given (a driven revolution covers all of a crank's).
///
/// For a four-bar they are eq. 57 (tests/balance/planar_balance_test.cpp checks it).
#include <Eigen/Dense>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "balance/counterweight.hpp"
#include "core/expected.hpp"
#include "core/planar/dynamics.hpp"
#include "core/series.hpp"
#include "core/types.hpp"

namespace bd::balance::planar {

namespace cp = core::planar;

/// The layout of the mass-parameter vector, core's (core/planar/model.hpp, mass_parameters()):
/// per link k, columns 4k + 0..3 are m [kg], m e, m f [kg m] (its first moment about its first
/// node, in link axes) and J [kg m^2] (inertia about its first node: I + m (e² + f²)); then one
/// column per point mass [kg].
struct Parameters {
  static int link_mass(int k) { return 4 * k; }
  static int link_me(int k) { return 4 * k + 1; }
  static int link_mf(int k) { return 4 * k + 2; }
  static int link_J(int k) { return 4 * k + 3; }
  static int point_mass(const cp::Linkage& l, int j) {
    return 4 * static_cast<int>(l.links.size()) + j;
  }
  static int count(const cp::Linkage& l) { return cp::mass_parameter_count(l); }
  /// The linkage's values.
  static Eigen::VectorXd of(const cp::Linkage& l);
};

/// The complex equivalent mass at every node [kg] (ground nodes included; their velocity is 0).
std::vector<ComplexMass> equivalent_masses(const cp::Linkage& linkage);

/// The kinematics of a motion at its samples: node positions and accelerations, link angles,
/// rates and accelerations, and per input the node velocities at unit rate of that input (the
/// others held). Independent of the mass parameters (the motion is given).
struct Kinematics {
  struct Sample {
    std::vector<Vec2> x, a;                             // per node
    std::vector<double> angle, omega, alpha;            // per link
    std::vector<std::vector<Vec2>> unit_rate_velocity;  // per input, per node [m/rad or m/m]
    std::vector<std::vector<double>> unit_rate_omega;   // per input, per link [rad/rad or rad/m]
  };
  std::vector<Sample> samples;
};

/// The kinematics at the given samples: per sample the inputs' values, rates and accelerations.
/// Positions are solved from the previous sample's (the first from the drawn configuration), so
/// the samples must follow a motion closely enough to stay on its assembly branch (a simulated
/// run's samples do).
/// @return the kinematics, or the first sample that cannot be evaluated (its error).
Expected<Kinematics, cp::PlanarError> kinematics(
    const cp::Model& model, const std::vector<std::vector<double>>& values,
    const std::vector<std::vector<double>>& rates,
    const std::vector<std::vector<double>>& accelerations);

/// One revolution of a linkage's only input, a link's angle, at unit speed from its drawn value:
/// `samples` configurations, equally spaced; `angles` (if not null) receives the input's values.
/// @return the kinematics, or the first configuration that does not assemble (a crank that
///         cannot turn fully).
Expected<Kinematics, cp::PlanarError> crank_revolution(const cp::Model& model, int samples,
                                                       std::vector<double>* angles = nullptr);

/// The inputs' values, rates and accelerations at every row of a simulated run's table
/// (core/planar/simulate.hpp, columns()).
struct InputSeries {
  std::vector<std::vector<double>> values, rates, accelerations;
};
InputSeries input_series(const cp::Model& model, const core::Series& table);

/// Regressors: matrices with one column per mass parameter (Parameters).
/// The linear momentum per unit input rate: rows (sample, input, x | y); L = Z θ ż.
Eigen::MatrixXd momentum_regressor(const cp::Linkage& linkage, const Kinematics& k);
/// The inertial shaking force -Σ m a: rows (sample, x | y) [N].
Eigen::MatrixXd shaking_force_regressor(const cp::Linkage& linkage, const Kinematics& k);
/// The inertial shaking moment -dH/dt about the origin: one row per sample [N m].
Eigen::MatrixXd shaking_moment_regressor(const cp::Linkage& linkage, const Kinematics& k);
/// The angular momentum about the origin per unit input rate: rows (sample, input); H = Σ_j
/// (row of input j) θ ż_j [kg m^2 per s per unit rate].
Eigen::MatrixXd angular_momentum_regressor(const cp::Linkage& linkage, const Kinematics& k);

/// The balance shafts' part of the linkage's momentum and inertial shaking force and moment
/// (core/planar/model.hpp BalanceShaft; they are not mass parameters): vectors with the rows of
/// momentum_regressor, shaking_force_regressor and shaking_moment_regressor, to be added to
/// those regressors' products; and their angular momentum about the origin per unit input rate
/// (the rows of angular_momentum_regressor).
struct ShaftSeries {
  Eigen::VectorXd momentum, force, moment, angular_momentum;
};
ShaftSeries shaft_series(const cp::Linkage& linkage, const Kinematics& k);

/// How many independent conditions of full force balance the configurations of `k` show (the
/// rank of the momentum regressor, as force_balance() counts them). A motion through too few
/// configurations (a linkage at rest) shows fewer than the linkage has.
int force_balance_conditions(const cp::Linkage& linkage, const Kinematics& k);

/// True when the linkage's linear momentum (its shafts' included) vanishes to round-off in every
/// configuration of `k`: against the sum of its terms' sizes, to 1e-10.
bool force_balanced(const cp::Linkage& linkage, const Kinematics& k);

/// Where a counterweight on a link is measured from: the link's ground node, or its first node
/// for a link that does not turn about the frame.
int counterweight_pivot(const cp::Linkage& linkage, int link);

/// A drawn point in a link's axes (along and to the left of its first-to-second node line), from
/// its first node [m].
Vec2 in_link_axes(const cp::Linkage& linkage, int link, const Vec2& point);

/// A counterweight asked for on a link, realised as balance::CounterweightSpec says. Its position
/// is measured in link axes (along and to the left of the link's first-to-second node line) from
/// the link's pivot: its ground node, or its first node for a link that does not turn about the
/// frame (a floating link, whose counterweight needs its mass given: its position is solved).
struct LinkCounterweightSpec {
  int link{};
  CounterweightSpec spec;
};

/// Balance shafts asked for (balance/planar_shafts.hpp): a Lanchester balancer.
struct ShaftRequest {
  std::vector<int> orders;  // the orders of the shaking force to cancel, each >= 1
  std::optional<Vec2> at;   // where the shafts sit [m]; default: the crank's pivot
  std::map<int, Vec2> at_shaft;  // where the shaft of a ratio (±order) sits, over `at` [m]
  std::optional<double>
      radius;  // their centres of mass from the shaft [m]; default: the crank's length
};

/// A counter-rotation asked for on a link that turns about one ground node, its shaft at `at`
/// [m] (default: below the link's pivot by the link's length, as a four-bar's);
/// balance/planar_moment.hpp synthesises it.
struct CounterRotationRequest {
  int link{};
  std::optional<Vec2> at;
};

/// The study file's `balance:` section for a planar linkage: force balance by counterweights on
/// the links named (default: every link that turns about a ground node), or an engine's crank
/// counterweight by its balancing factor; then, if asked, balance shafts that cancel orders of
/// the shaking force; then, if asked, counter-rotations that cancel the shaking moment.
struct BalanceRequest {
  std::vector<LinkCounterweightSpec> counterweights;
  /// An engine's crank counterweight: the fraction of the reciprocating mass it balances on top
  /// of the rotating mass (force_balance()).
  std::optional<double> balancing_factor;
  std::optional<ShaftRequest> shafts;
  /// Moment balance (after the rest) by counter-rotations on these links, when asked for.
  std::optional<std::vector<CounterRotationRequest>> counter_rotations;
};

/// The links that turn about a ground node (one of their nodes is fixed to the frame), each with
/// a default counterweight: where counterweights go when the study names none.
std::vector<LinkCounterweightSpec> grounded_links(const cp::Linkage& linkage);

/// Checks counterweight specs against the linkage without balancing anything.
/// @throws bd::InputError as force_balance().
void check_counterweights(const cp::Linkage& linkage,
                          const std::vector<LinkCounterweightSpec>& counterweights);

/// Checks a balancing factor's rule against the linkage (force_balance()'s conditions).
/// @throws bd::InputError as force_balance().
void check_balancing_factor(const cp::Linkage& linkage,
                            const std::vector<LinkCounterweightSpec>& counterweights, double beta);

/// A realised counterweight on a link.
struct LinkCounterweight {
  int link{};
  int pivot{};  // the node its position is measured from
  Counterweight counterweight;
};

/// The result of force balancing.
struct ForceBalance {
  std::optional<double> balancing_factor;  // the engine rule used, if it was
  cp::Linkage linkage;                     // the links with their counterweights merged in
  std::vector<LinkCounterweight> added;    // links already balanced get none
  bool full{};                             // full force balance reached (L ≡ 0 to round-off)
  int conditions{};                        // independent conditions of full force balance
  /// Empty when full; else one line naming what cannot be balanced with the counterweights
  /// allowed, and what the least-squares design leaves. (A study's runner may add a note on
  /// where the conditions came from: a scene that shows too few of them.)
  std::string message;
  /// |Z θ| over |Z θ0| at the design: the linear momentum left, relative to the original's.
  double momentum_left{};
  /// RMS of the inertial shaking force over the samples, original and design [N].
  double Fsh_rms_before{}, Fsh_rms_after{};
  double added_mass{}, added_inertia{};  // Σ masses [kg]; Σ inertias about the pivots [kg m^2]
};

/// Counterweights on the given links that make the linkage fully force balanced over the
/// motion `k` describes (its configurations); where that cannot be reached with these links,
/// the design that minimises the RMS of the inertial shaking force over k's samples instead,
/// with `full` false and the message saying why. Among several designs that balance, the one
/// whose counterweight masses have the least sum of squares (a unique design when the
/// counterweights are as many as the conditions need).
///
/// With a balancing factor β (an engine's rule): one counterweight, on a crank O-A that drives a
/// piston B (a node on a frame guide) through a connecting rod A-B; it makes the crank pin's
/// complex equivalent mass -β times the piston's, μ_A + p/|OA| = -β μ_B (p its first moment
/// about O in the crank's axes O->A): the rotating mass balanced and the fraction β of the
/// reciprocating mass, whose primary force it turns into a rotating one. `full` is false and the
/// message says what the rule leaves.
/// @throws bd::InputError for an invalid spec (field "counterweights.<link>"), two on one link,
///         a link through two ground nodes, or a floating link's counterweight without a mass;
///         with a balancing factor, anything but one counterweight on such a crank (field
///         "balancing_factor").
ForceBalance force_balance(const cp::Linkage& linkage, const Kinematics& k,
                           const std::vector<LinkCounterweightSpec>& counterweights,
                           std::optional<double> balancing_factor = std::nullopt);

/// A link with a counterweight merged in (parallel axes), its position given in link axes from
/// the link's first node [m].
cp::Link merged(const cp::Link& link, const Counterweight& counterweight, const Vec2& from_first);

}  // namespace bd::balance::planar
