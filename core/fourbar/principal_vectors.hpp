#pragma once
/// Principal vectors and points (Fischer), equivalent complex masses (Freudenstein) and the
/// system centre of mass S traced by the principal-vector constructions (paper §3, §4.1).
///
/// A principal vector ā_kj starts at the principal point P_k of link k and ends at the joint of
/// link k with link j (or at the joint with the frame, j = 4). All are fixed in their link: each
/// is a constant complex factor times the link vector l̄_k, so they turn with the link. The
/// vectors are Vec2; the complex masses and the factors are the paper's complex scalars
/// (ComplexMass, ComplexCoefficient in core/types.hpp).
#include "core/fourbar/kinematics.hpp"
#include "core/fourbar/model.hpp"
#include "core/types.hpp"

namespace bd::core {

/// The equivalent masses of a link (eq. 29 and §4.1): the complex masses at its first joint p and
/// second joint q, m̄_p = m(1 - s̄/l) = m^a - i m^c and m̄_q = m s̄/l = m^b + i m^c, whose sum is m.
struct EquivalentMasses {
  ComplexMass mp, mq;  // complex masses at the first and second joint [kg]
  double ma{};         // real equivalent mass at p: m (1 - e/l) [kg]
  double mb{};         // real equivalent mass at q: m e/l [kg]
  double mc{};         // virtual equivalent mass: m f/l [kg]
};
EquivalentMasses equivalent_masses(const Link& link);

/// The opened-loop set about A0 (eqs. 12-13, Figs. 2-3): ā12, ā21, ā23, ā32 and the derived
/// ā14', ā34', in ground axes [m].
struct OpenedLoopVectors {
  Vec2 a12, a21, a23, a32, a14p, a34p;
};
OpenedLoopVectors opened_loop_vectors(const FourBar& model, const Pose& pose);
/// The same from the link vectors of the pose (no trigonometry).
OpenedLoopVectors opened_loop_vectors(const FourBar& model, const LinkVectors& l);

/// The frame set (eqs. 30-31, Fig. 4): ā14, ā41, ā43, ā34 and the derived ā12', ā32', in ground
/// axes [m]. ā41 and ā43 are constant; S is stationary iff ā14 = ā34 = 0 (eq. 57).
struct FrameVectors {
  Vec2 a14, a41, a43, a34, a12p, a32p;
};
FrameVectors frame_vectors(const FourBar& model, const Pose& pose);
/// The same from the link vectors of the pose (no trigonometry).
FrameVectors frame_vectors(const FourBar& model, const LinkVectors& l);

/// The same vectors as constant complex factors c with ā = c·l̄_k (c depends on the masses and
/// centres of mass only). Used by the formulations and the balance conditions.
struct OpenedLoopFactors {
  ComplexCoefficient a12, a21, a23, a32, a14p, a34p;  // times l̄1, l̄2, l̄2, l̄3, l̄1, l̄3
};
OpenedLoopFactors opened_loop_factors(const FourBar& model);
struct FrameFactors {
  ComplexCoefficient a14, a41, a43, a34, a12p, a32p;  // times l̄1, l̄4, l̄4, l̄3, l̄1, l̄3
};
FrameFactors frame_factors(const FourBar& model);

/// Principal points [m] of a set, ground axes: P_k = joint - ā_kj.
struct PrincipalPoints {
  Vec2 P1, P2, P3;  // opened-loop set: in links 1, 2, 3
};
PrincipalPoints opened_loop_principal_points(const FourBar& model, const Pose& pose);
struct FramePrincipalPoints {
  Vec2 P1, P3, P4;  // frame set: in links 1, 3 and the frame
};
FramePrincipalPoints frame_principal_points(const FourBar& model, const Pose& pose);

/// Position [m], velocity [m/s] and acceleration [m/s^2] of the system centre of mass S.
struct PointKinematics {
  Vec2 r{0, 0}, v{0, 0}, a{0, 0};
};
/// S by the opened-loop construction (eq. 16): r̄_S = -ā14' - ā21 - ā32, differentiated with the
/// link rates; needs the state's acceleration stage.
PointKinematics centre_of_mass_opened_loop(const FourBar& model, const FourBarState& s);
/// The same from the state's opened-loop vectors, when the caller has them already.
PointKinematics centre_of_mass_opened_loop(const OpenedLoopVectors& a, const FourBarState& s);
/// S by the frame construction (eq. 32): r̄_S = -ā14 - ā41 - ā34; only links 1 and 3 move it.
PointKinematics centre_of_mass_frame(const FourBar& model, const FourBarState& s);
/// The same from the state's frame vectors, when the caller has them already.
PointKinematics centre_of_mass_frame(const FrameVectors& a, const FourBarState& s);

}  // namespace bd::core
