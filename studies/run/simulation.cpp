#include "studies/run/simulation.hpp"

#include <variant>

#include "core/planar/from_fourbar.hpp"
#include "core/planar/metrics.hpp"

namespace bd::studies {

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

core::planar::Trajectory general_engine(const core::planar::Model& model, const Scene& scene,
                                        const MethodChoice& method, const Tolerances& tolerances) {
  if (const auto* driven = std::get_if<core::planar::DrivenScene>(&scene)) {
    return core::planar::simulate_driven(model, *driven);
  }
  core::planar::SimulateOptions options;
  options.route = method.route();
  options.integrator = method.integrator;
  options.tolerance = tolerances.relative;
  options.absolute_tolerance = tolerances.absolute;
  return core::planar::simulate_free(model, std::get<core::planar::FreeScene>(scene), options);
}

// a four-bar scene as the general engine's: the crank the one input
Scene planar_scene(const Scene& scene) {
  if (const auto* f = std::get_if<core::FreeScene>(&scene)) {
    return core::planar::FreeScene{{f->theta1}, {f->omega1}, f->duration, f->samples};
  }
  const auto& d = std::get<core::DrivenScene>(scene);
  return core::planar::DrivenScene{{d.theta1}, {d.omega1}, d.revolutions, 0, d.samples};
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
  Simulation s;
  s.method = method;
  if (study.is_fourbar()) {
    if (!method.general_engine()) {
      s.fourbar = closed_form(study, method, tolerances);
      return s;
    }
    const core::FourBar& fb = study.fourbar();
    const core::planar::Model model(
        core::planar::linkage_of(fb, crank_angle_at_start(study.scene)));
    s.fourbar = core::planar::fourbar_trajectory(
        general_engine(model, planar_scene(study.scene), method, tolerances));
    return s;
  }
  s.is_planar = true;
  const core::planar::Model model(study.planar());
  s.planar = general_engine(model, study.scene, method, tolerances);
  // auto, free: a limit position stops the reduced equations; the DAE passes through it
  if (study.method == Method::kAuto && is_free(study.scene) &&
      s.planar.status == core::SimulationStatus::kSingular && method.method == Method::kTruss) {
    MethodChoice dae = method;
    dae.method = Method::kTrussDae;
    dae.reason =
        "planar linkage on the paper's truss elements, as a stabilised DAE in every node "
        "coordinate: the equations reduced to the inputs stopped at a limit position (" +
        s.planar.message + "), which the DAE passes through; integrated by CVODE Adams";
    s.method = dae;
    s.planar = general_engine(model, study.scene, dae, tolerances);
  }
  return s;
}

MetricList metric_list(const core::Metrics& metrics) {
  MetricList list;
  for (const core::MetricInfo& info : core::kMetricTable) {
    list.push_back({info.name, info.unit, metrics.*info.field});
  }
  return list;
}

std::vector<std::string> metric_names(const Study& study) {
  std::vector<std::string> names;
  if (study.is_fourbar()) {
    for (const core::MetricInfo& info : core::kMetricTable) names.emplace_back(info.name);
  } else {
    for (const auto& m : core::planar::metric_table(core::planar::Model(study.planar()))) {
      names.push_back(m.name);
    }
  }
  return names;
}

MetricList metric_list(const Study& study, const Simulation& simulation) {
  if (!simulation.is_planar) return metric_list(core::metrics(simulation.fourbar));
  const core::planar::Model model(study.planar());
  const std::vector<core::planar::ColumnMetric> table = core::planar::metric_table(model);
  const std::vector<double> values = core::planar::metric_values(table, simulation.planar.table);
  MetricList list;
  for (std::size_t k = 0; k < table.size(); ++k)
    list.push_back({table[k].name, table[k].unit, values[k]});
  return list;
}

}  // namespace bd::studies
