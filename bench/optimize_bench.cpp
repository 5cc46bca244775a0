// Timings of the optimisation layer on the paper's four-bar (no loads), driven at 1 rev/s with
// 360 samples per revolution, counterweights on crank and rocker (docs/performance.md):
// - one evaluation of the program by the regressor: the objective with its gradient, and the
//   whole program (objective, equalities and inequalities with their Jacobians);
// - one fresh driven simulation of the same design (core::simulate_driven, what an evaluation
//   would cost without the regressor), and of one revolution's metrics from it;
// - one whole optimisation of the Berkof–Lowen problem (force balance as equalities, least RMS
//   shaking moment) by SLSQP and by Ipopt;
// - one whole optimisation in a free scene (the loaded linkage under gravity swinging from a
//   push), derivative-free (cobyla) and with gradients by forward sensitivities (slsqp, mma,
//   ipopt), and one evaluation there with and without the gradient; the same free problem on
//   the general planar engine (the paper's four-bar as a planar linkage, under gravity alone).
#include <benchmark/benchmark.h>

#include <numbers>

#include "core/fourbar/metrics.hpp"
#include "core/fourbar/samples.hpp"
#include "core/fourbar/simulate.hpp"
#include "core/planar/from_fourbar.hpp"
#include "optimize/nlp.hpp"
#include "optimize/optimize.hpp"
#include "optimize/planar.hpp"

namespace {

using namespace bd;
using namespace bd::optimize;

DesignProblem berkof_lowen() {
  DesignProblem p;
  p.original = core::samples::paper_fourbar_unloaded();
  p.scene = core::DrivenScene{
      .theta1 = 0.0, .omega1 = 2.0 * std::numbers::pi, .revolutions = 1, .samples = 360};
  p.formulation = core::Formulation::kComplexMasses;
  p.counterweights = {CounterweightVariables{.link = 1, .mass_max = 10.0, .distance_max = 1.0},
                      CounterweightVariables{.link = 3, .mass_max = 10.0, .distance_max = 1.0}};
  p.objective = {Term{Metric::kMshRms, 1.0}};
  p.force_balance = true;
  return p;
}

// a design point a little away from the start, nudged every iteration so nothing is hoisted
Eigen::VectorXd nudged(const Nlp& nlp, Eigen::VectorXd& x) {
  x[0] = x[0] < 0.5 * nlp.upper()[0] ? x[0] + 1e-9 : x[0] - 1e-9;
  return x;
}

void BM_NlpObjectiveWithGradient(benchmark::State& state) {
  const Nlp nlp(berkof_lowen());
  Eigen::VectorXd x = nlp.start(), g(nlp.n());
  for (auto _ : state) {
    double f = nlp.objective(nudged(nlp, x), &g);
    benchmark::DoNotOptimize(f);
    benchmark::DoNotOptimize(g.data());
  }
}
BENCHMARK(BM_NlpObjectiveWithGradient)->Unit(benchmark::kMicrosecond);

void BM_NlpEvaluationWithDerivatives(benchmark::State& state) {
  const Nlp nlp(berkof_lowen());
  Eigen::VectorXd x = nlp.start(), g(nlp.n()), ceq, cin;
  Eigen::MatrixXd jeq, jin;
  for (auto _ : state) {
    double f = nlp.objective(nudged(nlp, x), &g);
    nlp.equalities(x, ceq, &jeq);
    nlp.inequalities(x, cin, &jin);
    benchmark::DoNotOptimize(f);
    benchmark::DoNotOptimize(cin.data());
    benchmark::DoNotOptimize(jin.data());
  }
}
BENCHMARK(BM_NlpEvaluationWithDerivatives)->Unit(benchmark::kMicrosecond);

// the same design simulated afresh (no derivatives), and summarised
void BM_DrivenSimulation(benchmark::State& state) {
  const DesignProblem p = berkof_lowen();
  const Nlp nlp(p);
  Eigen::VectorXd x = nlp.start();
  core::SimulateOptions options;
  options.formulation = p.formulation;
  for (auto _ : state) {
    const core::Trajectory t =
        core::simulate_driven(nlp.design(nudged(nlp, x)), std::get<core::DrivenScene>(p.scene),
                              options);
    core::Metrics m = core::metrics(t);
    benchmark::DoNotOptimize(m);
  }
}
BENCHMARK(BM_DrivenSimulation)->Unit(benchmark::kMicrosecond);

// building the program: the regressor (one inverse-dynamics call per column per sample)
void BM_NlpConstruction(benchmark::State& state) {
  const DesignProblem p = berkof_lowen();
  for (auto _ : state) {
    const Nlp nlp(p);
    benchmark::DoNotOptimize(&nlp);
  }
}
BENCHMARK(BM_NlpConstruction)->Unit(benchmark::kMillisecond);

// the convex budget problem (docs/performance.md, "A budget that rules out full balance"): the
// least RMS shaking force with an added mass of 2 kg, a third of what full balance needs
DesignProblem budget() {
  DesignProblem p = berkof_lowen();
  p.force_balance = false;
  p.objective = {Term{Metric::kFshRms, 1.0}};
  p.limits = {Limit{Metric::kAddedMass, 2.0}};
  return p;
}

// a whole optimize(): program construction, solve, first-order check, verification
void BM_Optimize(benchmark::State& state, DesignProblem (*problem)(), Algorithm algorithm) {
  const DesignProblem p = problem();
  OptimizeOptions options;
  options.algorithm = algorithm;
  int evaluations = 0, iterations = 0;
  bool converged = true;
  double objective = 0;
  for (auto _ : state) {
    const OptimizeResult r = bd::optimize::optimize(p, options);
    evaluations = r.evaluations;
    iterations = r.iterations;
    objective = r.objective;
    converged = converged && r.termination == Termination::kConverged;
    benchmark::DoNotOptimize(r.objective);
  }
  state.counters["evaluations"] = evaluations;
  state.counters["iterations"] = iterations;
  state.counters["objective"] = objective;
  state.counters["converged"] = converged ? 1 : 0;
}
BENCHMARK_CAPTURE(BM_Optimize, slsqp, berkof_lowen, Algorithm::kSlsqp)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Optimize, ipopt, berkof_lowen, Algorithm::kIpopt)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Optimize, budget_slsqp, budget, Algorithm::kSlsqp)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Optimize, budget_mma, budget, Algorithm::kMma)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Optimize, budget_ipopt, budget, Algorithm::kIpopt)
    ->Unit(benchmark::kMillisecond);

