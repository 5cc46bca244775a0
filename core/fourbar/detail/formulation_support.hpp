#pragma once
/// Steps every formulation of the dynamics shares: closing the loop with the singularity check,
/// the kinematics of the instant, and completing a sample (shaking force and moment, the
/// non-finite check); and each formulation's evaluation with its model constants, the route of
/// the loops over many instants (the overloads with DynamicsConstants, the driven sweep).
/// Internal to core, not part of its API (core/detail/xy.hpp says what the detail folders hold).
///
/// How the hot path is written, and why (docs/performance.md has the measurements): an
/// evaluation is a chain of dependent steps (sincos, two square roots, divisions, two atan2,
/// the formulation's algebra), so its time is mostly latency, and what lengthens the chain
/// shows directly.
/// - The per-instant stages are inline, so a loop over instants compiles an evaluation as one
///   piece; calls across translation units that passed the instant's kinematics through memory
///   cost a good share of an evaluation.
/// - They compute in plain doubles (Xy, core/detail/xy.hpp says why not Vec2), fill their results
///   field by field into the caller's objects, and report failure as a small value (Failure):
///   results passed as whole structs are written as doubles and copied by the compiler in
///   16-byte pieces, which cannot be forwarded from the store buffer either.
#include <cmath>
#include <limits>
#include <optional>

#include "core/detail/xy.hpp"
#include "core/fourbar/detail/dynamics_constants.hpp"
#include "core/fourbar/detail/loop_closure.hpp"
#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/kinematics.hpp"
#include "core/fourbar/model.hpp"

