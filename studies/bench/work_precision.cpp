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
#include "studies/run/files.hpp"

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

core::SimulateOptions simulate_options(core::Formulation f, core::Integrator integrator,
                                       double tolerance) {
  core::SimulateOptions o;
  o.formulation = f;
  o.integrator = integrator;
  o.tolerance = tolerance;
  o.absolute_tolerance = 1e-2 * tolerance;
  return o;
}

// the other formulation that references f (docs/architecture.md: the formulations agree to round-off)
core::Formulation other_formulation(core::Formulation f) {
  return f == core::Formulation::kMassMatrix ? core::Formulation::kComplexMasses
                                             : core::Formulation::kMassMatrix;
}

struct Reference {
  core::Formulation formulation{};
  core::Integrator integrator = core::Integrator::kErk8;
  core::Trajectory trajectory;
};

// the largest relative error of theta1..3 of `a` at the final time, or NaN when either run
// stopped early
double final_error(const core::Trajectory& a, const core::Trajectory& reference) {
  if (!a.ok() || !reference.ok() || a.samples.size() != reference.samples.size()) return kNaN;
  const core::FourBarState& x = a.samples.back().state;
  const core::FourBarState& r = reference.samples.back().state;
  double e = 0;
  for (const auto& [value, exact] : {std::pair{x.theta1, r.theta1}, std::pair{x.theta2, r.theta2},
                                     std::pair{x.theta3, r.theta3}}) {
    e = std::max(e, std::abs(value - exact) / std::abs(exact));
  }
  return e;
}

