#pragma once
/// Kinematics and dynamics of a planar linkage at one instant (core/planar/model.hpp), in node
/// coordinates on truss elements (core/planar/system.hpp has the equations):
/// - assembly: Newton's method on the constraints from a guess (the drawn positions choose the
///   branch), the inputs held;
/// - velocities and accelerations from the square system of the constraints and the inputs;
/// - inverse dynamics (the inputs' accelerations given): M q̈ = F + Gᵀ λ solved for the
///   multipliers, which are the axial forces, guide forces and the drives' efforts;
/// - forward dynamics (the drives' efforts given), reduced to the inputs: with q̇ = T ż and
///   q̈ = T z̈ + c from the same square system, (Tᵀ M T) z̈ = Tᵀ (F - M c) + efforts;
/// - the outputs of an instant from those: link angles and rates, ground reactions, guide
///   reactions, joint forces, the shaking force and moment and their inertial parts.
/// Model and Workspace follow Pinocchio's Model/Data: the model is compiled once and read-only,
/// the workspace holds every buffer, sized once, so an evaluation allocates nothing.
#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <memory>
#include <string>
#include <vector>

#include "core/expected.hpp"
#include "core/planar/model.hpp"
#include "core/planar/small_lu.hpp"

namespace bd::core::planar {

namespace detail {
struct System;
}

/// A joint whose force is an output: the force on `link` at `node` from the joint there.
struct JointForce {
  std::string name;  // "A1" (two links at the node), "A1_rocker" (more than two)
  int node{};
  int link{};
};

/// A compiled linkage: its equations and the names of its outputs.
class Model {
 public:
  /// Compiles a linkage checked by make_linkage().
  /// @throws bd::InputError as make_linkage().
  explicit Model(const Linkage& linkage);
  ~Model();
  Model(const Model&);
  Model& operator=(const Model&);

  const Linkage& linkage() const;
  int coordinates() const;  // free node coordinates
  int inputs() const;       // degrees of freedom asked for
  /// The ground nodes, in node order (their reactions R<name> are outputs).
  const std::vector<int>& ground_nodes() const { return ground_nodes_; }
  /// The sliders on frame guides, in slider order (their reactions R<name> are outputs).
  const std::vector<int>& frame_guides() const { return frame_guides_; }
  /// The sliders on guides that move with a link, in slider order (the force on the guide's link
  /// from the slider, F<slider>_guide, is an output).
  const std::vector<int>& link_guides() const { return link_guides_; }
  /// The joints whose forces are outputs: every moving node in two or more links (the force on
  /// each link but the first, from the joint), or in one link and carrying a slider or a point
  /// mass (the force on that link).
  const std::vector<JointForce>& joints() const { return joints_; }
  /// Per joint, its slot in the system (detail::System::slots: the force on its link there).
  const std::vector<int>& joint_slots() const { return joint_slots_; }
  /// The springs with an end on the frame, in spring order (their pull on the frame at that
  /// node, R<node>_<spring>, is an output: part of the shaking force, not of the pin's reaction).
  const std::vector<int>& frame_springs() const { return frame_springs_; }
  /// The inputs that drive a slider along a frame guide, in input order (the drive's reaction on
  /// the frame, R<slider>_drive, is an output).
  const std::vector<int>& frame_drives() const { return frame_drives_; }
  /// A length scale of the linkage: its longest element [m].
  double length_scale() const { return length_scale_; }
  const detail::System& system() const { return *system_; }
  /// Replaces the mass parameters (model.hpp, mass_parameters()' layout) in place, unchecked:
  /// what forward sensitivities' difference quotients evaluate (simulate_free_sensitivities()).
  void set_mass_parameters(const double* pi);

