#include "studies/run/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <variant>

#include "core/number_text.hpp"
#include "core/planar/from_fourbar.hpp"
#include "core/planar/metrics.hpp"

namespace bd::studies {

void DisplayScales::add(const std::string& unit, double value) {
  if (!std::isfinite(value)) return;
  if (unit == "N") force = std::max(force, std::abs(value));
  if (unit == "N m") moment = std::max(moment, std::abs(value));
  if (unit == "kg m") imbalance = std::max(imbalance, std::abs(value));
}

void DisplayScales::add(const MetricList& metrics) {
  for (const MetricValue& m : metrics) add(m.unit, m.value);
}

double DisplayScales::of(const std::string& unit) const {
  if (unit == "m") return length;
  if (unit == "N") return force;
  if (unit == "N m") return std::max(moment, force * length);
  if (unit == "kg m") return imbalance;
  return 0;
}

namespace {

core::Trajectory closed_form(const Study& study, const MethodChoice& method,
                             const Tolerances& tolerances) {
  core::SimulateOptions options;
  options.formulation = method.formulation;
  options.integrator = method.integrator;
  options.tolerance = tolerances.relative;
  options.absolute_tolerance = tolerances.absolute;
  if (const auto* free = std::get_if<core::FreeScene>(&study.scene)) {
    return core::simulate_free(study.fourbar(), *free, options);
  }
  return core::simulate_driven(study.fourbar(), std::get<core::DrivenScene>(study.scene), options);
}

// how the general engine integrates a free scene by the method, at the tolerances
core::planar::SimulateOptions free_options(const MethodChoice& method,
                                           const Tolerances& tolerances) {
  core::planar::SimulateOptions options;
  options.route = method.route();
  options.integrator = method.integrator;
  options.tolerance = tolerances.relative;
  options.absolute_tolerance = tolerances.absolute;
  return options;
}

core::planar::Trajectory general_engine(const core::planar::Model& model, const Scene& scene,
                                        const MethodChoice& method, const Tolerances& tolerances) {
  if (const auto* driven = std::get_if<core::planar::DrivenScene>(&scene)) {
    return core::planar::simulate_driven(model, *driven);
  }
  return core::planar::simulate_free(model, std::get<core::planar::FreeScene>(scene),
                                     free_options(method, tolerances));
}

// a four-bar scene as the general engine's: the crank the one input
Scene planar_scene(const Scene& scene) {
  if (const auto* f = std::get_if<core::FreeScene>(&scene)) {
    return core::planar::FreeScene{{f->theta1}, {f->omega1}, f->duration, f->samples};
  }
  const auto& d = std::get<core::DrivenScene>(scene);
  return core::planar::DrivenScene{{d.theta1}, {d.omega1}, d.revolutions, 0, d.samples};
}

Simulation simulate_unchecked(const Study& study, const MethodChoice& method,
                              const Tolerances& tolerances);

// "the run stopped at a value that is not finite", naming the instant and the value
std::string non_finite_message(double t, const std::string& where, const std::string& column,
                               double value) {
  return "a computed value is not finite at t = " + text::digits(t, 10) + " s" + where + " (" +
         column + " = " + text::shortest(value) +
         "): the linkage's numbers leave the range of double precision; the samples before it "
         "are kept";
}

// No NaN or infinity is ever data (issue 17): a run whose sample holds one stops at that
// sample, as at a singular position, keeping the samples before it. The engines check their
// own results; this is the one guard every run (original, balanced, optimised, a sweep's point)
// passes before its numbers reach a file.
void stop_at_non_finite(core::Trajectory& r) {
  for (std::size_t i = 0; i < r.samples.size(); ++i) {
    const core::DynamicsSample& s = r.samples[i];
    const core::FourBarState& q = s.state;
    // every number of the sample, and below its column's name (one list, in the same order)
    const double values[] = {i < r.t.size() ? r.t[i] : 0.0,
                             q.theta1, q.theta2, q.theta3, q.omega1, q.omega2, q.omega3,
                             q.alpha1, q.alpha2, q.alpha3, s.RA0.x(), s.RA0.y(), s.RA3.x(),
                             s.RA3.y(), s.RC1.x(), s.RC1.y(), s.RC3.x(), s.RC3.y(), s.Fsh.x(),
                             s.Fsh.y(), s.Msh, s.tau};
    static constexpr const char* kNames[] = {
        "t",    "theta1", "theta2", "theta3", "omega1", "omega2", "omega3", "alpha1",
        "alpha2", "alpha3", "RA0x", "RA0y", "RA3x", "RA3y", "RC1x", "RC1y",
        "RC3x", "RC3y",   "Fshx",   "Fshy",   "Msh",    "tau"};
    static_assert(std::size(kNames) == std::size(values));
    // the common case in one branch-free pass: 0 * v is 0 for every finite v, NaN for an
    // infinity or a NaN; the names are looked at only where that fails (four sums side by
    // side, so that the additions need not wait for each other)
    constexpr std::size_t kCount = std::size(values);
    double a0 = 0.0, a1 = 0.0, a2 = 0.0, a3 = 0.0;
    std::size_t k = 0;
    for (; k + 4 <= kCount; k += 4) {
      a0 += 0.0 * values[k];
      a1 += 0.0 * values[k + 1];
      a2 += 0.0 * values[k + 2];
      a3 += 0.0 * values[k + 3];
    }
    for (; k < kCount; ++k) a0 += 0.0 * values[k];
    if ((a0 + a1) + (a2 + a3) == 0.0) continue;
    for (k = 0; k < kCount; ++k) {
      const double v = values[k];
      if (std::isfinite(v)) continue;
      const double t = i < r.t.size() ? r.t[i] : 0.0;
      const std::string where = std::isfinite(q.theta1)
                                    ? ", theta1 = " + text::digits(q.theta1, 10) + " rad"
                                    : std::string();
      r.message = non_finite_message(t, where, kNames[k], v);
      r.status = core::SimulationStatus::kIntegratorFailed;
      r.samples.resize(i);
      r.t.resize(std::min(r.t.size(), i));
      return;
    }
  }
}

void stop_at_non_finite(core::planar::Trajectory& r) {
  core::Series& table = r.table;
  const std::size_t width = table.width();
  const int tc = table.column("t");
  for (std::size_t i = 0; i < table.rows(); ++i) {
    for (std::size_t k = 0; k < width; ++k) {
      const double v = table.at(i, k);
      if (std::isfinite(v)) continue;
      const double t = tc >= 0 ? table.at(i, static_cast<std::size_t>(tc)) : 0.0;
      r.message = non_finite_message(t, "", table.columns[k], v);
      r.status = core::SimulationStatus::kIntegratorFailed;
      table.values.resize(i * width);
      r.states.resize(std::min(r.states.size(), i * r.state_size));
      return;
    }
  }
}

}  // namespace

RunStatus run_status(const core::Trajectory& t) {
  return {t.status, t.message, t.samples.size(), t.steps, t.rhs_evaluations};
}

RunStatus run_status(const core::planar::Trajectory& t) {
  return {t.status, t.message, t.table.rows(), t.steps, t.rhs_evaluations};
}

RunStatus Simulation::status() const {
  return is_planar ? run_status(planar) : run_status(fourbar);
}

Simulation simulate(const Study& study) { return simulate(study, choose_method(study)); }

Simulation simulate(const Study& study, const MethodChoice& method) {
  return simulate(study, method, Tolerances{study.tolerance, Tolerances{}.absolute});
}

Simulation simulate(const Study& study, const MethodChoice& method, const Tolerances& tolerances) {
  Simulation s = simulate_unchecked(study, method, tolerances);
  if (s.is_planar) {
    stop_at_non_finite(s.planar);
  } else {
    stop_at_non_finite(s.fourbar);
  }
  return s;
}

namespace {

Simulation simulate_unchecked(const Study& study, const MethodChoice& method,
                              const Tolerances& tolerances) {
  Simulation s;
  s.method = method;
  s.tolerances = tolerances;
  if (study.is_fourbar()) {
    if (!method.general_engine()) {
      s.fourbar = closed_form(study, method, tolerances);
      return s;
    }
    const core::FourBar& fb = study.fourbar();
    const core::planar::Model model(
        core::planar::linkage_of(fb, crank_angle_at_start(study.scene)));
    core::planar::Trajectory run =
        general_engine(model, planar_scene(study.scene), method, tolerances);
    s.fourbar = core::planar::fourbar_trajectory(run);
    // a driven run's peaks are resolved by the engine (fourbar_metrics()); a free run's by the
    // closed form from its samples, which need no copy of the engine's table
    if (!is_free(study.scene)) s.engine = std::move(run);
    return s;
  }
  s.is_planar = true;
  const core::planar::Model model(study.planar());
  s.planar = general_engine(model, study.scene, method, tolerances);
  // auto, free: a limit position stops the reduced equations; the DAE passes through it
  if (study.method == Method::kAuto && is_free(study.scene) &&
      s.planar.status == core::SimulationStatus::kSingular && method.method == Method::kTruss) {
    const MethodChoice dae = through_limits(method, s.planar.message);
    s.method = dae;
    s.planar = general_engine(model, study.scene, dae, tolerances);
  }
  return s;
}

}  // namespace

namespace {
// whether a four-bar's metric is one of the model's: a counter-rotation shaft's only with its
// disc
bool has_metric(const core::FourBar& model, std::string_view name) {
  if (name.starts_with("RC1_")) return model.counter_rotations.crank.inertia > 0;
  if (name.starts_with("RC3_")) return model.counter_rotations.rocker.inertia > 0;
  return true;
}
}  // namespace

MetricList metric_list(const core::FourBar& model, const core::Metrics& metrics,
                       const core::PeakList* peaks) {
  MetricList list;
  // a peak's place: its time and, in a free scene, the crank's angle there
  auto add = [&](const char* name, const char* unit, double value, const std::vector<core::Peak>* p,
                 std::size_t k, core::Statistic s) {
    const bool peak = p && k < p->size() && s == core::Statistic::kMax;
    list.push_back({name, unit, value, peak ? std::optional<double>((*p)[k].t) : std::nullopt,
                    peak ? (*p)[k].inputs : std::vector<double>{}});
  };
  for (std::size_t k = 0; k < core::kMetricCount; ++k) {
    const core::MetricInfo& info = core::kMetricTable[k];
    add(info.name, info.unit, metrics.*info.field, peaks ? &peaks->table : nullptr, k,
        info.statistic);
  }
  for (std::size_t k = 0; k < std::size(core::kOutputMetrics); ++k) {
    const core::OutputMetricInfo& info = core::kOutputMetrics[k];
    if (!has_metric(model, info.name)) continue;
    add(info.name, info.unit, metrics.*info.field, peaks ? &peaks->output : nullptr, k,
        info.statistic);
  }
  return list;
}

core::Metrics fourbar_metrics(const Study& study, const Simulation& simulation,
                              core::PeakList* peaks) {
  const auto* driven = std::get_if<core::DrivenScene>(&study.scene);
  if (!driven) {
    // the peaks located between the samples by the closed form: the run's own formulation and
    // integrator, or, for a run on the general engine, the mass-matrix form where the crank
    // turns fully and the opened loop where it reaches limit positions (which it passes)
    core::SimulateOptions options;
    if (simulation.method.general_engine()) {
      options.formulation = core::crank_turns_fully(study.fourbar())
                                ? core::Formulation::kMassMatrix
                                : core::Formulation::kOpenedLoop;
    } else {
      options.formulation = simulation.method.formulation;
      options.integrator = simulation.method.integrator;
    }
    options.tolerance = simulation.tolerances.relative;
    options.absolute_tolerance = simulation.tolerances.absolute;
    return core::metrics(study.fourbar(), simulation.fourbar, options, peaks);
  }
  if (simulation.method.general_engine() && simulation.engine.table.rows() > 0) {
    // the peaks resolved by the engine that computed the run: it follows the linkage closer to
    // a dead centre than the closed forms' singular test, which declines there
    const core::FourBar& fb = study.fourbar();
    const core::planar::Model model(
        core::planar::linkage_of(fb, crank_angle_at_start(study.scene)));
    const Scene scene = planar_scene(study.scene);
    const auto& engine_scene = std::get<core::planar::DrivenScene>(scene);
    const core::planar::FourBarSampleOf sample_of(simulation.engine.table);
    const std::size_t width = simulation.engine.table.width();
    core::planar::DrivenRows rows(model, engine_scene, simulation.engine);
    return core::metrics(
        simulation.fourbar, rows.period(),
        [&](double s) -> std::optional<core::DynamicsSample> {
          const double* row = rows.at(s);
          if (!row) return std::nullopt;
          return sample_of({row, width});
        },
        peaks);
  }
  return core::metrics(study.fourbar(), *driven, simulation.fourbar, simulation.method.formulation,
                       peaks);
}

std::vector<std::string> metric_names(const Study& study) {
  std::vector<std::string> names;
  if (study.is_fourbar()) {
    for (const core::MetricInfo& info : core::kMetricTable) names.emplace_back(info.name);
    for (const core::OutputMetricInfo& info : core::kOutputMetrics) {
      if (has_metric(study.fourbar(), info.name)) names.emplace_back(info.name);
    }
  } else {
    for (const auto& m : core::planar::metric_table(core::planar::Model(study.planar()))) {
      names.push_back(m.name);
    }
  }
  return names;
}

MetricList& without_samples_none(MetricList& list, const Simulation& simulation) {
  const std::size_t samples =
      simulation.is_planar ? simulation.planar.table.rows() : simulation.fourbar.samples.size();
  if (samples > 0) return list;
  for (MetricValue& m : list) {
    m.value = std::numeric_limits<double>::quiet_NaN();
    m.t.reset();
    m.inputs.clear();
  }
  return list;
}

MetricList metric_list(const Study& study, const Simulation& simulation) {
  if (!simulation.is_planar) {
    core::PeakList peaks;
    const core::Metrics m = fourbar_metrics(study, simulation, &peaks);
    return metric_list(study.fourbar(), m, &peaks);
  }
  const core::planar::Model model(study.planar());
  const std::vector<core::planar::ColumnMetric> table = core::planar::metric_table(model);
  std::vector<core::Peak> peaks;
  std::vector<double> values;
  if (const auto* driven = std::get_if<core::planar::DrivenScene>(&study.scene)) {
    values = core::planar::metric_values(model, *driven, table, simulation.planar, &peaks);
  } else {
    // the run continued between its samples as it was integrated
    values = core::planar::metric_values(
        model, free_options(simulation.method, simulation.tolerances), table, simulation.planar,
        &peaks);
  }
  MetricList list;
  for (std::size_t k = 0; k < table.size(); ++k) {
    const bool peak = table[k].statistic == core::Statistic::kMax && k < peaks.size();
    list.push_back({table[k].name, table[k].unit, values[k],
                    peak ? std::optional<double>(peaks[k].t) : std::nullopt,
                    peak ? peaks[k].inputs : std::vector<double>{}});
  }
  return list;
}

}  // namespace bd::studies
