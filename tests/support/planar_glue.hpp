#pragma once
// Test support: a general planar linkage of the engine (core/planar/model.hpp) described to the
// independent referee (tests/reference/planar/referee.hpp), and the engine's outputs computed
// from the referee's samples, column by column, so that the two compare quantity by quantity.
//
// How the linkage is described (glue_of):
//  * each link -> one Body: its mass and inertia, its centre of mass at nodes[0] + e u + f perp(u)
//    (u the unit vector nodes[0] -> nodes[1] as drawn, perp(u) its left normal);
//  * each moving node -> its HOST: the first link through it (in link order). Every other link
//    through the node gets a Pin {host, link} there ("star" pins, not a chain), so the referee's
//    force of that pin is the force of the host side on that link;
//  * each ground node -> a Pin {kGround, link} per link through it;
//  * point masses at a node -> merged into the host body at the node. Why the host: the engine's
//    joint force F<node> is the force on the joint's link (every link through the node but the
//    first) from the JOINT, and the joint is the node with its point mass: the node's point mass,
//    the sliders, springs and node forces acting there are all on the joint side. In the referee
//    the pin {host, link} transmits the force of the host body (which carries the point mass,
//    the slider's point, the spring's end, the node force) to the link: the same force. Put on
//    the other link, the pin force would lack the point mass's inertia and weight;
//  * sliders -> PointOnLine {host of the node, kGround or the guide's link, node, guide}; the
//    engine's slider block has no mass of its own (a point mass at its node is the block);
//  * springs -> Spring between the hosts (kGround for a ground node) at the nodes;
//  * link loads -> a PointForce at the link's centre of mass and a BodyMoment; node forces -> a
//    PointForce on the host at the node; gravity as is;
//  * inputs -> AngleInput {link} or SlideInput {slider}, their efforts as functions of time.
//
// Outputs (reference_table): the engine's columns (core/planar/simulate.hpp, columns()) from the
// referee's samples:
//  * theta = the link's drawn angle (atan2 of nodes[0] -> nodes[1], as the engine starts it) +
//    the referee's rotation from the drawn configuration; omega, alpha as they are;
//  * node positions: the drawn node as a point of its host body (point_motion);
//  * s, v, a of a slider: the node's position along the guide from `from` (or the guide's
//    from_node) towards `to`, and its first and second time derivatives relative to the guide's
//    link, from the point motions of the node and the guide's two nodes;
//  * R<ground node> = sum over the node's ground pins of -pin force (force ON the frame);
//    R<slider> (frame guide) = -slider force (the guide's normal force ON the frame);
//    F<slider>_guide (moving guide) = -slider force - a slide drive's effort along the guide;
//  * F<joint> on a link through two or more: the force of pin {host, link}; on the only link
//    through the node (a slider's or point mass's node): the resultant of everything else on the
//    node (slider normal forces, slide drives, node forces, springs, weight of the point masses)
//    minus the point masses' m a, i.e. what the node exerts on the link;
//  * Fsh, Msh, tau, Fsh_inertial, Msh_inertial: the referee's shaking_force, shaking_moment,
//    input_efforts, inertial_force, inertial_moment.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/planar/dynamics.hpp"
#include "core/planar/model.hpp"
#include "core/planar/simulate.hpp"
#include "core/series.hpp"
#include "tests/reference/planar/referee.hpp"

