#pragma once
/// An independent referee for planar linkages: Newton–Euler equations of rigid bodies in maximal
/// coordinates (x, y of the centre of mass and the angle phi of every body) with Lagrange
/// multipliers for the joints. It shares no code with core/ (it depends on Eigen only) and is
/// meant to check the project's engine in tests; speed is secondary to clarity and accuracy.
///
/// Conventions (all SI units; "global" = the frame's axes, origin at the global origin):
///  * Every geometric datum is given in GLOBAL coordinates at one "described" configuration
///    (the one the user drew). The referee converts to body-local coordinates itself.
///  * A body's angle is its rotation from the described configuration, counter-clockwise
///    positive, continuous (never wrapped). In the described configuration every angle is 0.
///  * A body's position is that of its centre of mass after merging its point masses.
///  * Cross product in the plane: a x b = a.x b.y - a.y b.x; moments are counter-clockwise
///    positive; shaking moments are taken about the global origin.
///  * Force "of X on Y": the force body X exerts on body Y (Y feels it; X feels the opposite).
///  * Degrees of freedom: exactly one Input per degree of freedom. The referee requires
///    3 * bodies == 2 * pins + sliders + gears + inputs and a full-rank constraint Jacobian
///    (redundant constraints, e.g. a parallelogram with an extra link, are not supported).
///  * Errors (invalid descriptions, singular positions, failed closure) throw std::domain_error.
///
/// Describing a mechanism (notes for glue code):
///  * A link with k joints (binary, ternary, ...) is ONE Body (mass, inertia about its centre
///    of mass, centre of mass) plus one Pin per joint to the neighbouring body or kGround, at the
///    joint's described position. The ground is never a Body.
///  * A mass concentrated at a joint (a slider block, a piston, a node mass) goes into
///    point_masses of ONE of the bodies meeting there. The motion does not depend on which, but
///    the reported force of that pin does: it excludes the inertia and weight of the point mass
///    on the side it was attached to.
///  * A piston / slider block on a guide: the rod gets the block's mass as a point mass at the
///    wrist pin and a PointOnLine{rod, kGround, wrist pin, guide}. (A block as a separate Body
///    would be free to turn about the wrist pin: a point-on-line joint does not stop rotation.)
///  * A slider driven by a force: SlideInput{slider} as the input, the force (along the line,
///    towards line_to positive) in input_efforts. A crank driven by a motor: AngleInput{crank}
///    and the torque in input_efforts. Driven scenes prescribe the inputs instead.
///  * Gears (e.g. counter-rotating discs): each geared body also needs its Pin to the ground.
#include <Eigen/Dense>
#include <functional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace bd::referee {

using Vec2 = Eigen::Vector2d;
/// The frame (ground), usable wherever a body index is expected.
inline constexpr int kGround = -1;

/// A rigid body (link).
struct Body {
  std::string name;
  double mass = 0;     ///< [kg] >= 0
  double inertia = 0;  ///< about its own centre of mass [kg m^2] >= 0
  Vec2 com{0, 0};      ///< centre of mass in the described configuration, global [m]
  /// Point masses rigidly attached (e.g. a piston or slider block at a joint): merged into the
  /// body (combined mass, centre of mass, and inertia by the parallel-axis rule; a point mass
  /// has no inertia of its own). (mass [kg], global point [m]).
  std::vector<std::pair<double, Vec2>> point_masses;
};

/// Revolute joint: the point `point` of body a coincides with that of body b.
struct Pin {
  std::string name;
  int a = kGround, b = kGround;  ///< body indices or kGround (not both ground, a != b)
  Vec2 point{0, 0};              ///< global, described configuration [m]
};

/// Frictionless point-on-line joint: the point `point` of body point_body stays on the line
/// through line_from -> line_to, both fixed in body line_body (kGround: a guide in the frame).
/// Only a force normal to the line is transmitted, acting at the point (a massless slider block
/// pinned to point_body and sliding on line_body). line_from != line_to. The point need not
/// coincide with line_from but must lie on the line in the described configuration.
struct PointOnLine {
  std::string name;
  int point_body = kGround, line_body = kGround;     ///< not both ground
  Vec2 point{0, 0}, line_from{0, 0}, line_to{0, 0};  ///< global, described configuration [m]
};

/// External spur-gear mesh between two bodies that are each pinned to the frame: the mechanism
/// must ALSO contain the Pins {kGround or body, body, pivot} (the gear does not pin the bodies).
/// The pitch point lies on the segment between the pivots; r_a = |pitch_point - pivot_a|,
/// r_b = |pitch_point - pivot_b| (both > 0) and omega_b = -(r_a / r_b) omega_a. The ideal mesh
/// transmits only the force perpendicular to (pivot_b - pivot_a), acting at the pitch point.
struct Gear {
  std::string name;
  int a = 0, b = 0;                                      ///< body indices (not ground, a != b)
  Vec2 pivot_a{0, 0}, pivot_b{0, 0}, pitch_point{0, 0};  ///< global [m]
};

