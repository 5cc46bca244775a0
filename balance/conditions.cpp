#include "balance/conditions.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/number_text.hpp"

namespace bd::balance {

namespace {

// s̄_k / l_k
ComplexCoefficient relative_com(const core::Link& l) {
  return ComplexCoefficient(l.e, l.f) / l.length;
}

Condition make_condition(std::string name, std::string meaning, double residual, double scale,
                         std::string unit, double relative_tolerance) {
  Condition c;
  c.name = std::move(name);
  c.meaning = std::move(meaning);
  c.residual = residual;
  c.scale = scale;
  c.unit = std::move(unit);
  c.holds = residual <= relative_tolerance * scale;
  return c;
}

bool all_hold(const std::vector<Condition>& conditions) {
  return std::all_of(conditions.begin(), conditions.end(),
                     [](const Condition& c) { return c.holds; });
}

}  // namespace

ForceBalanceResiduals force_balance_residuals(const core::FourBar& model) {
  // eq. 57: the complex equivalent masses left at A1 and A2
  const core::EquivalentMasses e1 = core::equivalent_masses(model.crank);
  const core::EquivalentMasses e2 = core::equivalent_masses(model.coupler);
  const core::EquivalentMasses e3 = core::equivalent_masses(model.rocker);
  return {e1.mq + e2.mp, e2.mq + e3.mp};
}

ForceBalanceScales force_balance_scales(const core::FourBar& model) {
  // the larger of the masses involved and the sum of the terms' magnitudes, which bounds the
  // round-off of the sum
  const double m1 = model.crank.mass, m2 = model.coupler.mass, m3 = model.rocker.mass;
  const ComplexCoefficient s1 = relative_com(model.crank), s2 = relative_com(model.coupler),
                           s3 = relative_com(model.rocker);
  return {std::max(m1 + m2, std::abs(m1 * s1) + std::abs(m2 * (1.0 - s2))),
          std::max(m2 + m3, std::abs(m2 * s2) + std::abs(m3 * (1.0 - s3)))};
}

ReducedInertias reduced_inertias(const core::FourBar& model) {
  const core::Link &l1 = model.crank, &l2 = model.coupler, &l3 = model.rocker;
  const double ma = l2.mass * (1.0 - l2.e / l2.length);  // coupler point mass at A1
  const double mb = l2.mass * l2.e / l2.length;          // coupler point mass at A2
  // about A0: the crank and the coupler's mass at A1
  const double crank =
      l1.inertia + l1.mass * (l1.e * l1.e + l1.f * l1.f) + ma * l1.length * l1.length;
  // about A3: the rocker (centre of mass at s̄3 - l3 from A3) and the coupler's mass at A2
  const double de3 = l3.e - l3.length;
  const double rocker =
      l3.inertia + l3.mass * (de3 * de3 + l3.f * l3.f) + mb * l3.length * l3.length;
  return {crank, rocker};
}

bool BalanceReport::force_balanced() const { return !force.empty() && all_hold(force); }

bool BalanceReport::moment_balanced() const {
  return force_balanced() && !moment.empty() && all_hold(moment);
}

std::string BalanceReport::text() const {
  std::string out;
  auto add = [&out](const Condition& c) {
    out += "  " + c.name + ": " + (c.holds ? "holds" : "FAILS") + ", residual " +
           text::digits(c.residual, 3) + " " + c.unit + " of " + text::digits(c.scale, 3) + " " +
           c.unit + " (" + c.meaning + ")\n";
  };
  out += std::string("shaking force: ") + (force_balanced() ? "balanced" : "not balanced") + "\n";
  for (const Condition& c : force) add(c);
  out += std::string("shaking moment: ") + (moment_balanced() ? "balanced" : "not balanced") + "\n";
  for (const Condition& c : moment) add(c);
  return out;
}

BalanceReport check_balance(const core::FourBar& model, double relative_tolerance) {
  BalanceReport r;
  const ForceBalanceResiduals f = force_balance_residuals(model);
  const ForceBalanceScales fs = force_balance_scales(model);
  r.force.push_back(make_condition("force.crank",
                                   "eq. 57: m1 s1/l1 + m2 (1 - s2/l2) = 0, no mass left at A1",
                                   std::abs(f.crank), fs.crank, "kg", relative_tolerance));
  r.force.push_back(make_condition("force.rocker",
                                   "eq. 57: m2 s2/l2 + m3 (1 - s3/l3) = 0, no mass left at A2",
                                   std::abs(f.rocker), fs.rocker, "kg", relative_tolerance));

  // Berkof's coupler: dynamically two point masses at A1 and A2
  const core::Link& c = model.coupler;
  const double target_I2 = c.mass * c.e * (c.length - c.e);
  r.moment.push_back(make_condition("coupler.f2", "f2 = 0: the coupler's centre of mass on A1A2",
                                    std::abs(c.f), c.length, "m", relative_tolerance));
  r.moment.push_back(make_condition(
      "coupler.inertia", "I2 = m2 e2 (l2 - e2): the coupler is two point masses at A1 and A2",
      std::abs(c.inertia - target_I2), c.inertia + 0.25 * c.mass * c.length * c.length, "kg m²",
      relative_tolerance));

  // counter-rotations equal to the reduced inertias; scale: the sum of the terms' magnitudes
  const ReducedInertias K = reduced_inertias(model);
  const core::Link &l1 = model.crank, &l3 = model.rocker;
  const double ma = c.mass * (1.0 - c.e / c.length), mb = c.mass * c.e / c.length;
  const double de3 = l3.e - l3.length;
  const double scale1 =
      l1.inertia + l1.mass * (l1.e * l1.e + l1.f * l1.f) + std::abs(ma) * l1.length * l1.length;
  const double scale3 =
      l3.inertia + l3.mass * (de3 * de3 + l3.f * l3.f) + std::abs(mb) * l3.length * l3.length;
  const double J1 = model.counter_rotations.crank.inertia;
  const double J3 = model.counter_rotations.rocker.inertia;
  r.moment.push_back(make_condition(
      "counter_rotation.crank",
      "J1 = I1 + m1 |s1|^2 + m2 (1 - e2/l2) l1^2 = " + text::digits(K.crank, 3) + " kg m²",
      std::abs(J1 - K.crank), std::max(scale1, J1), "kg m²", relative_tolerance));
  r.moment.push_back(make_condition(
      "counter_rotation.rocker",
      "J3 = I3 + m3 |l3 - s3|^2 + m2 (e2/l2) l3^2 = " + text::digits(K.rocker, 3) + " kg m²",
      std::abs(J3 - K.rocker), std::max(scale3, J3), "kg m²", relative_tolerance));
  return r;
}

}  // namespace bd::balance
