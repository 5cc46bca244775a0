#include "core/fourbar/model.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdio>

#include "core/input_error.hpp"
#include "core/number_text.hpp"

namespace bd::core {

double Link::s() const { return std::hypot(e, f); }
double Link::sigma() const { return std::atan2(f, e); }

Link link_from_polar(double length, double mass, double s, double sigma, double inertia) {
  return {length, mass, s * std::cos(sigma), s * std::sin(sigma), inertia};
}

const Link& link(const FourBar& model, int k) {
  assert(k >= 1 && k <= 3);
  return k == 1 ? model.crank : (k == 2 ? model.coupler : model.rocker);
}

const LinkLoad& link_load(const FourBar& model, int k) {
  assert(k >= 1 && k <= 3);
  return k == 1 ? model.loads.crank : (k == 2 ? model.loads.coupler : model.loads.rocker);
}

const char* link_name(int k) {
  static constexpr std::array<const char*, 3> kNames = {"crank", "coupler", "rocker"};
  assert(k >= 1 && k <= 3);
  return kNames[static_cast<std::size_t>(k - 1)];
}

bool has_counter_rotations(const FourBar& model) {
  return model.counter_rotations.crank.inertia > 0 || model.counter_rotations.rocker.inertia > 0;
}

double total_mass(const FourBar& model) {
  return model.crank.mass + model.coupler.mass + model.rocker.mass;
}

namespace {

// throws "<what> must be <expected> <unit>, got <value>" unless ok
void require(bool ok, const std::string& what, const char* expected, const char* unit,
             double value) {
  if (!ok) {
    throw InputError(what + " must be " + expected + (unit[0] ? " " : "") + unit + ", got " +
                     text::exact(value));
  }
}

void check_finite(const std::string& what, const char* unit, double value) {
  require(std::isfinite(value), what, "finite", unit, value);
}

}  // namespace

FourBar make_fourbar(const FourBar& candidate) {
  const FourBar& m = candidate;
  require(std::isfinite(m.frame_length) && m.frame_length > 0, "frame", "> 0", "m", m.frame_length);
  for (int k = 1; k <= 3; ++k) {
    const Link& l = link(m, k);
    const std::string name = link_name(k);
    require(std::isfinite(l.length) && l.length > 0, name + ".length", "> 0", "m", l.length);
    require(std::isfinite(l.mass) && l.mass > 0, name + ".mass", "> 0", "kg", l.mass);
    check_finite(name + ".e", "m", l.e);
    check_finite(name + ".f", "m", l.f);
    require(std::isfinite(l.inertia) && l.inertia >= 0, name + ".inertia", ">= 0", "kg m^2",
            l.inertia);
    const LinkLoad& load = link_load(m, k);
    check_finite("loads." + name + ".force[0]", "N", load.force.x());
    check_finite("loads." + name + ".force[1]", "N", load.force.y());
    check_finite("loads." + name + ".moment", "N m", load.moment);
  }
  check_finite("loads.gravity[0]", "m/s^2", m.loads.gravity.x());
  check_finite("loads.gravity[1]", "m/s^2", m.loads.gravity.y());
  const CounterRotation* rotations[2] = {&m.counter_rotations.crank, &m.counter_rotations.rocker};
  const Vec2 pivots[2] = {Vec2(0, 0), Vec2(m.frame_length, 0)};
  const char* names[2] = {"counter_rotations.crank", "counter_rotations.rocker"};
  for (int i = 0; i < 2; ++i) {
    const CounterRotation& c = *rotations[i];
    const std::string name = names[i];
    require(std::isfinite(c.inertia) && c.inertia >= 0, name + ".inertia", ">= 0", "kg m^2",
            c.inertia);
    check_finite(name + ".at[0]", "m", c.at.x());
    check_finite(name + ".at[1]", "m", c.at.y());
    if (c.inertia > 0) {
      const double d = (c.at - pivots[i]).norm();
      require(d > 0, name + ": distance of the shaft from the link's pivot", "> 0", "m", d);
    }
  }
  if (m.branch != Branch::kPlus && m.branch != Branch::kMinus) {
    throw InputError("branch must be +1 or -1");
  }
  return candidate;
}

GrashofClass classify_grashof(const FourBar& model) {
  const double l1 = model.crank.length, l2 = model.coupler.length, l3 = model.rocker.length,
               l4 = model.frame_length;
  std::array<double, 4> sorted = {l1, l2, l3, l4};
  std::sort(sorted.begin(), sorted.end());
  const double s = sorted[0], l = sorted[3], p = sorted[1], q = sorted[2];
  const double tol = 1e-12 * (l + p + q + s);
  if (std::abs((s + l) - (p + q)) <= tol) return GrashofClass::kChangePoint;
  if (s + l > p + q) return GrashofClass::kNonGrashof;
  if (l4 == s) return GrashofClass::kDoubleCrank;
  if (l1 == s) return GrashofClass::kCrankRocker;
  if (l3 == s) return GrashofClass::kRockerCrank;
  return GrashofClass::kDoubleRocker;
}

const char* to_string(GrashofClass c) {
  switch (c) {
    case GrashofClass::kCrankRocker:
      return "crank-rocker";
    case GrashofClass::kDoubleCrank:
      return "double-crank";
    case GrashofClass::kRockerCrank:
      return "rocker-crank";
    case GrashofClass::kDoubleRocker:
      return "double-rocker";
    case GrashofClass::kChangePoint:
      return "change-point";
    case GrashofClass::kNonGrashof:
      return "non-Grashof";
  }
  return "?";
}

bool crank_turns_fully(const FourBar& model) {
  // |A1A3| sweeps [|l1 - l4|, l1 + l4] over a crank turn; the loop closes everywhere iff that
  // range lies inside [|l2 - l3|, l2 + l3]
  const double l1 = model.crank.length, l2 = model.coupler.length, l3 = model.rocker.length,
               l4 = model.frame_length;
  const double tol = 1e-12 * (l1 + l2 + l3 + l4);
  return l1 + l4 <= l2 + l3 + tol && std::abs(l1 - l4) + tol >= std::abs(l2 - l3);
}

}  // namespace bd::core