 private:
  std::unique_ptr<detail::System> system_;
  std::vector<int> ground_nodes_, frame_guides_, link_guides_, frame_springs_, frame_drives_;
  std::vector<JointForce> joints_;
  std::vector<int> joint_slots_;
  double length_scale_{};
};

/// Everything at one instant. Sized by Workspace for the model; vectors indexed like the model's
/// nodes, links, sliders, inputs, ground_nodes(), frame_guides() and joints().
struct Instant {
  double t{};
  std::vector<Vec2> x, v, a;  // node positions, velocities, accelerations [m, m/s, m/s^2]
  std::vector<double> input, input_rate, input_acceleration;  // [rad or m] and rates
  /// Drive efforts: torque on the link from the frame [N m] or force on the slider's node along
  /// its guide [N]; computed in driven scenes, given in free ones.
  std::vector<double> effort;
  std::vector<double> angle, omega, alpha;                    // per link [rad, rad/s, rad/s^2]
  std::vector<double> slide, slide_rate, slide_acceleration;  // per slider [m, m/s, m/s^2]
  std::vector<Vec2> ground_reaction;  // per ground node: force of the mechanism ON the frame [N]
  std::vector<Vec2> guide_reaction;   // per frame guide: force ON the frame at the node [N]
  std::vector<Vec2> joint_force;      // per joint: force on the link at the node [N]
  /// per slider on a moving guide (Model::link_guides()): the force on the guide's link from the
  /// slider's node, the guide's normal force and a drive's force along it [N]
  std::vector<Vec2> guide_force;
  /// Per balance shaft: the force ON the frame at its bearing [N] (its weight and inertia, and
  /// the reaction of its tooth force; the tooth force's action on the link reaches the frame
  /// through the link's pivot, in that ground node's reaction).
  std::vector<Vec2> shaft_reaction;
  std::vector<Vec2> spring_reaction;  // per frame spring: its pull ON the frame [N]
  std::vector<Vec2> drive_reaction;   // per frame slide drive: its reaction ON the frame [N]
  /// shaking force: every force of the mechanism ON the frame, the sum of ground_reaction,
  /// guide_reaction, shaft_reaction, spring_reaction and drive_reaction [N]
  Vec2 Fsh{0, 0};
  double Msh{};             // shaking moment about the origin, drives' reactions included [N m]
  /// The shaking force and moment split by their cause: Fsh = Fsh_inertial + Fsh_static and
  /// Msh = Msh_inertial + Msh_static to round-off (Newton's law on the moving parts; springs
  /// and drives between the frame and the mechanism cancel out of the sum). The inertial part
  /// is what balancing acts on.
  Vec2 Fsh_inertial{0, 0};  // -Σ m a [N]
  double Msh_inertial{};    // -dH/dt about the origin [N m]
  Vec2 Fsh_static{0, 0};    // the weights and the applied forces (loads) [N]
  double Msh_static{};      // their moment about the origin and the applied moments [N m]
};

/// Why an instant could not be evaluated.
struct PlanarError {
  enum class Kind {
    kAssembly,   // Newton found no position closing every constraint
    kSingular,   // the constraints and inputs are singular (a dead centre, a limit position)
    kMobility,   // the inputs do not match the degrees of freedom
    kNonFinite,  // a value that is not finite appeared
  };
  Kind kind = Kind::kAssembly;
  std::string detail;  // one line, naming the constraint or the condition
};

/// The buffers of evaluations on one model.
class Workspace {
 public:
  explicit Workspace(const Model& model);
  Instant instant;  // the last instant evaluated
  // scratch
  Eigen::VectorXd q, qd, qdd, g, gamma, F, rhs, lambda, step, c, right, zdd;
  Eigen::MatrixXd G, T, MT, reduced;
  detail::SmallLu lu;
  bool factorised = false;  // lu holds the Jacobian at the last position solve_position solved
  Eigen::LDLT<Eigen::MatrixXd> ldlt;
  std::vector<Vec2> target;  // the inputs of the last position solve (detail::input_targets)
  std::vector<Vec2> on_link;        // force recovery: per joint slot (System::slots), the force on
                                    // the link from the joint
  std::vector<Vec4> element_force;  // per link: its element's nodal inertia less load (p, q)
  // the block-triangular route (core/planar/blocks.hpp): whether the last position was placed
  // by it (then G is the Jacobian there and the blocks are factorised, lu is not), per block
  // its branch, its determinant (two rows) or factorisation, and scratch; per dyad and guide
  // its closure margin at the last placement (detail::place_by_blocks(): below 0 it does not
  // close)
  bool by_blocks = false;
  std::vector<double> block_sign, block_det, block_margin;
  std::vector<detail::SmallLu> block_lu;
  Eigen::MatrixXd block_matrix;
  Eigen::VectorXd block_rhs, block_x;
};

/// How solve_position() finds the positions.
enum class PositionRoute {
  /// The block-triangular closed forms (core/planar/blocks.hpp) where the linkage is built of
  /// cranks, dyads, guides and further nodes of links and `guess` tells each dyad's and guide's
  /// branch clearly; the general route otherwise, and wherever the closed forms decline (a dead
  /// centre near). ws.lu is then not factorised (ws.by_blocks says which route answered).
  kLeanest,
  /// Newton's method on every constraint from `guess`, the whole Jacobian factorised in ws.lu
  /// at the solution (its determinant's sign tells the assembly branch).
  kGeneral,
};

/// Solves the positions with the inputs at `inputs` from `guess` (node positions; the drawn
/// ones, or the last instant's, choose the branch) by the route asked for, and factorises the
/// constraints' Jacobian there (the whole of it on the general route, block by block on the
/// leanest). The routes agree to round-off. Sets ws.instant.x and .input.
Expected<bool, PlanarError> solve_position(const Model& model, Workspace& ws,
                                           const std::vector<Vec2>& guess,
                                           const std::vector<double>& inputs,
                                           PositionRoute route = PositionRoute::kLeanest);

/// Assembles the linkage at `inputs`, stepping them from the drawn configuration's values in
/// small increments so that Newton follows the drawn branch (the general route: ws.lu holds the
/// Jacobian at the result). On success ws.instant.x is set.
Expected<bool, PlanarError> assemble(const Model& model, Workspace& ws,
                                     const std::vector<double>& inputs);

/// The inputs' values in the drawn configuration.
std::vector<double> drawn_inputs(const Model& model);

/// Checks that the drawn positions close every constraint (a sliding node on its guide) to 1e-9 of
/// the length scale; otherwise the error names the constraint that does not close and by how
/// much.
Expected<bool, PlanarError> check_drawn(const Model& model);

/// The degrees of freedom of the drawn configuration: coordinates minus the rank of the
/// constraints' Jacobian (the structural rows).
int mobility(const Model& model);

/// After solve_position(): velocities and accelerations for the inputs' rates and
/// accelerations, and every output for the given efforts (driven: `efforts` empty, computed).
/// Inverse dynamics.
Expected<bool, PlanarError> inverse_dynamics(const Model& model, Workspace& ws, double t,
                                             const std::vector<double>& rates,
                                             const std::vector<double>& accelerations);

/// After solve_position(): the inputs' accelerations under the given efforts (forward
/// dynamics, reduced to the inputs), then every output. Sets ws.instant.
Expected<bool, PlanarError> forward_dynamics(const Model& model, Workspace& ws, double t,
                                             const std::vector<double>& rates,
                                             const std::vector<double>& efforts);

namespace detail {
/// The inputs' values as messages name them: "crank = 1.5707963268 rad, slider = 0.25 m".
std::string inputs_text(const Model& model, const std::vector<double>& inputs);

/// With ws.instant's positions, velocities, accelerations and efforts and ws.lambda (the
/// multipliers of every row, the input rows' matching the efforts) set: the link angles and
/// rates, the sliders' positions and every force output.
void finish_outputs(const Model& model, Workspace& ws);
}  // namespace detail

/// The efforts of the model's inputs at time t (their TimeFunctions).
std::vector<double> efforts_at(const Model& model, double t);
/// The same into `out` (resized to the inputs).
void efforts_at(const Model& model, double t, std::vector<double>& out);

}  // namespace bd::core::planar