// the largest |theta_k - theta_k,ref| over the samples both computed [rad]
double max_error(const core::Trajectory& a, const core::Trajectory& reference) {
  double e = 0;
  const std::size_t n = std::min(a.samples.size(), reference.samples.size());
  for (std::size_t i = 0; i < n; ++i) {
    const core::FourBarState& x = a.samples[i].state;
    const core::FourBarState& r = reference.samples[i].state;
    e = std::max({e, std::abs(x.theta1 - r.theta1), std::abs(x.theta2 - r.theta2),
                  std::abs(x.theta3 - r.theta3)});
  }
  return n > 0 ? e : kNaN;
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

std::vector<WorkPrecisionRow> work_precision(const Study& study, const BenchOptions& options) {
  check(options);
  const auto* scene = std::get_if<core::FreeScene>(&study.scene);
  if (scene == nullptr) throw InputError("bench: work_precision needs a free scene");

  // the references, computed once per formulation that serves as one
  std::map<core::Formulation, core::Trajectory> computed;
  const auto reference_run = [&](core::Formulation f) -> const core::Trajectory& {
    auto it = computed.find(f);
    if (it == computed.end()) {
      const core::SimulateOptions o =
          simulate_options(f, core::Integrator::kErk8, options.reference_tolerance);
      it = computed.emplace(f, core::simulate_free(study.fourbar(), *scene, o)).first;
    }
    return it->second;
  };
  const auto reference_of = [&](core::Formulation f) {
    Reference r;
    r.formulation = other_formulation(f);
    r.trajectory = reference_run(r.formulation);
    if (!r.trajectory.ok() && f == core::Formulation::kOpenedLoop) {
      // a crank reaching its limits: no reduced formulation follows the motion through them
      const core::Trajectory& other = reference_run(core::Formulation::kComplexMasses);
      if (other.ok()) {
        r.formulation = core::Formulation::kComplexMasses;
        r.trajectory = other;
      } else {
        r.formulation = core::Formulation::kOpenedLoop;
        r.trajectory = reference_run(core::Formulation::kOpenedLoop);
      }
    }
    return r;
  };

  std::vector<WorkPrecisionRow> rows;
  for (core::Formulation f : core::kFormulations) {
    const Reference reference = reference_of(f);
    for (core::Integrator integrator : core::kIntegrators) {
      if (simulate_options(f, integrator, 1e-10).validate()) continue;
      const double start = cpu_seconds();
      std::string summary;
      for (double tolerance : options.tolerances) {
        const core::SimulateOptions o = simulate_options(f, integrator, tolerance);
        auto [trajectory, timing] =
            timed(options, [&] { return core::simulate_free(study.fourbar(), *scene, o); });
        WorkPrecisionRow row;
        row.formulation = f;
        row.integrator = integrator;
        row.tolerance = tolerance;
        row.reference_formulation = reference.formulation;
        row.reference_integrator = reference.integrator;
        row.reference_tolerance = options.reference_tolerance;
        row.status = trajectory.status;
        row.message = trajectory.message;
        row.cpu_time = timing.seconds;
        row.repeats = timing.repeats;
        row.steps = trajectory.steps;
        row.rhs_evaluations = trajectory.rhs_evaluations;
        row.samples = trajectory.samples.size();
        row.final_error = final_error(trajectory, reference.trajectory);
        row.digits = std::isnan(row.final_error) ? kNaN
                     : row.final_error > 0       ? std::min(16.0, -std::log10(row.final_error))
                                                 : 16.0;
        row.max_error = max_error(trajectory, reference.trajectory);
        summary += " " + text::digits(tolerance, 3) + ": " +
                   (trajectory.ok() ? text::digits(1e3 * row.cpu_time, 3) + " ms " +
                                          text::digits(row.digits, 3) + " digits"
                                    : std::string(core::to_string(trajectory.status))) +
                   ";";
        rows.push_back(std::move(row));
      }
      if (options.progress) {
        options.progress(std::string("bench: ") + core::to_string(f) + " / " +
                         core::to_string(integrator) + " (" +
                         text::digits(cpu_seconds() - start, 3) + " s):" + summary);
      }
    }
  }
  return rows;
}

std::vector<DrivenConvergenceRow> driven_convergence(const Study& study,
                                                     const BenchOptions& options) {
  check(options);
  const auto* scene = std::get_if<core::DrivenScene>(&study.scene);
  if (scene == nullptr) throw InputError("bench: driven_convergence needs a driven scene");

  const auto revolution = [&](int samples, core::Formulation f) {
    core::DrivenScene one = *scene;
    one.revolutions = 1;
    one.samples = samples;
    core::SimulateOptions o;
    o.formulation = f;
    return core::simulate_driven(study.fourbar(), one, o);
  };
  std::map<core::Formulation, core::Metrics> references;
  std::map<core::Formulation, bool> reference_ok;
  for (core::Formulation f : core::kFormulations) {
    const core::Trajectory t = revolution(options.reference_samples, f);
    references[f] = core::metrics(t);
    reference_ok[f] = t.ok();
  }
  const auto relative = [](double value, double exact, bool ok) {
    return ok && exact > 0 ? std::abs(value - exact) / exact : kNaN;
  };

  std::vector<DrivenConvergenceRow> rows;
  for (core::Formulation f : core::kFormulations) {
    const core::Formulation rf = other_formulation(f);
    const core::Metrics& ref = references[rf];
    const double start = cpu_seconds();
    std::string summary;
    for (int samples : options.samples) {
      // a revolution as the runner computes it, with the metrics it reports
      struct Result {
        core::Trajectory trajectory;
        core::Metrics metrics;
        bool ok() const { return trajectory.ok(); }
      };
      auto [result, timing] = timed(options, [&] {
        Result r{revolution(samples, f), {}};
        r.metrics = core::metrics(r.trajectory);
        return r;
      });
      DrivenConvergenceRow row;
      row.formulation = f;
      row.samples = samples;
      row.reference_formulation = rf;
      row.reference_samples = options.reference_samples;
      row.status = result.trajectory.status;
      row.message = result.trajectory.message;
      row.cpu_time = timing.seconds;
      row.repeats = timing.repeats;
      row.Fsh_rms = result.metrics.Fsh_rms;
      row.Msh_rms = result.metrics.Msh_rms;
      const bool ok = result.ok() && reference_ok[rf];
      row.Fsh_rms_error = relative(row.Fsh_rms, ref.Fsh_rms, ok);
      row.Msh_rms_error = relative(row.Msh_rms, ref.Msh_rms, ok);
      if (samples == 360 || samples == options.samples.back()) {
        summary += " " + std::to_string(samples) + ": " + text::digits(1e6 * row.cpu_time, 3) +
                   " us, errors " + text::digits(row.Fsh_rms_error, 3) + ", " +
                   text::digits(row.Msh_rms_error, 3) + ";";
      }
      rows.push_back(std::move(row));
    }
    if (options.progress) {
      options.progress(std::string("bench: ") + core::to_string(f) + " (" +
                       text::digits(cpu_seconds() - start, 3) + " s):" + summary);
    }
  }
  return rows;
}

std::string work_precision_csv(const std::vector<WorkPrecisionRow>& rows) {
  std::string s = std::string(kWorkPrecisionHeader) + "\n";
  for (const WorkPrecisionRow& r : rows) {
    s += std::string(core::to_string(r.formulation)) + "," + core::to_string(r.integrator) + "," +
         csv_number(r.tolerance) + "," + core::to_string(r.reference_formulation) + "," +
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
    s += std::string(core::to_string(r.formulation)) + "," + std::to_string(r.samples) + "," +
         core::to_string(r.reference_formulation) + "," + std::to_string(r.reference_samples) +
         "," + core::to_string(r.status) + "," + csv_number(r.cpu_time) + "," +
         std::to_string(r.repeats) + "," + csv_number(r.Fsh_rms) + "," + csv_number(r.Msh_rms) +
         "," + csv_number(r.Fsh_rms_error) + "," + csv_number(r.Msh_rms_error) + "," +
         csv_line_field(r.message) + "\n";
  }
  return s;
}

BenchResult write_bench(const Study& study, const fs::path& out_dir, const BenchOptions& options) {
  check(options);
  BenchResult result;
  if (std::holds_alternative<core::FreeScene>(study.scene)) {
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
