#pragma once
// Test support: the kinematics, energies, powers and applied loads of one row of a planar
// engine's table (core/planar/simulate.hpp, columns()), from its columns only: node positions,
// link angles, rates and accelerations, slider rates and accelerations. Node velocities and
// accelerations follow link by link from the ground nodes and the frame guides (rigid-body
// kinematics); centres of mass from the links' e and f.
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/planar/dynamics.hpp"
#include "core/planar/simulate.hpp"
#include "core/series.hpp"
#include "tests/support/planar_glue.hpp"

namespace bd::testing::planar {

// ---------------------------------------------------------------------------------------------
// Kinematics of one row of a table

struct Row {
  std::vector<Vec2> x, v, a;         // per node
  std::vector<Vec2> G, vG, aG;       // per link: centre of mass
  std::vector<double> w, alpha;      // per link
  std::vector<double> effort, rate;  // per input
  Vec2 Fsh, Fsh_inertial;
  double Msh{}, Msh_inertial{}, t{};
};

inline Row row_of(const cp::Model& model, const core::Series& table, std::size_t r) {
  const cp::Linkage& l = model.linkage();
  auto col = [&](const std::string& name) {
    const int c = table.column(name);
    if (c < 0) throw std::logic_error("no column " + name);
    return table.at(r, static_cast<std::size_t>(c));
  };
  Row out;
  out.t = col("t");
  const std::size_t nodes = l.nodes.size();
  out.x.resize(nodes);
  out.v.assign(nodes, Vec2(NAN, NAN));
  out.a.assign(nodes, Vec2(NAN, NAN));
  std::vector<bool> known(nodes, false);
  for (std::size_t i = 0; i < nodes; ++i) {
    const cp::Node& n = l.nodes[i];
    if (n.ground) {
      out.x[i] = n.position;
      out.v[i] = out.a[i] = Vec2(0, 0);
      known[i] = true;
    } else {
      out.x[i] = Vec2(col("x_" + n.name), col("y_" + n.name));
    }
  }
  for (const cp::Slider& s : l.sliders) {  // a node on a frame guide moves along it
    if (s.link >= 0) continue;
    const Vec2 u = (s.to - s.from).normalized();
    const std::size_t i = static_cast<std::size_t>(s.node);
    out.v[i] = col("v_" + s.name) * u;
    out.a[i] = col("a_" + s.name) * u;
    known[i] = true;
  }
  for (const cp::Link& k : l.links) {
    out.w.push_back(col("omega_" + k.name));
    out.alpha.push_back(col("alpha_" + k.name));
  }
  // a link with a node of known motion: all its nodes (rigid-body kinematics)
  for (bool changed = true; changed;) {
    changed = false;
    for (std::size_t k = 0; k < l.links.size(); ++k) {
      const auto& ns = l.links[k].nodes;
      int from = -1;
      for (int n : ns)
        if (known[static_cast<std::size_t>(n)]) from = n;
      if (from < 0) continue;
      const std::size_t p = static_cast<std::size_t>(from);
      for (int n : ns) {
        const std::size_t q = static_cast<std::size_t>(n);
        if (known[q]) continue;
        const Vec2 d = out.x[q] - out.x[p];
        out.v[q] = out.v[p] + out.w[k] * left_normal(d);
        out.a[q] = out.a[p] + out.alpha[k] * left_normal(d) - out.w[k] * out.w[k] * d;
        known[q] = changed = true;
      }
    }
  }
  for (std::size_t i = 0; i < nodes; ++i)
    if (!known[i]) throw std::logic_error("node " + l.nodes[i].name + " not reached");
  for (std::size_t k = 0; k < l.links.size(); ++k) {
    const cp::Link& link = l.links[k];
    const std::size_t p = static_cast<std::size_t>(link.nodes[0]), q = static_cast<std::size_t>(link.nodes[1]);
    const Vec2 u = (out.x[q] - out.x[p]).normalized();
    const Vec2 d = link.e * u + link.f * left_normal(u);
    out.G.push_back(out.x[p] + d);
    out.vG.push_back(out.v[p] + out.w[k] * left_normal(d));
    out.aG.push_back(out.a[p] + out.alpha[k] * left_normal(d) - out.w[k] * out.w[k] * d);
  }
  for (std::size_t k = 0; k < l.inputs.size(); ++k) {
    const cp::Input& in = l.inputs[k];
    out.effort.push_back(col(l.inputs.size() == 1 ? "tau" : "tau_" + in.name));
    out.rate.push_back(in.kind == cp::Input::Kind::kAngle
                           ? out.w[static_cast<std::size_t>(in.link)]
                           : col("v_" + l.sliders[static_cast<std::size_t>(in.slider)].name));
  }
  out.Fsh = Vec2(col("Fshx"), col("Fshy"));
  out.Fsh_inertial = Vec2(col("Fshx_inertial"), col("Fshy_inertial"));
  out.Msh = col("Msh");
  out.Msh_inertial = col("Msh_inertial");
  return out;
}

// ---------------------------------------------------------------------------------------------
// Energies and powers of a row

struct Balance {
  double kinetic{}, kinetic_rate{}, gravity{}, spring{};
  double input_power{}, damper_power{}, applied_power{}, gravity_power{}, spring_power{};
  Vec2 applied_force{0, 0};  // loads and weights
  double applied_moment{};   // their moments about the origin, and the load moments
};

inline Balance balance_of(const cp::Model& model, const Row& r) {
  const cp::Linkage& l = model.linkage();
  const Vec2 g = l.loads.gravity;
  Balance b;
  for (std::size_t k = 0; k < l.links.size(); ++k) {
    const cp::Link& link = l.links[k];
    b.kinetic += 0.5 * (link.mass * r.vG[k].squaredNorm() + link.inertia * r.w[k] * r.w[k]);
    b.kinetic_rate += link.mass * r.vG[k].dot(r.aG[k]) + link.inertia * r.w[k] * r.alpha[k];
    b.gravity -= link.mass * g.dot(r.G[k]);
    b.gravity_power += link.mass * g.dot(r.vG[k]);
    b.applied_force += link.mass * g;
    b.applied_moment += cross(r.G[k], link.mass * g);
  }
  for (const cp::PointMass& pm : l.point_masses) {
    const std::size_t i = static_cast<std::size_t>(pm.node);
    b.kinetic += 0.5 * pm.mass * r.v[i].squaredNorm();
    b.kinetic_rate += pm.mass * r.v[i].dot(r.a[i]);
    b.gravity -= pm.mass * g.dot(r.x[i]);
    b.gravity_power += pm.mass * g.dot(r.v[i]);
    b.applied_force += pm.mass * g;
    b.applied_moment += cross(r.x[i], pm.mass * g);
  }
  for (const cp::Spring& s : l.springs) {
    const std::size_t i = static_cast<std::size_t>(s.a), j = static_cast<std::size_t>(s.b);
    const Vec2 d = r.x[j] - r.x[i];
    const double L = d.norm(), rate = d.dot(r.v[j] - r.v[i]) / L;
    const double tension = s.stiffness * (L - s.free_length) + s.damping * rate;
    b.spring += 0.5 * s.stiffness * (L - s.free_length) * (L - s.free_length);
    b.spring_power -= tension * rate;  // a tension pulls the ends together: work -T dL
    b.damper_power += s.damping * rate * rate;
  }
  for (const cp::LinkLoad& ld : l.loads.link_loads) {
    const std::size_t k = static_cast<std::size_t>(ld.link);
    b.applied_power += ld.force.dot(r.vG[k]) + ld.moment * r.w[k];
    b.applied_force += ld.force;
    b.applied_moment += cross(r.G[k], ld.force) + ld.moment;
  }
  for (const cp::NodeForce& nf : l.loads.node_forces) {
    const std::size_t i = static_cast<std::size_t>(nf.node);
    b.applied_power += nf.force.dot(r.v[i]);
    b.applied_force += nf.force;
    b.applied_moment += cross(r.x[i], nf.force);
  }
  for (std::size_t k = 0; k < r.effort.size(); ++k) b.input_power += r.effort[k] * r.rate[k];
  return b;
}

// The momentum balance of one row, relative to the forces' and moments' sizes in it.
struct MomentumGap {
  double force{}, moment{};
};
inline MomentumGap momentum_gap(const Row& r, const Balance& b, double length) {
  const double F = std::max({r.Fsh.norm(), r.Fsh_inertial.norm(), b.applied_force.norm()});
  const double M = std::max({std::abs(r.Msh), std::abs(r.Msh_inertial), std::abs(b.applied_moment),
                             F * length});
  return {(r.Fsh - r.Fsh_inertial - b.applied_force).norm() / F,
          std::abs(r.Msh - r.Msh_inertial - b.applied_moment) / M};
}

}  // namespace bd::testing::planar
