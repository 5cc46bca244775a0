// What a sweep point costs beyond its physics (docs/performance.md, "Sweeps"): the paper's
// four-bar driven over one revolution of 360 samples, the coupler's mass and s swept on a grid
// (paper-fourbar-sweep.yaml without its balance section):
// - Physics: compute_study() of a point's study built beforehand (the dynamics and metrics);
// - PointStudy/Setter: the point's study from the loaded model (what a sweep does);
// - PointStudy/Yaml: the point's study from the study file's YAML tree (point_study(), the
//   referee, and every point's route before);
// - Row: one whole sweep.csv row (the study, compute_study(), the row's text);
// - Sweep: write_sweep() over a grid of state.range(0) points on one thread (files in /tmp),
//   then the sweep's report page without charts; reported per point.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <unistd.h>

#include "studies/report/report.hpp"
#include "studies/run/runner.hpp"
#include "studies/study/load_study.hpp"
#include "studies/sweep/point_setter.hpp"
#include "studies/sweep/sweep.hpp"

namespace {

using namespace bd::studies;
namespace fs = std::filesystem;

// the example sweep without its balance section, `count` values per parameter
Study sweep_study(int count) {
  std::ifstream in(BD_SOURCE_DIR "/studies/examples/paper-fourbar-sweep.yaml");
  std::stringstream buf;
  buf << in.rdbuf();
  std::string text = buf.str();
  const std::size_t b = text.find("\nbalance:");
  const std::size_t e = text.find("\nsweep:");
  text.erase(b, e - b);
  const std::string counted = "count: " + std::to_string(count);
  for (std::size_t at = 0; (at = text.find("count: 21", at)) != std::string::npos;
       at += counted.size()) {
    text.replace(at, 9, counted);
  }
  return parse_study(text, "paper-fourbar-sweep.yaml");
}

const Study& base() {
  static const Study study = sweep_study(21);
  return study;
}
const std::vector<std::vector<double>>& points() {
  static const std::vector<std::vector<double>> p = sweep_points(*base().sweep);
  return p;
}

void Physics(benchmark::State& state) {
  const Study point = point_study(base(), points()[100]);
  for (auto _ : state) benchmark::DoNotOptimize(compute_study(point));
}
BENCHMARK(Physics)->Unit(benchmark::kMicrosecond);

void PointStudySetter(benchmark::State& state) {
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(detail::sweep_point_study(base(), points()[i]));
    i = (i + 1) % points().size();
  }
}
BENCHMARK(PointStudySetter)->Name("PointStudy/Setter")->Unit(benchmark::kMicrosecond);

void PointStudyYaml(benchmark::State& state) {
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(point_study(base(), points()[i]));
    i = (i + 1) % points().size();
  }
}
BENCHMARK(PointStudyYaml)->Name("PointStudy/Yaml")->Unit(benchmark::kMicrosecond);

void Row(benchmark::State& state) {
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(sweep_row(base(), static_cast<int>(i), points()[i]));
    i = (i + 1) % points().size();
  }
}
BENCHMARK(Row)->Unit(benchmark::kMicrosecond);

void Sweep(benchmark::State& state) {
  const int side = static_cast<int>(state.range(0));
  const Study study = sweep_study(side);
  const fs::path dir = fs::temp_directory_path() / ("bd_sweep_bench_" + std::to_string(::getpid()));
  ::setenv("BD_GNUPLOT", "/nonexistent", 1);  // the page without charts: gnuplot is not ours
  SweepOptions options;
  options.threads = 1;
  for (auto _ : state) {
    fs::remove_all(dir);
    write_sweep(study, dir, options);
    write_sweep_report(study, dir);
  }
  state.counters["s_per_point"] = benchmark::Counter(
      static_cast<double>(side) * side, benchmark::Counter::kIsIterationInvariantRate |
                                            benchmark::Counter::kInvert);
  state.counters["report_bytes"] = static_cast<double>(fs::file_size(dir / "report.html"));
  fs::remove_all(dir);
}
BENCHMARK(Sweep)->Arg(31)->Arg(101)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
