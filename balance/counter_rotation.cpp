#include "balance/counter_rotation.hpp"

#include <fmt/printf.h>

#include <cstdio>

#include "balance/conditions.hpp"
#include "core/input_error.hpp"

namespace bd::balance {

namespace {

// the input checks allow for a design written down with finitely many digits
constexpr double kInputTolerance = 1e-9;

std::string describe(const Condition& c) {
  const std::string buf = fmt::sprintf(": residual %.6g %s exceeds %.0e of %.6g %s", c.residual,
                                       c.unit.c_str(), kInputTolerance, c.scale, c.unit.c_str());
  return c.name + " (" + c.meaning + ")" + buf;
}

}  // namespace

MomentBalancedDesign moment_balance(const core::FourBar& force_balanced, Vec2 crank_at,
                                    Vec2 rocker_at) {
  const core::FourBar checked = core::make_fourbar(force_balanced);
  const BalanceReport report = check_balance(checked, kInputTolerance);
  for (const Condition& c : report.force) {
    if (!c.holds) {
      throw InputError(
          FieldError{"", -1, "moment_balance needs a force-balanced design: " + describe(c)});
    }
  }
  const core::Link& coupler = checked.coupler;
  for (const Condition& c : report.moment) {
    if (c.name.rfind("coupler.", 0) != 0 || c.holds) continue;
    const std::string values = fmt::sprintf(
        "; got f2 = %.17g m, I2 = %.17g kg m², m2 e2 (l2 - e2) = %.17g kg m²", coupler.f,
        coupler.inertia, coupler.mass * coupler.e * (coupler.length - coupler.e));
    throw InputError(
        FieldError{"", -1, "moment_balance needs a Berkof coupler: " + describe(c) + values});
  }

  // a Berkof coupler has 0 <= e2 <= l2, so both reduced inertias are >= 0
  const ReducedInertias K = reduced_inertias(checked);
  MomentBalancedDesign out;
  out.model = checked;
  out.crank_inertia = K.crank;
  out.rocker_inertia = K.rocker;
  out.model.counter_rotations.crank = {K.crank, crank_at};
  out.model.counter_rotations.rocker = {K.rocker, rocker_at};
  out.model = core::make_fourbar(out.model);
  return out;
}

}  // namespace bd::balance
