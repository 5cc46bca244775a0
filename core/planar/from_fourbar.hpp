#pragma once
/// The four-bar as a planar linkage (method `truss`, and the cross-checks of the general engine
/// against the dedicated four-bar formulations): nodes A0 (ground, origin), A1, A2, A3 (ground,
/// (l4, 0)); links crank A0->A1, coupler A1->A2, rocker A2->A3 with the four-bar's mass data
/// (the rocker's centre of mass measured from A2, as in the four-bar); the links' loads at their
/// centres of mass; the crank's angle as the input.
#include <cstddef>
#include <span>

#include "core/fourbar/model.hpp"
#include "core/fourbar/simulate.hpp"
#include "core/planar/model.hpp"
#include "core/planar/simulate.hpp"

namespace bd::core::planar {

/// The linkage drawn at crank angle theta1 on the four-bar's branch.
/// Counter-rotating discs become balance shafts C1 (on the crank) and C3 (on the rocker) with
/// ratio -1, so that their reactions are the four-bar's RC1 and RC3.
/// @throws bd::InputError if the loop cannot close at theta1.
Linkage linkage_of(const FourBar& fourbar, double theta1);

/// The general engine's samples of that linkage as the four-bar's (its crank, coupler and rocker
/// angles as theta1..3, the reactions at A0 and A3, the shaking force and moment, the drive
/// torque), with the same status and message, and where a stopped run stopped.
core::Trajectory fourbar_trajectory(const Trajectory& planar);

/// A row of such a table (e.g. a driven run's row between its samples, DrivenRows::at()) as the
/// four-bar's sample; the columns are looked up once, on construction (`table` must outlive it).
class FourBarSampleOf {
 public:
  explicit FourBarSampleOf(const Series& table);
  DynamicsSample operator()(std::span<const double> row) const;
  /// The column of the time.
  std::size_t time() const { return c_t; }

 private:
  static std::size_t at(int c) { return static_cast<std::size_t>(c); }
  std::size_t col(const char* name) const { return at(t_.column(name)); }
  const Series& t_;
  const std::size_t c_t = col("t"), th1 = col("theta_crank"), th2 = col("theta_coupler"),
                    th3 = col("theta_rocker"), om1 = col("omega_crank"), om2 = col("omega_coupler"),
                    om3 = col("omega_rocker"), al1 = col("alpha_crank"), al2 = col("alpha_coupler"),
                    al3 = col("alpha_rocker"), r0 = col("RA0x"), r3 = col("RA3x"), f = col("Fshx"),
                    m = col("Msh"), tau = col("tau"), fi = col("Fshx_inertial"),
                    mi = col("Msh_inertial"), fs = col("Fshx_static"), ms = col("Msh_static");
  const int fa1 = t_.column("FA1x"), fa2 = t_.column("FA2x"), rc1 = t_.column("RC1x"),
            rc3 = t_.column("RC3x");
};

}  // namespace bd::core::planar
