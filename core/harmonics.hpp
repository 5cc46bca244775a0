#pragma once
/// Harmonic orders of a periodic quantity over one period of a driven input: the shaking force and
/// moment of a linkage driven at constant speed, analysed by the discrete Fourier transform of its
/// exact samples (no small-rod-ratio expansion). Order k is the part that repeats k times per
/// revolution of the input.
#include <span>
#include <vector>

namespace bd::core {

/// One order of a real quantity q(θ) = Σ amplitude cos(order θ + phase), θ the input's angle.
struct Harmonic {
  int order{};
  double amplitude{};  // ≥ 0; order 0: the mean (signed, phase 0)
  double phase{};      // [rad], in (-π, π]; 0 where the amplitude is round-off (at most 1e-11
                       // of the largest order's): its phase would be noise
};

/// One order of a planar vector quantity F = Fx + i Fy, split into the part that turns with the
/// input (forward: F₊ e^{i(kθ + φ₊)}) and the part that turns against it (backward:
/// F₋ e^{-i(kθ - φ₋)}). A counterweight turning with the input cancels forward order 1; a pair of
/// shafts counter-rotating at k times the input's speed (a Lanchester balancer) cancels the
/// forward and backward parts of order k when they are equal, as for a force along a line.
struct RotatingHarmonic {
  int order{};
  double forward{}, backward{};              // magnitudes
  double forward_phase{}, backward_phase{};  // [rad], in (-π, π]; 0 for round-off, as Harmonic
};

/// Orders 0..max_order of `samples`, taken at θ0 + 2π j / N, j = 0..N-1 (one period, its end
/// excluded). Orders above N/2 - 1 are left out (they alias). Exact for a quantity whose orders
/// above N/2 - 1 vanish; otherwise each order carries the aliased part of orders N ± k.
std::vector<Harmonic> harmonic_orders(std::span<const double> samples, double theta0,
                                      int max_order);

/// Orders 1..max_order of the vector quantity (x, y), sampled as for harmonic_orders().
std::vector<RotatingHarmonic> rotating_orders(std::span<const double> x, std::span<const double> y,
                                              double theta0, int max_order);

}  // namespace bd::core