namespace bd::testing::planar {

namespace cp = bd::core::planar;
namespace rf = bd::referee;
using bd::Vec2;

inline Vec2 left_normal(const Vec2& v) { return {-v.y(), v.x()}; }

/// A link's centre of mass as drawn (global).
inline Vec2 drawn_com(const cp::Linkage& l, int k) {
  const cp::Link& link = l.links[static_cast<std::size_t>(k)];
  const Vec2 p = l.nodes[static_cast<std::size_t>(link.nodes[0])].position;
  const Vec2 u = (l.nodes[static_cast<std::size_t>(link.nodes[1])].position - p).normalized();
  return p + link.e * u + link.f * left_normal(u);
}

/// A link's angle as drawn: the direction of nodes[0] -> nodes[1], in (-π, π].
inline double drawn_angle(const cp::Linkage& l, int k) {
  const cp::Link& link = l.links[static_cast<std::size_t>(k)];
  const Vec2 d = l.nodes[static_cast<std::size_t>(link.nodes[1])].position -
                 l.nodes[static_cast<std::size_t>(link.nodes[0])].position;
  return std::atan2(d.y(), d.x());
}

/// The linkage as the referee's mechanism, and where each engine item went.
struct Glue {
  cp::Linkage linkage;
  rf::Mechanism mechanism;
  std::vector<int> host;                     // per node: its host body, kGround for ground nodes
  std::vector<std::vector<int>> node_links;  // per node: the links through it, in link order
  std::map<std::pair<int, int>, int> pin;    // (node, link) -> pin index (not the host's)
};

inline rf::Body body_of(const cp::Linkage& l, int k) {
  const cp::Link& link = l.links[static_cast<std::size_t>(k)];
  return rf::Body{link.name, link.mass, link.inertia, drawn_com(l, k), {}};
}

inline std::function<double(double)> function_of(const cp::TimeFunction& f) {
  if (f.is_zero()) return {};
  return [f](double t) { return f(t); };
}

inline Glue glue_of(const cp::Linkage& l) {
  Glue g;
  g.linkage = l;
  rf::Mechanism& m = g.mechanism;
  const std::size_t nodes = l.nodes.size();
  auto pos = [&](int n) { return l.nodes[static_cast<std::size_t>(n)].position; };
  for (int k = 0; k < static_cast<int>(l.links.size()); ++k) m.bodies.push_back(body_of(l, k));
  g.node_links.assign(nodes, {});
  for (int k = 0; k < static_cast<int>(l.links.size()); ++k) {
    for (int n : l.links[static_cast<std::size_t>(k)].nodes)
      g.node_links[static_cast<std::size_t>(n)].push_back(k);
  }
  g.host.assign(nodes, rf::kGround);
  for (int i = 0; i < static_cast<int>(nodes); ++i) {
    const auto& links = g.node_links[static_cast<std::size_t>(i)];
    const cp::Node& node = l.nodes[static_cast<std::size_t>(i)];
    if (node.ground) {
      for (int k : links) {
        g.pin[{i, k}] = static_cast<int>(m.pins.size());
        m.pins.push_back({node.name + "/" + l.links[static_cast<std::size_t>(k)].name, rf::kGround,
                          k, node.position});
      }
      continue;
    }
    if (links.empty()) throw std::logic_error("planar_glue: moving node " + node.name + " in no link");
    g.host[static_cast<std::size_t>(i)] = links[0];
    for (std::size_t j = 1; j < links.size(); ++j) {
      g.pin[{i, links[j]}] = static_cast<int>(m.pins.size());
      m.pins.push_back({node.name + "/" + l.links[static_cast<std::size_t>(links[j])].name,
                        links[0], links[j], node.position});
    }
  }
  auto host = [&](int n) { return g.host[static_cast<std::size_t>(n)]; };
  for (const cp::PointMass& pm : l.point_masses) {
    m.bodies[static_cast<std::size_t>(host(pm.node))].point_masses.push_back(
        {pm.mass, pos(pm.node)});
  }
  for (const cp::Slider& s : l.sliders) {
    rf::PointOnLine p;
    p.name = s.name;
    p.point_body = host(s.node);
    p.point = pos(s.node);
    if (s.link < 0) {
      p.line_body = rf::kGround;
      p.line_from = s.from;
      p.line_to = s.to;
    } else {
      p.line_body = s.link;
      p.line_from = pos(s.from_node);
      p.line_to = pos(s.to_node);
    }
    m.sliders.push_back(p);
  }
  for (const cp::Spring& s : l.springs) {
    m.springs.push_back({host(s.a), host(s.b), pos(s.a), pos(s.b), s.stiffness, s.free_length,
                         s.damping});
  }
  m.gravity = l.loads.gravity;
  for (const cp::LinkLoad& ld : l.loads.link_loads) {
    const Vec2 f = ld.force;
    const double mo = ld.moment;
    m.forces.push_back({ld.link, drawn_com(l, ld.link), [f](double) { return f; }});
    m.moments.push_back({ld.link, [mo](double) { return mo; }});
  }
  for (const cp::NodeForce& nf : l.loads.node_forces) {
    const Vec2 f = nf.force;
    m.forces.push_back({host(nf.node), pos(nf.node), [f](double) { return f; }});
  }
  for (const cp::Input& in : l.inputs) {
    if (in.kind == cp::Input::Kind::kAngle) {
      m.inputs.push_back(rf::AngleInput{in.link});
    } else {
      m.inputs.push_back(rf::SlideInput{in.slider});
    }
    m.input_efforts.push_back(function_of(in.effort));
  }
  return g;
}

/// The linkage described to the referee (see the top of this file).
inline rf::Mechanism referee_of(const cp::Linkage& l) { return glue_of(l).mechanism; }

/// Motion of node n in a referee sample (a ground node stays where it is drawn).
inline rf::PointMotion node_motion(const Glue& g, const rf::Sample& s, int n) {
  return rf::point_motion(g.mechanism, s, g.host[static_cast<std::size_t>(n)],
                          g.linkage.nodes[static_cast<std::size_t>(n)].position);
}

/// Position, rate and acceleration of slider k along its guide (relative to the guide's link).
struct Slide {
  double s{}, v{}, a{};
};
inline Slide slide_of(const Glue& g, const rf::Sample& smp, int k) {
  const cp::Slider& sl = g.linkage.sliders[static_cast<std::size_t>(k)];
  const rf::PointMotion P = node_motion(g, smp, sl.node);
  if (sl.link < 0) {
    const Vec2 u = (sl.to - sl.from).normalized();
    return {u.dot(P.p - sl.from), u.dot(P.v), u.dot(P.a)};
  }
  const rf::PointMotion Q = node_motion(g, smp, sl.from_node), R = node_motion(g, smp, sl.to_node);
  const double L = (g.linkage.nodes[static_cast<std::size_t>(sl.to_node)].position -
                    g.linkage.nodes[static_cast<std::size_t>(sl.from_node)].position)
                       .norm();
  const Vec2 a = P.p - Q.p, b = R.p - Q.p, ad = P.v - Q.v, bd = R.v - Q.v, aa = P.a - Q.a,
             ba = R.a - Q.a;
  return {a.dot(b) / L, (ad.dot(b) + a.dot(bd)) / L, (aa.dot(b) + 2 * ad.dot(bd) + a.dot(ba)) / L};
}

/// The current unit direction of slider k's guide.
inline Vec2 guide_direction(const Glue& g, const rf::Sample& smp, int k) {
  const cp::Slider& sl = g.linkage.sliders[static_cast<std::size_t>(k)];
  if (sl.link < 0) return (sl.to - sl.from).normalized();
  return (node_motion(g, smp, sl.to_node).p - node_motion(g, smp, sl.from_node).p).normalized();
}

/// The force on the only link through node n from the node (its point masses, sliders,
/// slide drives, node forces, springs): what the engine reports as that node's joint force.
inline Vec2 single_link_joint_force(const Glue& g, const rf::Sample& smp, int n) {
  const cp::Linkage& l = g.linkage;
  Vec2 f(0, 0);
  double mass = 0;
  for (const cp::PointMass& pm : l.point_masses) {
    if (pm.node == n) mass += pm.mass;
  }
  f += mass * (l.loads.gravity - node_motion(g, smp, n).a);
  for (std::size_t k = 0; k < l.sliders.size(); ++k) {
    if (l.sliders[k].node == n) f += smp.slider_forces[k];
  }
  for (std::size_t k = 0; k < l.inputs.size(); ++k) {
    const cp::Input& in = l.inputs[k];
    if (in.kind == cp::Input::Kind::kSlide && l.sliders[static_cast<std::size_t>(in.slider)].node == n)
      f += smp.input_efforts[k] * guide_direction(g, smp, in.slider);
  }
  for (const cp::NodeForce& nf : l.loads.node_forces) {
    if (nf.node == n) f += nf.force;
  }
  for (std::size_t k = 0; k < l.springs.size(); ++k) {
    const cp::Spring& sp = l.springs[k];
    if (sp.a != n && sp.b != n) continue;
    const int other = sp.a == n ? sp.b : sp.a;
    const Vec2 towards = (node_motion(g, smp, other).p - node_motion(g, smp, n).p).normalized();
    f += smp.spring_tensions[k] * towards;
  }
  return f;
}

/// The engine's columns (columns(model)) from the referee's samples.
inline core::Series reference_table(const cp::Model& model, const Glue& g,
                                    const std::vector<rf::Sample>& samples) {
  const cp::Linkage& l = g.linkage;
  core::Series out;
  out.columns = cp::columns(model);
  for (const rf::Sample& s : samples) {
    std::vector<double>& v = out.values;
    v.push_back(s.t);
    for (std::size_t k = 0; k < l.links.size(); ++k) {
      const rf::BodyState& b = s.bodies[k];
      v.insert(v.end(), {drawn_angle(l, static_cast<int>(k)) + b.angle, b.omega, b.alpha});
    }
    for (std::size_t k = 0; k < l.sliders.size(); ++k) {
      const Slide sl = slide_of(g, s, static_cast<int>(k));
      v.insert(v.end(), {sl.s, sl.v, sl.a});
    }
    for (std::size_t i = 0; i < l.nodes.size(); ++i) {
      if (l.nodes[i].ground) continue;
      const Vec2 p = node_motion(g, s, static_cast<int>(i)).p;
      v.insert(v.end(), {p.x(), p.y()});
    }
    for (int n : model.ground_nodes()) {
      Vec2 r(0, 0);
      for (int k : g.node_links[static_cast<std::size_t>(n)])
        r -= s.pin_forces[static_cast<std::size_t>(g.pin.at({n, k}))];
      v.insert(v.end(), {r.x(), r.y()});
    }
    for (int k : model.frame_guides()) {
      const Vec2 r = -s.slider_forces[static_cast<std::size_t>(k)];
      v.insert(v.end(), {r.x(), r.y()});
    }
    // a spring anchored on the frame pulls it towards the spring's other end with its tension
    for (int k : model.frame_springs()) {
      const cp::Spring& sp = l.springs[static_cast<std::size_t>(k)];
      const bool at_a = l.nodes[static_cast<std::size_t>(sp.a)].ground;
      const Vec2 anchor = node_motion(g, s, at_a ? sp.a : sp.b).p;
      const Vec2 other = node_motion(g, s, at_a ? sp.b : sp.a).p;
      const Vec2 r = s.spring_tensions[static_cast<std::size_t>(k)] * (other - anchor).normalized();
      v.insert(v.end(), {r.x(), r.y()});
    }
    // a slide drive on a frame guide pushes the frame back along the guide
    for (int k : model.frame_drives()) {
      const int slider = l.inputs[static_cast<std::size_t>(k)].slider;
      const Vec2 r = -s.input_efforts[static_cast<std::size_t>(k)] * guide_direction(g, s, slider);
      v.insert(v.end(), {r.x(), r.y()});
    }
    for (const cp::JointForce& j : model.joints()) {
      const Vec2 f = j.link == g.host[static_cast<std::size_t>(j.node)]
                         ? single_link_joint_force(g, s, j.node)
                         : s.pin_forces[static_cast<std::size_t>(g.pin.at({j.node, j.link}))];
      v.insert(v.end(), {f.x(), f.y()});
    }
    // a slider on a moving guide: the force on the guide's link from the node, the reaction of
    // the guide's force on the node and of a slide drive's along it
    for (int k : model.link_guides()) {
      Vec2 f = -s.slider_forces[static_cast<std::size_t>(k)];
      for (std::size_t i = 0; i < l.inputs.size(); ++i) {
        if (l.inputs[i].kind == cp::Input::Kind::kSlide && l.inputs[i].slider == k)
          f -= s.input_efforts[i] * guide_direction(g, s, k);
      }
      v.insert(v.end(), {f.x(), f.y()});
    }
    v.insert(v.end(), {s.shaking_force.x(), s.shaking_force.y(), s.shaking_moment});
    v.insert(v.end(), s.input_efforts.begin(), s.input_efforts.end());
    v.insert(v.end(), {s.inertial_force.x(), s.inertial_force.y(), s.inertial_moment});
    // the static part: what the referee's total has beyond its inertial part
    const Vec2 f = s.shaking_force - s.inertial_force;
    v.insert(v.end(), {f.x(), f.y(), s.shaking_moment - s.inertial_moment});
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// The engine's general route along a driven scene: each instant evaluated by the public
// per-instant API exactly as the scene is defined (inputs at start + speed t, constant speeds),
// its position by Newton's method continued from the previous instant (cp::solve_position), then
// its inverse dynamics; each instant is handed to `use`. Stops at the first failure (a test
// failure).

template <class Use>
void general_route(const cp::Model& model, const std::vector<double>& speeds,
                   const std::vector<double>& times, Use use) {
  cp::Workspace ws(model);
  const std::vector<double> start = cp::drawn_inputs(model);
  EXPECT_TRUE(cp::assemble(model, ws, start));
  std::vector<double> z(start.size()), zero(start.size(), 0.0);
  for (double t : times) {
    for (std::size_t k = 0; k < z.size(); ++k) z[k] = start[k] + speeds[k] * t;
    const std::vector<Vec2> guess = ws.instant.x;
    auto ok = cp::solve_position(model, ws, guess, z, cp::PositionRoute::kGeneral);
    if (ok) ok = cp::inverse_dynamics(model, ws, t, speeds, zero);
    EXPECT_TRUE(ok) << (ok ? "" : ok.error().detail);
    if (!ok) break;
    EXPECT_FALSE(ws.by_blocks);
    use(ws.instant);
  }
}

// ---------------------------------------------------------------------------------------------
// What an Instant has beyond the table: node velocities and accelerations, the inputs' values,
// rates and accelerations (as columns named so that compare_tables knows their families:
// theta_in_/omega_in_/alpha_in_ for an angle input, s_in_/v_in_/a_in_ for a slide input).

inline std::vector<std::string> instant_columns(const cp::Model& model) {
  const cp::Linkage& l = model.linkage();
  std::vector<std::string> c = {"t"};
  for (const cp::Node& n : l.nodes) {
    if (n.ground) continue;
    c.insert(c.end(), {"vx_" + n.name, "vy_" + n.name, "ax_" + n.name, "ay_" + n.name});
  }
  for (const cp::Input& in : l.inputs) {
    const bool angle = in.kind == cp::Input::Kind::kAngle;
    c.insert(c.end(), {(angle ? "theta_in_" : "s_in_") + in.name,
                       (angle ? "omega_in_" : "v_in_") + in.name,
                       (angle ? "alpha_in_" : "a_in_") + in.name});
  }
  return c;
}

inline void append_instant(const cp::Model& model, const cp::Instant& in, core::Series& t) {
  const cp::Linkage& l = model.linkage();
  t.values.push_back(in.t);
  for (std::size_t i = 0; i < l.nodes.size(); ++i) {
    if (l.nodes[i].ground) continue;
    t.values.insert(t.values.end(), {in.v[i].x(), in.v[i].y(), in.a[i].x(), in.a[i].y()});
  }
  for (std::size_t k = 0; k < l.inputs.size(); ++k) {
    t.values.insert(t.values.end(), {in.input[k], in.input_rate[k], in.input_acceleration[k]});
  }
}

/// The inputs' values as the engine measures them in the drawn configuration.
inline double drawn_input(const cp::Linkage& l, int k) {
  const cp::Input& in = l.inputs[static_cast<std::size_t>(k)];
  if (in.kind == cp::Input::Kind::kAngle) return drawn_angle(l, in.link);
  const cp::Slider& sl = l.sliders[static_cast<std::size_t>(in.slider)];
  const Vec2 P = l.nodes[static_cast<std::size_t>(sl.node)].position;
  if (sl.link < 0) return (sl.to - sl.from).normalized().dot(P - sl.from);
  const Vec2 Q = l.nodes[static_cast<std::size_t>(sl.from_node)].position,
             R = l.nodes[static_cast<std::size_t>(sl.to_node)].position;
  return (P - Q).dot((R - Q).normalized());
}

inline void append_reference_instant(const Glue& g, const rf::Sample& s, core::Series& t) {
  const cp::Linkage& l = g.linkage;
  t.values.push_back(s.t);
  for (std::size_t i = 0; i < l.nodes.size(); ++i) {
    if (l.nodes[i].ground) continue;
    const rf::PointMotion m = node_motion(g, s, static_cast<int>(i));
    t.values.insert(t.values.end(), {m.v.x(), m.v.y(), m.a.x(), m.a.y()});
  }
  for (std::size_t k = 0; k < l.inputs.size(); ++k) {
    t.values.insert(t.values.end(), {drawn_input(l, static_cast<int>(k)) + s.input_values[k],
                                     s.input_rates[k], s.input_accelerations[k]});
  }
}

// ---------------------------------------------------------------------------------------------
// Comparing tables

/// What a column measures: its family of quantities (a unit), and whether it is the x or y of a
/// vector (R<n>x/y, F<j>x/y, Fshx/y, Fshx/y_inertial, x_/y_<node>) compared as one.
enum class Family {
  kTime, kAngle, kLength, kAngularRate, kRate, kAngularAcceleration, kAcceleration,
  kReaction, kJointForce, kShakingForce, kShakingMoment, kEffort, kNodeVelocity,
  kNodeAcceleration
};
inline const char* to_string(Family f) {
  switch (f) {
    case Family::kTime: return "time";
    case Family::kAngle: return "link angles";
    case Family::kLength: return "positions";
    case Family::kAngularRate: return "angular rates";
    case Family::kRate: return "slide rates";
    case Family::kAngularAcceleration: return "angular accelerations";
    case Family::kAcceleration: return "slide accelerations";
    case Family::kReaction: return "ground and guide reactions";
    case Family::kJointForce: return "joint forces";
    case Family::kShakingForce: return "Fsh and its inertial and static parts";
    case Family::kShakingMoment: return "Msh and its inertial and static parts";
    case Family::kEffort: return "drive efforts";
    case Family::kNodeVelocity: return "node velocities";
    case Family::kNodeAcceleration: return "node accelerations";
  }
  return "?";
}

inline bool starts(const std::string& s, const char* p) { return s.rfind(p, 0) == 0; }

inline Family family_of(const std::string& c) {
  if (c == "t") return Family::kTime;
  if (starts(c, "theta_")) return Family::kAngle;
  if (starts(c, "vx_") || starts(c, "vy_")) return Family::kNodeVelocity;
  if (starts(c, "ax_") || starts(c, "ay_")) return Family::kNodeAcceleration;
  if (starts(c, "omega_")) return Family::kAngularRate;
  if (starts(c, "alpha_")) return Family::kAngularAcceleration;
  if (starts(c, "s_") || starts(c, "x_") || starts(c, "y_")) return Family::kLength;
  if (starts(c, "v_")) return Family::kRate;
  if (starts(c, "a_")) return Family::kAcceleration;
  if (c == "Fshx" || c == "Fshy" || c == "Fshx_inertial" || c == "Fshy_inertial" ||
      c == "Fshx_static" || c == "Fshy_static")
    return Family::kShakingForce;
  if (c == "Msh" || c == "Msh_inertial" || c == "Msh_static") return Family::kShakingMoment;
  if (starts(c, "tau")) return Family::kEffort;
  if (starts(c, "R")) return Family::kReaction;
  if (starts(c, "F")) return Family::kJointForce;
  throw std::logic_error("planar_glue: unknown column " + c);
}

/// The partner of a vector's x column (the y column), or "" for a scalar.
inline std::string partner(const std::string& c) {
  if (starts(c, "x_")) return "y_" + c.substr(2);
  if (starts(c, "vx_")) return "vy_" + c.substr(3);
  if (starts(c, "ax_")) return "ay_" + c.substr(3);
  if (c == "Fshx_inertial") return "Fshy_inertial";
  if (c == "Fshx_static") return "Fshy_static";
  const Family f = family_of(c);
  if ((f == Family::kReaction || f == Family::kJointForce || f == Family::kShakingForce) &&
      c.back() == 'x')
    return c.substr(0, c.size() - 1) + "y";
  return "";
}
inline bool is_y_of_vector(const std::string& c) {
  if (starts(c, "y_") || starts(c, "vy_") || starts(c, "ay_")) return true;
  if (c == "Fshy_inertial" || c == "Fshy_static") return true;
  const Family f = family_of(c);
  return (f == Family::kReaction || f == Family::kJointForce || f == Family::kShakingForce) &&
         c.back() == 'y';
}

/// The largest relative difference per family, and where.
struct Agreement {
  std::map<Family, double> worst;
  std::map<Family, std::string> where;
  double overall = 0;
  std::string overall_where;
  void add(Family f, double gap, const std::string& what) {
    if (!worst.count(f) || !(gap <= worst[f])) {  // NaN counts as the worst
      worst[f] = gap;
      where[f] = what;
    }
    if (overall_where.empty() || !(gap <= overall)) {
      overall = gap;
      overall_where = what;
    }
  }
  void merge(const Agreement& o) {
    for (const auto& [f, gap] : o.worst) add(f, gap, o.where.at(f));
  }
  std::string text() const {
    std::string s;
    char buf[160];
    for (const auto& [f, gap] : worst) {
      std::snprintf(buf, sizeof buf, "  %-28s %.2e  (%s)\n", to_string(f), gap, where.at(f).c_str());
      s += buf;
    }
    return s;
  }
};

/// Compares two tables of the same columns and rows. Each quantity (a scalar column, or the
/// x and y columns of a vector, compared by the norm of the difference) is compared relative to
/// its own scale over the run: its largest magnitude in the reference table, but at least 1e-3
/// of the largest magnitude of its family in the run (a quantity a thousand times smaller than
/// its family carries the round-off of the family's larger terms it is computed from, e.g. the
/// angular acceleration of a crank turning at constant speed, 0 exactly, is a difference of
/// centripetal terms of size omega^2: the angular accelerations' family size is the larger of
/// max |alpha| and max omega^2; a slide acceleration's, of max |a|, max v^2 / the linkage's
/// size and that size times the angular accelerations' family size). Positions (x_, y_, s_) are relative to the linkage's
/// size (model.length_scale()); angles to max(1 rad, their largest magnitude); time exactly.
inline Agreement compare_tables(const cp::Model& model, const core::Series& engine,
                                const core::Series& reference, const std::string& label) {
  Agreement out;
  EXPECT_EQ(engine.columns, reference.columns) << label;
  EXPECT_EQ(engine.rows(), reference.rows()) << label;
  if (engine.columns != reference.columns || engine.rows() != reference.rows()) {
    out.add(Family::kTime, INFINITY, label + ": tables differ in shape");
    return out;
  }
  const std::size_t rows = reference.rows();
  auto magnitude = [&](const core::Series& t, std::size_t r, int cx, int cy) {
    const double x = t.at(r, static_cast<std::size_t>(cx));
    return cy < 0 ? std::abs(x) : std::hypot(x, t.at(r, static_cast<std::size_t>(cy)));
  };
  struct Quantity {
    std::string name;
    Family family;
    int cx, cy;
    double scale = 0;
  };
  std::vector<Quantity> qs;
  for (std::size_t c = 0; c < reference.width(); ++c) {
    const std::string& name = reference.columns[c];
    if (is_y_of_vector(name)) continue;
    const std::string p = partner(name);
    Quantity q{name, family_of(name), static_cast<int>(c), p.empty() ? -1 : reference.column(p)};
    for (std::size_t r = 0; r < rows; ++r) q.scale = std::max(q.scale, magnitude(reference, r, q.cx, q.cy));
    qs.push_back(q);
  }
  std::map<Family, double> family_scale;
  for (const Quantity& q : qs) family_scale[q.family] = std::max(family_scale[q.family], q.scale);
  // an angular acceleration is formed from node accelerations that carry the centripetal
  // omega^2 of the link: its natural size is the larger of |alpha| and omega^2
  family_scale[Family::kAngularAcceleration] =
      std::max(family_scale[Family::kAngularAcceleration],
               family_scale[Family::kAngularRate] * family_scale[Family::kAngularRate]);
  // likewise a slide acceleration (0 exactly for a piston driven at constant speed) is formed
  // from node accelerations: its size is the linkage's acceleration, max(|alpha|, omega^2) times
  // its size, or v^2 / size
  family_scale[Family::kAcceleration] = std::max(
      {family_scale[Family::kAcceleration],
       family_scale[Family::kRate] * family_scale[Family::kRate] / model.length_scale(),
       family_scale[Family::kAngularAcceleration] * model.length_scale()});
  for (Quantity& q : qs) {
    switch (q.family) {
      case Family::kTime: q.scale = 0; break;
      case Family::kAngle: q.scale = std::max(1.0, q.scale); break;
      case Family::kLength: q.scale = model.length_scale(); break;
      default: q.scale = std::max(q.scale, 1e-3 * family_scale[q.family]);
    }
    double gap = 0;
    std::size_t at = 0;
    for (std::size_t r = 0; r < rows; ++r) {
      const double dx = engine.at(r, static_cast<std::size_t>(q.cx)) - reference.at(r, static_cast<std::size_t>(q.cx));
      const double dy = q.cy < 0 ? 0.0 : engine.at(r, static_cast<std::size_t>(q.cy)) - reference.at(r, static_cast<std::size_t>(q.cy));
      const double d = std::hypot(dx, dy);
      if (!(d <= gap)) {
        gap = d;
        at = r;
      }
    }
    const double rel = q.family == Family::kTime ? gap : (q.scale > 0 ? gap / q.scale : gap);
    out.add(q.family, rel, label + ": " + q.name + " at t = " + std::to_string(reference.at(at, 0)));
  }
  return out;
}

/// Fails unless every family agrees to `tolerance`; prints the agreement.
inline void expect_agreement(const Agreement& a, double tolerance, const std::string& label) {
  for (const auto& [f, gap] : a.worst) {
    EXPECT_LE(gap, tolerance) << label << ": " << to_string(f) << " differ by " << gap
                              << " relative, worst " << a.where.at(f);
  }
}

/// True when no value of the table is NaN or infinite.
inline bool all_finite(const core::Series& t) {
  return std::all_of(t.values.begin(), t.values.end(), [](double v) { return std::isfinite(v); });
}

}  // namespace bd::testing::planar
