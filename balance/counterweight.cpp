#include "balance/counterweight.hpp"

#include <cmath>
#include <complex>
#include <cstdio>
#include <numbers>

#include "balance/conditions.hpp"
#include "core/input_error.hpp"
#include "core/number_text.hpp"

namespace bd::balance {

namespace {

// Centre-of-mass offsets s̄ = e + i f and mass moments m s̄ in link axes, in the paper's complex
// notation (eq. 57); what leaves this file (Counterweight::position) is a Vec2.
using Complex = std::complex<double>;

// nothing when v is finite and > 0, else "<field> must be > 0 <unit>, got <v>"
Problem positive(const char* field, const char* unit, double v) {
  if (std::isfinite(v) && v > 0) return std::nullopt;
  return FieldError{field, -1, std::string("must be > 0 ") + unit + ", got " + text::exact(v)};
}

}  // namespace

Problem CounterweightSpec::validate() const {
  const int given = (mass ? 1 : 0) + (distance ? 1 : 0) + (radius ? 1 : 0);
  if (given > 1) {
    std::string what;
    auto add = [&what](const std::string& s) { what += (what.empty() ? "" : " and ") + s; };
    if (mass) add("mass = " + text::exact(*mass) + " kg");
    if (distance) add("distance = " + text::exact(*distance) + " m");
    if (radius) add("radius = " + text::exact(*radius) + " m");
    return FieldError{
        "", -1,
        "give at most one of mass, distance and radius (the others are solved), got " + what};
  }
  if (shape != CounterweightShape::kPoint && shape != CounterweightShape::kDisc) {
    return FieldError{"shape", -1, "must be point or disc"};
  }
  if (radius && shape != CounterweightShape::kDisc) {
    return FieldError{"radius", -1, "is given for a point counterweight; radius needs shape disc"};
  }
  if (mass) {
    if (Problem p = positive("mass", "kg", *mass)) return p;
  }
  if (distance) {
    if (Problem p = positive("distance", "m", *distance)) return p;
  }
  if (radius) {
    if (Problem p = positive("radius", "m", *radius)) return p;
  }
  if (shape == CounterweightShape::kDisc) {
    if (Problem p = positive("thickness", "m", thickness)) return p;
    if (Problem p = positive("density", "kg/m^3", density)) return p;
  }
  return std::nullopt;
}

Counterweight realise(const CounterweightSpec& spec, const Vec2& mass_moment,
                      double default_distance) {
  const Complex moment(mass_moment.x(), mass_moment.y());
  const double needed = std::abs(moment);  // mc·distance [kg m]
  const Complex direction = moment / needed;
  const bool disc = spec.shape == CounterweightShape::kDisc;
  const double area_density = spec.density * std::numbers::pi * spec.thickness;  // m / r² [kg/m²]
  Counterweight cw;
  if (spec.mass) {
    cw.mass = *spec.mass;
    cw.distance = needed / cw.mass;
  } else if (spec.radius) {
    cw.mass = area_density * *spec.radius * *spec.radius;
    cw.distance = needed / cw.mass;
  } else {
    cw.distance = spec.distance ? *spec.distance : default_distance;
    cw.mass = needed / cw.distance;
  }
  const Complex position = cw.distance * direction;
  cw.position = Vec2(position.real(), position.imag());
  if (disc) {
    cw.radius = spec.radius ? *spec.radius : std::sqrt(cw.mass / area_density);
    cw.thickness = spec.thickness;
    cw.inertia = 0.5 * cw.mass * cw.radius * cw.radius;
  }
  return cw;
}

core::Link merged(const core::Link& link, const Counterweight& counterweight,
                  bool from_second_joint) {
  const double m = link.mass, mc = counterweight.mass, M = m + mc;
  // both centres of mass in link axes from the first joint
  const Vec2 s(link.e, link.f);
  const Vec2 r = from_second_joint ? Vec2(Vec2(link.length, 0) + counterweight.position)
                                   : counterweight.position;
  const Vec2 c = (m * s + mc * r) / M;
  core::Link out = link;
  out.mass = M;
  out.e = c.x();
  out.f = c.y();
  // parallel axes: each body's own inertia plus its mass times its squared distance from c
  out.inertia =
      link.inertia + m * (s - c).squaredNorm() + counterweight.inertia + mc * (r - c).squaredNorm();
  return out;
}

ForceBalancedDesign force_balance(const core::FourBar& model, const CounterweightSpec& crank,
                                  const CounterweightSpec& rocker) {
  // the field names the spec, its message the spec's own field
  if (const Problem p = crank.validate()) {
    throw InputError(FieldError{"crank counterweight", -1, ": " + p->text()});
  }
  if (const Problem p = rocker.validate()) {
    throw InputError(FieldError{"rocker counterweight", -1, ": " + p->text()});
  }
  const core::FourBar checked = core::make_fourbar(model);
  const core::Link &l1 = checked.crank, &l2 = checked.coupler, &l3 = checked.rocker;
  const Complex s1(l1.e, l1.f), s2(l2.e, l2.f), s3(l3.e, l3.f);

  // a side whose residual is round-off already keeps its link as it is
  const BalanceReport before = check_balance(checked);
  ForceBalancedDesign out;
  out.model = checked;

  // crank, about A0: m1' s̄1' = m1 s̄1 + mc p must equal -m2 (1 - s̄2/l2) l1 (eq. 57, first)
  if (!before.force[0].holds) {
    const Complex target = -l2.mass * (1.0 - s2 / l2.length) * l1.length;
    const Complex moment = target - l1.mass * s1;
    const Counterweight cw = realise(crank, Vec2(moment.real(), moment.imag()), l1.length);
    out.model.crank = merged(l1, cw, false);
    out.crank = cw;
  }
  // rocker, about A3: its mass moment m3 (s̄3 - l3) + mc q must equal m2 s̄2 l3 / l2
  // (eq. 57, second, times l3)
  if (!before.force[1].holds) {
    const Complex target = l2.mass * s2 * l3.length / l2.length;
    const Complex moment = target - l3.mass * (s3 - l3.length);
    const Counterweight cw = realise(rocker, Vec2(moment.real(), moment.imag()), l3.length);
    out.model.rocker = merged(l3, cw, true);
    out.rocker = cw;
  }
  for (const std::optional<Counterweight>& cw : {out.crank, out.rocker}) {
    if (!cw) continue;
    out.added_mass += cw->mass;
    out.added_inertia += cw->inertia + cw->mass * cw->distance * cw->distance;
  }
  out.model = core::make_fourbar(out.model);
  return out;
}

}  // namespace bd::balance