// the free-scene problem (docs/performance.md, "Free scenes"): the paper's loaded four-bar under
// gravity, from theta1 = 1 rad at 3 rad/s for 1 s (41 samples), least RMS shaking force with
// counterweights on crank and rocker and at most 2 kg added
DesignProblem free_budget() {
  DesignProblem p;
  p.original = core::samples::with_paper_loads(core::samples::paper_fourbar_unloaded(),
                                               Vec2(0, -9.81));
  p.scene = core::FreeScene{.theta1 = 1.0, .omega1 = 3.0, .duration = 1.0, .samples = 41};
  p.formulation = core::Formulation::kComplexMasses;
  p.counterweights = {CounterweightVariables{.link = 1, .mass_max = 4.0, .distance_max = 0.8},
                      CounterweightVariables{.link = 3, .mass_max = 4.0, .distance_max = 0.8}};
  p.objective = {Term{Metric::kFshRms, 1.0}};
  p.limits = {Limit{Metric::kAddedMass, 2.0}};
  return p;
}
BENCHMARK_CAPTURE(BM_Optimize, free_cobyla, free_budget, Algorithm::kCobyla)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Optimize, free_slsqp, free_budget, Algorithm::kSlsqp)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Optimize, free_mma, free_budget, Algorithm::kMma)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Optimize, free_ipopt, free_budget, Algorithm::kIpopt)
    ->Unit(benchmark::kMillisecond);

// one free-scene evaluation: a simulation (no gradient) or the sensitivity run (with it)
void BM_FreeObjective(benchmark::State& state) {
  const Nlp nlp(free_budget());
  Eigen::VectorXd x = nlp.start(), g(nlp.n());
  const bool gradient = state.range(0) != 0;
  for (auto _ : state) {
    double f = nlp.objective(nudged(nlp, x), gradient ? &g : nullptr);
    benchmark::DoNotOptimize(f);
  }
}
BENCHMARK(BM_FreeObjective)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// The free problem on the general planar engine: the paper's four-bar drawn at theta1 = 1 rad
// under gravity (no link loads: they would act at centres of mass the counterweights move),
// pushed at 3 rad/s for 1 s (41 samples), least RMS shaking force with counterweights on crank
// and rocker and at most 2 kg added; gradients by the engine's forward sensitivities
// (core/planar/simulate.hpp).
bd::optimize::planar::DesignProblem planar_free_budget() {
  namespace op = bd::optimize::planar;
  namespace cp = bd::core::planar;
  core::FourBar f = core::samples::paper_fourbar_unloaded();
  op::DesignProblem p;
  p.original = cp::linkage_of(f, 1.0);
  p.original.loads.gravity = Vec2(0, -9.81);
  p.scene = cp::FreeScene{{}, {3.0}, 1.0, 41};
  p.counterweights = {op::CounterweightVariables{.link = 0, .mass_max = 4.0, .distance_max = 0.8},
                      op::CounterweightVariables{.link = 2, .mass_max = 4.0, .distance_max = 0.8}};
  p.objective = {op::Term{"Fsh_rms", 1.0}};
  p.limits = {op::Limit{"added_mass", 2.0}};
  return p;
}

void BM_PlanarFreeOptimize(benchmark::State& state, Algorithm algorithm) {
  const auto p = planar_free_budget();
  OptimizeOptions options;
  options.algorithm = algorithm;
  int evaluations = 0;
  bool converged = true;
  double objective = 0;
  for (auto _ : state) {
    const auto r = bd::optimize::planar::optimize(p, options);
    evaluations = r.evaluations;
    objective = r.objective;
    converged = converged && r.termination == Termination::kConverged;
    benchmark::DoNotOptimize(r.objective);
  }
  state.counters["evaluations"] = evaluations;
  state.counters["objective"] = objective;
  state.counters["converged"] = converged ? 1 : 0;
}
BENCHMARK_CAPTURE(BM_PlanarFreeOptimize, cobyla, Algorithm::kCobyla)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_PlanarFreeOptimize, slsqp, Algorithm::kSlsqp)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_PlanarFreeOptimize, mma, Algorithm::kMma)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_PlanarFreeOptimize, ipopt, Algorithm::kIpopt)
    ->Unit(benchmark::kMillisecond);

// one planar free-scene evaluation: a simulation (no gradient) or the run with sensitivities
void BM_PlanarFreeObjective(benchmark::State& state) {
  const bd::optimize::planar::PlanarNlp nlp(planar_free_budget());
  Eigen::VectorXd x = nlp.start(), g(nlp.n());
  const bool gradient = state.range(0) != 0;
  for (auto _ : state) {
    x[0] = x[0] < 0.5 * nlp.upper()[0] ? x[0] + 1e-9 : x[0] - 1e-9;
    double f = nlp.objective(x, gradient ? &g : nullptr);
    benchmark::DoNotOptimize(f);
  }
}
BENCHMARK(BM_PlanarFreeObjective)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
