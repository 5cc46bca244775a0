#pragma once
/// The harmonic orders of a driven run: the shaking force and moment (their inertial part, what
/// balancing acts on, as the metrics take them) and the drive torque over the first revolution of
/// the input that turns, by the FFT of the run's exact samples (core/harmonics.hpp, which the
/// engine balancing's shafts use too).
#include <optional>
#include <string>
#include <vector>

#include "core/fourbar/simulate.hpp"
#include "core/harmonics.hpp"
#include "core/planar/simulate.hpp"
#include "studies/study/study.hpp"

namespace bd::studies {

/// The orders the outputs list: 1 to this (and 0, the mean).
inline constexpr int kHarmonicOrders = 8;

/// One order of the shaking force and moment: Fshx, Fshy and Msh as real quantities of the input
/// angle, and the force as its parts turning with and against the input.
struct HarmonicOrder {
  int order{};
  core::Harmonic Fshx, Fshy, Msh;
  core::Harmonic tau;  // the drive's torque (or force) on the turning input
  core::RotatingHarmonic Fsh;  // order 0: zero
};

/// The harmonic orders of a run, over its first revolution.
struct Harmonics {
  std::string input;                  // the input that turns ("crank" for a four-bar)
  double speed{};                     // its speed [rad/s]
  int samples{};                      // per revolution
  std::vector<HarmonicOrder> orders;  // 0..kHarmonicOrders (fewer when samples are few)
};

/// The harmonic orders of a driven run of `study` (the four-bar's `fourbar` or the planar
/// linkage's `planar`, the other empty). Empty for a free scene, a planar scene given by its
/// duration or with more than one input moving, and a run that stopped within its first
/// revolution.
std::optional<Harmonics> harmonics(const Study& study, const core::Trajectory& fourbar,
                                   const core::planar::Trajectory& planar);

/// The header line of harmonics.csv (without the newline).
inline constexpr const char* kHarmonicsHeader =
    "design,order,Fshx_amplitude,Fshx_phase,Fshy_amplitude,Fshy_phase,Fsh_forward,"
    "Fsh_forward_phase,Fsh_backward,Fsh_backward_phase,Msh_amplitude,Msh_phase,tau_amplitude,"
    "tau_phase";

/// The rows of harmonics.csv for one design (`design`: "original", "balanced"), "%.17g".
std::string harmonics_rows(const std::string& design, const Harmonics& h);

}  // namespace bd::studies
