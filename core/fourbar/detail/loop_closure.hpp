#pragma once
/// The loop closure at one instant (paper eqs. 2-4), inline and in plain doubles: the first stage
/// of every dynamics evaluation, compiled into it rather than called across translation units,
/// and kept in registers (core/detail/xy.hpp says why not in Vec2). Internal to core, not part
/// of its API; the public entry point is solve_loop() (core/fourbar/kinematics.hpp).
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "core/detail/xy.hpp"
#include "core/fourbar/kinematics.hpp"
#include "core/polar_angle.hpp"

namespace bd::core::detail {

/// A closed loop's link vectors [m].
struct LoopXy {
  Xy l1, l2, l3;
};

/// The angle of a link vector [rad] in [-π, π].
inline double link_angle(const Xy& l) { return polar_angle(l.y, l.x); }

/// solve_loop(model, theta1, l1, branch) in plain doubles, without the angles (link_angle()
/// gives them; the dynamics does not need them, and a sweep computes them in a pass of their
/// own): fills `loop`, or returns why the loop cannot close
/// (core/fourbar/detail/formulation_support.hpp says why not as an Expected).
inline std::optional<AssemblyError> close_loop(const FourBar& model, double theta1, const Xy& l1,
                                               Branch branch, LoopXy& loop) {
  const double l2 = model.coupler.length, l3 = model.rocker.length, l4 = model.frame_length;
  // l̄23 = l̄2 + l̄3 = -l̄1 - l̄4 = A3 - A1 (eq. 2)
  const Xy l23v{l4 - l1.x, -l1.y};
  const double l23_sq = squared_norm(l23v);
  const double l23 = std::sqrt(l23_sq);
  if (!(l23 > 0)) return AssemblyError{theta1, 0.0};

  // triangle l2, l3, l23: Kahan's stable Heron formula, sides sorted a >= b >= c;
  // the only factor that can turn negative is c - (a - b) (triangle inequality violated)
  double a = l2, b = l3, c = l23;
  if (a < b) std::swap(a, b);
  if (b < c) std::swap(b, c);
  if (a < b) std::swap(a, b);
  double slack = c - (a - b);
  if (slack < 0) {
    // within round-off of a flat triangle: accept as flat
    if (slack >= -8 * std::numeric_limits<double>::epsilon() * a) {
      slack = 0;
    } else {
      const double gap = (a == l23) ? l23 - (l2 + l3) : l23 - std::abs(l2 - l3);
      return AssemblyError{theta1, gap};
    }
  }
  const double area4 = std::sqrt((a + (b + c)) * slack * (c + (a - b)) * (a + (b - c)));
  // eqs. 3-4: l̄2 = (d23 + i h23) l̄23 / l23 with d23 = (l23² + l2² - l3²)/(2 l23) along l̄23
  // from A1 and h23 = ±area4/(2 l23) to its left (branch +1); both over 2 l23², one division
  const double along = l23_sq + (l2 - l3) * (l2 + l3);
  const double left = sign(branch) * area4;
  const double scale = 1.0 / (2.0 * l23_sq);
  loop.l1 = l1;
  loop.l2 = (along * l23v + left * perp(l23v)) * scale;
  loop.l3 = l23v - loop.l2;
  return std::nullopt;
}

}  // namespace bd::core::detail
