#pragma once
/// The planar 4R four-bar model: geometry, inertia and applied loads (paper §2, Fig. 1).
/// A FourBar is built and checked by make_fourbar() and is read-only afterwards; state and
/// scratch live elsewhere.
#include <string>

#include "core/types.hpp"

namespace bd::core {

/// Assembly mode: kPlus when A2 lies to the left of the directed line A1->A3 (h23 > 0).
enum class Branch { kPlus = 1, kMinus = -1 };

/// +1 or -1 for a branch.
inline double sign(Branch b) { return b == Branch::kPlus ? 1.0 : -1.0; }

/// One moving link, paper notation. The centre of mass lies at s̄ = e + i f from the first
/// joint, in link axes (x along the link towards the second joint).
struct Link {
  double length{};   // l_k [m]
  double mass{};     // m_k [kg]
  double e{};        // centre-of-mass offset along the link from the first joint [m]
  double f{};        // centre-of-mass offset to the left of the link line [m]
  double inertia{};  // I_k about the centre of mass [kg m^2]

  double s() const;      // |s̄_k| [m]
  double sigma() const;  // arg s̄_k [rad]
};

/// A link from the paper's polar form s̄ = s·e^{iσ}.
Link link_from_polar(double length, double mass, double s, double sigma, double inertia);

/// Applied load on one link: a force at its centre of mass and a moment, in global axes.
struct LinkLoad {
  Vec2 force{0.0, 0.0};  // F̄_k [N]
  double moment{};       // M_k [N m]
};

/// Loads on the moving links; gravity acts on every mass (m_k·g added at each centre of mass).
struct Loads {
  Vec2 gravity{0.0, 0.0};  // g [m/s^2]
  LinkLoad crank, coupler, rocker;
};

/// A counter-rotating inertia (Berkof's moment balance, paper §5.2): a disc on a shaft fixed in
/// the frame at `at`, geared to a link's pivot with ratio -1 (equal pitch radii |at - pivot|/2,
/// an ideal mesh that transmits a tangential force only). The disc turns at minus the link's
/// rate; its shaft carries the mesh force to the frame. Absent when inertia == 0.
struct CounterRotation {
  double inertia{};  // J about the shaft [kg m^2], >= 0
  Vec2 at{0, 0};     // shaft position on the frame [m]; away from the link's pivot if J > 0
};

/// Counter-rotations geared to the crank (pivot A0) and to the rocker (pivot A3).
struct CounterRotations {
  CounterRotation crank, rocker;
};

/// Joints A0 (origin), A1, A2, A3 = (l4, 0). Link 1 crank A0->A1, link 2 coupler A1->A2,
/// link 3 rocker A2->A3 (so the rocker's centre of mass is measured from A2).
struct FourBar {
  Link crank, coupler, rocker;  // links 1, 2, 3
  double frame_length{};        // l4 = |A0A3| [m]
  Branch branch{Branch::kPlus};
  Loads loads;
  CounterRotations counter_rotations;  // none by default
};

/// True when the model has a counter-rotating inertia on the crank or the rocker.
bool has_counter_rotations(const FourBar& model);

/// Link k = 1, 2, 3 of the model.
const Link& link(const FourBar& model, int k);
/// Load on link k = 1, 2, 3.
const LinkLoad& link_load(const FourBar& model, int k);

/// Checks and returns the model.
/// @throws bd::InputError if a length or mass is not > 0 or finite, an inertia is < 0, or any
///         value is not finite, or a counter-rotation with J > 0 sits on its link's pivot; the
///         message names the link and quantity with its unit, e.g.
///         "coupler.mass must be > 0 kg, got -1.2". Its FieldError's field is the value's path
///         in the FourBar: "frame", "branch", "<link>.<length|mass|e|f|inertia>",
///         "loads.<link>.moment", "loads.<link>.force" and "loads.gravity" with index 0 (x) or
///         1 (y), "counter_rotations.<crank|rocker>.inertia", "counter_rotations.<side>.at"
///         with index 0 or 1, and "counter_rotations.<side>" for a shaft on its link's pivot.
FourBar make_fourbar(const FourBar& candidate);

/// Name of link k ("crank", "coupler", "rocker").
const char* link_name(int k);

/// Total moving mass m1 + m2 + m3 [kg].
double total_mass(const FourBar& model);

/// Grashof classes of the four-bar with the frame fixed and link 1 as input.
enum class GrashofClass {
  kCrankRocker,   // shortest link is the crank: the crank turns fully, the rocker rocks
  kDoubleCrank,   // shortest link is the frame: crank and rocker both turn fully (drag link)
  kRockerCrank,   // shortest link is the rocker: the rocker turns fully, the crank rocks
  kDoubleRocker,  // Grashof, shortest link is the coupler: neither turns fully
  kChangePoint,   // s + l = p + q: the linkage can fold flat (branch points)
  kNonGrashof,    // s + l > p + q: triple rocker, no link turns fully
};
/// Classifies the linkage by Grashof's criterion (with a relative tolerance 1e-12 on equality).
GrashofClass classify_grashof(const FourBar& model);
/// "crank-rocker", "double-crank", "rocker-crank", "double-rocker", "change-point", "non-Grashof".
const char* to_string(GrashofClass c);
/// True when the loop closes at every crank angle, so the crank can make full turns
/// (crank-rocker, double-crank, and change-point linkages whose crank or frame is shortest).
bool crank_turns_fully(const FourBar& model);

}  // namespace bd::core