/// A force applied at a point of a body (not the ground), global axes [N], function of time [s].
struct PointForce {
  int body = 0;
  Vec2 point{0, 0};  ///< global, described configuration; the point moves with the body
  std::function<Vec2(double t)> force;
};
/// A pure moment on a body (not the ground) [N m], counter-clockwise positive.
struct BodyMoment {
  int body = 0;
  std::function<double(double t)> moment;
};
/// Linear spring-damper between a point of body a and a point of body b (either may be kGround,
/// not both). Tension T = stiffness (L - free_length) + damping dL/dt, L = current distance
/// (must stay > 0). A positive tension pulls the two points towards each other.
struct Spring {
  int a = kGround, b = kGround;
  Vec2 point_a{0, 0}, point_b{0, 0};                   ///< global, described configuration [m]
  double stiffness = 0, free_length = 0, damping = 0;  ///< [N/m], [m], [N s/m]
};

/// Angle input: the rotation of `body` relative to the frame, measured from the described
/// configuration [rad]. Its effort is a torque applied to the body BY THE FRAME (the frame
/// feels -torque: a motor whose stator is fixed in the frame).
struct AngleInput {
  int body = 0;
};
/// Slide input: the displacement of PointOnLine[slider]'s point along its line, relative to the
/// line body, positive towards line_to, measured from the described configuration [m]. Its
/// effort is a force along the line applied to the point body at the point BY THE LINE BODY
/// (for a guide in the frame: by the frame); the line body feels the opposite force at the same
/// point.
struct SlideInput {
  int slider = 0;
};
using Input = std::variant<AngleInput, SlideInput>;

struct Mechanism {
  std::vector<Body> bodies;
  std::vector<Pin> pins;
  std::vector<PointOnLine> sliders;
  std::vector<Gear> gears;
  std::vector<PointForce> forces;
  std::vector<BodyMoment> moments;
  std::vector<Spring> springs;
  Vec2 gravity{0, 0};  ///< [m/s^2], acts on every mass
  std::vector<Input> inputs;
  /// Free runs only: the effort (torque [N m] or force [N], conventions of AngleInput /
  /// SlideInput) of each input as a function of time; empty vector or empty function = no
  /// effort. Ignored by driven().
  std::vector<std::function<double(double t)>> input_efforts;
};

/// Position of one body: centre of mass [m] (global) and angle [rad] from the described one.
struct Pose {
  Vec2 com{0, 0};
  double angle = 0;
};
struct BodyState {
  Vec2 com{0, 0}, velocity{0, 0}, acceleration{0, 0};  ///< of the centre of mass [m, m/s, m/s^2]
  double angle = 0, omega = 0, alpha = 0;              ///< [rad, rad/s, rad/s^2]
};
struct GearForce {
  Vec2 force{0, 0};  ///< mesh force of body a ON body b [N] (perpendicular to the pivot line)
  Vec2 point{0, 0};  ///< where it acts: the pitch point [m]
};
struct PointMotion {
  Vec2 p{0, 0}, v{0, 0}, a{0, 0};  ///< [m, m/s, m/s^2]
};

