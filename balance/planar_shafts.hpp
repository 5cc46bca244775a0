#pragma once
/// Balance shafts for any planar linkage with a crank (a Lanchester balancer, generalised): at a
/// constant crank speed ω the inertial shaking force is a sum of rotating vectors,
///   F(θ) = Σ_k C_k ω² e^{ikθ}  (complex x + iy, θ the crank's angle, k = ..., -2, -1, 1, 2, ...),
/// order n being the pair k = ±n (a forward and a backward rotating vector; an inline engine's
/// piston has |C_n| = |C_-n|, an oscillation along the stroke). A shaft geared to the crank with
/// ratio k, carrying m at eccentricity ε, adds m k² ω² ε e^{ik(θ - θ_drawn)}: with
///   m ε = -C_k e^{ikθ_drawn} / k²
/// it cancels the k-th rotating vector exactly, for every speed. The coefficients come from the
/// exact motion (one crank revolution, 720 samples), not from a series in the rod ratio.
#include <string>
#include <vector>

#include "balance/planar.hpp"

namespace bd::balance::planar {

/// The result: the linkage with its new shafts, and what they do.
struct ShaftBalance {
  cp::Linkage linkage;     // the input with the shafts added (named shaft_<ratio>)
  std::vector<int> added;  // their indices in linkage.shafts
  int crank{};             // the link they are geared to
  /// Per order asked for: the amplitudes of its forward and backward rotating vectors per unit
  /// crank speed squared [kg m] before and after (|C_n|, |C_-n|).
  struct Order {
    int order{};
    double forward_before{}, backward_before{}, forward_after{}, backward_after{};
  };
  std::vector<Order> orders;
};

/// Shafts that cancel the orders asked for of `linkage`'s inertial shaking force (its
/// counterweights and any shafts it has included). The crank is the link of its only input, an
/// angle that must turn a full revolution. A rotating vector already smaller than 1e-12 of the
/// force's size gets no shaft.
/// @throws bd::InputError (field "shafts") when the linkage has not one angle input, its crank
///         cannot turn a full revolution (the position it cannot reach), an order is < 1, or a
///         shaft's name is taken.
ShaftBalance balance_shafts(const cp::Linkage& linkage, const ShaftRequest& request);

/// The force balance `design` completed by the shafts of `shafts` (balanced from its linkage):
/// its linkage becomes theirs, their masses and inertias about their shafts join the added ones,
/// the RMS inertial shaking force and the momentum left (against the original linkage's) are
/// those with the shafts over `k`'s samples, and the message says what they cancel.
void add_shafts(ForceBalance& design, const ShaftBalance& shafts, const Kinematics& k,
                const cp::Linkage& original);

}  // namespace bd::balance::planar
