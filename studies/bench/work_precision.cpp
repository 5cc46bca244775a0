#include "studies/bench/work_precision.hpp"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <system_error>
#include <utility>
#include <variant>

#include "core/fourbar/metrics.hpp"
#include "core/input_error.hpp"
#include "core/number_text.hpp"
#include "core/planar/metrics.hpp"
#include "studies/run/files.hpp"
#include "studies/run/simulation.hpp"

namespace bd::studies {

namespace fs = std::filesystem;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// CPU time of this process [s]: what the measured code costs, whatever else the machine runs
double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

struct Timing {
  double seconds{};  // median CPU time of one call
  int repeats{};
};

// Times `run` (which returns whether it completed): the first call's result is returned with
// the timing; `repeats` timed calls in all, each repeated back to back until min_time has
// passed; one call only when it failed or took longer than long_run.
template <class Run>
auto timed(const BenchOptions& options, Run run) {
  std::vector<double> times;
  double start = cpu_seconds();
  auto first = run();
  double elapsed = cpu_seconds() - start;
  int calls = 1;
  const bool once = !first.ok() || elapsed > options.long_run;
  while (!once && elapsed < options.min_time) {
    (void)run();
    ++calls;
    elapsed = cpu_seconds() - start;
  }
  times.push_back(elapsed / calls);
  for (int r = 1; r < options.repeats && !once; ++r) {
    start = cpu_seconds();
    calls = 0;
    do {
      (void)run();
      ++calls;
      elapsed = cpu_seconds() - start;
    } while (elapsed < options.min_time);
    times.push_back(elapsed / calls);
  }
  std::sort(times.begin(), times.end());
  const std::size_t n = times.size();
  const double median = n % 2 == 1 ? times[n / 2] : 0.5 * (times[n / 2 - 1] + times[n / 2]);
  return std::pair{std::move(first), Timing{median, static_cast<int>(n)}};
}

// the method that computes with the four-bar formulation f
Method method_of(core::Formulation f) {
  for (Method m : kMethods) {
    if (formulation_of(m) == f) return m;
  }
  throw std::logic_error("no method computes with the formulation");
}

// whether `method` runs with `integrator`: a four-bar formulation as core::SimulateOptions
// allows it (IDA with the opened loop only), the general engine with every ODE integrator
bool supports(Method method, core::Integrator integrator) {
  if (const auto f = formulation_of(method)) {
    core::SimulateOptions o;
    o.formulation = *f;
    o.integrator = integrator;
    return !o.validate();
  }
  return integrator != core::Integrator::kIda;
}

MethodChoice choice(Method method, core::Integrator integrator) {
  MethodChoice c;
  c.method = method;
  if (const auto f = formulation_of(method)) c.formulation = *f;
  c.integrator = integrator;
  return c;
}

// the study as the bench runs it: its linkage and scene, the method explicit (a planar study on
// auto repeats a free run on the DAE at a limit position: a bench row is one method's run)
Study bench_study(const Study& study, Method method) {
  Study s;
  s.name = study.name;
  s.linkage = study.linkage;
  s.scene = study.scene;
  s.method = method;
  s.tolerance = study.tolerance;
  return s;
}

Tolerances tolerances(double relative) { return {relative, 1e-2 * relative}; }

// The linkage's length scale: core::planar::Model::length_scale(), its longest element. A
// four-bar's elements (core::planar::linkage_of) are its crank, coupler and rocker.
double length_scale(const Study& study) {
  if (!study.is_fourbar()) return core::planar::Model(study.planar()).length_scale();
  const core::FourBar& m = study.fourbar();
  return std::max({m.crank.length, m.coupler.length, m.rocker.length});
}

// A run's positions sample by sample, on the one scale of the bench's errors: link angles
// [rad], slider positions and moving node coordinates divided by the length scale [-].
struct Positions {
  std::size_t width{};
  std::vector<double> values;  // row-major
  bool completed{};
  std::size_t rows() const { return width == 0 ? 0 : values.size() / width; }
  double at(std::size_t i, std::size_t k) const { return values[i * width + k]; }
};

Positions positions(const Study& study, const Simulation& run, double scale) {
  Positions p;
  p.completed = run.ok();
  if (!run.is_planar) {
    // the four-bar: theta1..3 and its moving nodes A1 = l1 e^(i theta1), A2 = A1 + l2 e^(i theta2)
    const double l1 = study.fourbar().crank.length, l2 = study.fourbar().coupler.length;
    p.width = 7;
    for (const core::DynamicsSample& sample : run.fourbar.samples) {
      const core::FourBarState& x = sample.state;
      const double a1x = l1 * std::cos(x.theta1), a1y = l1 * std::sin(x.theta1);
      p.values.insert(p.values.end(), {x.theta1, x.theta2, x.theta3, a1x / scale, a1y / scale,
                                       (a1x + l2 * std::cos(x.theta2)) / scale,
                                       (a1y + l2 * std::sin(x.theta2)) / scale});
    }
    return p;
  }
  // a planar linkage: the columns of its table (core::planar::columns()) by name
  const core::planar::Linkage& l = study.planar();
  const core::Series& table = run.planar.table;
  std::vector<std::pair<int, double>> picked;  // column, divisor
  const auto pick = [&](const std::string& column, double divisor) {
    const int c = table.column(column);
    if (c < 0) throw std::logic_error("bench: the run's table has no column " + column);
    picked.emplace_back(c, divisor);
  };
  for (const core::planar::Link& k : l.links) pick("theta_" + k.name, 1.0);
  for (const core::planar::Slider& s : l.sliders) pick("s_" + s.name, scale);
  for (const core::planar::Node& n : l.nodes) {
    if (n.ground) continue;
    pick("x_" + n.name, scale);
    pick("y_" + n.name, scale);
  }
  p.width = picked.size();
  p.values.reserve(table.rows() * p.width);
  for (std::size_t i = 0; i < table.rows(); ++i) {
    for (const auto& [c, divisor] : picked) {
      p.values.push_back(table.at(i, static_cast<std::size_t>(c)) / divisor);
    }
  }
  return p;
}

// the largest |a - reference| over the positions of rows [first, last) (NaN stays NaN)
double largest_difference(const Positions& a, const Positions& reference, std::size_t first,
                          std::size_t last) {
  double e = 0;
  for (std::size_t i = first; i < last; ++i) {
    for (std::size_t k = 0; k < a.width; ++k) {
      const double d = std::abs(a.at(i, k) - reference.at(i, k));
      if (!(d <= e)) e = d;
    }
  }
  return e;
}

// at the final time, or NaN when either run stopped early
double final_error(const Positions& a, const Positions& reference) {
  if (!a.completed || !reference.completed || a.width != reference.width ||
      a.rows() != reference.rows() || a.rows() == 0) {
    return kNaN;
  }
  return largest_difference(a, reference, a.rows() - 1, a.rows());
}

// over the samples both runs computed, or NaN when there are none
double max_error(const Positions& a, const Positions& reference) {
  const std::size_t n = std::min(a.rows(), reference.rows());
  if (n == 0 || a.width != reference.width) return kNaN;
  return largest_difference(a, reference, 0, n);
}

void check(const BenchOptions& options) {
  if (const std::string problem = options.validate(); !problem.empty()) {
    throw InputError("bench: " + problem);
  }
}

}  // namespace

