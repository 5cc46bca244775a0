// The library API in a few lines: build the paper's four-bar, solve one instant with the core
// (balance_design::core), then run a whole study, balanced, as the program does
// (balance_design::studies). Built against the installed package by docs/examples/CMakeLists.txt.
#include <cstdio>

#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/model.hpp"
#include "studies/run/runner.hpp"
#include "studies/study/load_study.hpp"

int main() {
  using namespace bd::core;
  FourBar model;
  model.crank = link_from_polar(1.0, 2.1, 0.6, 0.3, 1.1);  // length, mass, s, sigma, inertia
  model.coupler = link_from_polar(3.0, 3.0, 1.45, 0.4, 3.1);
  model.rocker = link_from_polar(2.0, 2.2, 1.66, -0.4, 2.1);
  model.frame_length = 3.2;
  model.branch = Branch::kPlus;
  model = make_fourbar(model);  // throws bd::InputError on a non-physical value

  // crank driven at 2 pi rad/s through theta1 = 1 rad: drive torque and support reactions
  const auto s = inverse_dynamics(model, 1.0, 2 * 3.141592653589793, 0.0);
  if (!s) return std::fprintf(stderr, "%s\n", s.error().what().c_str()), 1;
  std::printf("theta2 = %.6f rad, theta3 = %.6f rad\n", s->state.theta2, s->state.theta3);
  std::printf("tau = %.6f N m, RA0 = (%.6f, %.6f) N, RA3 = (%.6f, %.6f) N\n", s->tau, s->RA0.x(),
              s->RA0.y(), s->RA3.x(), s->RA3.y());
  std::printf("shaking force = (%.6f, %.6f) N, shaking moment = %.6f N m\n", s->Fsh.x(), s->Fsh.y(),
              s->Msh);

  // the same linkage as a study, driven for one revolution and force balanced: what
  // `balance-design study.yaml` computes, without writing files (run_study() writes them)
  const char* text = R"(
name: embedded
linkage:
  type: fourbar
  frame: 3.2
  branch: 1
  crank:   {length: 1.0, mass: 2.1, s: 0.6,  sigma: 0.3,  inertia: 1.1}
  coupler: {length: 3.0, mass: 3.0, s: 1.45, sigma: 0.4,  inertia: 3.1}
  rocker:  {length: 2.0, mass: 2.2, s: 1.66, sigma: -0.4, inertia: 2.1}
scene: {type: driven, theta1: 0, omega1: 6.283185307179586, revolutions: 1, samples: 360}
balance: {force: full}
)";
  try {
    const bd::studies::Study study = bd::studies::parse_study(text, "embedded.yaml");
    const bd::studies::RunResult run = bd::studies::compute_study(study);
    std::printf("RMS shaking force: %.6g N, force balanced %.3g N (%zu samples)\n",
                run.metrics.Fsh_rms, run.balanced->metrics.Fsh_rms, run.trajectory.samples.size());
  } catch (const bd::InputError& e) {  // a mistake in the study: one line, file:line:column
    return std::fprintf(stderr, "%s\n", e.what()), 2;
  }
}
