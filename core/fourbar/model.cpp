#include "core/fourbar/model.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

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

// throws "<field>[<index>] must be <expected> <unit>, got <value>" unless ok
void require(bool ok, std::string field, int index, const char* expected, const char* unit,
             double value) {
  if (!ok) {
    throw InputError(FieldError{std::move(field), index,
                                std::string("must be ") + expected + (unit[0] ? " " : "") + unit +
                                    ", got " + text::shortest(value)});
  }
}

void require(bool ok, std::string field, const char* expected, const char* unit, double value) {
  require(ok, std::move(field), -1, expected, unit, value);
}

void check_finite(std::string field, int index, const char* unit, double value) {
  require(std::isfinite(value), std::move(field), index, "finite", unit, value);
}

void check_finite(std::string field, const char* unit, double value) {
  check_finite(std::move(field), -1, unit, value);
}

// a planar vector's two components, as field[0] and field[1]
void check_components(const std::string& field, const char* unit, const Vec2& v) {
  check_finite(field, 0, unit, v.x());
  check_finite(field, 1, unit, v.y());
}

void check_link(const Link& l, const std::string& name) {
  require(std::isfinite(l.length) && l.length > 0, name + ".length", "> 0", "m", l.length);
  require(std::isfinite(l.mass) && l.mass > 0, name + ".mass", "> 0", "kg", l.mass);
  check_finite(name + ".e", "m", l.e);
  check_finite(name + ".f", "m", l.f);
  require(std::isfinite(l.inertia) && l.inertia >= 0, name + ".inertia", ">= 0", "kg m²",
          l.inertia);
}

void check_load(const LinkLoad& load, const std::string& name) {
  check_components(name + ".force", "N", load.force);
  check_finite(name + ".moment", "N m", load.moment);
}

// `pivot`: the joint of the link the disc is geared to [m]
void check_counter_rotation(const CounterRotation& c, const std::string& name, const Vec2& pivot) {
  require(std::isfinite(c.inertia) && c.inertia >= 0, name + ".inertia", ">= 0", "kg m²",
          c.inertia);
  check_components(name + ".at", "m", c.at);
  if (c.inertia > 0) {
    // the disc as a whole: with J > 0 its shaft must be away from the pivot
    const double d = (c.at - pivot).norm();
    if (!(d > 0)) {
      throw InputError(FieldError{name, -1,
                                  ": distance of the shaft from the link's pivot must be > 0 m, "
                                  "got " +
                                      text::shortest(d)});
    }
  }
}

}  // namespace

FourBar make_fourbar(const FourBar& candidate) {
  const FourBar& m = candidate;
  require(std::isfinite(m.frame_length) && m.frame_length > 0, "frame", "> 0", "m", m.frame_length);
  for (int k = 1; k <= 3; ++k) {
    check_link(link(m, k), link_name(k));
    check_load(link_load(m, k), std::string("loads.") + link_name(k));
  }
  check_components("loads.gravity", "m/s²", m.loads.gravity);
  check_counter_rotation(m.counter_rotations.crank, "counter_rotations.crank", Vec2(0, 0));
  check_counter_rotation(m.counter_rotations.rocker, "counter_rotations.rocker",
                         Vec2(m.frame_length, 0));
  if (m.branch != Branch::kPlus && m.branch != Branch::kMinus) {
    throw InputError(FieldError{"branch", -1, "must be +1 or -1"});
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
