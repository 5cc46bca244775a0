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
#include "studies/report/report.hpp"
#include "studies/report/report_support.hpp"

namespace bd::studies {

namespace fs = std::filesystem;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// "%.17g" of a value, empty for NaN (as the data files write it)
std::string csv_number(double x) {
  if (std::isnan(x)) return "";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

std::string short_number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", x);
  return buf;
}

// a CSV field, quoted (RFC 4180)
std::string quoted(const std::string& text) {
  std::string q = "\"";
  for (char c : text) q += c == '"' ? std::string("\"\"") : std::string(1, c == '\n' ? ' ' : c);
  return q + "\"";
}

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

// the other formulation that references f (DESIGN.md: they must agree to round-off)
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
    if (!(t > 0 && t < 1)) return "every tolerance must be > 0 and < 1, got " + short_number(t);
  }
  if (!(reference_tolerance > 0 && reference_tolerance < 1)) {
    return "reference_tolerance must be > 0 and < 1, got " + short_number(reference_tolerance);
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
    return "min_time must be >= 0 s, got " + short_number(min_time);
  }
  if (!(long_run >= 0) || !std::isfinite(long_run)) {
    return "long_run must be >= 0 s, got " + short_number(long_run);
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
      it = computed.emplace(f, core::simulate_free(study.model, *scene, o)).first;
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
            timed(options, [&] { return core::simulate_free(study.model, *scene, o); });
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
        summary += " " + short_number(tolerance) + ": " +
                   (trajectory.ok() ? short_number(1e3 * row.cpu_time) + " ms " +
                                          short_number(row.digits) + " digits"
                                    : std::string(core::to_string(trajectory.status))) +
                   ";";
        rows.push_back(std::move(row));
      }
      if (options.progress) {
        options.progress(std::string("bench: ") + core::to_string(f) + " / " +
                         core::to_string(integrator) + " (" + short_number(cpu_seconds() - start) +
                         " s):" + summary);
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
    return core::simulate_driven(study.model, one, o);
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
        summary += " " + std::to_string(samples) + ": " + short_number(1e6 * row.cpu_time) +
                   " us, errors " + short_number(row.Fsh_rms_error) + ", " +
                   short_number(row.Msh_rms_error) + ";";
      }
      rows.push_back(std::move(row));
    }
    if (options.progress) {
      options.progress(std::string("bench: ") + core::to_string(f) + " (" +
                       short_number(cpu_seconds() - start) + " s):" + summary);
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
         "," + quoted(r.message) + "\n";
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
         quoted(r.message) + "\n";
  }
  return s;
}

BenchResult run_bench(const Study& study, const fs::path& out_dir, const BenchOptions& options) {
  check(options);
  const bool free = std::holds_alternative<core::FreeScene>(study.scene);
  // no stale measurements in the report that run_study() writes
  for (const char* name : {"work-precision.csv", "driven-convergence.csv"}) {
    std::error_code ec;
    fs::remove(out_dir / name, ec);
  }
  BenchResult result;
  result.run = run_study(study, out_dir);
  if (free) {
    result.free_rows = work_precision(study, options);
    result.csv = out_dir / "work-precision.csv";
    write_text_file(work_precision_csv(result.free_rows), result.csv);
  } else {
    result.driven_rows = driven_convergence(study, options);
    result.csv = out_dir / "driven-convergence.csv";
    write_text_file(driven_convergence_csv(result.driven_rows), result.csv);
  }
  try {
    result.report = write_report(study, out_dir);
  } catch (const std::exception& e) {
    std::error_code ec;
    fs::remove(out_dir / "report.html", ec);  // never a page without the measurements
    std::fprintf(stderr, "balance-design: warning: report.html not written: %s\n", e.what());
  }
  return result;
}

// ---------------------------------------------------------------------------------------------
// the report section

