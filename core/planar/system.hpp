#pragma once
/// The equations of a planar linkage in node coordinates (core/planar/model.hpp), compiled once:
/// the free coordinates q (x, y of every moving node), the constraint rows g(q) = 0, the constant
/// mass matrix M of the truss elements and point masses, and the applied forces F(q, q̇, t).
///
/// Constraint rows, in this order (structural rows first, then one row per input):
/// - element length of each link, g = (|q - p|² - l²) / (2 l) (gradient of unit length, λ the
///   element's axial force [N]);
/// - each further node r of a link, r - A p - B q = 0 (two rows): the material point ξ + iη of
///   the element p->q (eq. 41), exact for the rigid link because the element keeps its length;
/// - each slider on a frame guide, n·(P - from) = 0 (n the guide's unit normal); on a link's
///   guide through its nodes Q, R: (P - Q) × (R - Q) / |R - Q| = 0;
/// - each input: an angle l (φ(q) - θ) = 0 (φ the link's first-to-second node direction, kept
///   continuous, l its element length, so that the gradient has unit length and λ l is the
///   drive's torque), or a slide s(q) - s = 0 (s the node's position along the guide, λ the
///   drive's force).
/// Every row is written g(q) = 0 with its gradient G = ∂g/∂q and its curvature term γ = Ġ q̇,
/// so that q̈ satisfies G q̈ = -γ + (0, ..., z̈). The equations of motion with the multipliers λ
/// are M q̈ = F + Gᵀ λ: λ of an element is its axial force over its length, λ of a rigid node the
/// force the node exerts on the link, λ of a slider the normal force of its guide, λ of an input
/// the drive's torque or force.
///
/// Internal to core/planar: the public interface is core/planar/dynamics.hpp and simulate.hpp.
#include <Eigen/Core>
#include <vector>

#include "core/planar/model.hpp"
#include "core/truss_element.hpp"

namespace bd::core::planar::detail {

using Eigen::MatrixXd;
using Eigen::VectorXd;

/// Positions, velocities or accelerations of every node (ground nodes included, fixed there).
using NodeVectors = std::vector<Vec2>;

/// One diagonal block of the system in block-triangular form (core/planar/blocks.hpp): its rows
/// and the coordinates they determine.
struct Block {
  enum class Kind {
    kGeneral,  // Newton's method on the block's rows
    kCrank,    // an angle input and its link's element from a known end A: P = A ± l u
    kDyad,     // two elements from known nodes A and B meet at P: two circles
    kGuide,    // an element from a known node A meets a frame guide at P: a circle and a line
    kSlide,    // a slide input on a frame guide: P = from + s u
    kRigid,    // a further node of a link whose element nodes are known: P = Wp p + Wq q
  };
  Kind kind = Kind::kGeneral;
  int first{}, size{};  // into BlockPlan::rows and ::coords
  int node = -1;        // the closed forms: the node placed
  int a = -1, b = -1;   // the known nodes it is placed from (dyad: both; crank, guide: a)
  double ra{}, rb{};    // dyad: |P - A|, |P - B|; crank, guide: |P - A| (crank: signed, ± l)
  int index = -1;       // crank, slide: the input; guide: the slider; rigid: the rigid entry
  int entry[4]{};       // two rows: the offsets in G of its entries (0,0), (0,1), (1,0), (1,1)
};

struct BlockPlan {
  /// The rows matched one to one with the coordinates (false for a linkage whose inputs do not
  /// match its mobility structurally, or without moving nodes): then there are no blocks.
  bool usable = false;
  bool closed = false;            // every block has a closed form (no Newton's method, no guess)
  std::vector<int> rows, coords;  // the blocks' rows and coordinates, block after block
  std::vector<Block> blocks;      // in the order of solution
  /// The sign of the two permutations together (rows, coords): det G = permutation_sign times
  /// the product of the diagonal blocks' determinants.
  double permutation_sign = 1;
  /// A term of the substitutions: an entry of the Jacobian G outside the diagonal blocks (its
  /// offset in G, column-major, rows x n) and the unknown it multiplies (forward: a coordinate
  /// of an earlier block; backward: a row of a later block).
  struct Term {
    int entry{}, other{};
  };
  /// Per entry i of `rows`, its forward terms row_terms[row_first[i]] up to
  /// row_terms[row_first[i + 1]]; per entry j of `coords`, its backward terms likewise.
  std::vector<int> row_first, coord_first;
  std::vector<Term> row_terms, coord_terms;
};

/// The compiled equations of one linkage.
struct System {
  Linkage linkage;
  int n{};                 // free coordinates (2 per moving node)
  int structural_rows{};   // rows of the constraints (not the inputs)
  int rows{};              // structural rows + inputs
  std::vector<int> coord;  // per node: index of its x in q, -1 for a ground node
  std::vector<int> moving, fixed;  // the moving and the ground nodes, in node order