/// Everything at one instant. Vectors are indexed like the corresponding Mechanism vectors.
struct Sample {
  double t = 0;  ///< [s]
  std::vector<BodyState> bodies;
  /// Force of body a ON body b at the pin [N]. The force ON the frame of a ground pin is
  /// -pin_forces[k] when a == kGround and +pin_forces[k] when b == kGround.
  std::vector<Vec2> pin_forces;
  std::vector<Vec2> slider_forces;  ///< normal force of line_body ON point_body, at the point [N]
  std::vector<Vec2> slider_points;  ///< current position of each slider's point [m]
  std::vector<GearForce> gear_forces;
  std::vector<double> input_values;         ///< [rad or m], from the described configuration
  std::vector<double> input_rates;          ///< [rad/s or m/s]
  std::vector<double> input_accelerations;  ///< [rad/s^2 or m/s^2]
  /// Driven scenes: the torque/force the drive must supply; free scenes: the given effort.
  std::vector<double> input_efforts;
  std::vector<double> spring_lengths;   ///< [m]
  std::vector<double> spring_tensions;  ///< [N], elastic + damping, positive = pulling together
  /// The sum of all forces of the mechanism ON the frame: ground pins (gear shafts included),
  /// ground sliders, springs anchored to the frame, reactions of slide drives on a frame guide.
  Vec2 shaking_force{0, 0};  ///< [N]
  /// The moments about the origin of those forces at their points, plus -torque of every angle
  /// drive (its stator reacts on the frame) [N m]. About a point P: shaking_moment - P x F.
  double shaking_moment = 0;
  Vec2 inertial_force{0, 0};    ///< -sum m_i a_i [N]
  double inertial_moment = 0;   ///< -dH/dt about the origin = -sum(r_i x m_i a_i + I_i alpha_i)
  Vec2 momentum{0, 0};          ///< sum m_i v_i [kg m/s]
  double angular_momentum = 0;  ///< about the origin, sum(r_i x m_i v_i + I_i omega_i) [kg m^2/s]
  double kinetic_energy = 0;    ///< [J]
  double gravity_energy = 0;    ///< -sum m_i g . r_i [J]
  double spring_energy = 0;     ///< sum stiffness (L - free_length)^2 / 2 [J]
  double input_power = 0;       ///< sum effort * input rate [W]
  double damper_power = 0;      ///< dissipated by the dampers, sum damping (dL/dt)^2 >= 0 [W]
  double applied_power = 0;     ///< of the PointForces and BodyMoments [W]
  double gravity_power = 0;     ///< sum m_i g . v_i = -d(gravity_energy)/dt [W]
  double spring_power = 0;      ///< of all spring-damper forces on the bodies and frame [W]
  /// Free runs only (0 in driven scenes): the work done since t = 0 by the input efforts, the
  /// work dissipated by the dampers, the work of the applied forces and moments [J], integrated
  /// with the motion (to the integrator's tolerance).
  double input_work = 0, damper_work = 0, applied_work = 0;
};

/// Positions with the inputs held at `input_values` (offsets from the described configuration,
/// one per Mechanism::inputs): Newton on all position constraints, continued from the described
/// configuration in small steps of the inputs (so the described assembly branch is followed).
/// @throws std::domain_error on invalid input, non-convergence or a rank-deficient Jacobian.
std::vector<Pose> assemble(const Mechanism& mechanism, const std::vector<double>& input_values);

/// Driven scene: input k is held at input_rates[k] * (t - t0) (so the mechanism is in the
/// described configuration at t = t0), with constant rates. At each of `times` (ascending,
/// any t, before t0 too) the full state and every force; loads are evaluated at the absolute t.
/// Positions are continued from one sample to the next (the branch is followed).
/// @throws std::domain_error naming the time at a singular position (the Jacobian with the
///         inputs held loses rank) or where the loop cannot be closed.
std::vector<Sample> driven(const Mechanism& mechanism, const std::vector<double>& input_rates,
                           double t0, const std::vector<double>& times);

/// Free scene (forward dynamics) from the described configuration at t = 0 with the given input
/// rates (all body velocities follow from the constraints), under all loads and input_efforts,
/// over [0, duration]. `times` ascending within [0, duration]; the integrator steps exactly onto
/// each (many samples cost steps). Method (free_run.cpp): coordinate partitioning on the inputs
/// (dependent coordinates by Newton at every evaluation: no drift), Gragg–Bulirsch–Stoer
/// extrapolation, all in long double. `tolerance` bounds each step's local error estimate
/// relative to 1 rad / the mechanism size for input positions and to the largest |rate| so far
/// for input rates. At the default the self-tests find samples within ~1e-12 (worst 1.2e-12,
/// typically 1e-14) of runs at half and a tenth of it: the claim is 1e-11 relative.
/// @throws std::domain_error naming the time at a singular position (the inputs stop being
///         valid coordinates) or when the integrator fails.
std::vector<Sample> free_run(const Mechanism& mechanism, const std::vector<double>& initial_rates,
                             double duration, const std::vector<double>& times,
                             double tolerance = 1e-15);

/// Counters of the last free_run on this thread (for tests and reports).
struct FreeRunStats {
  long steps = 0, rejected = 0, evaluations = 0;
};
FreeRunStats last_free_run_stats();

/// Motion of a point of a body in a sample, the point given in the described configuration
/// (global). body == kGround gives the fixed point.
PointMotion point_motion(const Mechanism& mechanism, const Sample& sample, int body,
                         const Vec2& described_point);

/// The merged mass [kg], centre of mass (described, global) [m] and inertia about it [kg m^2]
/// of a body with its point masses.
struct MassProperties {
  double mass = 0;
  Vec2 com{0, 0};
  double inertia = 0;
};
MassProperties merged(const Body& body);

}  // namespace bd::referee
