#include "core/planar/system.hpp"

#include <algorithm>
#include <cmath>

namespace bd::core::planar::detail {

namespace {

constexpr double kPi = 3.14159265358979323846;

// adds `force` to F at node `node`'s coordinates (nothing for a ground node)
void add_force(const System& s, VectorXd& F, int node, const Vec2& force) {
  const int c = s.coord[static_cast<std::size_t>(node)];
  if (c < 0) return;
  F[c] += force.x();
  F[c + 1] += force.y();
}

const Vec2& at(const NodeVectors& x, int node) { return x[static_cast<std::size_t>(node)]; }

// the angle of d continued to within π of `near`
double continued_angle(const Vec2& d, double near) {
  const double a = std::atan2(d.y(), d.x());
  return a + 2 * kPi * std::round((near - a) / (2 * kPi));
}

// the angle from the direction u (a target's) to d, in [-π, π], exact to round-off for any
// |target|: the difference of two angles would carry the round-off of the target's whole turns
// (ulp(80 rad) = 1.4e-14 rad), which after some 13 turns exceeds what Newton's stopping test on
// the positions (1e-14 of the length scale) can see converge
double angle_from(const Vec2& u, const Vec2& d) { return std::atan2(cross(u, d), u.dot(d)); }

}  // namespace

namespace {

// link k's element mass, mass matrix and centre of mass on the element, from its parameters
void set_element_mass(System& s, int k) {
  const Link& link = s.linkage.links[static_cast<std::size_t>(k)];
  double geared = 0;  // the balance shafts' inertia, as the link sees it
  for (const BalanceShaft& b : s.linkage.shafts) {
    if (b.link == k) geared += b.ratio * b.ratio * (b.inertia + b.mass * b.eccentricity.squaredNorm());
  }
  const auto i = static_cast<std::size_t>(k);
  const ElementMass em{s.elements[i].length, link.mass, link.e, link.f, link.inertia + geared};
  s.element_mass[i] = em;
  s.element_M[i] = element_mass_matrix(em);
  s.com_weights[i] = point_weights(link.e / em.length, link.f / em.length);
}

// one row per link (its element's length), then two per further node of a link (held on the
// element as a material point); returns the next free row
int add_link_rows(System& s) {
  const Linkage& l = s.linkage;
  int row = static_cast<int>(l.links.size());
  std::vector<int> pending_rigid;  // rigid entries in row order, after the element rows
  for (std::size_t k = 0; k < l.links.size(); ++k) {
    const Link& link = l.links[k];
    const int p = link.nodes[0], q = link.nodes[1];
    const Vec2 d = l.nodes[static_cast<std::size_t>(q)].position -
                   l.nodes[static_cast<std::size_t>(p)].position;
    s.elements.push_back({p, q, d.norm(), d.squaredNorm()});
    s.row_ref.push_back({System::RowRef::Kind::kElement, static_cast<int>(k)});
    s.element_mass.emplace_back();
    s.element_M.emplace_back();
    s.com_weights.emplace_back();
    set_element_mass(s, static_cast<int>(k));
    for (std::size_t j = 2; j < link.nodes.size(); ++j) {
      const int r = link.nodes[j];
      const Vec2 c = link_coordinates(l.nodes[static_cast<std::size_t>(p)].position,
                                      l.nodes[static_cast<std::size_t>(q)].position,
                                      l.nodes[static_cast<std::size_t>(r)].position);
      const int index = static_cast<int>(s.rigid.size());
      s.rigid.push_back({row, static_cast<int>(k), r, p, q, point_weights(c.x(), c.y())});
      row += 2;
      pending_rigid.push_back(index);
    }
  }
  for (int index : pending_rigid) {
    s.row_ref.push_back({System::RowRef::Kind::kRigid, index});
    s.row_ref.push_back({System::RowRef::Kind::kRigid, index});
  }
  return row;
}

// one row per slider (the node on its guide); returns the next free row
int add_slider_rows(System& s, int row) {
  const Linkage& l = s.linkage;
  for (std::size_t k = 0; k < l.sliders.size(); ++k) {
    const Slider& sl = l.sliders[k];
    s.row_ref.push_back({System::RowRef::Kind::kSlider, static_cast<int>(k)});
    System::SliderRow r;
    r.row = row++;
    r.slider = static_cast<int>(k);
    r.node = sl.node;
    r.on_link = sl.link >= 0;
    if (r.on_link) {
      r.from_node = sl.from_node;
      r.to_node = sl.to_node;
      r.length = (l.nodes[static_cast<std::size_t>(sl.to_node)].position -
                  l.nodes[static_cast<std::size_t>(sl.from_node)].position)
                     .norm();
    } else {
      r.from = sl.from;
      r.unit = (sl.to - sl.from).normalized();
      r.normal = perp(r.unit);
    }
    s.sliders.push_back(r);
  }
  return row;
}

// one row per input (a link's angle or a slider's position); returns the next free row
int add_input_rows(System& s, int row) {
  const Linkage& l = s.linkage;
  s.link_input.assign(l.links.size(), -1);
  for (std::size_t k = 0; k < l.inputs.size(); ++k) {
    const Input& in = l.inputs[k];
    s.row_ref.push_back({System::RowRef::Kind::kInput, static_cast<int>(k)});
    System::InputRow r;
    r.row = row++;
    r.input = static_cast<int>(k);
    r.angle = in.kind == Input::Kind::kAngle;
    if (r.angle) {
      s.link_input[static_cast<std::size_t>(in.link)] = static_cast<int>(k);
      r.p = l.links[static_cast<std::size_t>(in.link)].nodes[0];
      r.q = l.links[static_cast<std::size_t>(in.link)].nodes[1];
      r.length = s.elements[static_cast<std::size_t>(in.link)].length;
    } else {
      r.slider = in.slider;
    }
    s.inputs.push_back(r);
  }
  return row;
}

// the constant mass matrix (the elements' blocks at their moving nodes, point masses) and the
// links' constant loads (weights and applied forces at the centres of mass, moments)
void add_masses_and_loads(System& s) {
  const Linkage& l = s.linkage;
  s.M = MatrixXd::Zero(s.n, s.n);
  for (std::size_t k = 0; k < l.links.size(); ++k) {
    const int nodes[2] = {s.elements[k].p, s.elements[k].q};
    for (int a = 0; a < 2; ++a) {
      const int ca = s.coord[static_cast<std::size_t>(nodes[a])];
      if (ca < 0) continue;
      for (int b = 0; b < 2; ++b) {
        const int cb = s.coord[static_cast<std::size_t>(nodes[b])];
        if (cb < 0) continue;
        s.M.block<2, 2>(ca, cb) += s.element_M[k].block<2, 2>(2 * a, 2 * b);
      }
    }
  }
  s.node_mass.assign(l.nodes.size(), 0.0);
  for (const PointMass& pm : l.point_masses) {
    s.node_mass[static_cast<std::size_t>(pm.node)] += pm.mass;
    const int c = s.coord[static_cast<std::size_t>(pm.node)];
    s.M(c, c) += pm.mass;
    s.M(c + 1, c + 1) += pm.mass;
  }
  s.link_force.assign(l.links.size(), Vec2(0, 0));
  s.link_moment.assign(l.links.size(), 0.0);
  for (std::size_t k = 0; k < l.links.size(); ++k)
    s.link_force[k] = l.links[k].mass * l.loads.gravity;
  for (const LinkLoad& ld : l.loads.link_loads) {
    s.link_force[static_cast<std::size_t>(ld.link)] += ld.force;
    s.link_moment[static_cast<std::size_t>(ld.link)] += ld.moment;
  }
}

// the balance shafts' references: their link's direction, the gear pair's geometry
void add_shafts(System& s) {
  const Linkage& l = s.linkage;
  for (const BalanceShaft& b : l.shafts) {
    System::ShaftRef r;
    r.link = b.link;
    r.pivot = pivot_of(l, b.link);
    r.ratio = b.ratio;
    r.p = s.elements[static_cast<std::size_t>(b.link)].p;
    r.q = s.elements[static_cast<std::size_t>(b.link)].q;
    r.drawn = (l.nodes[static_cast<std::size_t>(r.q)].position -
               l.nodes[static_cast<std::size_t>(r.p)].position)
                  .normalized();
    r.J = b.inertia + b.mass * b.eccentricity.squaredNorm();
    const Vec2 d = b.at - l.nodes[static_cast<std::size_t>(r.pivot)].position;
    // a shaft within 1e-12 of the linkage's size of its link's pivot is coaxial with it
    double size = 0;
    for (const System::ElementRow& e : s.elements) size = std::max(size, e.length);
    r.mesh = b.ratio != 1 && d.norm() > 1e-12 * size;
    if (r.mesh) {
      r.normal = perp(d / d.norm());
      r.per_torque = (1.0 - b.ratio) / d.norm();
    }
    s.shafts.push_back(r);
  }
}

}  // namespace

ShaftMotion shaft_motion(const System& s, int k, const NodeVectors& x, double omega_link,
                         double alpha_link) {
  const System::ShaftRef& r = s.shafts[static_cast<std::size_t>(k)];
  const BalanceShaft& b = s.linkage.shafts[static_cast<std::size_t>(k)];
  const Vec2 d = at(x, r.q) - at(x, r.p);
  ShaftMotion m;
  m.r = shaft_centre(b, std::atan2(cross(r.drawn, d), r.drawn.dot(d)));
  m.omega = r.ratio * omega_link;
  m.alpha = r.ratio * alpha_link;
  m.a = m.alpha * perp(m.r) - m.omega * m.omega * m.r;
  m.torque = r.J * m.alpha - cross(m.r, b.mass * s.linkage.loads.gravity);
  return m;
}

double link_moment_at(const System& s, int k, const NodeVectors& x) {
  double moment = s.link_moment[static_cast<std::size_t>(k)];
  const Vec2& g = s.linkage.loads.gravity;
  if (g.isZero(0.0)) return moment;
  for (std::size_t j = 0; j < s.shafts.size(); ++j) {
    const BalanceShaft& b = s.linkage.shafts[j];
    if (b.link != k || b.mass == 0.0) continue;
    const ShaftMotion m = shaft_motion(s, static_cast<int>(j), x, 0.0, 0.0);
    moment += b.ratio * cross(m.r, b.mass * g);
  }
  return moment;
}

System::System(const Linkage& l) : linkage(l) {
  coord.assign(l.nodes.size(), -1);
  for (std::size_t i = 0; i < l.nodes.size(); ++i) {
    if (!l.nodes[i].ground) {
      coord[i] = n;
      n += 2;
      moving.push_back(static_cast<int>(i));
    } else {
      fixed.push_back(static_cast<int>(i));
    }
  }
  const std::size_t nodes = l.nodes.size();
  slot_of.assign(l.links.size() * nodes, -1);
  for (std::size_t k = 0; k < l.links.size(); ++k) {
    first_slot.push_back(slots);
    for (int node : l.links[k].nodes) slot_of[k * nodes + static_cast<std::size_t>(node)] = slots++;
  }
  first_slot.push_back(slots);
  for (int g : fixed) {
    ground_first.push_back(static_cast<int>(ground_slots.size()));
    for (std::size_t k = 0; k < l.links.size(); ++k) {
      const int slot = slot_of[k * nodes + static_cast<std::size_t>(g)];
      if (slot >= 0) ground_slots.push_back(slot);
    }
  }
  ground_first.push_back(static_cast<int>(ground_slots.size()));
  structural_rows = add_slider_rows(*this, add_link_rows(*this));
  rows = add_input_rows(*this, structural_rows);
  add_masses_and_loads(*this);
  add_shafts(*this);
  blocks = plan_blocks(*this);
}

void set_mass_parameters(System& s, const double* pi) {
  planar::set_mass_parameters(s.linkage, pi);
  for (std::size_t k = 0; k < s.linkage.links.size(); ++k) set_element_mass(s, static_cast<int>(k));
  add_masses_and_loads(s);
}

void nodes_from_q(const System& s, const VectorXd& q, NodeVectors& x) {
  x.resize(s.coord.size());
  for (int i : s.fixed) x[static_cast<std::size_t>(i)] = s.linkage.nodes[static_cast<std::size_t>(i)].position;
  const double* qv = q.data();
  for (int i : s.moving) {
    const int c = s.coord[static_cast<std::size_t>(i)];
    x[static_cast<std::size_t>(i)] = Vec2(qv[c], qv[c + 1]);
  }
}

void node_rates_from(const System& s, const VectorXd& qd, NodeVectors& v) {
  v.resize(s.coord.size());
  for (std::size_t i = 0; i < s.coord.size(); ++i) {
    const int c = s.coord[i];
    v[i] = c < 0 ? Vec2(0, 0) : Vec2(qd[c], qd[c + 1]);
  }
}

void q_from_nodes(const System& s, const NodeVectors& x, VectorXd& q) {
  q.resize(s.n);
  double* out = q.data();
  for (int i : s.moving) {
    const Vec2& node = at(x, i);
    const int c = s.coord[static_cast<std::size_t>(i)];
    out[c] = node.x();
    out[c + 1] = node.y();
  }
}

VectorXd q_from_nodes(const System& s, const NodeVectors& x) {
  VectorXd q;
  q_from_nodes(s, x, q);
  return q;
}

double input_angle(const System&, const System::InputRow& in, const NodeVectors& x, double near) {
  return continued_angle(at(x, in.q) - at(x, in.p), near);
}

double slide_position(const System&, const System::SliderRow& sl, const NodeVectors& x) {
  if (!sl.on_link) return sl.unit.dot(at(x, sl.node) - sl.from);
  const Vec2 a = at(x, sl.node) - at(x, sl.from_node), b = at(x, sl.to_node) - at(x, sl.from_node);
  return a.dot(b) / sl.length;
}

double slide_rate(const System&, const System::SliderRow& sl, const NodeVectors& x,
                  const NodeVectors& v) {
  if (!sl.on_link) return sl.unit.dot(at(v, sl.node));
  const Vec2 a = at(x, sl.node) - at(x, sl.from_node), b = at(x, sl.to_node) - at(x, sl.from_node);
  const Vec2 ad = at(v, sl.node) - at(v, sl.from_node),
             bd = at(v, sl.to_node) - at(v, sl.from_node);
  return (ad.dot(b) + a.dot(bd)) / sl.length;
}

void input_targets(const System& s, const std::vector<double>& inputs, std::vector<Vec2>& targets) {
  targets.resize(inputs.size());
  for (const System::InputRow& in : s.inputs) {
    const double z = inputs[static_cast<std::size_t>(in.input)];
    targets[static_cast<std::size_t>(in.input)] =
        in.angle ? Vec2(std::cos(z), std::sin(z)) : Vec2(z, 0.0);
  }
}

void constraint_values(const System& s, const NodeVectors& x, const std::vector<Vec2>& targets,
                       VectorXd& g, AngleRow angle_row) {
  g.resize(targets.empty() ? s.structural_rows : s.rows);
  for (std::size_t k = 0; k < s.elements.size(); ++k) {
    const System::ElementRow& e = s.elements[k];
    g[static_cast<Eigen::Index>(k)] =
        ((at(x, e.q) - at(x, e.p)).squaredNorm() - e.length_sq) / (2 * e.length);
  }
  for (const System::RigidRows& r : s.rigid) {
    g.segment<2>(r.row) = at(x, r.node) - r.weights.at_p * at(x, r.p) - r.weights.at_q * at(x, r.q);
  }
  for (const System::SliderRow& sl : s.sliders) {
    if (!sl.on_link) {
      g[sl.row] = sl.normal.dot(at(x, sl.node) - sl.from);
    } else {
      const Vec2 a = at(x, sl.node) - at(x, sl.from_node),
                 b = at(x, sl.to_node) - at(x, sl.from_node);
      g[sl.row] = cross(a, b) / sl.length;
    }
  }
  if (targets.empty()) return;
  for (const System::InputRow& in : s.inputs) {
    const Vec2& target = targets[static_cast<std::size_t>(in.input)];
    if (!in.angle) {
      g[in.row] = slide_position(s, s.sliders[static_cast<std::size_t>(in.slider)], x) - target.x();
    } else if (angle_row == AngleRow::kCross) {
      g[in.row] = cross(target, at(x, in.q) - at(x, in.p));
    } else {
      g[in.row] = in.length * angle_from(target, at(x, in.q) - at(x, in.p));
    }
  }
}

namespace {

// the gradient of a slider's guide row, or of a slide input on it: the sliding node's entry on
// the node, the guide nodes' entries on the guide's link
int slider_gradient(const System::SliderRow& sl, const NodeVectors& x, bool along, int link,
                    GradientEntry out[3]) {
  if (!sl.on_link) {
    out[0] = {sl.node, along ? sl.unit : sl.normal, -1};
    return 1;
  }
  const Vec2 a = at(x, sl.node) - at(x, sl.from_node), b = at(x, sl.to_node) - at(x, sl.from_node);
  if (along) {  // s = a·b / L
    out[0] = {sl.node, b / sl.length, -1};
    out[1] = {sl.to_node, a / sl.length, link};
    out[2] = {sl.from_node, -(a + b) / sl.length, link};
  } else {  // g = a × b / L
    out[0] = {sl.node, -perp(b) / sl.length, -1};
    out[1] = {sl.to_node, perp(a) / sl.length, link};
    out[2] = {sl.from_node, (perp(b) - perp(a)) / sl.length, link};
  }
  return 3;
}

}  // namespace

int row_gradient(const System& s, const NodeVectors& x, int row, GradientEntry out[3]) {
  const System::RowRef& ref = s.row_ref[static_cast<std::size_t>(row)];
  switch (ref.kind) {
    case System::RowRef::Kind::kElement: {
      const System::ElementRow& e = s.elements[static_cast<std::size_t>(ref.index)];
      const Vec2 d = (at(x, e.q) - at(x, e.p)) / e.length;
      out[0] = {e.q, d, ref.index};
      out[1] = {e.p, -d, ref.index};
      return 2;
    }
    case System::RowRef::Kind::kRigid: {
      const System::RigidRows& r = s.rigid[static_cast<std::size_t>(ref.index)];
      const int i = row - r.row;  // 0: x, 1: y
      out[0] = {r.node, Vec2::Unit(i), r.link};
      out[1] = {r.p, -r.weights.at_p.row(i).transpose(), r.link};
      out[2] = {r.q, -r.weights.at_q.row(i).transpose(), r.link};
      return 3;
    }
    case System::RowRef::Kind::kSlider: {
      const System::SliderRow& sl = s.sliders[static_cast<std::size_t>(ref.index)];
      return slider_gradient(sl, x, false,
                             s.linkage.sliders[static_cast<std::size_t>(ref.index)].link, out);
    }
    case System::RowRef::Kind::kInput: {
      const System::InputRow& in = s.inputs[static_cast<std::size_t>(ref.index)];
      if (in.angle) {
        const Vec2 grad = angle_input_gradient(in, x);
        const int link = s.linkage.inputs[static_cast<std::size_t>(in.input)].link;
        out[0] = {in.q, grad, link};
        out[1] = {in.p, -grad, link};
        return 2;
      }
      const System::SliderRow& sl = s.sliders[static_cast<std::size_t>(in.slider)];
      return slider_gradient(sl, x, true,
                             s.linkage.sliders[static_cast<std::size_t>(in.slider)].link, out);
    }
  }
  return 0;
}

void constraint_jacobian(const System& s, const NodeVectors& x, int rows, MatrixXd& G) {
  // Every call writes the same entries (a row's nodes are the linkage's, each once per row), and
  // nothing else writes G: the entries outside them are zero from the zeroing at a change of
  // shape, and each entry is assigned, not added to.
  if (G.rows() != rows || G.cols() != s.n) G.setZero(rows, s.n);
  double* g = G.data();
  const int* coord = s.coord.data();
  auto put = [g, coord, rows](int row, int node, const Vec2& d) {
    const int c = coord[node];
    if (c < 0) return;
    g[row + c * rows] = d.x();
    g[row + (c + 1) * rows] = d.y();
  };
  // the element rows (the first, one per link) written directly: row_gradient()'s
  // element case without its dispatch
  const int elements = std::min(rows, static_cast<int>(s.elements.size()));
  for (int row = 0; row < elements; ++row) {
    const System::ElementRow& e = s.elements[static_cast<std::size_t>(row)];
    const Vec2 d = (at(x, e.q) - at(x, e.p)) / e.length;
    put(row, e.q, d);
    put(row, e.p, -d);
  }
  GradientEntry entries[3];
  for (int row = elements; row < rows; ++row) {
    const System::RowRef& ref = s.row_ref[static_cast<std::size_t>(row)];
    if (ref.kind == System::RowRef::Kind::kInput) {  // an angle input's row, without dispatch
      const System::InputRow& in = s.inputs[static_cast<std::size_t>(ref.index)];
      if (in.angle) {
        const Vec2 grad = angle_input_gradient(in, x);
        put(row, in.q, grad);
        put(row, in.p, -grad);
        continue;
      }
    }
    const int count = row_gradient(s, x, row, entries);
    for (int k = 0; k < count; ++k) put(row, entries[k].node, entries[k].grad);
  }
}

void constraint_bias(const System& s, const NodeVectors& x, const NodeVectors& v, int rows,
                     VectorXd& gamma) {
  gamma.setZero(rows);  // the rigid rows and frame guides are linear: no curvature
  for (std::size_t k = 0; k < s.elements.size(); ++k) {
    const System::ElementRow& e = s.elements[k];
    gamma[static_cast<Eigen::Index>(k)] = (at(v, e.q) - at(v, e.p)).squaredNorm() / e.length;
  }
  for (const System::SliderRow& sl : s.sliders) {
    if (!sl.on_link) continue;
    const Vec2 ad = at(v, sl.node) - at(v, sl.from_node),
               bd = at(v, sl.to_node) - at(v, sl.from_node);
    gamma[sl.row] = 2 * cross(ad, bd) / sl.length;
  }
  if (rows <= s.structural_rows) return;
  for (const System::InputRow& in : s.inputs) {
    if (in.angle) {
      const Vec2 d = at(x, in.q) - at(x, in.p), dd = at(v, in.q) - at(v, in.p);
      const double n2 = d.squaredNorm();
      gamma[in.row] = -2 * in.length * d.dot(dd) * perp(d).dot(dd) / (n2 * n2);
    } else {
      const System::SliderRow& sl = s.sliders[static_cast<std::size_t>(in.slider)];
      if (!sl.on_link) continue;
      const Vec2 ad = at(v, sl.node) - at(v, sl.from_node),
                 bd = at(v, sl.to_node) - at(v, sl.from_node);
      gamma[in.row] = 2 * ad.dot(bd) / sl.length;
    }
  }
}

SpringState spring_state(const System& s, int k, const NodeVectors& x, const NodeVectors& v) {
  const Spring& sp = s.linkage.springs[static_cast<std::size_t>(k)];
  SpringState st;
  const Vec2 d = at(x, sp.b) - at(x, sp.a);
  st.length = d.norm();
  st.unit = d / st.length;
  st.rate = st.unit.dot(at(v, sp.b) - at(v, sp.a));
  st.tension = sp.stiffness * (st.length - sp.free_length) + sp.damping * st.rate;
  return st;
}

void applied_forces(const System& s, const NodeVectors& x, const NodeVectors& v,
                    const std::vector<double>* efforts, VectorXd& F, bool link_loads) {
  F.setZero(s.n);
  const Linkage& l = s.linkage;
  const Vec2& g = l.loads.gravity;
  // weights at the centres of mass, and the links' loads (eq. 46)
  for (std::size_t k = 0; link_loads && k < l.links.size(); ++k) {
    const double moment =
        s.shafts.empty() ? s.link_moment[k] : link_moment_at(s, static_cast<int>(k), x);
    if (s.link_force[k].isZero(0.0) && moment == 0.0) continue;
    const System::ElementRow& e = s.elements[k];
    const Vec4 f =
        element_nodal_forces(s.com_weights[k], s.link_force[k], moment, at(x, e.p), at(x, e.q));
    add_force(s, F, e.p, f.segment<2>(0));
    add_force(s, F, e.q, f.segment<2>(2));
  }
  for (const NodeForce& nf : l.loads.node_forces) add_force(s, F, nf.node, nf.force);
  for (const PointMass& pm : l.point_masses) add_force(s, F, pm.node, pm.mass * g);
  for (std::size_t k = 0; k < l.springs.size(); ++k) {
    const SpringState st = spring_state(s, static_cast<int>(k), x, v);
    add_force(s, F, l.springs[k].a, st.tension * st.unit);
    add_force(s, F, l.springs[k].b, -st.tension * st.unit);
  }
  if (!efforts) return;
  GradientEntry entries[3];
  for (const System::InputRow& in : s.inputs) {
    const double e = (*efforts)[static_cast<std::size_t>(in.input)];
    if (e == 0.0) continue;
    // the row's gradient is scaled by the element length for an angle (λ l is the torque)
    const double scale = in.angle ? e / in.length : e;
    const int count = row_gradient(s, x, in.row, entries);
    for (int k = 0; k < count; ++k) add_force(s, F, entries[k].node, scale * entries[k].grad);
  }
}

}  // namespace bd::core::planar::detail