  struct ElementRow {  // one per link, row = link index
    int p{}, q{};      // element nodes
    double length{}, length_sq{};
  };
  struct RigidRows {  // two rows per further node of a link
    int row{}, link{}, node{}, p{}, q{};
    PointWeights weights;
  };
  struct SliderRow {
    int row{}, slider{}, node{};
    bool on_link{};                             // false: frame guide
    Vec2 from{0, 0}, unit{0, 0}, normal{0, 0};  // frame guide
    int from_node{-1}, to_node{-1};             // guide on a link
    double length{};                            // |to_node - from_node|, constant
  };
  struct InputRow {
    int row{}, input{};
    bool angle{};
    int p{}, q{};     // angle: the link's first two nodes
    double length{};  // angle: the link's element length, the row's scale [m]
    int slider{};     // slide: index into sliders (SliderRow)
  };
  /// What each row is: its kind and the index into elements, rigid, sliders or inputs (for a
  /// rigid pair, both rows name the same entry).
  struct RowRef {
    enum class Kind { kElement, kRigid, kSlider, kInput } kind = Kind::kElement;
    int index{};
  };
  std::vector<RowRef> row_ref;       // per row
  std::vector<ElementRow> elements;  // per link
  /// Per link, the angle input that turns it (its angle is the input's value), or -1.
  std::vector<int> link_input;
  /// The joint slots: one per link and node of that link (the force on the link from the joint
  /// there), link after link in the order of each link's nodes, so that an element's first and
  /// second node are slots first_slot[k] and first_slot[k] + 1 (first_slot[links] = slots).
  /// slot_of[link * nodes + node] is
  /// the slot, or -1 where the link does not hold the node; per ground node (in node order) its
  /// slots are ground_slots[ground_first[i]] up to ground_slots[ground_first[i + 1]].
  int slots{};
  std::vector<int> first_slot, slot_of, ground_first, ground_slots;
  std::vector<RigidRows> rigid;
  std::vector<SliderRow> sliders;  // per linkage slider
  std::vector<InputRow> inputs;    // per input

  std::vector<ElementMass> element_mass;  // per link
  std::vector<Mat4> element_M;            // per link
  std::vector<PointWeights> com_weights;  // per link: its centre of mass on the element
  std::vector<Vec2> link_force;           // per link: its weight and load at its centre of mass [N]
  std::vector<double> link_moment;        // per link: its load's moment [N m]
  /// A balance shaft (model.hpp BalanceShaft). Its kinetic energy ½ J ratio² ω² is carried by its
  /// link as extra rotary inertia (element_M includes it), so that M stays constant and the
  /// multipliers are the joint forces of the link loaded by the drive's torque -ratio τ; the
  /// shaft's own forces are added to the outputs (core/planar/dynamics.cpp).
  struct ShaftRef {
    int link{}, pivot{}, ratio{};
    int p{}, q{};         // the link's element nodes (its direction)
    Vec2 drawn{0, 0};     // the element's unit direction as drawn
    double J{};           // inertia about the shaft [kg m^2]
    bool mesh{};          // a gear pair with a pitch point; else a pure torque
    Vec2 normal{0, 0};    // the tooth force's direction: normal to the line of centres
    double per_torque{};  // tooth force per unit shaft torque, (1 - ratio) / |at - pivot|
  };
  std::vector<ShaftRef> shafts;
  MatrixXd M;                     // n x n, constant
  BlockPlan blocks;               // the rows and coordinates in block-triangular form
  std::vector<double> node_mass;  // per node: point masses there [kg]

