// The general planar engine on the paper's four-bar next to the dedicated closed form
// (docs/performance.md, "The general engine"): one position solve plus inverse or forward dynamics
// at an instant, a driven revolution of 360 samples, and the paper's 5 s free run.
#include <benchmark/benchmark.h>

#include "core/fourbar/samples.hpp"
#include "core/fourbar/simulate.hpp"
#include "core/planar/dynamics.hpp"
#include "core/planar/from_fourbar.hpp"
#include "core/planar/simulate.hpp"

namespace {

using namespace bd::core;

// one instant: Newton from the previous instant's positions (one step of 1e-6 rad, as a driven
// sample's predictor leaves it), then inverse (arg 1) or forward (arg 0) dynamics
void BM_PlanarInstant(benchmark::State& state) {
  const FourBar fb = samples::paper_fourbar();
  const planar::Model model(planar::linkage_of(fb, 1.0));
  planar::Workspace ws(model);
  const bool inverse = state.range(0) == 1;
  double theta1 = 1.0;
  std::vector<bd::Vec2> guess = ws.instant.x;
  for (auto _ : state) {
    auto ok = planar::solve_position(model, ws, guess, {theta1});
    if (ok) {
      ok = inverse ? planar::inverse_dynamics(model, ws, 0.0, {2.0}, {0.5})
                   : planar::forward_dynamics(model, ws, 0.0, {2.0}, {0.0});
    }
    benchmark::DoNotOptimize(ok);
    guess = ws.instant.x;
    theta1 += 1e-6;
  }
}
BENCHMARK(BM_PlanarInstant)->Arg(0)->Arg(1);

// a driven revolution, 360 samples, general engine against the closed form (arg 1)
void BM_DrivenRevolution(benchmark::State& state) {
  const FourBar fb = samples::paper_fourbar();
  const planar::Model model(planar::linkage_of(fb, 0.0));
  for (auto _ : state) {
    if (state.range(0) == 1) {
      auto t = simulate_driven(fb, DrivenScene{0.0, 6.283185307179586, 1, 360});
      benchmark::DoNotOptimize(t);
    } else {
      auto t = planar::simulate_driven(model, planar::DrivenScene{{0.0}, {6.283185307179586}, 1, 0, 360});
      benchmark::DoNotOptimize(t);
    }
  }
}
BENCHMARK(BM_DrivenRevolution)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

// the paper's free run, 5 s, 501 samples at tolerance 1e-10: general engine reduced (arg 0),
// general engine dae (arg 1), closed form (arg 2)
void BM_FreeRun(benchmark::State& state) {
  const FourBar fb = samples::paper_fourbar();
  const planar::Model model(planar::linkage_of(fb, 1.0));
  for (auto _ : state) {
    if (state.range(0) == 2) {
      auto t = simulate_free(fb, FreeScene{1.0, 0.0, 5.0, 501});
      benchmark::DoNotOptimize(t);
    } else {
      planar::SimulateOptions o;
      o.route = state.range(0) == 1 ? planar::Route::kDae : planar::Route::kReduced;
      auto t = planar::simulate_free(model, planar::FreeScene{{1.0}, {0.0}, 5.0, 501}, o);
      benchmark::DoNotOptimize(t);
    }
  }
}
BENCHMARK(BM_FreeRun)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

}  // namespace
