#pragma once
/// A general planar linkage on the paper's truss elements (§4.2, §5.1, §6): named nodes (joint
/// points) in the plane, some fixed to the frame; links that are rigid bodies through two or more
/// nodes; point masses at nodes; sliders (prismatic joints) on a guide fixed in the frame or on
/// the line through two nodes of a moving link; linear spring-dampers between nodes; applied
/// loads; and the inputs (the degrees of freedom), each a link's angle or a slider's position.
///
/// Conventions (shared with the four-bar, so that results of both compare):
/// - SI units, angles in radians, the global origin as the fixed point for moments.
/// - A link's angle is the direction of the line from its first node to its second, continuous
///   in time. Its centre of mass lies at e along and f to the left of that line from its first
///   node (or s, σ: e + i f = s e^{iσ}); its inertia is about the centre of mass.
/// - A link's mass sits on one truss element between its first two nodes (the paper's constant
///   4x4 mass matrix); every further node of the link is held by the element exactly, as the
///   material point ξ + iη of eq. 41 (two linear constraints per node), so a ternary link or a
///   coupler plate needs no extra massive element.
/// - Reactions are forces of the mechanism ON the frame; joint forces are forces on a link at a
///   node from the joint there.
///
/// A Linkage is built and checked by make_linkage() and is read-only afterwards; state and
/// scratch live in planar::Workspace (core/planar/kinematics.hpp).
#include <string>
#include <vector>

#include "core/types.hpp"