  explicit System(const Linkage& linkage);
};

/// The block-triangular form of a compiled system (System's constructor sets System::blocks), from
/// the rows' structure.
BlockPlan plan_blocks(const System& s);

/// Replaces the links' and point masses' mass parameters by `pi` (core/planar/model.hpp,
/// mass_parameters()' layout) in place: the element masses, the mass matrix and the weights.
/// For the difference quotients of forward sensitivities; not checked.
void set_mass_parameters(System& s, const double* pi);

/// All coordinates of the nodes: ground nodes as drawn, moving ones from q.
void nodes_from_q(const System& s, const VectorXd& q, NodeVectors& x);
/// The velocities (or accelerations) of the nodes, ground nodes 0.
void node_rates_from(const System& s, const VectorXd& qd, NodeVectors& v);
/// q from the node positions (the moving nodes' coordinates).
VectorXd q_from_nodes(const System& s, const NodeVectors& x);
void q_from_nodes(const System& s, const NodeVectors& x, VectorXd& q);

/// The angle of input row k from node positions, continued to within π of `near` [rad].
double input_angle(const System& s, const System::InputRow& in, const NodeVectors& x, double near);
/// The position of a slider's node along its guide [m].
double slide_position(const System& s, const System::SliderRow& sl, const NodeVectors& x);
/// A slider's velocity along its guide [m/s] (relative to the guide's link).
double slide_rate(const System& s, const System::SliderRow& sl, const NodeVectors& x,
                  const NodeVectors& v);

/// One entry of a row's gradient: ∂g_row/∂(x, y of `node`), and the link the row's force acts
/// on there (-1: on the node itself, e.g. a guide's force on its sliding node).
struct GradientEntry {
  int node{};
  Vec2 grad{0, 0};
  int link{-1};
};
/// The (at most three) nonzero entries of row `row`'s gradient at x, ground nodes included;
/// returns how many.
int row_gradient(const System& s, const NodeVectors& x, int row, GradientEntry out[3]);
/// An angle input row's gradient at x with respect to its link's second node (q); the first
/// node's (p) is its negative. row_gradient()'s case, for the loops that take it without the
/// dispatch.
inline Vec2 angle_input_gradient(const System::InputRow& in, const NodeVectors& x) {
  const Vec2 d = x[static_cast<std::size_t>(in.q)] - x[static_cast<std::size_t>(in.p)];
  return in.length * perp(d) / d.squaredNorm();
}

/// The inputs' targets as constraint_values() takes them: per input, the direction (cos θ, sin θ)
/// of an angle input at θ, (s, 0) for a slide at s. Computed once per position solve, so that
/// its iterations evaluate no trigonometric function.
void input_targets(const System& s, const std::vector<double>& inputs, std::vector<Vec2>& targets);
/// How constraint_values() writes an angle input's row.
enum class AngleRow {
  /// l (φ - θ) by atan2 of the angle from the target direction: linear in the angle, for
  /// iterations from afar (Newton's method, assembly).
  kAngle,
  /// u × d, u the target direction (cos θ, sin θ) and d the link's element vector: linear in the
  /// node coordinates, no trigonometric function. Near the root it equals l sin(φ - θ) with
  /// |d| = l, so it has the same root (φ = θ; its other, φ = θ + π, lies half a turn away) and
  /// there the same gradient as the angle form, l perp(d) / |d|² = perp(u): the chord method's
  /// factorisation serves both. For iterations that start near the root.
  kCross,
};
/// g(q) with the inputs at `targets` (input_targets()); the structural rows only when `targets`
/// is empty.
void constraint_values(const System& s, const NodeVectors& x, const std::vector<Vec2>& targets,
                       VectorXd& g, AngleRow angle_row = AngleRow::kAngle);
/// G = ∂g/∂q (rows x n); without the input rows when rows == structural_rows.
void constraint_jacobian(const System& s, const NodeVectors& x, int rows, MatrixXd& G);
/// γ = Ġ q̇ (rows), for the velocities v of the nodes.
void constraint_bias(const System& s, const NodeVectors& x, const NodeVectors& v, int rows,
                     VectorXd& gamma);

/// The applied forces on q at time t: the links' loads and weights (eq. 46; not with
/// `link_loads` false, for a caller that has them per element), the node forces and point-mass
/// weights, the spring-dampers; with `efforts`, the inputs' drive efforts too.
void applied_forces(const System& s, const NodeVectors& x, const NodeVectors& v,
                    const std::vector<double>* efforts, VectorXd& F, bool link_loads = true);

/// A balance shaft's motion: its centre of mass from the shaft and that point's acceleration,
/// its rate and acceleration, and the torque τ its drive applies to it (J α - r × m g) [N m].
struct ShaftMotion {
  Vec2 r{0, 0}, a{0, 0};
  double omega{}, alpha{}, torque{};
};
/// Shaft k's motion for node positions x and its link's rate and acceleration.
ShaftMotion shaft_motion(const System& s, int k, const NodeVectors& x, double omega_link,
                         double alpha_link);
/// The moment on link k at x: its load's and the gravity torque its balance shafts pass back
/// through their drives (ratio × r × m g) [N m].
double link_moment_at(const System& s, int k, const NodeVectors& x);

/// The tension of spring k [N] (positive pulls its nodes together), its length and its unit
/// vector from a to b.
struct SpringState {
  double tension{}, length{}, rate{};
  Vec2 unit{0, 0};
};
SpringState spring_state(const System& s, int k, const NodeVectors& x, const NodeVectors& v);

}  // namespace bd::core::planar::detail