BenchOptions BenchOptions::quick() {
  BenchOptions o;
  o.tolerances = {1e-4, 1e-7, 1e-10};
  o.repeats = 1;
  return o;
}

std::string BenchOptions::validate() const {
  if (tolerances.empty()) return "tolerances must not be empty";
  for (double t : tolerances) {
    if (!(t > 0 && t < 1)) return "every tolerance must be > 0 and < 1, got " + text::digits(t, 3);
  }
  if (!(reference_tolerance > 0 && reference_tolerance < 1)) {
    return "reference_tolerance must be > 0 and < 1, got " + text::digits(reference_tolerance, 3);
  }
  if (samples.empty()) return "samples must not be empty";
  for (int n : samples) {
    if (n < 1) return "every samples count must be >= 1, got " + std::to_string(n);
  }
  if (reference_samples < 1) {
    return "reference_samples must be >= 1, got " + std::to_string(reference_samples);
  }
  if (repeats < 1) return "repeats must be >= 1, got " + std::to_string(repeats);
  if (!(min_time >= 0) || !std::isfinite(min_time)) {
    return "min_time must be >= 0 s, got " + text::digits(min_time, 3);
  }
  if (!(long_run >= 0) || !std::isfinite(long_run)) {
    return "long_run must be >= 0 s, got " + text::digits(long_run, 3);
  }
  return {};
}