namespace bd::core::detail {

/// The pose at theta1 on the model's branch, or kAssembly / kSingular.
Expected<Pose, DynamicsError> nonsingular_pose(const FourBar& model, double theta1);

/// Why an instant has no dynamics, with the number its message needs: cheap to return on the
/// hot path (no string), turned into a DynamicsError where a caller reports it.
struct Failure {
  enum class Reason {
    kAssembly,     // the loop cannot close; value: AssemblyError::gap [m]
    kDeadCentre,   // |sin(theta3 - theta2)| < kSingularSin; value: sin(theta3 - theta2)
    kAllParallel,  // the opened loop's 5x5 system is singular; value: the largest |sin|
    kNonFinite,    // a non-finite acceleration, reaction or torque
  };
  Reason reason{Reason::kAssembly};
  double theta1{};  // [rad]
  double value{};
  /// The error with its message (as DynamicsError::what() prints it).
  DynamicsError error() const;
};

/// One closed instant's kinematics, computed once and shared by all steps of a formulation (the
/// public kinematics functions would each redo the trigonometry of the pose): the position and
/// velocity stages, the link vectors straight from the position solve, and the coefficients of
/// the dependent accelerations alpha_k = Θk·alpha1 + gamma_k.
struct ClosedInstant {
  FourBarState state;     // position and velocity stages; acceleration stage zero
  Xy l1, l2, l3;          // l̄1, l̄2, l̄3 [m]
  double inv_l2_x_l3{};   // 1/(l̄2 × l̄3) [1/m^2], the divisor of the dependent rates
  TransferFunctions tf;   // Θ2, Θ3 [-]
  AccelerationBias bias;  // gamma2, gamma3 [rad/s^2]
};

/// Fills `c` with the closed instant at theta1 [rad] with crank vector l̄1 = l1·(cos theta1,
/// sin theta1) [m] and crank rate omega1 [rad/s] on the model's branch, or returns kAssembly
/// where the loop cannot close and kDeadCentre where |sin(theta3 - theta2)| < kSingularSin.
inline std::optional<Failure> close_instant(const FourBar& model, double theta1, const Xy& l1,
                                            double omega1, ClosedInstant& c) {
  LoopXy loop;
  if (const auto error = close_loop(model, theta1, l1, model.branch, loop)) {
    return Failure{Failure::Reason::kAssembly, theta1, error->gap};
  }
  // sin(theta3 - theta2) = l̄2 × l̄3 / (l2 l3)
  const double l2_x_l3 = cross(loop.l2, loop.l3);
  const double sin_mu = l2_x_l3 / (model.coupler.length * model.rocker.length);
  if (!(std::abs(sin_mu) >= kSingularSin)) {
    return Failure{Failure::Reason::kDeadCentre, theta1, sin_mu};
  }
  c.l1 = loop.l1;
  c.l2 = loop.l2;
  c.l3 = loop.l3;
  c.inv_l2_x_l3 = 1.0 / l2_x_l3;
  // eq. 7 via cross products: l̄1 + l̄2 Θ2 + l̄3 Θ3 = 0 (eq. 5) crossed with l̄3 and with l̄2
  // (the operations of transfer_functions(), kinematics.hpp)
  c.tf.dtheta2_dtheta1 = cross(c.l3, c.l1) * c.inv_l2_x_l3;
  c.tf.dtheta3_dtheta1 = cross(c.l1, c.l2) * c.inv_l2_x_l3;
  c.state.theta1 = theta1;
  // the angles: two atan2, the longest chain of the instant, but only its outputs need them, so
  // they run alongside the rest
  c.state.theta2 = link_angle(c.l2);
  c.state.theta3 = link_angle(c.l3);
  c.state.omega1 = omega1;
  c.state.omega2 = c.tf.dtheta2_dtheta1 * omega1;
  c.state.omega3 = c.tf.dtheta3_dtheta1 * omega1;
  c.state.alpha1 = c.state.alpha2 = c.state.alpha3 = 0.0;
  // eq. 8: Σ l̄k α_k = -i b with b = Σ l̄k ω_k²; crossed with l̄3 and l̄2 (eqs. 9-10), as
  // acceleration_bias()
  const Xy b = c.l1 * (omega1 * omega1) + c.l2 * (c.state.omega2 * c.state.omega2) +
               c.l3 * (c.state.omega3 * c.state.omega3);
  c.bias.gamma2 = dot(c.l3, b) * c.inv_l2_x_l3;
  c.bias.gamma3 = -dot(c.l2, b) * c.inv_l2_x_l3;
  return std::nullopt;
}

/// The crank vector l̄1 = l1·(cos theta1, sin theta1) [m].
inline Xy crank_vector(const FourBar& model, double theta1) {
  return {model.crank.length * std::cos(theta1), model.crank.length * std::sin(theta1)};
}

/// Writes the instant's state into `s` with the acceleration stage for crank acceleration alpha1
/// [rad/s^2] (eqs. 9-10), field by field.
inline void set_state(const ClosedInstant& c, double alpha1, FourBarState& s) {
  s.theta1 = c.state.theta1;
  s.theta2 = c.state.theta2;
  s.theta3 = c.state.theta3;
  s.omega1 = c.state.omega1;
  s.omega2 = c.state.omega2;
  s.omega3 = c.state.omega3;
  s.alpha1 = alpha1;
  s.alpha2 = c.tf.dtheta2_dtheta1 * alpha1 + c.bias.gamma2;
  s.alpha3 = c.tf.dtheta3_dtheta1 * alpha1 + c.bias.gamma3;
}

/// Fills the reactions RA0, RA3 [N], Fsh = RA0 + RA3, tau [N m] and Msh = l4·RA3y - tau of `s`,
/// whose state is filled, or returns kNonFinite if any rate, acceleration, reaction or the
/// torque is not finite. The shaft reactions RC1, RC3 are zero.
inline std::optional<Failure> complete_sample(const FourBar& model, const Xy& RA0, const Xy& RA3,
                                              double tau, DynamicsSample& s) {
  s.RA0.x() = RA0.x;
  s.RA0.y() = RA0.y;
  s.RA3.x() = RA3.x;
  s.RA3.y() = RA3.y;
  s.RC1.x() = s.RC1.y() = s.RC3.x() = s.RC3.y() = 0.0;
  s.Fsh.x() = RA0.x + RA3.x;
  s.Fsh.y() = RA0.y + RA3.y;
  s.tau = tau;
  s.Msh = model.frame_length * RA3.y - tau;
  const FourBarState& x = s.state;
  // 0·v is 0 for every finite v and NaN for an infinity or a NaN: one test for all of them
  const double zero_if_finite = 0.0 * x.omega2 + 0.0 * x.omega3 + 0.0 * x.alpha1 + 0.0 * x.alpha2 +
                                0.0 * x.alpha3 + 0.0 * RA0.x + 0.0 * RA0.y + 0.0 * RA3.x +
                                0.0 * RA3.y + 0.0 * tau;
  if (!(zero_if_finite == 0.0)) return Failure{Failure::Reason::kNonFinite, x.theta1, 0.0};
  return std::nullopt;
}

/// Fills the outputs of `s` derived from its state, its reactions and the model (the constants
/// `c`): the inertial and static parts of the shaking force and moment and the joint forces FA1,
/// FA2, as set_derived_outputs() (core/fourbar/dynamics.hpp) says. l1, l2, l3 are the link
/// vectors l̄k = l_k (cos θk, sin θk) [m] of the sample's pose: a sweep passes those of its
/// position solve, so no angle goes through sincos again.
inline void derived_outputs_at(const DerivedConstants& c, const Xy& l1, const Xy& l2, const Xy& l3,
                               DynamicsSample& s) {
  const FourBarState& x = s.state;
  // each centre of mass: its link's first joint (A0 = 0, A1 = l̄1, A2 = A3 - l̄3) plus s̄_k in
  // ground axes; its acceleration: the joint's plus α_k i s̄_k - ω_k² s̄_k
  const Xy rho1 = cmul(c.s1, l1), rho2 = cmul(c.s2, l2), rho3 = cmul(c.s3, l3);
  const Xy c1 = rho1, c2 = l1 + rho2, c3 = Xy{c.l4 - l3.x, -l3.y} + rho3;
  const Xy a_A1 = x.alpha1 * perp(l1) - (x.omega1 * x.omega1) * l1;
  const Xy a_A2 = (x.omega3 * x.omega3) * l3 - x.alpha3 * perp(l3);
  const Xy ma1 = c.m1 * (x.alpha1 * perp(rho1) - (x.omega1 * x.omega1) * rho1);
  const Xy ma2 = c.m2 * (a_A1 + x.alpha2 * perp(rho2) - (x.omega2 * x.omega2) * rho2);
  const Xy ma3 = c.m3 * (a_A2 + x.alpha3 * perp(rho3) - (x.omega3 * x.omega3) * rho3);
  // H about A0 = Σ (c × m v + I ω), so dH/dt = Σ (c × m a + I α); a disc turns at minus its
  // link's rate about a shaft fixed in the frame: -dH/dt = +J α_link
  const Xy Fi = -(ma1 + ma2 + ma3);
  s.Fsh_inertial.x() = Fi.x;
  s.Fsh_inertial.y() = Fi.y;
  s.Msh_inertial = -((cross(c1, ma1) + c.I1 * x.alpha1) + (cross(c2, ma2) + c.I2 * x.alpha2) +
                     (cross(c3, ma3) + c.I3 * x.alpha3)) +
                   (c.J1 * x.alpha1 + c.J3 * x.alpha3);
  const Xy Fs = c.F1 + c.F2 + c.F3;
  s.Fsh_static.x() = Fs.x;
  s.Fsh_static.y() = Fs.y;
  s.Msh_static = (cross(c1, c.F1) + c.M1) + (cross(c2, c.F2) + c.M2) + (cross(c3, c.F3) + c.M3);
  // per link, m a - (F + m g) is what the joints, supports and gears supply: on the crank
  // -RA0 - RC1 - FA1 (its support, its gear, the coupler), on the rocker -RA3 - RC3 + FA2
  const Xy FA1 = (c.F1 - ma1) - xy(s.RA0) - xy(s.RC1);
  const Xy FA2 = (ma3 - c.F3) + xy(s.RA3) + xy(s.RC3);
  s.FA1.x() = FA1.x;
  s.FA1.y() = FA1.y;
  s.FA2.x() = FA2.x;
  s.FA2.y() = FA2.y;
}

/// Which of θ̈1 and tau a formulation solves for at an instant: forward dynamics (tau = 0) has
/// the crank acceleration unknown, inverse dynamics the torque for a given one.
struct CrankInput {
  bool torque_unknown{};  // false: forward (tau = 0); true: inverse with alpha1 given
  double alpha1{};        // [rad/s^2], inverse only

