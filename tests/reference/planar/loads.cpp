// Mass matrix and applied generalized forces (gravity, point forces, moments, spring-dampers).
// A force f at a point P of body i (arm rho = P - r_i) contributes f to the force rows and
// rho x f to the moment row of body i: the virtual work f . dP with dP = dr_i + dphi_i perp(rho).
#include <stdexcept>

#include "tests/reference/planar/model.hpp"

namespace bd::referee::detail {

VecX mass_diagonal(const Model& model) {
  VecX m(model.n());
  for (int i = 0; i < model.nb; ++i)
    m.segment<3>(3 * i) << model.mass[i], model.mass[i], model.inertia[i];
  return m;
}

void add_point_force(VecX& Q, const VecX& q, const Attach& p, const V2& f) {
  if (p.body == kGround) return;
  Q.segment<2>(3 * p.body) += f;
  Q[3 * p.body + 2] += cross(arm(q, p), f);
}

SpringState spring_state(const Model& model, const Mechanism& mech, std::size_t k, const VecX& q,
                         const VecX& qd) {
  const SpringRow& row = model.springs[k];
  const Spring& s = mech.springs[k];
  const V2 d = position(q, row.b) - position(q, row.a);
  SpringState st;
  st.length = d.norm();
  if (!(st.length > 1e-12 * model.length))
    throw std::domain_error("bd::referee: spring " + std::to_string(k) + " has zero length");
  st.e = d / st.length;
  st.rate = st.e.dot(velocity(q, qd, row.b) - velocity(q, qd, row.a));
  st.tension = s.stiffness * (st.length - s.free_length) + s.damping * st.rate;
  return st;
}

VecX applied_forces(const Model& model, const Mechanism& mech, Real t, const VecX& q,
                    const VecX& qd) {
  VecX Q = VecX::Zero(model.n());
  for (int i = 0; i < model.nb; ++i) Q.segment<2>(3 * i) += model.mass[i] * ext(mech.gravity);
  for (std::size_t k = 0; k < mech.forces.size(); ++k)
    add_point_force(Q, q, model.force_points[k], force_at(mech.forces[k], t));
  for (const auto& m : mech.moments) Q[3 * m.body + 2] += moment_at(m, t);
  for (std::size_t k = 0; k < mech.springs.size(); ++k) {
    const SpringState st = spring_state(model, mech, k, q, qd);
    // tension pulls b towards a and a towards b
    add_point_force(Q, q, model.springs[k].b, -st.tension * st.e);
    add_point_force(Q, q, model.springs[k].a, st.tension * st.e);
  }
  return Q;
}

}  // namespace bd::referee::detail