std::vector<Method> bench_methods(const Study& study) {
  std::vector<Method> methods;
  if (study.is_fourbar()) {
    for (core::Formulation f : core::kFormulations) methods.push_back(method_of(f));
  }
  methods.push_back(Method::kTruss);
  if (is_free(study.scene)) methods.push_back(Method::kTrussDae);
  return methods;
}

std::vector<Method> reference_methods(const Study& study, Method method) {
  using M = Method;
  const bool free = is_free(study.scene);
  if (!study.is_fourbar()) {
    if (!free) return {M::kTruss};
    if (method == M::kTrussDae) return {M::kTruss, M::kTrussDae};
    return {M::kTrussDae, M::kTruss};
  }
  if (method == M::kMassMatrix) return {M::kComplexMasses};
  if (!free || method == M::kComplexMasses) return {M::kMassMatrix};
  return {M::kMassMatrix, M::kComplexMasses, M::kOpenedLoop};
}

std::vector<WorkPrecisionRow> work_precision(const Study& study, const BenchOptions& options) {
  check(options);
  if (!is_free(study.scene)) throw InputError("bench: work_precision needs a free scene");
  const double scale = length_scale(study);

  // the reference runs, computed once per method that serves as one
  std::map<Method, Positions> computed;
  const auto reference_run = [&](Method m) -> const Positions& {
    auto it = computed.find(m);
    if (it == computed.end()) {
      const Simulation run = simulate(bench_study(study, m), choice(m, core::Integrator::kErk8),
                                      tolerances(options.reference_tolerance));
      it = computed.emplace(m, positions(study, run, scale)).first;
    }
    return it->second;
  };
  // the first candidate whose reference run completes, else the last
  const auto reference_of = [&](Method m) {
    const std::vector<Method> candidates = reference_methods(study, m);
    for (Method c : candidates) {
      const Positions& p = reference_run(c);
      if (p.completed || c == candidates.back()) return std::pair{c, &p};
    }
    throw std::logic_error("bench: no reference method");
  };

  std::vector<WorkPrecisionRow> rows;
  for (Method m : bench_methods(study)) {
    const auto [reference_method, reference] = reference_of(m);
    const Study run_study = bench_study(study, m);
    for (core::Integrator integrator : core::kIntegrators) {
      if (!supports(m, integrator)) continue;
      const double start = cpu_seconds();
      std::string summary;
      for (double tolerance : options.tolerances) {
        const MethodChoice method = choice(m, integrator);
        auto [run, timing] =
            timed(options, [&] { return simulate(run_study, method, tolerances(tolerance)); });
        const RunStatus status = run.status();
        const Positions x = positions(study, run, scale);
        WorkPrecisionRow row;
        row.method = m;
        row.integrator = integrator;
        row.tolerance = tolerance;
        row.reference_method = reference_method;
        row.reference_integrator = core::Integrator::kErk8;
        row.reference_tolerance = options.reference_tolerance;
        row.status = status.status;
        row.message = status.message;
        row.cpu_time = timing.seconds;
        row.repeats = timing.repeats;
        row.steps = status.steps;
        row.rhs_evaluations = status.rhs_evaluations;
        row.samples = status.samples;
        row.final_error = final_error(x, *reference);
        row.digits = std::isnan(row.final_error) ? kNaN
                     : row.final_error > 0       ? std::min(16.0, -std::log10(row.final_error))
                                                 : 16.0;
        row.max_error = max_error(x, *reference);
        summary += " " + text::digits(tolerance, 3) + ": " +
                   (status.ok() ? text::digits(1e3 * row.cpu_time, 3) + " ms " +
                                      text::digits(row.digits, 3) + " digits"
                                : std::string(core::to_string(status.status))) +
                   ";";
        rows.push_back(std::move(row));
      }
      if (options.progress) {
        options.progress(std::string("bench: ") + to_string(m) + " / " +
                         core::to_string(integrator) + " (" +
                         text::digits(cpu_seconds() - start, 3) + " s):" + summary);
      }
    }
  }
  return rows;
}