namespace bd::core::planar {

/// A joint point.
struct Node {
  std::string name;
  Vec2 position{0, 0};  // where it is drawn (the initial configuration) [m]
  bool ground = false;  // fixed to the frame
};

/// A rigid link through two or more nodes.
struct Link {
  std::string name;
  std::vector<int> nodes;  // node indices, >= 2, distinct; the first two carry the element
  double mass{};           // [kg], >= 0
  double e{}, f{};  // centre of mass from nodes[0]: along and to the left of nodes[0]->nodes[1] [m]
  double inertia{};  // about the centre of mass [kg m^2], >= 0
};

/// A mass concentrated at a moving node (a piston, a slider block), moving with it.
struct PointMass {
  int node{};
  double mass{};  // [kg], > 0
};

/// A prismatic joint: node `node` slides, frictionless, along a line. The line is fixed in the
/// frame (link < 0: through `from` towards `to`), or is the line through the nodes `from_node`
/// and `to_node` of the moving link `link` (an inverted slider-crank, a quick-return linkage).
/// The guide transmits only the force normal to the line, at the node.
struct Slider {
  std::string name;
  int node{};
  int link = -1;                     // the link carrying the guide; < 0: the frame
  Vec2 from{0, 0}, to{0, 0};         // frame guide: the line through from towards to [m]
  int from_node = -1, to_node = -1;  // guide on a link: two of its nodes
};

/// A linear spring-damper between two nodes: tension T = k (L - L0) + c dL/dt pulls them together.
struct Spring {
  std::string name;
  int a{}, b{};          // node indices (either may be a ground node, not both)
  double stiffness{};    // k [N/m], >= 0
  double free_length{};  // L0 [m], >= 0
  double damping{};      // c [N s/m], >= 0
};

/// A balance shaft: a rigid body on a shaft fixed in the frame at `at`, geared to a link that
/// turns about a ground node so that it turns at `ratio` times the link's rate (-1: Berkof's
/// counter-rotation; ±1, ±2: a Lanchester balancer's shafts). It carries `mass` with its centre
/// of mass at `eccentricity` from the shaft (global axes, in the drawn configuration) and
/// `inertia` about that centre of mass. Its motion is the link's, so it adds no degree of
/// freedom; the drive between them is an ideal gear pair whose tooth force is normal to the line
/// of centres at the pitch point (the pair's relative instant centre, (pivot - ratio at) /
/// (1 - ratio)), or a pure torque where there is none (ratio 1, or a shaft on the link's pivot:
/// a chain, a belt or a coaxial train, housed in the frame).
struct BalanceShaft {
  std::string name;
  int link = -1;
  int ratio = -1;           // the shaft's rate over the link's; an integer, not 0
  Vec2 at{0, 0};            // [m]
  double mass{};            // [kg], >= 0
  Vec2 eccentricity{0, 0};  // [m]
  double inertia{};         // about its centre of mass [kg m^2], >= 0
};

/// A balance shaft's centre of mass from its shaft when its link has turned `link_turn` [rad]
/// from the drawn configuration: the eccentricity turned by ratio × link_turn [m].
Vec2 shaft_centre(const BalanceShaft& shaft, double link_turn);

/// A value over time: a constant, a piecewise-linear table (held at its ends), or a harmonic
/// mean + amplitude sin(2π frequency t + phase).
struct TimeFunction {
  enum class Kind { kConstant, kTable, kHarmonic } kind = Kind::kConstant;
  double value{};                                    // kConstant
  std::vector<double> times, values;                 // kTable: times strictly increasing [s]
  double mean{}, amplitude{}, frequency{}, phase{};  // kHarmonic: [Hz], [rad]
  double operator()(double t) const;
  bool is_zero() const { return kind == Kind::kConstant && value == 0.0; }
};

/// A degree of freedom: the angle of a link that turns about a ground node (its first-to-second
/// node direction [rad]), or the position of a slider's node along its guide (measured from the
/// guide's `from` point, or from its `from_node`, towards `to` [m]).
struct Input {
  enum class Kind { kAngle, kSlide } kind = Kind::kAngle;
  std::string name;
  int link = -1;    // kAngle
  int slider = -1;  // kSlide
  /// Free scenes: the drive's torque on the link from the frame [N m] (the frame feels its
  /// opposite), or its force on the slider's node along the guide [N]. Driven scenes prescribe
  /// the input instead and compute this.
  TimeFunction effort;
};

/// A force at a moving node, global axes [N].
struct NodeForce {
  int node{};
  Vec2 force{0, 0};
};
/// A force at a link's centre of mass (global axes) and a moment on the link.
struct LinkLoad {
  int link{};
  Vec2 force{0, 0};  // [N]
  double moment{};   // [N m]
};
struct Loads {
  Vec2 gravity{0, 0};  // [m/s^2], on every mass
  std::vector<NodeForce> node_forces;
  std::vector<LinkLoad> link_loads;
};

struct Linkage {
  std::vector<Node> nodes;
  std::vector<Link> links;
  std::vector<PointMass> point_masses;
  std::vector<Slider> sliders;
  std::vector<Spring> springs;
  std::vector<Input> inputs;
  Loads loads;
  std::vector<BalanceShaft> shafts;
};

/// Checks and returns the linkage: names unique and not empty, node indices valid, a link
/// through >= 2 distinct nodes whose first two are apart, masses and inertias >= 0 and finite,
/// every number finite, a slider's guide of non-zero length, a guide on a link through two of
/// that link's nodes, an angle input on a link with a ground node, loads on moving parts, a
/// balance shaft geared to a link with exactly one ground node, its name not a node's or a
/// slider's (its reaction is R<name>).
/// (Whether the drawn positions close every constraint, and whether the inputs match the
/// mobility, is checked by the kinematics: assemble().)
/// @throws bd::InputError with a FieldError whose field names the item, e.g. {"links", 2,
///         ".mass must be >= 0 kg, got -1"}, {"nodes", 3, ": ..."}.
Linkage make_linkage(const Linkage& candidate);

/// The index of the node, link, slider or input named `name`, or -1.
int node_index(const Linkage& linkage, const std::string& name);
int link_index(const Linkage& linkage, const std::string& name);

/// The element length of link k: |nodes[1] - nodes[0]| as drawn [m].
double element_length(const Linkage& linkage, int k);

/// The ground node a link turns about: its only ground node, or -1 (none, or two: a link fixed to
/// the frame).
int pivot_of(const Linkage& linkage, int link);

/// Σ of the link masses, point masses and balance shafts' masses [kg].
double total_mass(const Linkage& linkage);

/// The linkage's mass parameters π, in which every force of a given motion is affine: per link
/// k at 4k its mass m [kg], its first moments m e and m f about its first node in its axes
/// [kg m] and its inertia about that node J = I + m (e² + f²) [kg m^2]; then per point mass j
/// at 4 (links) + j its mass [kg]. (The balance layer's regressors and the optimiser's
/// sensitivities use this layout.)
int mass_parameter_count(const Linkage& linkage);
std::vector<double> mass_parameters(const Linkage& linkage);
/// The linkage with its links' and point masses' mass parameters set from `pi` (the layout
/// above, mass_parameter_count() values): e = m e / m, f = m f / m, I = J - m (e² + f²) (a link
/// without mass: e = f = 0, I = J). Not checked (make_linkage() checks).
Linkage with_mass_parameters(const Linkage& linkage, const double* pi);
/// The same in place.
void set_mass_parameters(Linkage& linkage, const double* pi);

}  // namespace bd::core::planar
