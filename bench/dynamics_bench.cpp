// Timings of the core on the paper's four-bar (docs/performance.md, "Dynamics evaluation"): the
// position solve, one forward- and one inverse-dynamics evaluation per formulation, a driven
// revolution and the paper's free simulation. Each evaluation benchmark moves theta1 by 1e-6 rad
// per iteration, so every call is a new instant and nothing is hoisted out of the loop.
#include <benchmark/benchmark.h>

#include "core/fourbar/detail/dynamics_constants.hpp"
#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/kinematics.hpp"
#include "core/fourbar/samples.hpp"
#include "core/fourbar/simulate.hpp"

namespace {

using namespace bd::core;

// the position solve: theta2, theta3 and the link vectors for a crank angle
void BM_PositionSolve(benchmark::State& state) {
  const FourBar model = samples::paper_fourbar();
  double theta1 = 1.0;
  for (auto _ : state) {
    auto pose = solve_position(model, theta1);
    benchmark::DoNotOptimize(pose);
    theta1 += 1e-6;
  }
}
BENCHMARK(BM_PositionSolve);

// One evaluation by each formulation, forward (arg 0: crank acceleration, reactions, shaking
// force and moment at theta1 = 1 rad + ..., omega1 = 2 rad/s, tau = 0) and inverse (arg 1: the
// drive torque for alpha1 = 0.5 rad/s^2 and all the rest), as a loop over instants calls it:
// with the model's constants computed once (core::detail::dynamics_constants). This is the figure
// the project's target "one forward-dynamics evaluation < 100 ns" (docs/performance.md) is about.
void BM_Formulation(benchmark::State& state, Formulation f) {
  const FourBar model = samples::paper_fourbar();
  const detail::DynamicsConstants constants = detail::dynamics_constants(model);
  const bool inverse = state.range(0) == 1;
  double theta1 = 1.0;
  for (auto _ : state) {
    auto sample = inverse ? inverse_dynamics(model, constants, theta1, 2.0, 0.5, f)
                          : forward_dynamics(model, constants, theta1, 2.0, f);
    benchmark::DoNotOptimize(sample);
    theta1 += 1e-6;
  }
}
BENCHMARK_CAPTURE(BM_Formulation, mass_matrix, Formulation::kMassMatrix)->Arg(0)->Arg(1);
BENCHMARK_CAPTURE(BM_Formulation, opened_loop, Formulation::kOpenedLoop)->Arg(0)->Arg(1);
BENCHMARK_CAPTURE(BM_Formulation, complex_masses, Formulation::kComplexMasses)->Arg(0)->Arg(1);

// The same through the one-instant calls forward_dynamics(model, theta1, omega1, f), which
// compute the formulation's model constants at every call (a single evaluation's cost).
void BM_FormulationOneInstant(benchmark::State& state, Formulation f) {
  const FourBar model = samples::paper_fourbar();
  const bool inverse = state.range(0) == 1;
  double theta1 = 1.0;
  for (auto _ : state) {
    auto sample = inverse ? inverse_dynamics(model, theta1, 2.0, 0.5, f)
                          : forward_dynamics(model, theta1, 2.0, f);
    benchmark::DoNotOptimize(sample);
    theta1 += 1e-6;
  }
}
BENCHMARK_CAPTURE(BM_FormulationOneInstant, mass_matrix, Formulation::kMassMatrix)->Arg(0)->Arg(1);
BENCHMARK_CAPTURE(BM_FormulationOneInstant, opened_loop, Formulation::kOpenedLoop)->Arg(0)->Arg(1);
BENCHMARK_CAPTURE(BM_FormulationOneInstant, complex_masses, Formulation::kComplexMasses)
    ->Arg(0)
    ->Arg(1);

// One driven revolution of 360 samples with all reactions (core::simulate_driven, default
// options: mass-matrix formulation): angles, rates, accelerations, both support reactions,
// shaking force and moment and drive torque at every sample, in the returned Trajectory.
void BM_DrivenRevolution(benchmark::State& state) {
  const FourBar model = samples::paper_fourbar_unloaded();
  const DrivenScene scene{
      .theta1 = 0.0, .omega1 = 6.283185307179586, .revolutions = 1, .samples = 360};
  for (auto _ : state) {
    Trajectory trajectory = simulate_driven(model, scene);
    benchmark::DoNotOptimize(trajectory.samples.data());
  }
}
BENCHMARK(BM_DrivenRevolution)->Unit(benchmark::kMicrosecond);

// the paper's free simulation: 5 s from theta1 = 1 rad at rest, 501 samples, tolerance 1e-10
void BM_PaperFreeSimulation(benchmark::State& state) {
  const FourBar model = samples::paper_fourbar();
  const FreeScene scene{.theta1 = 1.0, .omega1 = 0.0, .duration = 5.0, .samples = 501};
  long steps = 0, evaluations = 0;
  for (auto _ : state) {
    Trajectory trajectory = simulate_free(model, scene);
    benchmark::DoNotOptimize(trajectory.samples.data());
    steps = trajectory.steps;
    evaluations = trajectory.rhs_evaluations;
  }
  state.counters["steps"] = static_cast<double>(steps);
  state.counters["evaluations"] = static_cast<double>(evaluations);
}
BENCHMARK(BM_PaperFreeSimulation)->Unit(benchmark::kMillisecond);

}  // namespace