namespace {

using report_support::Chart;
using report_support::Csv;
using report_support::esc;
using report_support::fmt;
using report_support::gp_string;

// the column index of `name` in a CSV header
std::size_t column(const Csv& csv, const char* name, const fs::path& file) {
  const auto it = std::find(csv.header.begin(), csv.header.end(), name);
  if (it == csv.header.end()) {
    throw std::runtime_error(file.string() + ": no column " + name);
  }
  return static_cast<std::size_t>(it - csv.header.begin());
}

double number_at(const std::vector<std::string>& row, std::size_t i) {
  if (i >= row.size() || row[i].empty()) return kNaN;
  char* end = nullptr;
  const double v = std::strtod(row[i].c_str(), &end);
  return end == row[i].c_str() ? kNaN : v;
}

const char* const kChartNotice =
    "<p class=\"notice\">The charts need gnuplot, which was not found on this machine; the table "
    "and the data file hold every number.</p>\n";

std::string figure(const Chart& chart, const std::string& svg) {
  return "<h3>" + esc(chart.heading) + "</h3>\n<figure class=\"chart\" id=\"chart-" + chart.id +
         "\">\n" + svg + "\n<figcaption>" + esc(chart.caption) + "</figcaption>\n</figure>\n";
}

// the line colour and point type of an integrator, the same in every chart
std::string line_style(const std::string& integrator) {
  static const char* const colours[] = {"#9400d3", "#009e73", "#56b4e9", "#e69f00", "#c8b400",
                                        "#0072b2", "#e51e10", "#000000", "#a0522d"};
  std::size_t i = 0;
  for (core::Integrator k : core::kIntegrators) {
    if (integrator == core::to_string(k)) break;
    ++i;
  }
  return " lc rgb '" + std::string(colours[i % 9]) + "' pt " + std::to_string(i + 1);
}

std::string free_section(const fs::path& file, const std::string& gnuplot) {
  const Csv csv = report_support::read_csv(file);
  const std::size_t c_f = column(csv, "formulation", file), c_i = column(csv, "integrator", file),
                    c_tol = column(csv, "tolerance", file), c_st = column(csv, "status", file),
                    c_t = column(csv, "cpu_time", file), c_e = column(csv, "final_error", file),
                    c_d = column(csv, "digits", file), c_m = column(csv, "max_error", file),
                    c_steps = column(csv, "steps", file),
                    c_rf = column(csv, "reference_formulation", file),
                    c_ri = column(csv, "reference_integrator", file),
                    c_rt = column(csv, "reference_tolerance", file);

  // methods in file order, each with its rows
  std::vector<std::pair<std::string, std::string>> methods;
  std::map<std::pair<std::string, std::string>, std::vector<const std::vector<std::string>*>> of;
  for (const auto& row : csv.rows) {
    if (row.size() < csv.header.size()) continue;
    const auto key = std::pair{row[c_f], row[c_i]};
    if (of.find(key) == of.end()) methods.push_back(key);
    of[key].push_back(&row);
  }
  std::vector<std::string> formulations;
  for (const auto& m : methods) {
    if (std::find(formulations.begin(), formulations.end(), m.first) == formulations.end()) {
      formulations.push_back(m.first);
    }
  }

  std::string h =
      "<p>From <a href=\"work-precision.csv\">work-precision.csv</a> (<code>balance-design "
      "bench</code>): every formulation with every integrator it supports, at each tolerance "
      "(absolute tolerance 1e-2 of it), the median CPU time of one run of the study's free "
      "scene against its error. The error is that of &theta;1..&theta;3 against a reference "
      "computed by a different formulation";
  if (!csv.rows.empty() && csv.rows.front().size() > c_rt) {
    const auto& r = csv.rows.front();
    h += " (" + esc(r[c_ri]) + " at tolerance " + esc(fmt(number_at(r, c_rt), "%.0e")) +
         "; the reference of " + esc(r[c_f]) + " is " + esc(r[c_rf]) + ")";
  }
  h += ": the largest relative error at the final time (its -log10 is the number of correct "
       "digits) and the largest error over all samples.</p>\n";

  // the charts: one per formulation, a line per integrator
  std::string datablocks;
  std::vector<Chart> charts;
  for (std::size_t fi = 0; fi < formulations.size(); ++fi) {
    std::string plot;
    int lines = 0;
    for (std::size_t mi = 0; mi < methods.size(); ++mi) {
      if (methods[mi].first != formulations[fi]) continue;
      const std::string block = "$wp_" + std::to_string(mi);
      std::string data;
      for (const auto* row : of[methods[mi]]) {
        const double e = number_at(*row, c_e), t = number_at(*row, c_t);
        if ((*row)[c_st] != "completed" || !(e > 0) || !(t > 0)) continue;
        data += fmt(e, "%.6g") + "," + fmt(1e3 * t, "%.6g") + "\n";
      }
      if (data.empty()) continue;
      datablocks += block + " << EOD\n" + data + "EOD\n";
      ++lines;
      plot += std::string(lines > 1 ? ", " : "") + block + " using 1:2 with linespoints lw 2" +
              line_style(methods[mi].second) + " title " + gp_string(methods[mi].second);
    }
    if (lines == 0) continue;
    charts.push_back(
        {"work-precision-" + formulations[fi], "Work-precision: " + formulations[fi],
         "CPU time of one run against the largest relative error of theta1..theta3 at the "
         "final time, one line per integrator, one point per tolerance (more accurate to the "
         "right); runs that stopped early are left out. From work-precision.csv.",
         "set logscale xy\nset format x '1e%L'\nset xrange [*:*] reverse\n"
         "set xlabel 'relative error at the final time'\nset ylabel 'CPU time per run [ms]'\n"
         "plot " +
             plot});
  }

  // the compact table: per method, the run at tolerance 1e-10 and the cheapest run with
  // 10 correct digits
  h += "<table><tr><th>formulation</th><th>integrator</th><th>at tolerance 1e-10: CPU time "
       "[ms]</th><th>digits</th><th>max error [rad]</th><th>steps</th><th>cheapest run with "
       "&ge; 10 digits: tolerance</th><th>CPU time [ms]</th><th>failed runs</th></tr>";
  for (const auto& m : methods) {
    const std::vector<std::string>* at = nullptr;
    const std::vector<std::string>* best = nullptr;
    int failed = 0;
    for (const auto* row : of[m]) {
      if ((*row)[c_st] != "completed") ++failed;
      if (std::abs(number_at(*row, c_tol) / 1e-10 - 1) < 1e-6) at = row;
      if ((*row)[c_st] == "completed" && number_at(*row, c_d) >= 10 &&
          (best == nullptr || number_at(*row, c_t) < number_at(*best, c_t))) {
        best = row;
      }
    }
    const auto cell = [](double v, const char* f) {
      return std::isnan(v) ? std::string("<td class=\"n\">&ndash;</td>")
                           : "<td class=\"n\">" + esc(fmt(v, f)) + "</td>";
    };
    h += "<tr><td>" + esc(m.first) + "</td><td>" + esc(m.second) + "</td>";
    if (at != nullptr && (*at)[c_st] == "completed") {
      h += cell(1e3 * number_at(*at, c_t), "%.3g") + cell(number_at(*at, c_d), "%.1f") +
           cell(number_at(*at, c_m), "%.2g") + cell(number_at(*at, c_steps), "%.0f");
    } else {
      h += "<td colspan=\"4\">" + esc(at != nullptr ? (*at)[c_st] : std::string("not run")) +
           "</td>";
    }
    if (best != nullptr) {
      h += cell(number_at(*best, c_tol), "%.0e") + cell(1e3 * number_at(*best, c_t), "%.3g");
    } else {
      h += "<td colspan=\"2\">none</td>";
    }
    h += "<td class=\"n\">" + std::to_string(failed) + "</td></tr>";
  }
  h += "</table>\n";

  if (gnuplot.empty()) return h + kChartNotice;
  const std::vector<std::string> svgs = report_support::draw(gnuplot, datablocks, charts);
  for (std::size_t i = 0; i < charts.size(); ++i) h += figure(charts[i], svgs[i]);
  return h;
}

std::string driven_section(const fs::path& file, const std::string& gnuplot) {
  const Csv csv = report_support::read_csv(file);
  const std::size_t c_f = column(csv, "formulation", file), c_n = column(csv, "samples", file),
                    c_st = column(csv, "status", file), c_t = column(csv, "cpu_time", file),
                    c_ef = column(csv, "Fsh_rms_error", file),
                    c_em = column(csv, "Msh_rms_error", file),
                    c_rf = column(csv, "reference_formulation", file),
                    c_rn = column(csv, "reference_samples", file);
  std::vector<std::string> formulations;
  std::map<std::string, std::vector<const std::vector<std::string>*>> of;
  for (const auto& row : csv.rows) {
    if (row.size() < csv.header.size()) continue;
    if (of.find(row[c_f]) == of.end()) formulations.push_back(row[c_f]);
    of[row[c_f]].push_back(&row);
  }

  std::string h =
      "<p>From <a href=\"driven-convergence.csv\">driven-convergence.csv</a> "
      "(<code>balance-design bench</code>): one revolution of the study's driven scene per "
      "formulation and number of samples per revolution, its median CPU time, and the relative "
      "error of its RMS shaking force and moment against a revolution of ";
  if (!csv.rows.empty()) {
    h += esc(csv.rows.front()[c_rn]) + " samples computed by a different formulation (that of " +
         esc(csv.rows.front()[c_f]) + " is " + esc(csv.rows.front()[c_rf]) + ")";
  }
  h += ". Evenly spaced samples of a periodic motion make the RMS a trapezoidal rule of a "
       "smooth periodic function, which converges faster than any power of the samples "
       "(spectrally) down to round-off.</p>\n";

  std::string datablocks, errors, times;
  int lines = 0;
  for (std::size_t fi = 0; fi < formulations.size(); ++fi) {
    std::string ef, em, t;
    for (const auto* row : of[formulations[fi]]) {
      if ((*row)[c_st] != "completed") continue;
      const double n = number_at(*row, c_n);
      const double e1 = number_at(*row, c_ef), e2 = number_at(*row, c_em);
      const double ct = number_at(*row, c_t);
      if (e1 > 0) ef += fmt(n, "%.0f") + "," + fmt(e1, "%.6g") + "\n";
      if (e2 > 0) em += fmt(n, "%.0f") + "," + fmt(e2, "%.6g") + "\n";
      if (ct > 0) t += fmt(n, "%.0f") + "," + fmt(1e6 * ct, "%.6g") + "\n";
    }
    const std::string id = std::to_string(fi);
    const std::string name = formulations[fi];
    const auto add = [&](const std::string& block, const std::string& data, std::string& plot,
                         const std::string& title, int dash) {
      if (data.empty()) return;
      datablocks += block + " << EOD\n" + data + "EOD\n";
      plot += std::string(plot.empty() ? "" : ", ") + block +
              " using 1:2 with linespoints lw 2 lc " + std::to_string(fi + 1) + " dt " +
              std::to_string(dash) + " pt " + std::to_string(fi + 5) + " title " + gp_string(title);
      ++lines;
    };
    add("$dc_f" + id, ef, errors, name + ": Fsh_rms", 1);
    add("$dc_m" + id, em, errors, name + ": Msh_rms", 2);
    add("$dc_t" + id, t, times, name, 1);
  }
  std::vector<Chart> charts;
  if (!errors.empty()) {
    charts.push_back({"driven-convergence-error", "RMS error against samples per revolution",
                      "Relative error of the RMS shaking force and moment of one revolution "
                      "against the reference, per formulation; errors of exactly 0 are left "
                      "out. From driven-convergence.csv.",
                      "set logscale xy\nset format y '1e%L'\nset xlabel 'samples per "
                      "revolution'\nset ylabel 'relative error of the RMS'\nplot " +
                          errors});
  }
  if (!times.empty()) {
    charts.push_back({"driven-convergence-time", "CPU time against samples per revolution",
                      "Median CPU time of one revolution (core::simulate_driven and "
                      "core::metrics), per formulation. From driven-convergence.csv.",
                      "set logscale xy\nset xlabel 'samples per revolution'\nset ylabel 'CPU "
                      "time per revolution [us]'\nplot " +
                          times});
  }

  h += "<table><tr><th>formulation</th><th>samples for both errors &lt; 1e-12</th><th>CPU time "
       "[&micro;s]</th><th>at 360 samples: CPU time [&micro;s]</th><th>Fsh_rms error</th>"
       "<th>Msh_rms error</th></tr>";
  for (const std::string& f : formulations) {
    const std::vector<std::string>* enough = nullptr;
    const std::vector<std::string>* at = nullptr;
    for (const auto* row : of[f]) {
      const double e1 = number_at(*row, c_ef), e2 = number_at(*row, c_em);
      const bool small = (std::isnan(e1) || e1 < 1e-12) && (std::isnan(e2) || e2 < 1e-12) &&
                         !(std::isnan(e1) && std::isnan(e2));
      if ((*row)[c_st] == "completed" && small && enough == nullptr) enough = row;
      if ((*row)[c_n] == "360") at = row;
    }
    const auto cell = [](const std::string& v) { return report_support::num_cell(v); };
    h += "<tr><td>" + esc(f) + "</td>";
    h += enough != nullptr ? cell((*enough)[c_n]) + "<td class=\"n\">" +
                                 esc(fmt(1e6 * number_at(*enough, c_t), "%.3g")) + "</td>"
                           : std::string("<td colspan=\"2\">none</td>");
    h += at != nullptr ? "<td class=\"n\">" + esc(fmt(1e6 * number_at(*at, c_t), "%.3g")) +
                             "</td>" + cell((*at)[c_ef]) + cell((*at)[c_em])
                       : std::string("<td colspan=\"3\">not measured</td>");
    h += "</tr>";
  }
  h += "</table>\n";

  if (gnuplot.empty()) return h + kChartNotice;
  const std::vector<std::string> svgs = report_support::draw(gnuplot, datablocks, charts);
  for (std::size_t i = 0; i < charts.size(); ++i) h += figure(charts[i], svgs[i]);
  return h;
}

}  // namespace

std::string work_precision_section(const fs::path& dir, const std::string& gnuplot) {
  std::string h;
  std::error_code ec;
  if (fs::is_regular_file(dir / "work-precision.csv", ec)) {
    h += free_section(dir / "work-precision.csv", gnuplot);
  }
  if (fs::is_regular_file(dir / "driven-convergence.csv", ec)) {
    h += driven_section(dir / "driven-convergence.csv", gnuplot);
  }
  return h.empty() ? h : "<h2 id=\"speed-against-accuracy\">Speed against accuracy</h2>\n" + h;
}

}  // namespace bd::studies
