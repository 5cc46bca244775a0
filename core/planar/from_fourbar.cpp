#include "core/planar/from_fourbar.hpp"

#include <span>

#include "core/fourbar/kinematics.hpp"
#include "core/input_error.hpp"

namespace bd::core::planar {

Linkage linkage_of(const FourBar& m, double theta1) {
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
  // the counter-rotating discs: balance shafts geared to the crank and the rocker with ratio -1
  // (equal pitch radii, as the four-bar's), named so that their reactions are RC1 and RC3
  const CounterRotation* discs[] = {&m.counter_rotations.crank, &m.counter_rotations.rocker};
  for (int side = 0; side < 2; ++side) {
    if (!(discs[side]->inertia > 0)) continue;
    l.shafts.push_back({side == 0 ? std::string("C1") : std::string("C3"), side == 0 ? 0 : 2, -1,
                        discs[side]->at, 0.0, Vec2(0, 0), discs[side]->inertia});
  }
  Input crank;
  crank.kind = Input::Kind::kAngle;
  crank.name = "crank";
  crank.link = 0;
  l.inputs.push_back(crank);
  return make_linkage(l);
}

FourBarSampleOf::FourBarSampleOf(const Series& t) : t_(t) {}

DynamicsSample FourBarSampleOf::operator()(std::span<const double> r) const {
  DynamicsSample d;
  d.state = {r[th1], r[om1], r[al1], r[th2], r[th3], r[om2], r[om3], r[al2], r[al3]};
  d.RA0 = Vec2(r[r0], r[r0 + 1]);
  d.RA3 = Vec2(r[r3], r[r3 + 1]);
  d.Fsh = Vec2(r[f], r[f + 1]);
  d.Msh = r[m];
  d.tau = r[tau];
  d.Fsh_inertial = Vec2(r[fi], r[fi + 1]);
  d.Msh_inertial = r[mi];
  d.Fsh_static = Vec2(r[fs], r[fs + 1]);
  d.Msh_static = r[ms];
  if (fa1 >= 0) d.FA1 = Vec2(r[at(fa1)], r[at(fa1) + 1]);
  if (fa2 >= 0) d.FA2 = Vec2(r[at(fa2)], r[at(fa2) + 1]);
  if (rc1 >= 0) d.RC1 = Vec2(r[at(rc1)], r[at(rc1) + 1]);
  if (rc3 >= 0) d.RC3 = Vec2(r[at(rc3)], r[at(rc3) + 1]);
  return d;
}

core::Trajectory fourbar_trajectory(const Trajectory& planar) {
  const Series& t = planar.table;
  const FourBarSampleOf sample_of(t);
  core::Trajectory out;
  out.t.reserve(t.rows());
  out.samples.reserve(t.rows());
  for (std::size_t i = 0; i < t.rows(); ++i) {
    out.t.push_back(t.at(i, sample_of.time()));
    out.samples.push_back(sample_of(t.row(i)));
  }
  out.stop_time = planar.stop_time;
  if (planar.stop_row.size() == t.width()) out.stop = sample_of(planar.stop_row);
  out.status = planar.status;
  out.message = planar.message;
  out.steps = planar.steps;
  out.steps_to = planar.steps_to;
  out.rhs_evaluations = planar.rhs_evaluations;
  return out;
}

}  // namespace bd::core::planar
