// Timings of the per-instant dynamics and of the two scenes on the paper's four-bar.
#include <benchmark/benchmark.h>

#include "core/dynamics.hpp"
#include "core/samples.hpp"
#include "core/simulate.hpp"

namespace {

using namespace bd::core;

// one forward-dynamics evaluation (what the integrator's right-hand side costs)
void BM_ForwardDynamics(benchmark::State& state) {
  const FourBar model = samples::paper_fourbar();
  double theta1 = 1.0;
  for (auto _ : state) {
    auto sample = forward_dynamics(model, theta1, 2.0);
    benchmark::DoNotOptimize(sample);
    theta1 += 1e-6;  // a new instant each time, so nothing is hoisted
  }
}
BENCHMARK(BM_ForwardDynamics);

// one evaluation by each formulation, forward (arg 0) and inverse (arg 1)
void BM_Formulation(benchmark::State& state, Formulation f) {
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
BENCHMARK_CAPTURE(BM_Formulation, mass_matrix, Formulation::kMassMatrix)->Arg(0)->Arg(1);
BENCHMARK_CAPTURE(BM_Formulation, opened_loop, Formulation::kOpenedLoop)->Arg(0)->Arg(1);
BENCHMARK_CAPTURE(BM_Formulation, complex_masses, Formulation::kComplexMasses)->Arg(0)->Arg(1);

// one inverse-dynamics evaluation (one driven sample)
void BM_InverseDynamics(benchmark::State& state) {
  const FourBar model = samples::paper_fourbar();
  double theta1 = 1.0;
  for (auto _ : state) {
    auto sample = inverse_dynamics(model, theta1, 2.0, 0.5);
    benchmark::DoNotOptimize(sample);
    theta1 += 1e-6;
  }
}
BENCHMARK(BM_InverseDynamics);

// a driven revolution of 360 samples
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