  static CrankInput forward() { return {false, 0.0}; }
  static CrankInput inverse(double alpha1) { return {true, alpha1}; }
};

/// Each formulation at a closed instant of `model`, whose constants are `c` (model without
/// counter-rotations): fills `out` and returns std::nullopt, or returns why not (`out` is then
/// partly filled). The opened loop takes its link vectors from the state's angles, so that it
/// agrees bit for bit with its state form, forward_dynamics_opened_loop(model, state). (The mass
/// matrix's, mass_matrix_at(), and dynamics_at(), which calls one of them, are inline in
/// core/fourbar/detail/instant_dynamics.hpp.)
std::optional<Failure> complex_masses_at(const FourBar& model, const ComplexMassConstants& c,
                                         const ClosedInstant& instant, CrankInput input,
                                         DynamicsSample& out);
std::optional<Failure> opened_loop_at(const FourBar& model, const OpenedLoopConstants& c,
                                      const ClosedInstant& instant, CrankInput input,
                                      DynamicsSample& out);
/// close_instant() and then formulation `evaluate` (one of the above with its constants bound),
/// as the public one-instant functions return it.
template <class Evaluate>
Expected<DynamicsSample, DynamicsError> evaluated(const FourBar& model, double theta1,
                                                  double omega1, Evaluate evaluate) {
  Expected<DynamicsSample, DynamicsError> result;
  ClosedInstant instant;
  std::optional<Failure> failure =
      close_instant(model, theta1, crank_vector(model, theta1), omega1, instant);
  if (!failure) failure = evaluate(instant, *result);
  if (failure) result = Unexpected(failure->error());
  return result;
}

/// The crank vectors l̄1 = l1·(cos θ1, sin θ1) of a sweep over closely spaced crank angles, at a
/// fraction of a sine and cosine per sample. An anchor angle takes std::cos and std::sin; an
/// angle within kMaxTurn of the latest anchor is the anchor turned by δ = θ1 - θ1_anchor,
/// l̄1 = l̄1_anchor + l̄1_anchor·(cos δ - 1 + i sin δ), with sin δ and cos δ - 1 from their Taylor
/// series (truncation below 3e-18 relative). The correction is small, so each component differs
/// from l1·cos θ1, l1·sin θ1 of the sample's own θ1 by about one rounding of l1 (~1e-16·l1), as
/// std::cos and std::sin do, and nothing accumulates along the sweep. A driven sweep of 360
/// samples per revolution takes one anchor per 15 samples.
class CrankSweep {
 public:
  static constexpr double kMaxTurn = 0.25;  // [rad]
  /// For crank length l1 [m].
  explicit CrankSweep(double crank_length) : length_(crank_length) {}
  /// l̄1 [m] at crank angle theta1 [rad].
  Xy l1(double theta1);

