// From a complete State (q, q', q'', multipliers) to the public Sample: joint forces from the
// multipliers (conventions in model.hpp), the forces on the frame, energies and powers.
#include <cmath>
#include <variant>

#include "tests/reference/planar/solve.hpp"

namespace bd::referee::detail {

namespace {

// A force `f` at point `at` and a pure torque on `body` (kGround: on the frame).
struct Wrench {
  int body = kGround;
  Vec2 f{0, 0}, at{0, 0};
  double torque = 0;
};

Vec2 line_direction(const VectorXd& q, const LineRow& l) {
  return rotate(l.line_body == kGround ? 0.0 : q[3 * l.line_body + 2], l.u0);
}

// The joint and drive forces of the sample (pins, sliders, gears, input efforts) as wrenches,
// and their per-joint values stored in the sample.
void joint_forces(const Model& model, const State& s, Sample& out, std::vector<Wrench>& w) {
  const VectorXd& q = s.q;
  Index r = 0;
  for (const auto& [a, b] : model.pins) {
    const Vec2 f = s.lambda.segment<2>(r), at = position(q, b);
    r += 2;
    out.pin_forces.push_back(f);
    w.push_back({b.body, f, at, 0});
    w.push_back({a.body, -f, at, 0});
  }
  for (const auto& l : model.lines) {
    const Vec2 f = s.lambda[r++] * perp(line_direction(q, l)), at = position(q, l.p);
    out.slider_forces.push_back(f);
    out.slider_points.push_back(at);
    w.push_back({l.p.body, f, at, 0});
    w.push_back({l.line_body, -f, at, 0});
  }
  for (const auto& g : model.gears) {
    const Vec2 f_on_a = s.lambda[r++] * g.t;
    out.gear_forces.push_back({-f_on_a, g.pitch});
    w.push_back({g.a, f_on_a, g.pitch, 0});
    w.push_back({g.b, -f_on_a, g.pitch, 0});
  }
  for (const auto& in : model.inputs) {
    const double effort = s.lambda[r++];
    out.input_efforts.push_back(effort);
    if (in.angle) {
      w.push_back({in.body, {0, 0}, {0, 0}, effort});
      w.push_back({kGround, {0, 0}, {0, 0}, -effort});
    } else {
      const LineRow& l = model.lines[in.slider];
      const Vec2 f = effort * line_direction(q, l), at = position(q, l.p);
      w.push_back({l.p.body, f, at, 0});
      w.push_back({l.line_body, -f, at, 0});
    }
  }
}

void body_quantities(const Model& model, const Mechanism& mech, const State& s, Sample& out) {
  for (int i = 0; i < model.nb; ++i) {
    BodyState b;
    b.com = s.q.segment<2>(3 * i);
    b.velocity = s.qd.segment<2>(3 * i);
    b.acceleration = s.qdd.segment<2>(3 * i);
    b.angle = s.q[3 * i + 2];
    b.omega = s.qd[3 * i + 2];
    b.alpha = s.qdd[3 * i + 2];
    const double m = model.mass[i], J = model.inertia[i];
    out.inertial_force -= m * b.acceleration;
    out.inertial_moment -= m * cross(b.com, b.acceleration) + J * b.alpha;
    out.momentum += m * b.velocity;
    out.angular_momentum += m * cross(b.com, b.velocity) + J * b.omega;
    out.kinetic_energy += 0.5 * (m * b.velocity.squaredNorm() + J * b.omega * b.omega);
    out.gravity_energy -= m * mech.gravity.dot(b.com);
    out.gravity_power += m * mech.gravity.dot(b.velocity);
    out.bodies.push_back(b);
  }
}

void load_quantities(const Model& model, const Mechanism& mech, const State& s, Sample& out,
                     std::vector<Wrench>& w) {
  for (std::size_t k = 0; k < mech.forces.size(); ++k) {
    out.applied_power += mech.forces[k].force(s.t).dot(velocity(s.q, s.qd, model.force_points[k]));
  }
  for (const auto& m : mech.moments) out.applied_power += m.moment(s.t) * s.qd[3 * m.body + 2];
  for (std::size_t k = 0; k < mech.springs.size(); ++k) {
    const SpringState st = spring_state(model, mech, k, s.q, s.qd);
    const Spring& sp = mech.springs[k];
    out.spring_lengths.push_back(st.length);
    out.spring_tensions.push_back(st.tension);
    out.spring_energy += 0.5 * sp.stiffness * std::pow(st.length - sp.free_length, 2);
    out.damper_power += sp.damping * st.rate * st.rate;
    out.spring_power -= st.tension * st.rate;
    const SpringRow& row = model.springs[k];
    w.push_back({row.a.body, st.tension * st.e, position(s.q, row.a), 0});
    w.push_back({row.b.body, -st.tension * st.e, position(s.q, row.b), 0});
  }
}

}  // namespace

Sample make_sample(const Model& model, const Mechanism& mech, const State& s) {
  Sample out;
  out.t = s.t;
  std::vector<Wrench> wrenches;
  joint_forces(model, s, out, wrenches);
  body_quantities(model, mech, s, out);
  load_quantities(model, mech, s, out, wrenches);
  for (const Wrench& w : wrenches) {
    if (w.body != kGround) continue;
    out.shaking_force += w.f;
    out.shaking_moment += cross(w.at, w.f) + w.torque;
  }
  const MatrixXd J_in = jacobian(model, s.q).bottomRows(model.ndof());
  const VectorXd rates = J_in * s.qd;
  const VectorXd accels = J_in * s.qdd - gamma(model, s.q, s.qd).tail(model.ndof());
  const VectorXd values = input_values(model, s.q);
  for (Index k = 0; k < model.ndof(); ++k) {
    out.input_values.push_back(values[k]);
    out.input_rates.push_back(rates[k]);
    out.input_accelerations.push_back(accels[k]);
    out.input_power += out.input_efforts[k] * rates[k];
  }
  out.input_work = s.input_work;
  out.damper_work = s.damper_work;
  out.applied_work = s.applied_work;
  return out;
}

}  // namespace bd::referee::detail
