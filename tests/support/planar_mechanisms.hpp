#pragma once
// Test support: random planar linkages for the engine (core/planar/model.hpp), from a seeded
// generator. Every generator draws lengths, a random placement and orientation in the plane
// (so that moments about the origin are not trivial), masses, inertias, centre-of-mass offsets
// (f != 0), point masses and loads, and rejects draws whose crank cannot turn a full revolution
// with every transmission angle away from 0 and π (|sin| >= kTransmission), checked by closed-
// form geometry at 720 crank angles. So a driven revolution and a free run with the crank as
// input stay far from singular positions, and both codes are well conditioned there.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "core/planar/model.hpp"

namespace bd::testing::planar {

namespace cp = bd::core::planar;
using bd::Vec2;
using Rng = std::mt19937_64;

inline constexpr double kPi = std::numbers::pi;
/// The smallest |sin| of a transmission angle a generated linkage reaches over a revolution.
inline constexpr double kTransmission = 0.3;

inline double uniform(Rng& rng, double a, double b) {
  return std::uniform_real_distribution<double>(a, b)(rng);
}
inline bool coin(Rng& rng, double p = 0.5) { return uniform(rng, 0, 1) < p; }
/// A driven input's speed: 5 to 40 (rad/s or m/s), either sign.
inline double random_speed(Rng& rng) { return (coin(rng) ? 1.0 : -1.0) * uniform(rng, 5.0, 40.0); }
inline Vec2 polar(double r, double angle) { return {r * std::cos(angle), r * std::sin(angle)}; }
inline Vec2 perp_of(const Vec2& v) { return {-v.y(), v.x()}; }
inline double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

/// The point at distance r1 from p1 and r2 from p2, left of p1 -> p2 for side = +1; with the
/// |sin| of the angle between the two arms at that point; nullopt if the circles do not meet.
struct Meet {
  Vec2 p;
  double sin_angle;
};
inline std::optional<Meet> circle_intersection(const Vec2& p1, double r1, const Vec2& p2,
                                               double r2, double side) {
  const Vec2 d = p2 - p1;
  const double L = d.norm();
  const double x = (L * L + r1 * r1 - r2 * r2) / (2 * L), h2 = r1 * r1 - x * x;
  if (!(h2 > 0)) return std::nullopt;
  const Vec2 e = d / L;
  const Vec2 p = p1 + x * e + side * std::sqrt(h2) * perp_of(e);
  const double s = std::abs(cross2((p - p1).normalized(), (p - p2).normalized()));
  return Meet{p, s};
}

/// Mass properties of a link of element length L.
struct Mass {
  double mass, e, f, inertia;
};
inline Mass random_mass(Rng& rng, double L, bool off_line = true) {
  const double m = uniform(rng, 0.2, 3.0);
  return {m, uniform(rng, -0.2, 1.2) * L, off_line ? uniform(rng, -0.25, 0.25) * L : 0.0,
          m * L * L * uniform(rng, 0.02, 0.15)};
}

inline int add_node(cp::Linkage& l, const std::string& name, const Vec2& p, bool ground = false) {
  l.nodes.push_back({name, p, ground});
  return static_cast<int>(l.nodes.size()) - 1;
}
inline double node_distance(const cp::Linkage& l, int a, int b) {
  return (l.nodes[static_cast<std::size_t>(a)].position -
          l.nodes[static_cast<std::size_t>(b)].position)
      .norm();
}
inline int add_link(cp::Linkage& l, Rng& rng, const std::string& name, std::vector<int> nodes,
                    bool off_line = true) {
  const double L = node_distance(l, nodes[0], nodes[1]);
  const Mass m = random_mass(rng, L, off_line);
  l.links.push_back({name, std::move(nodes), m.mass, m.e, m.f, m.inertia});
  return static_cast<int>(l.links.size()) - 1;
}
inline void maybe_point_mass(cp::Linkage& l, Rng& rng, int node, double p = 0.6) {
  if (coin(rng, p)) l.point_masses.push_back({node, uniform(rng, 0.05, 1.5)});
}
inline cp::Input angle_input(const std::string& name, int link) {
  cp::Input in;
  in.kind = cp::Input::Kind::kAngle;
  in.name = name;
  in.link = link;
  return in;
}
inline cp::Input slide_input(const std::string& name, int slider) {
  cp::Input in;
  in.kind = cp::Input::Kind::kSlide;
  in.name = name;
  in.slider = slider;
  return in;
}
inline cp::TimeFunction constant(double v) {
  cp::TimeFunction f;
  f.value = v;
  return f;
}
inline cp::TimeFunction harmonic(double mean, double amplitude, double frequency, double phase) {
  cp::TimeFunction f;
  f.kind = cp::TimeFunction::Kind::kHarmonic;
  f.mean = mean;
  f.amplitude = amplitude;
  f.frequency = frequency;
  f.phase = phase;
  return f;
}

/// A constant or harmonic drive effort of up to `size`, or none.
inline cp::TimeFunction random_effort(Rng& rng, double size) {
  if (coin(rng, 0.3)) return cp::TimeFunction{};
  if (coin(rng)) return constant(uniform(rng, -size, size));
  return harmonic(uniform(rng, -size, size), uniform(rng, 0, size), uniform(rng, 1, 10),
                  uniform(rng, -kPi, kPi));
}

/// The size of a linkage: its longest element [m].
inline double size_of(const cp::Linkage& l) {
  double L = 0;
  for (std::size_t k = 0; k < l.links.size(); ++k) L = std::max(L, cp::element_length(l, static_cast<int>(k)));
  return L;
}
/// The kinetic energy of the linkage's mass moving at 20 rad/s times its size, roughly [J]:
/// what a crank turning at some 20 rad/s carries.
inline double energy_of(const cp::Linkage& l) {
  const double v = 20.0 * size_of(l);
  return 0.5 * cp::total_mass(l) * v * v;
}

/// Gravity of random direction and size; a force and a moment on a random link, and sometimes a
/// force at a random moving node. The forces are of the size of the weight (they are
/// conservative, like gravity: they make the speed fluctuate); the moment, which does work turn
/// after turn, is kept to 0.5 % of energy_of() per radian, so that a crank at 20 rad/s changes
/// its speed by tens of percent in 0.3 s rather than spinning up to hundreds of rad/s (which
/// tests the integrator's step count, not the physics).
inline void random_loads(cp::Linkage& l, Rng& rng) {
  const double force = 9.81 * cp::total_mass(l), moment = 0.005 * energy_of(l);
  l.loads.gravity = coin(rng, 0.8) ? polar(uniform(rng, 0, 9.81), uniform(rng, -kPi, kPi))
                                   : Vec2(0, -9.81);
  const int k = static_cast<int>(uniform(rng, 0, static_cast<double>(l.links.size()) - 1e-9));
  l.loads.link_loads.push_back(
      {k, polar(uniform(rng, 0, force), uniform(rng, -kPi, kPi)), uniform(rng, -1, 1) * moment});
  if (coin(rng)) {
    std::vector<int> moving;
    for (std::size_t i = 0; i < l.nodes.size(); ++i)
      if (!l.nodes[i].ground) moving.push_back(static_cast<int>(i));
    const int n = moving[static_cast<std::size_t>(uniform(rng, 0, static_cast<double>(moving.size()) - 1e-9))];
    l.loads.node_forces.push_back({n, polar(uniform(rng, 0, force), uniform(rng, -kPi, kPi))});
  }
}

/// Sometimes (probability p) a spring-damper from a random moving node to a new ground node
/// "S" placed 1.5 to 3 sizes away from the linkage's nodes (so it never shrinks to length 0):
/// stiffness such that a stretch of the linkage's size stores 10 to 40 % of energy_of(), free
/// length random, damping dissipating about 1 % of energy_of() over 0.3 s at 20 rad/s.
inline void maybe_spring(cp::Linkage& l, Rng& rng, double p = 0.5) {
  if (!coin(rng, p)) return;
  std::vector<int> moving;
  Vec2 mid(0, 0);
  for (std::size_t i = 0; i < l.nodes.size(); ++i) {
    mid += l.nodes[i].position;
    if (!l.nodes[i].ground) moving.push_back(static_cast<int>(i));
  }
  mid /= static_cast<double>(l.nodes.size());
  const double size = size_of(l), energy = energy_of(l);
  const int a = moving[static_cast<std::size_t>(uniform(rng, 0, static_cast<double>(moving.size()) - 1e-9))];
  const int anchor = add_node(l, "S", mid + polar(size * uniform(rng, 1.5, 3.0), uniform(rng, -kPi, kPi)), true);
  cp::Spring sp;
  sp.name = "spring";
  sp.a = coin(rng) ? a : anchor;
  sp.b = sp.a == a ? anchor : a;
  sp.stiffness = uniform(rng, 0.2, 0.8) * energy / (size * size);
  sp.free_length = node_distance(l, a, anchor) * uniform(rng, 0.5, 1.2);
  sp.damping = uniform(rng, 0, 1) * 0.01 * energy / (0.3 * std::pow(20 * size, 2));
  l.springs.push_back(sp);
}

// ---------------------------------------------------------------------------------------------
// Slider-cranks

/// Crank O-A turning about O, rod A-B, the piston B on a frame guide of random direction at the
/// offset `offset` (times the crank) from O (0: inline). Input: the crank's angle. Nodes O, A,
/// B; links crank, rod; slider piston.
inline cp::Linkage slider_crank(Rng& rng, bool inline_guide) {
  cp::Linkage l;
  const Vec2 O = polar(uniform(rng, 0, 0.3), uniform(rng, -kPi, kPi));
  const double r = uniform(rng, 0.03, 0.12), rod = r * uniform(rng, 2.5, 5.0);
  const double e = inline_guide ? 0.0 : r * uniform(rng, -0.6, 0.6);
  const double psi = uniform(rng, -kPi, kPi), theta0 = uniform(rng, -kPi, kPi);
  const Vec2 u = polar(1, psi), n = perp_of(u);
  const double phi = theta0 - psi, side = coin(rng, 0.8) ? 1.0 : -1.0;
  const double along = r * std::cos(phi) + side * std::sqrt(rod * rod - std::pow(r * std::sin(phi) - e, 2));
  const int o = add_node(l, "O", O, true);
  const int a = add_node(l, "A", O + polar(r, theta0));
  const int b = add_node(l, "B", O + along * u + e * n);
  add_link(l, rng, "crank", {o, a});
  add_link(l, rng, "rod", coin(rng) ? std::vector<int>{a, b} : std::vector<int>{b, a});
  cp::Slider s;
  s.name = "piston";
  s.node = b;
  s.from = O + e * n + uniform(rng, -0.5, 0.5) * u;
  s.to = s.from + (coin(rng) ? 1.0 : -1.0) * uniform(rng, 0.1, 1.0) * u;
  l.sliders.push_back(s);
  l.point_masses.push_back({b, uniform(rng, 0.1, 2.0)});
  maybe_point_mass(l, rng, a, 0.5);
  l.inputs.push_back(angle_input("crank", 0));
  maybe_spring(l, rng);
  random_loads(l, rng);
  return cp::make_linkage(l);
}

/// The stroke of a slider_crank()'s piston: the slide values (as the engine measures them, from
/// the guide's `from` towards `to`) of the two dead centres around the drawn one, where the
/// piston's distance from the crank's pivot is rod - crank and rod + crank.
struct Stroke {
  double drawn, lo, hi;
};
inline Stroke stroke_of(const cp::Linkage& l) {
  const Vec2 O = l.nodes[0].position;
  const double r = node_distance(l, 0, 1), rod = node_distance(l, 1, 2);
  const cp::Slider& s = l.sliders[0];
  const Vec2 u = (s.to - s.from).normalized();
  // |from + x u - O| = d  <=>  x^2 + 2 b x + c - d^2 = 0 with b = u.(from - O), c = |from - O|^2
  const double b = u.dot(s.from - O), c = (s.from - O).squaredNorm();
  const double drawn = u.dot(l.nodes[2].position - s.from);
  auto roots = [&](double d) {
    const double disc = std::sqrt(b * b - c + d * d);
    return std::pair<double, double>{-b - disc, -b + disc};
  };
  const auto [outer_lo, outer_hi] = roots(rod + r);
  const auto [inner_lo, inner_hi] = roots(rod - r);
  // the drawn piston lies between an inner and an outer root on one side of the foot of O
  return drawn > -b ? Stroke{drawn, inner_hi, outer_hi} : Stroke{drawn, outer_lo, inner_lo};
}
/// The slider_crank() driven by its piston's slide instead of the crank.
inline cp::Linkage driven_by_piston(cp::Linkage l) {
  l.inputs = {slide_input("piston", 0)};
  return cp::make_linkage(l);
}

/// Inverted slider-crank (quick return): crank O-A about O, the rocker through its pivot Q and
/// its end R, the crank pin A sliding on the rocker's line Q-R (a block of mass at A). With
/// `rotating` the crank is longer than OQ (Whitworth: the rocker turns too), else shorter (the
/// rocker swings). With `shaper` a rod R-P drives a ram P on a frame guide (the shaper). Input:
/// the crank's angle. Links crank, rocker (, rod); sliders block (, ram).
inline cp::Linkage quick_return(Rng& rng, bool rotating, bool shaper) {
  cp::Linkage l;
  const Vec2 O = polar(uniform(rng, 0, 0.3), uniform(rng, -kPi, kPi));
  const double h = uniform(rng, 0.05, 0.15);
  const double r = rotating ? h * uniform(rng, 1.4, 2.5) : h * uniform(rng, 0.3, 0.7);
  const double gamma = uniform(rng, -kPi, kPi), theta0 = uniform(rng, -kPi, kPi);
  const Vec2 Q = O + polar(h, gamma), A = O + polar(r, theta0);
  const double reach = (h + r) * uniform(rng, 1.1, 1.6);
  const Vec2 R = Q + reach * (A - Q).normalized();
  const int o = add_node(l, "O", O, true);
  const int a = add_node(l, "A", A);
  const int q = add_node(l, "Q", Q, true);
  const int rr = add_node(l, "R", R);
  add_link(l, rng, "crank", {o, a});
  add_link(l, rng, "rocker", coin(rng) ? std::vector<int>{q, rr} : std::vector<int>{rr, q});
  cp::Slider block;
  block.name = "block";
  block.node = a;
  block.link = 1;
  const bool forward = coin(rng);
  block.from_node = forward ? q : rr;
  block.to_node = forward ? rr : q;
  l.sliders.push_back(block);
  l.point_masses.push_back({a, uniform(rng, 0.05, 1.0)});
  if (shaper) {
    // the ram's guide through the rocker's pivot region, the rod long enough for the rocker's
    // end to turn a full circle about Q without the rod reaching a dead centre
    const double psi = uniform(rng, -kPi, kPi), offset = reach * uniform(rng, -0.3, 0.3);
    const double rod = (reach + std::abs(offset)) * uniform(rng, 1.6, 2.5);
    const Vec2 u = polar(1, psi), n = perp_of(u);
    const Vec2 rel = R - Q;
    const double across = rel.dot(n) - offset;
    const double along = rel.dot(u) + std::sqrt(rod * rod - across * across);
    const int p = add_node(l, "P", Q + along * u + offset * n);
    add_link(l, rng, "rod", coin(rng) ? std::vector<int>{rr, p} : std::vector<int>{p, rr});
    cp::Slider ram;
    ram.name = "ram";
    ram.node = p;
    ram.from = Q + offset * n + uniform(rng, -0.3, 0.3) * u;
    ram.to = ram.from + (coin(rng) ? 1.0 : -1.0) * u;
    l.sliders.push_back(ram);
    l.point_masses.push_back({p, uniform(rng, 0.2, 3.0)});
  }
  l.inputs.push_back(angle_input("crank", 0));
  maybe_spring(l, rng);
  random_loads(l, rng);
  return cp::make_linkage(l);
}

/// The stroke of a quick_return()'s block along the rocker (as the engine measures it, from the
/// guide's from_node towards its to_node): its dead centres are where the crank lies along the
/// line of the pivots, |QA| = |OQ - OA| and OQ + OA.
inline Stroke block_stroke_of(const cp::Linkage& l) {
  const double h = node_distance(l, 0, 2), r = node_distance(l, 0, 1);
  const double qa = node_distance(l, 2, 1), reach = node_distance(l, 2, 3);
  const bool from_q = l.sliders[0].from_node == 2;
  const double near = std::abs(h - r), far = h + r;
  return from_q ? Stroke{qa, near, far} : Stroke{reach - qa, reach - far, reach - near};
}
/// The quick_return() driven by its block's slide along the rocker instead of the crank.
inline cp::Linkage driven_by_block(cp::Linkage l) {
  l.inputs = {slide_input("block", 0)};
  return cp::make_linkage(l);
}

// ---------------------------------------------------------------------------------------------
// Four-bar loops and six-bars

/// A Grashof crank-rocker O-A-B-Q (crank a about O, coupler b, rocker c about Q, frame d),
/// drawn at crank angle theta0 on branch `side`; the positions of A and B at any crank angle.
struct CrankRocker {
  Vec2 O, Q;
  double a{}, b{}, c{}, theta0{}, side{};
  Vec2 A(double th) const { return O + polar(a, th); }
  std::optional<Meet> B(double th) const { return circle_intersection(A(th), b, Q, c, side); }
};
inline std::optional<CrankRocker> random_crank_rocker(Rng& rng) {
  CrankRocker fb;
  const double d = uniform(rng, 0.1, 0.4);
  fb.O = polar(uniform(rng, 0, 0.3), uniform(rng, -kPi, kPi));
  fb.Q = fb.O + polar(d, uniform(rng, -kPi, kPi));
  fb.a = d * uniform(rng, 0.15, 0.4);
  fb.b = d * uniform(rng, 0.6, 1.6);
  fb.c = d * uniform(rng, 0.6, 1.6);
  fb.theta0 = uniform(rng, -kPi, kPi);
  fb.side = coin(rng) ? 1.0 : -1.0;
  for (int i = 0; i < 720; ++i) {
    const auto B = fb.B(fb.theta0 + 2 * kPi * i / 720);
    if (!B || B->sin_angle < kTransmission) return std::nullopt;
  }
  return fb;
}

/// A random permutation of a ternary link's nodes whose first two are apart (always).
inline std::vector<int> shuffled(Rng& rng, std::vector<int> nodes) {
  std::shuffle(nodes.begin(), nodes.end(), rng);
  return nodes;
}

/// A dyad C-D-E from a moving point C (its path given at 720 crank angles) to a new ground
/// pivot E, with |sin| of the angle at D >= kTransmission along the path; the lengths and side.
struct Dyad {
  Vec2 E;
  double l5{}, l6{}, side{};
};
/// With `limited`, the dyad cannot follow the whole path: l5 + l6 lies between the smallest and
/// the largest distance of C from E (the dyad stretches straight and the linkage locks at a
/// limit), and only the drawn point (the path's first) is checked for its transmission angle.
inline std::optional<Dyad> random_dyad(Rng& rng, const std::vector<Vec2>& path, bool limited = false) {
  Dyad dy;
  Vec2 mid(0, 0);
  for (const Vec2& p : path) mid += p;
  mid /= static_cast<double>(path.size());
  double size = 0;
  for (const Vec2& p : path) size = std::max(size, (p - mid).norm());
  dy.E = mid + polar(size * uniform(rng, 1.0, 3.0), uniform(rng, -kPi, kPi));
  double lo = INFINITY, hi = 0;
  for (const Vec2& p : path) {
    lo = std::min(lo, (p - dy.E).norm());
    hi = std::max(hi, (p - dy.E).norm());
  }
  const double sum = limited ? lo + (hi - lo) * uniform(rng, 0.3, 0.7) : hi * uniform(rng, 1.15, 1.6);
  const double diff = lo * uniform(rng, -0.5, 0.5);
  dy.l5 = (sum + diff) / 2;
  dy.l6 = (sum - diff) / 2;
  dy.side = coin(rng) ? 1.0 : -1.0;
  if (limited) {
    const auto D = circle_intersection(path.front(), dy.l5, dy.E, dy.l6, dy.side);
    if (!D || D->sin_angle < kTransmission) return std::nullopt;
    return dy;
  }
  for (const Vec2& p : path) {
    const auto D = circle_intersection(p, dy.l5, dy.E, dy.l6, dy.side);
    if (!D || D->sin_angle < kTransmission) return std::nullopt;
  }
  return dy;
}

/// Watt II six-bar: the crank-rocker O-A-B-Q whose rocker is a ternary link {Q, B, C}, and the
/// dyad C-D-E to the ground pivot E. Links crank, coupler, rocker (ternary), link5, link6.
/// Stephenson III (`stephenson`): the coupler is the ternary link {A, B, C} instead.
/// With `limited`, the dyad locks at some crank angle (random_dyad()); drawn where C is nearest
/// E, so the crank can turn some way either way before the lock.
inline std::optional<cp::Linkage> six_bar(Rng& rng, bool stephenson, bool limited = false) {
  auto fb = random_crank_rocker(rng);
  if (!fb) return std::nullopt;
  // C as a point of the ternary link, in the frame of its two other joints (x along, y left)
  const double cx = uniform(rng, -0.3, 1.3), cy = uniform(rng, 0.2, 0.8) * (coin(rng) ? 1 : -1);
  auto C_at = [&](double th) -> Vec2 {
    const Vec2 A = fb->A(th), B = fb->B(th)->p;
    const Vec2 p = stephenson ? A : fb->Q, q = B;
    const Vec2 u = q - p;
    return p + cx * u + cy * perp_of(u);
  };
  std::vector<Vec2> path;
  for (int i = 0; i < 720; ++i) path.push_back(C_at(fb->theta0 + 2 * kPi * i / 720));
  std::optional<Dyad> dy;
  if (limited) {  // the lengths from the whole path, then drawn where C is nearest E
    dy = random_dyad(rng, path, true);
    if (!dy) return std::nullopt;
    std::size_t nearest = 0;
    for (std::size_t i = 0; i < path.size(); ++i)
      if ((path[i] - dy->E).norm() < (path[nearest] - dy->E).norm()) nearest = i;
    fb->theta0 += 2 * kPi * static_cast<double>(nearest) / 720;
    const auto D = circle_intersection(C_at(fb->theta0), dy->l5, dy->E, dy->l6, dy->side);
    if (!D || D->sin_angle < kTransmission) return std::nullopt;
  } else {
    dy = random_dyad(rng, path);
  }
  if (!dy) return std::nullopt;
  cp::Linkage l;
  const Vec2 A = fb->A(fb->theta0), B = fb->B(fb->theta0)->p, C = C_at(fb->theta0);
  const Vec2 D = circle_intersection(C, dy->l5, dy->E, dy->l6, dy->side)->p;
  const int o = add_node(l, "O", fb->O, true);
  const int a = add_node(l, "A", A);
  const int b = add_node(l, "B", B);
  const int q = add_node(l, "Q", fb->Q, true);
  const int c = add_node(l, "C", C);
  const int d = add_node(l, "D", D);
  const int e = add_node(l, "E", dy->E, true);
  add_link(l, rng, "crank", {o, a});
  if (stephenson) {
    add_link(l, rng, "coupler", shuffled(rng, {a, b, c}));
    add_link(l, rng, "rocker", coin(rng) ? std::vector<int>{q, b} : std::vector<int>{b, q});
  } else {
    add_link(l, rng, "coupler", coin(rng) ? std::vector<int>{a, b} : std::vector<int>{b, a});
    add_link(l, rng, "rocker", shuffled(rng, {q, b, c}));
  }
  add_link(l, rng, "link5", coin(rng) ? std::vector<int>{c, d} : std::vector<int>{d, c});
  add_link(l, rng, "link6", coin(rng) ? std::vector<int>{e, d} : std::vector<int>{d, e});
  for (int n : {a, b, c, d}) maybe_point_mass(l, rng, n, 0.5);
  l.inputs.push_back(angle_input("crank", 0));
  maybe_spring(l, rng);
  random_loads(l, rng);
  return cp::make_linkage(l);
}
inline cp::Linkage six_bar_or_retry(Rng& rng, bool stephenson) {
  for (;;) {
    if (auto l = six_bar(rng, stephenson)) return *l;
  }
}

/// Five-bar O-A1-C-A3-E with two cranks (O-A1 and E-A3, the inputs "left" and "right") and two
/// couplers meeting at C; any pair of crank angles assembles with |sin| of the angle at C
/// >= kTransmission. Links left, left_coupler, right_coupler, right.
inline cp::Linkage five_bar(Rng& rng) {
  for (;;) {
    const double g = uniform(rng, 0.15, 0.4);
    const double l1 = g * uniform(rng, 0.1, 0.3), l4 = g * uniform(rng, 0.1, 0.3);
    const double lo = g - l1 - l4, hi = g + l1 + l4;
    const double sum = hi * uniform(rng, 1.2, 1.8), diff = lo * uniform(rng, -0.6, 0.6);
    const double l2 = (sum + diff) / 2, l3 = (sum - diff) / 2;
    bool ok = true;
    for (int i = 0; i <= 200 && ok; ++i) {  // the angle at C over the range of |A1 - A3|
      const double delta = lo + (hi - lo) * i / 200;
      const double cosg = (l2 * l2 + l3 * l3 - delta * delta) / (2 * l2 * l3);
      ok = std::abs(cosg) < 1 && std::sqrt(1 - cosg * cosg) >= kTransmission;
    }
    if (!ok) continue;
    cp::Linkage l;
    const Vec2 O = polar(uniform(rng, 0, 0.3), uniform(rng, -kPi, kPi));
    const double psi = uniform(rng, -kPi, kPi);
    const Vec2 E = O + polar(g, psi);
    const double th1 = uniform(rng, -kPi, kPi), th4 = uniform(rng, -kPi, kPi);
    const Vec2 A1 = O + polar(l1, th1), A3 = E + polar(l4, th4);
    const double side = coin(rng) ? 1.0 : -1.0;
    const Vec2 C = circle_intersection(A1, l2, A3, l3, side)->p;
    const int o = add_node(l, "O", O, true);
    const int a1 = add_node(l, "A1", A1);
    const int c = add_node(l, "C", C);
    const int a3 = add_node(l, "A3", A3);
    const int e = add_node(l, "E", E, true);
    add_link(l, rng, "left", {o, a1});
    add_link(l, rng, "left_coupler", coin(rng) ? std::vector<int>{a1, c} : std::vector<int>{c, a1});
    add_link(l, rng, "right_coupler", coin(rng) ? std::vector<int>{a3, c} : std::vector<int>{c, a3});
    add_link(l, rng, "right", {e, a3});
    for (int n : {a1, c, a3}) maybe_point_mass(l, rng, n, 0.5);
    l.inputs.push_back(angle_input("left", 0));
    l.inputs.push_back(angle_input("right", 3));
    maybe_spring(l, rng);
  random_loads(l, rng);
    return cp::make_linkage(l);
  }
}

}  // namespace bd::testing::planar