namespace {

// the study's driven scene as one revolution of `samples` samples (a planar scene given by a
// duration: `samples` over it)
Study revolution(const Study& study, Method method, int samples) {
  Study s = bench_study(study, method);
  if (auto* d = std::get_if<core::DrivenScene>(&s.scene)) {
    d->revolutions = 1;
    d->samples = samples;
  } else {
    auto& p = std::get<core::planar::DrivenScene>(s.scene);
    if (!(p.duration > 0)) p.revolutions = 1;
    p.samples = samples;
  }
  return s;
}

// A driven run with the RMS shaking force and moment the runner reports for it.
struct DrivenRun {
  Simulation simulation;
  double Fsh_rms{}, Msh_rms{};
  bool ok() const { return simulation.ok(); }
};

// Computes DrivenRuns: a four-bar's metrics (core::metrics) or the Fsh_rms and Msh_rms entries
// of a planar linkage's metric table (compiled once, not per run).
class DrivenRunner {
 public:
  explicit DrivenRunner(const Study& study) {
    if (study.is_fourbar()) return;
    for (core::planar::ColumnMetric& m :
         core::planar::metric_table(core::planar::Model(study.planar()))) {
      if (m.name == "Fsh_rms" || m.name == "Msh_rms") rms_.push_back(std::move(m));
    }
    if (rms_.size() != 2 || rms_[0].name != "Fsh_rms") {
      throw std::logic_error("bench: the planar metric table has no Fsh_rms, Msh_rms");
    }
  }
  DrivenRun operator()(const Study& revolution, const MethodChoice& method) const {
    DrivenRun r{simulate(revolution, method), 0, 0};
    if (!r.simulation.is_planar) {
      const core::Metrics m = core::metrics(r.simulation.fourbar);
      r.Fsh_rms = m.Fsh_rms;
      r.Msh_rms = m.Msh_rms;
    } else {
      const std::vector<double> v = core::planar::metric_values(rms_, r.simulation.planar.table);
      r.Fsh_rms = v[0];
      r.Msh_rms = v[1];
    }
    return r;
  }

 private:
  std::vector<core::planar::ColumnMetric> rms_;
};

}  // namespace

std::vector<DrivenConvergenceRow> driven_convergence(const Study& study,
                                                     const BenchOptions& options) {
  check(options);
  if (is_free(study.scene)) throw InputError("bench: driven_convergence needs a driven scene");
  const DrivenRunner run(study);
  // the driven scene has no integrator: the choice's is not used
  const auto method = [](Method m) { return choice(m, core::Integrator::kCvodeAdams); };

  std::map<Method, DrivenRun> references;
  const auto reference_of = [&](Method m) -> const DrivenRun& {
    auto it = references.find(m);
    if (it == references.end()) {
      it = references.emplace(m, run(revolution(study, m, options.reference_samples), method(m)))
               .first;
    }
    return it->second;
  };
  const auto relative = [](double value, double exact, bool ok) {
    return ok && exact > 0 ? std::abs(value - exact) / exact : kNaN;
  };

  std::vector<DrivenConvergenceRow> rows;
  for (Method m : bench_methods(study)) {
    if (m == Method::kTrussDae) continue;  // a driven scene has no route: truss only
    const Method rm = reference_methods(study, m).front();
    const DrivenRun& ref = reference_of(rm);
    const double start = cpu_seconds();
    std::string summary;
    for (int samples : options.samples) {
      const Study one = revolution(study, m, samples);
      auto [result, timing] = timed(options, [&] { return run(one, method(m)); });
      const RunStatus status = result.simulation.status();
      DrivenConvergenceRow row;
      row.method = m;
      row.samples = samples;
      row.reference_method = rm;
      row.reference_samples = options.reference_samples;
      row.status = status.status;
      row.message = status.message;
      row.cpu_time = timing.seconds;
      row.repeats = timing.repeats;
      row.Fsh_rms = result.Fsh_rms;
      row.Msh_rms = result.Msh_rms;
      const bool ok = result.ok() && ref.ok();
      row.Fsh_rms_error = relative(row.Fsh_rms, ref.Fsh_rms, ok);
      row.Msh_rms_error = relative(row.Msh_rms, ref.Msh_rms, ok);
      if (samples == 360 || samples == options.samples.back()) {
        summary += " " + std::to_string(samples) + ": " +
                   (status.ok() ? text::digits(1e6 * row.cpu_time, 3) + " us, errors " +
                                      text::digits(row.Fsh_rms_error, 3) + ", " +
                                      text::digits(row.Msh_rms_error, 3)
                                : std::string(core::to_string(status.status))) +
                   ";";
      }
      rows.push_back(std::move(row));
    }
    if (options.progress) {
      options.progress(std::string("bench: ") + to_string(m) + " (" +
                       text::digits(cpu_seconds() - start, 3) + " s):" + summary);
    }
  }
  return rows;
}

