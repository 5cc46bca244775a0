#pragma once
/// Shaking-force and shaking-moment balance conditions of the four-bar (paper §5.2, eqs. 57-58;
/// Berkof & Lowen 1969, Berkof 1973), as residuals for any design.
#include <string>
#include <vector>

#include "core/fourbar/model.hpp"
#include "core/fourbar/principal_vectors.hpp"
#include "core/types.hpp"

namespace bd::balance {

/// Eq. 57 as complex residuals [kg]; both zero iff the frame principal vectors ā14 = ā34 = 0, so
/// the centre of mass S stays still and the shaking force vanishes for every motion.
struct ForceBalanceResiduals {
  ComplexMass crank;   // m1 s̄1/l1 + m2 (1 - s̄2/l2): equivalent mass left at A1 [kg]
  ComplexMass rocker;  // m2 s̄2/l2 + m3 (1 - s̄3/l3): equivalent mass left at A2 [kg]
};
ForceBalanceResiduals force_balance_residuals(const core::FourBar& model);
/// What each residual of eq. 57 is measured against [kg]: the larger of the two masses involved
/// (m1 + m2, m2 + m3) and the sum of the two terms' magnitudes (which bounds its round-off).
struct ForceBalanceScales {
  double crank{}, rocker{};
};
ForceBalanceScales force_balance_scales(const core::FourBar& model);

/// Berkof's reduced inertias (§5.2) of a force-balanced inline design [kg m^2]: the moments of
/// inertia about the pivots of the crank and the rocker with the coupler's two point masses
/// (m2^a at A1, m2^b at A2) attached; counter-rotations equal to these cancel the angular
/// momentum:
///   crank  = I1 + m1 |s̄1|² + m2 (1 - e2/l2) l1²,
///   rocker = I3 + m3 |l3 - s̄3|² + m2 (e2/l2) l3²;
/// with f1 = f3 = 0 and eq. 57 these are I1 - m1 e1 (l1 - e1) and I3 + m3 e3 (e3 - l3) (§5.2).
struct ReducedInertias {
  double crank{}, rocker{};
};
ReducedInertias reduced_inertias(const core::FourBar& model);

/// One balance condition: its value, what it must be, and whether it holds.
struct Condition {
  std::string name;     // e.g. "force.crank" (eq. 57, first)
  std::string meaning;  // one line, for people
  double residual{};    // |value - target| [unit]
  double scale{};       // what the residual is measured against [unit]
  std::string unit;     // "kg", "m", "kg m²"
  bool holds{};         // residual <= tolerance * scale
};

/// Which conditions hold for a design and by how much.
struct BalanceReport {
  std::vector<Condition> force;   // eq. 57 for the crank and the rocker side
  std::vector<Condition> moment;  // Berkof: coupler.f2 (f2 = 0), coupler.inertia
                                  // (I2 = m2 e2 (l2 - e2)), counter_rotation.crank and
                                  // counter_rotation.rocker (J equal to the reduced inertias)
  bool force_balanced() const;    // every force condition holds
  bool moment_balanced() const;   // every force and every moment condition holds
  /// A few lines for the console and the report.
  std::string text() const;
};
/// Checks every condition with a relative tolerance (round-off of the synthesis: 1e-12).
/// Scales: eq. 57 as force_balance_scales; f2 against l2; I2 against I2 + m2 l2²/4 (the largest
/// m2 e2 (l2 - e2)); J against the sum of the magnitudes of the reduced inertia's terms.
BalanceReport check_balance(const core::FourBar& model, double relative_tolerance = 1e-12);

}  // namespace bd::balance
