#pragma once
/// Counterweight synthesis for full shaking-force balance (eq. 57): counterweights on the crank
/// (about A0) and on the rocker (about A3) that bring the equivalent masses at the moving joints
/// to zero, realised as a point mass or a disc whose own inertia is included.
#include <optional>
#include <string>

#include "core/fourbar/model.hpp"
#include "core/input_error.hpp"
#include "core/types.hpp"

namespace bd::balance {

enum class CounterweightShape { kPoint, kDisc };

/// How to realise a counterweight. Give at most one of `mass`, `distance` and (for a disc)
/// `radius`; with none, the default is a counterweight at a distance equal to the link's length.
/// A disc whose radius is not given gets r = sqrt(m / (density pi thickness)); its inertia about
/// its centre is m r²/2.
struct CounterweightSpec {
  CounterweightShape shape = CounterweightShape::kPoint;
  std::optional<double> mass;      // given mass [kg] > 0: the distance from the pivot is solved
  std::optional<double> distance;  // given distance from the pivot [m] > 0: the mass is solved
  std::optional<double> radius;    // disc: given radius [m] > 0 fixes the mass with thickness
                                   // and density; the distance is solved
  double thickness = 0.02;         // disc thickness [m] > 0
  double density = 7850.0;         // disc density [kg/m^3] > 0 (steel)
  /// Empty when valid, else the first problem: its field is "mass", "distance", "radius",
  /// "shape", "thickness" or "density", or empty when more than one of mass, distance and
  /// radius is given (e.g. "mass must be > 0 kg, got 0").
  Problem validate() const;
};

/// A realised counterweight.
struct Counterweight {
  double mass{};        // [kg]
  Vec2 position{0, 0};  // its centre in link axes from the pivot (A0 crank, A3 rocker) [m]
  double distance{};    // |position| [m]
  double radius{};      // disc radius [m]; 0 for a point mass
  double thickness{};   // disc thickness [m]; 0 for a point mass
  double inertia{};     // about its own centre [kg m^2]: m r²/2 for a disc, 0 for a point
};

/// A counterweight whose mass moment about its pivot is `mass_moment` = mass·position [kg m]
/// (link axes), realised as `spec` asks: the given mass at the distance that gives the moment, or
/// at the given distance (`default_distance` when the spec gives neither) the mass that does, or
/// a disc of the given radius. `mass_moment` must not be zero.
Counterweight realise(const CounterweightSpec& spec, const Vec2& mass_moment,
                      double default_distance);

/// The design after force balancing, and what was added.
struct ForceBalancedDesign {
  core::FourBar model;                 // links with their counterweights merged in
  std::optional<Counterweight> crank;  // empty where the side was already balanced
  std::optional<Counterweight> rocker;
  double added_mass{};     // Σ counterweight masses [kg]
  double added_inertia{};  // Σ counterweight inertias about their pivots [kg m^2]
};

/// Counterweights that make the model fully force balanced (both residuals of eq. 57 zero to
/// round-off: check_balance holds at 1e-12). The coupler is left as it is. A side already
/// balanced to round-off (its check_balance condition holds at 1e-12) gets no counterweight.
/// The counterweight's centre lies on the line through the pivot along the missing mass moment:
/// crank m1 s̄1 + mc p = -m2 (1 - s̄2/l2) l1; rocker m3 (s̄3 - l3) + mc q = m2 s̄2 l3/l2.
/// @throws bd::InputError if a spec is invalid ("crank counterweight: mass must be > 0 kg, got
///         -1": the field is "crank counterweight" or "rocker counterweight", the message the
///         spec's own problem) or the model fails make_fourbar (with its field).
ForceBalancedDesign force_balance(const core::FourBar& model, const CounterweightSpec& crank,
                                  const CounterweightSpec& rocker);

/// A link with a counterweight merged in: total mass, centre of mass and inertia about the new
/// centre of mass (parallel-axis sum). `position` is in link axes from the pivot: A0 (the first
/// joint) for the crank, A3 (the second joint) for the rocker; say which by `from_second_joint`.
core::Link merged(const core::Link& link, const Counterweight& counterweight,
                  bool from_second_joint);

}  // namespace bd::balance