std::string work_precision_csv(const std::vector<WorkPrecisionRow>& rows) {
  std::string s = std::string(kWorkPrecisionHeader) + "\n";
  for (const WorkPrecisionRow& r : rows) {
    s += std::string(to_string(r.method)) + "," + core::to_string(r.integrator) + "," +
         csv_number(r.tolerance) + "," + to_string(r.reference_method) + "," +
         core::to_string(r.reference_integrator) + "," + csv_number(r.reference_tolerance) + "," +
         core::to_string(r.status) + "," + csv_number(r.cpu_time) + "," +
         std::to_string(r.repeats) + "," + std::to_string(r.steps) + "," +
         std::to_string(r.rhs_evaluations) + "," + std::to_string(r.samples) + "," +
         csv_number(r.final_error) + "," + csv_number(r.digits) + "," + csv_number(r.max_error) +
         "," + csv_line_field(r.message) + "\n";
  }
  return s;
}

std::string driven_convergence_csv(const std::vector<DrivenConvergenceRow>& rows) {
  std::string s = std::string(kDrivenConvergenceHeader) + "\n";
  for (const DrivenConvergenceRow& r : rows) {
    s += std::string(to_string(r.method)) + "," + std::to_string(r.samples) + "," +
         to_string(r.reference_method) + "," + std::to_string(r.reference_samples) + "," +
         core::to_string(r.status) + "," + csv_number(r.cpu_time) + "," +
         std::to_string(r.repeats) + "," + csv_number(r.Fsh_rms) + "," + csv_number(r.Msh_rms) +
         "," + csv_number(r.Fsh_rms_error) + "," + csv_number(r.Msh_rms_error) + "," +
         csv_line_field(r.message) + "\n";
  }
  return s;
}

std::size_t BenchResult::stopped_early() const {
  std::size_t n = 0;
  for (const WorkPrecisionRow& r : free_rows) n += r.status != core::SimulationStatus::kCompleted;
  for (const DrivenConvergenceRow& r : driven_rows) {
    n += r.status != core::SimulationStatus::kCompleted;
  }
  return n;
}

BenchResult write_bench(const Study& study, const fs::path& out_dir, const BenchOptions& options) {
  check(options);
  BenchResult result;
  if (is_free(study.scene)) {
    result.free_rows = work_precision(study, options);
    result.csv = out_dir / "work-precision.csv";
    write_text_file(work_precision_csv(result.free_rows), result.csv);
  } else {
    result.driven_rows = driven_convergence(study, options);
    result.csv = out_dir / "driven-convergence.csv";
    write_text_file(driven_convergence_csv(result.driven_rows), result.csv);
  }
  return result;
}

void remove_bench_files(const fs::path& out_dir) {
  for (const char* name : {"work-precision.csv", "driven-convergence.csv"}) {
    std::error_code ec;
    fs::remove(out_dir / name, ec);
  }
}

}  // namespace bd::studies
