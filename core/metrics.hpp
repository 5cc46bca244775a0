#pragma once
/// Summary metrics of a trajectory (DESIGN.md summary.json contract).
#include "core/simulate.hpp"

namespace bd::core {

/// RMS over samples and maximum of magnitudes.
struct Metrics {
  double Fsh_rms{}, Fsh_max{};  // |F̄sh| [N]
  double Msh_rms{}, Msh_max{};  // |Msh| [N m]
  double tau_rms{}, tau_max{};  // |tau| [N m]
  double RA0_max{}, RA3_max{};  // |R̄A0|, |R̄A3| [N]
  double RA0_rms{}, RA3_rms{};  // |R̄A0|, |R̄A3| [N]
};
/// Metrics over the trajectory's samples (all zero when it has none).
Metrics metrics(const Trajectory& trajectory);

}  // namespace bd::core
