// Google Benchmark: one dynamics evaluation of the paper's four-bar.
#include <benchmark/benchmark.h>

#include "core/dynamics.hpp"
#include "core/samples.hpp"

static void BM_ForwardDynamics(benchmark::State& state) {
  const bd::core::FourBar m = bd::core::samples::paper_fourbar();
  double theta1 = 0.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(bd::core::forward_dynamics(m, theta1, 1.0));
    theta1 += 1e-3;
  }
}
BENCHMARK(BM_ForwardDynamics);