 private:
  double length_;
  double anchor_theta_ = std::numeric_limits<double>::quiet_NaN();  // [rad]
  Xy anchor_;                                                       // l̄1 there [m]
};

inline Xy CrankSweep::l1(double theta1) {
  const double delta = theta1 - anchor_theta_;
  if (!(std::abs(delta) <= kMaxTurn)) {  // also the first call (NaN)
    anchor_theta_ = theta1;
    anchor_ = Xy{length_ * std::cos(theta1), length_ * std::sin(theta1)};
    return anchor_;
  }
  // sin δ = δ - δ³/3! + ... - δ^11/11!, cos δ - 1 = -δ²/2! + ... + δ^12/12!: the first omitted
  // terms, δ^13/13! and δ^14/14!, are below 3e-18 at |δ| = 0.25 (l1 times that is far below
  // the rounding of l̄1)
  const double z = delta * delta;
  const double sin_delta =
      delta + delta * z *
                  (-1.0 / 6 + z * (1.0 / 120 +
                                   z * (-1.0 / 5040 + z * (1.0 / 362880 + z * (-1.0 / 39916800)))));
  const double cos_delta_m1 =
      z * (-1.0 / 2 +
           z * (1.0 / 24 + z * (-1.0 / 720 +
                                z * (1.0 / 40320 + z * (-1.0 / 3628800 + z * (1.0 / 479001600))))));
  return anchor_ + cmul(anchor_, Xy{cos_delta_m1, sin_delta});
}

}  // namespace bd::core::detail
