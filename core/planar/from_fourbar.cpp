#include "core/planar/from_fourbar.hpp"

#include "core/fourbar/kinematics.hpp"
#include "core/input_error.hpp"

namespace bd::core::planar {

Linkage linkage_of(const FourBar& m, double theta1) {
  if (has_counter_rotations(m)) {
    throw InputError(
        "counter_rotations: the general engine does not model the four-bar's counter-rotating "
        "inertias; use one of the four-bar's own methods");
  }
  const auto pose = solve_position(m, theta1);
  if (!pose) throw InputError(pose.error().what());
  const Joints j = joint_positions(m, *pose);
  Linkage l;
  l.nodes = {{"A0", Vec2(0, 0), true},
             {"A1", j.A1, false},
             {"A2", j.A2, false},
             {"A3", Vec2(m.frame_length, 0), true}};
  const char* names[] = {"crank", "coupler", "rocker"};
  for (int k = 1; k <= 3; ++k) {
    const core::Link& link = core::link(m, k);
    l.links.push_back({names[k - 1], {k - 1, k}, link.mass, link.e, link.f, link.inertia});
    const LinkLoad load{k - 1, core::link_load(m, k).force, core::link_load(m, k).moment};
    if (!load.force.isZero(0.0) || load.moment != 0.0) l.loads.link_loads.push_back(load);
  }
  l.loads.gravity = m.loads.gravity;
  Input crank;
  crank.kind = Input::Kind::kAngle;
  crank.name = "crank";
  crank.link = 0;
  l.inputs.push_back(crank);
  return make_linkage(l);
}

}  // namespace bd::core::planar
