// From a complete State (q, q', q'', multipliers) to the public Sample: joint forces from the
// multipliers (conventions in model.hpp), the forces on the frame, energies and powers. Sums are
// formed in long double and rounded to double once.
#include <cmath>
#include <variant>

#include "tests/reference/planar/solve.hpp"

namespace bd::referee::detail {

namespace {

inline double d(Real x) { return static_cast<double>(x); }

// A force `f` at point `at` and a pure torque on `body` (kGround: on the frame).
struct Wrench {
  int body = kGround;
  V2 f{0, 0}, at{0, 0};
  Real torque = 0;
};

V2 line_direction(const VecX& q, const LineRow& l) {
  return rotate(l.line_body == kGround ? Real(0) : q[3 * l.line_body + 2], l.u0);
}

// The joint and drive forces (pins, sliders, gears, input efforts) as wrenches, and their
// per-joint values stored in the sample.
void joint_forces(const Model& model, const State& s, Sample& out, std::vector<Wrench>& w) {
  const VecX& q = s.q;
  Index r = 0;
  for (const auto& [a, b] : model.pins) {
    const V2 f = s.lambda.segment<2>(r), at = position(q, b);
    r += 2;
    out.pin_forces.push_back(dbl(f));
    w.push_back({b.body, f, at, 0});
    w.push_back({a.body, -f, at, 0});
  }
  for (const auto& l : model.lines) {
    const V2 f = s.lambda[r++] * perp(line_direction(q, l)), at = position(q, l.p);
    out.slider_forces.push_back(dbl(f));
    out.slider_points.push_back(dbl(at));
    w.push_back({l.p.body, f, at, 0});
    w.push_back({l.line_body, -f, at, 0});
  }
  for (const auto& g : model.gears) {
    const V2 f_on_a = s.lambda[r++] * g.t;
    out.gear_forces.push_back({dbl(-f_on_a), dbl(g.pitch)});
    w.push_back({g.a, f_on_a, g.pitch, 0});
    w.push_back({g.b, -f_on_a, g.pitch, 0});
  }
  for (const auto& in : model.inputs) {
    const Real effort = s.lambda[r++];
    out.input_efforts.push_back(d(effort));
    if (in.angle) {
      w.push_back({in.body, {0, 0}, {0, 0}, effort});
      w.push_back({kGround, {0, 0}, {0, 0}, -effort});
    } else {
      const LineRow& l = model.lines[in.slider];
      const V2 f = effort * line_direction(q, l), at = position(q, l.p);
      w.push_back({l.p.body, f, at, 0});
      w.push_back({l.line_body, -f, at, 0});
    }
  }
}

void body_quantities(const Model& model, const Mechanism& mech, const State& s, Sample& out) {
  V2 inertial_force{0, 0}, momentum{0, 0};
  Real inertial_moment = 0, angular_momentum = 0, kinetic = 0, gravity = 0, gravity_power = 0;
  const V2 g = ext(mech.gravity);
  for (int i = 0; i < model.nb; ++i) {
    const V2 r = s.q.segment<2>(3 * i), v = s.qd.segment<2>(3 * i), a = s.qdd.segment<2>(3 * i);
    const Real w = s.qd[3 * i + 2], al = s.qdd[3 * i + 2];
    const Real m = model.mass[i], J = model.inertia[i];
    inertial_force -= m * a;
    inertial_moment -= m * cross(r, a) + J * al;
    momentum += m * v;
    angular_momentum += m * cross(r, v) + J * w;
    kinetic += (m * v.squaredNorm() + J * w * w) / 2;
    gravity -= m * g.dot(r);
    gravity_power += m * g.dot(v);
    out.bodies.push_back({dbl(r), dbl(v), dbl(a), d(s.q[3 * i + 2]), d(w), d(al)});
  }
  out.inertial_force = dbl(inertial_force);
  out.inertial_moment = d(inertial_moment);
  out.momentum = dbl(momentum);
  out.angular_momentum = d(angular_momentum);
  out.kinetic_energy = d(kinetic);
  out.gravity_energy = d(gravity);
  out.gravity_power = d(gravity_power);
}

void load_quantities(const Model& model, const Mechanism& mech, const State& s, Sample& out,
                     std::vector<Wrench>& w) {
  Real applied = 0, spring_energy = 0, damper = 0, spring_power = 0;
  for (std::size_t k = 0; k < mech.forces.size(); ++k)
    applied += force_at(mech.forces[k], s.t).dot(velocity(s.q, s.qd, model.force_points[k]));
  for (const auto& m : mech.moments) applied += moment_at(m, s.t) * s.qd[3 * m.body + 2];
  for (std::size_t k = 0; k < mech.springs.size(); ++k) {
    const SpringState st = spring_state(model, mech, k, s.q, s.qd);
    const Spring& sp = mech.springs[k];
    out.spring_lengths.push_back(d(st.length));
    out.spring_tensions.push_back(d(st.tension));
    const Real stretch = st.length - sp.free_length;
    spring_energy += sp.stiffness * stretch * stretch / 2;
    damper += sp.damping * st.rate * st.rate;
    spring_power -= st.tension * st.rate;
    const SpringRow& row = model.springs[k];
    w.push_back({row.a.body, st.tension * st.e, position(s.q, row.a), 0});
    w.push_back({row.b.body, -st.tension * st.e, position(s.q, row.b), 0});
  }
  out.applied_power = d(applied);
  out.spring_energy = d(spring_energy);
  out.damper_power = d(damper);
  out.spring_power = d(spring_power);
}

void input_quantities(const Model& model, const State& s, Sample& out) {
  const MatX J_in = jacobian(model, s.q).bottomRows(model.ndof());
  const VecX rates = J_in * s.qd;
  const VecX accels = J_in * s.qdd - gamma(model, s.q, s.qd).tail(model.ndof());
  const VecX values = input_values(model, s.q);
  Real power = 0;
  for (Index k = 0; k < model.ndof(); ++k) {
    out.input_values.push_back(d(values[k]));
    out.input_rates.push_back(d(rates[k]));
    out.input_accelerations.push_back(d(accels[k]));
    power += s.lambda[model.input_row(k)] * rates[k];
  }
  out.input_power = d(power);
}

}  // namespace

Sample make_sample(const Model& model, const Mechanism& mech, const State& s) {
  Sample out;
  out.t = d(s.t);
  std::vector<Wrench> wrenches;
  joint_forces(model, s, out, wrenches);
  body_quantities(model, mech, s, out);
  load_quantities(model, mech, s, out, wrenches);
  input_quantities(model, s, out);
  V2 force{0, 0};
  Real moment = 0;
  for (const Wrench& w : wrenches) {
    if (w.body != kGround) continue;
    force += w.f;
    moment += cross(w.at, w.f) + w.torque;
  }
  out.shaking_force = dbl(force);
  out.shaking_moment = d(moment);
  out.input_work = d(s.input_work);
  out.damper_work = d(s.damper_work);
  out.applied_work = d(s.applied_work);
  return out;
}

}  // namespace bd::referee::detail
