#pragma once
// Mechanisms for the referee's self-tests, described from their joint positions.
#include <cmath>
#include <numbers>

#include "tests/reference/planar/referee.hpp"

namespace bd::referee::selftest {

inline Vec2 perp(const Vec2& v) { return {-v.y(), v.x()}; }
inline Vec2 polar(double r, double angle) { return {r * std::cos(angle), r * std::sin(angle)}; }
inline double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

/// The point at distance r1 from p1 and r2 from p2, left of p1 -> p2 for side = +1.
inline Vec2 circle_intersection(const Vec2& p1, double r1, const Vec2& p2, double r2, double side) {
  const Vec2 d = p2 - p1;
  const double L = d.norm(), x = (L * L + r1 * r1 - r2 * r2) / (2 * L);
  const Vec2 e = d / L;
  return p1 + x * e + side * std::sqrt(r1 * r1 - x * x) * perp(e);
}

/// A link between two joints with its centre of mass at fraction f along it and offset o
/// to the left.
inline Body link(const char* name, const Vec2& p, const Vec2& q, double mass, double inertia,
                 double f = 0.5, double o = 0) {
  const Vec2 c = p + f * (q - p) + o * perp((q - p).normalized());
  return Body{name, mass, inertia, c, {}};
}

/// Slider-crank: crank (body 0) pinned at the origin, rod (body 1) with the piston mass at B
/// on the line y = e; crank angle theta0 in the described configuration; input: crank angle.
struct SliderCrank {
  double r = 0.05, l = 0.2, e = 0.01, piston = 0.4, theta0 = 0.7;
  Vec2 A() const { return polar(r, theta0); }
  double x(double th) const {
    const double s = r * std::sin(th) - e;
    return r * std::cos(th) + std::sqrt(l * l - s * s);
  }
  Vec2 B() const { return {x(theta0), e}; }
  Mechanism build(bool slide_input = false) const {
    Mechanism m;
    m.bodies = {link("crank", {0, 0}, A(), 0.3, 2e-4, 0.3, 0.004),
                link("rod", A(), B(), 0.5, 2.5e-3, 0.4, -0.006)};
    m.bodies[1].point_masses = {{piston, B()}};
    m.pins = {{"O", kGround, 0, {0, 0}}, {"A", 0, 1, A()}};
    m.sliders = {{"piston", 1, kGround, B(), {0, e}, {1, e}}};
    if (slide_input) {
      m.inputs = {SlideInput{0}};
    } else {
      m.inputs = {AngleInput{0}};
    }
    return m;
  }
};

/// Four-bar A0 (origin) - A1 - A2 - A3 = (d, 0): crank 0, coupler 1, rocker 2; input: crank.
struct FourBar {
  double a = 0.1, b = 0.35, c = 0.3, d = 0.3, theta0 = 0.4;
  Vec2 A1() const { return polar(a, theta0); }
  Vec2 A2() const { return circle_intersection(A1(), b, A3(), c, 1); }
  Vec2 A3() const { return {d, 0}; }
  Mechanism build() const {
    Mechanism m;
    m.bodies = {link("crank", {0, 0}, A1(), 0.5, 1e-3, 0.4, 0.01),
                link("coupler", A1(), A2(), 1.2, 1.5e-2, 0.5, 0.03),
                link("rocker", A3(), A2(), 0.9, 8e-3, 0.45, -0.02)};
    m.pins = {{"A0", kGround, 0, {0, 0}},
              {"A1", 0, 1, A1()},
              {"A2", 1, 2, A2()},
              {"A3", 2, kGround, A3()}};
    m.inputs = {AngleInput{0}};
    return m;
  }
};

/// Five-bar A0 (origin) - A1 - A2 - A3 - A4 = (g, 0): links 0..3; inputs: link 0 and link 3.
struct FiveBar {
  double l1 = 0.1, l2 = 0.25, l3 = 0.25, l4 = 0.1, g = 0.2;
  double th1 = 1.75, th4 = 1.4;
  Vec2 A1() const { return polar(l1, th1); }
  Vec2 A3() const { return A4() + polar(l4, th4); }
  Vec2 A2() const { return circle_intersection(A1(), l2, A3(), l3, -1); }
  Vec2 A4() const { return {g, 0}; }
  Mechanism build() const {
    Mechanism m;
    m.bodies = {link("left", {0, 0}, A1(), 0.4, 6e-4, 0.5, 0.005),
                link("left coupler", A1(), A2(), 0.8, 5e-3, 0.5, 0.01),
                link("right coupler", A3(), A2(), 0.7, 4e-3, 0.5, -0.01),
                link("right", A4(), A3(), 0.4, 6e-4, 0.5, 0.0)};
    m.pins = {{"A0", kGround, 0, {0, 0}},
              {"A1", 0, 1, A1()},
              {"A2", 1, 2, A2()},
              {"A3", 2, 3, A3()},
              {"A4", kGround, 3, A4()}};
    m.inputs = {AngleInput{0}, AngleInput{3}};
    return m;
  }
};

/// Watt six-bar: the four-bar plus a dyad C - D - E from a coupler point C to the ground at E.
struct SixBar {
  FourBar fb;
  double l5 = 0.3, l6 = 0.25;
  Vec2 E{0.45, 0.35};
  Vec2 C() const {
    return fb.A1() + 0.6 * (fb.A2() - fb.A1()) + 0.1 * perp((fb.A2() - fb.A1()).normalized());
  }
  Vec2 D() const { return circle_intersection(C(), l5, E, l6, -1); }
  Mechanism build() const {
    Mechanism m = fb.build();
    m.bodies.push_back(link("link5", C(), D(), 0.6, 4e-3, 0.5, 0.01));
    m.bodies.push_back(link("link6", E, D(), 0.5, 2.5e-3, 0.5, 0.0));
    m.pins.push_back({"C", 1, 3, C()});
    m.pins.push_back({"D", 3, 4, D()});
    m.pins.push_back({"E", kGround, 4, E});
    return m;
  }
};

/// Quick return (inverted slider-crank): crank 0 pinned at the origin; rocker 1 pinned at
/// Q = (0, -h); the crank pin A slides on the rocker's line Q -> A. Input: crank angle, or the
/// slide of A along the rocker.
struct QuickReturn {
  double r = 0.08, h = 0.2, theta0 = 0.3;
  Vec2 A() const { return polar(r, theta0); }
  Vec2 Q() const { return {0, -h}; }
  Mechanism build(bool slide_input = false) const {
    Mechanism m;
    m.bodies = {link("crank", {0, 0}, A(), 0.3, 3e-4, 0.4, 0.01),
                link("rocker", Q(), A(), 1.1, 2e-2, 0.8, 0.02)};
    m.bodies[0].point_masses = {{0.15, A()}};  // the slider block, carried by the crank pin
    m.pins = {{"O", kGround, 0, {0, 0}}, {"Q", kGround, 1, Q()}};
    m.sliders = {{"block", 0, 1, A(), Q(), Q() + 1.7 * (A() - Q())}};
    if (slide_input) {
      m.inputs = {SlideInput{0}};
    } else {
      m.inputs = {AngleInput{0}};
    }
    return m;
  }
};

/// Two discs on ground shafts at (0, 0) and (ra + rb, 0), meshing at (ra, 0). Input: disc 0.
inline Mechanism gear_pair(double ra, double rb, double Ia, double Ib) {
  Mechanism m;
  const Vec2 oa{0, 0}, ob{ra + rb, 0}, pitch{ra, 0};
  m.bodies = {Body{"a", 1.0, Ia, oa, {}}, Body{"b", 2.0, Ib, ob, {}}};
  m.pins = {{"shaft a", kGround, 0, oa}, {"shaft b", kGround, 1, ob}};
  m.gears = {{"mesh", 0, 1, oa, ob, pitch}};
  m.inputs = {AngleInput{0}};
  return m;
}

}  // namespace bd::referee::selftest
