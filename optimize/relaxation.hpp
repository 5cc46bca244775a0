#pragma once
/// Internal to bd_optimize: the convex relaxation of a counterweight's inertia, which both
/// linkage types' programs use in CounterweightVariablesAs::kRelaxation (optimize/program.hpp).
///
/// A counterweight of mass m at r from its pivot (|r| <= d, m <= m_max) has mass moment p = m r
/// and inertia about its pivot w + s, with w = m |r|² = |p|² / m (its mass at r) and, for a disc,
/// s = a m² (its own inertia, a = 1 / (2 π density thickness)). The metrics a driven problem
/// reads are affine in (m, p, w, s); only w and s are not affine in (m, p). The relaxation takes
/// w and s as variables of their own, within the convex set
///   |p|² <= m w                (a rotated second-order cone: w >= |p|² / m)
///   w <= m d²                  (|r| <= d)
///   m² <= s / a                (s >= a m²)
///   s <= a m_max m             (the secant of a m² over [0, m_max])
/// which holds every real counterweight (w = |p|² / m, s = a m²): the relaxed program's minimum
/// is a lower bound of the real one's. Its rows, scaled to order one with u = p / (m_max d),
/// α = m / m_max, β = w / (m_max d²), σ = s / (a m_max²):
///   sqrt(|u|² + ((α - β) / 2)² + δ²) - δ - (α + β) / 2 <= 0   (the cone, smoothed at its apex
///                                                              by δ = kConeSmoothing: never
///                                                              tighter, so still a relaxation)
///   β - α <= 0,   α² - σ <= 0,   σ - α <= 0
/// each a convex function with a gradient everywhere.
#include <Eigen/Core>
#include <cmath>
#include <string>
#include <vector>

#include "optimize/program.hpp"

namespace bd::optimize::detail {

/// One counterweight's variables in a relaxed program: its mass m = x(mass), moment
/// p = (x(mass + 1), x(mass + 2)), inertia w = x(w) of its mass about the pivot, and, for a disc
/// (disc_a > 0), its own inertia s = x(s) (s = -1 for a point mass).
struct RelaxedCounterweight {
  int mass{-1}, w{-1}, s{-1};
  double mass_max{}, distance_max{};
  double disc_a{};  // a = 1 / (2 π density thickness) [1/kg m² per kg²]; 0 for a point mass

  int rows() const { return s >= 0 ? 4 : 2; }
  /// The upper bounds of w and s: m_max d² and a m_max².
  double w_max() const { return mass_max * distance_max * distance_max; }
  double s_max() const { return disc_a * mass_max * mass_max; }

  /// The names of its rows, after `name` (e.g. "crank counterweight").
  std::vector<std::string> row_names(const std::string& name) const {
    std::vector<std::string> out = {
        name + ": inertia of its mass about the pivot >= |mass moment|² / mass (relaxed)",
        name + ": inertia of its mass about the pivot <= mass x distance_max²"};
    if (s >= 0) {
      out.push_back(name + ": own inertia of the disc >= its value for the mass (relaxed)");
      out.push_back(name + ": own inertia of the disc <= its value at mass_max, pro rata");
    }
    return out;
  }

  /// w and s at their real values for the mass and moment at x (within their bounds).
  void set_tight(Eigen::VectorXd& x) const {
    const double m = x(mass), p2 = x(mass + 1) * x(mass + 1) + x(mass + 2) * x(mass + 2);
    x(w) = m > 0 ? std::min(p2 / m, m * distance_max * distance_max) : 0.0;
    if (s >= 0) x(s) = disc_a * m * m;
  }

  /// Its rows at x from `row` on (c and, when jac is not null, their gradients; the rest of each
  /// Jacobian row is left as it is: zero).
  void fill(const Eigen::VectorXd& x, Eigen::Index row, Eigen::VectorXd& c,
            Eigen::MatrixXd* jac) const {
    const double pmax = mass_max * distance_max;
    const double ux = x(mass + 1) / pmax, uy = x(mass + 2) / pmax;
    const double a = x(mass) / mass_max, b = x(w) / w_max();
    const double half = (a - b) / 2, delta = kConeSmoothing;
    const double norm = std::sqrt(ux * ux + uy * uy + half * half + delta * delta);
    c(row) = norm - delta - (a + b) / 2;
    c(row + 1) = b - a;
    if (jac) {
      (*jac)(row, mass + 1) = ux / norm / pmax;
      (*jac)(row, mass + 2) = uy / norm / pmax;
      (*jac)(row, mass) = (half / (2 * norm) - 0.5) / mass_max;
      (*jac)(row, w) = (-half / (2 * norm) - 0.5) / w_max();
      (*jac)(row + 1, w) = 1 / w_max();
      (*jac)(row + 1, mass) = -1 / mass_max;
    }
    if (s < 0) return;
    const double sigma = x(s) / s_max();
    c(row + 2) = a * a - sigma;
    c(row + 3) = sigma - a;
    if (jac) {
      (*jac)(row + 2, mass) = 2 * a / mass_max;
      (*jac)(row + 2, s) = -1 / s_max();
      (*jac)(row + 3, s) = 1 / s_max();
      (*jac)(row + 3, mass) = -1 / mass_max;
    }
  }
};

}  // namespace bd::optimize::detail
