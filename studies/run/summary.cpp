// summary.json: what a run computed, as one JSON document written by nlohmann-json (keys in the
// order below, numbers in their shortest exact text; null only where a value was not computed,
// and a number that is not finite anywhere else an internal error, never written as null).
#include <algorithm>
#include <cassert>
#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "studies/run/files.hpp"
#include "studies/run/runner.hpp"

namespace bd::studies {

namespace {

using Json = nlohmann::ordered_json;

Json vec(const Vec2& v) { return Json::array({v.x(), v.y()}); }

// a value that may not have been computed (NaN): null then
Json value_or_null(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

// the metrics in their table's order
Json metrics_json(const MetricList& metrics) {
  Json j = Json::object();
  for (const MetricValue& m : metrics) j[m.name] = value_or_null(m.value);  // null: no samples
  return j;
}

// where each peak lies: its time, and in a driven scene the crank angle (a four-bar) or the
// inputs' values (a planar linkage) there
Json peaks_json(const Study& study, const MetricList& metrics) {
  Json j = Json::object();
  for (const MetricValue& m : metrics) {
    // a quantity that is 0 throughout (a free scene's drive torque) has no place to name
    if (!m.t || m.value == 0) continue;
    Json p = {{"value", m.value}, {"t", *m.t}};
    if (const auto* d = std::get_if<core::DrivenScene>(&study.scene)) {
      p["theta1"] = d->theta1 + d->omega1 * *m.t;
    } else if (const auto* pd = std::get_if<core::planar::DrivenScene>(&study.scene)) {
      std::vector<double> start =
          pd->start.empty() ? core::planar::drawn_inputs(core::planar::Model(study.planar()))
                            : pd->start;
      for (std::size_t k = 0; k < start.size() && k < pd->speeds.size(); ++k)
        start[k] += pd->speeds[k] * *m.t;
      p["inputs"] = start;
    } else if (!m.inputs.empty()) {
      // a free scene: where the motion had the inputs at that time
      if (study.is_fourbar()) {
        p["theta1"] = m.inputs[0];
      } else {
        p["inputs"] = m.inputs;
      }
    }
    j[m.name] = p;
  }
  return j;
}

// after / before per metric, paired by name as in comparison.csv; null where before is 0 (a
// metric the second design adds, a balance shaft's bearing force)
Json reduction_json(const MetricList& before, const MetricList& after) {
  Json j = Json::object();
  for (const ComparisonRow& row : compare_metrics(before, after)) {
    j[row.metric] = row.ratio ? value_or_null(*row.ratio) : Json(nullptr);
  }
  return j;
}

Json method_json(const Study& study, const MethodChoice& method) {
  return {{"requested", study.method_name()},
          {"used", to_string(method.method)},
          {"reason", method.reason},
          {"numerics", method.numerics}};
}

Json inputs_json(const std::vector<double>& values) {
  return values.empty() ? Json("as drawn") : Json(values);
}

Json scene_json(const Scene& scene) {
  if (const auto* free = std::get_if<core::FreeScene>(&scene)) {
    return {{"type", "free"},
            {"theta1", free->theta1},
            {"omega1", free->omega1},
            {"duration", free->duration},
            {"samples", free->samples}};
  }
  if (const auto* driven = std::get_if<core::DrivenScene>(&scene)) {
    return {{"type", "driven"},
            {"theta1", driven->theta1},
            {"omega1", driven->omega1},
            {"revolutions", driven->revolutions},
            {"samples", driven->samples}};
  }
  if (const auto* free = std::get_if<core::planar::FreeScene>(&scene)) {
    return {{"type", "free"},
            {"start", inputs_json(free->start)},
            {"rates", free->rates},
            {"duration", free->duration},
            {"samples", free->samples}};
  }
  const auto& driven = std::get<core::planar::DrivenScene>(scene);
  Json j = {{"type", "driven"}, {"start", inputs_json(driven.start)}, {"speeds", driven.speeds}};
  if (driven.duration > 0) {
    j["duration"] = driven.duration;
  } else {
    j["revolutions"] = driven.revolutions;
  }
  j["samples"] = driven.samples;
  return j;
}

// the harmonic orders of a driven run: per order Fshx, Fshy, Msh (amplitude, phase) and the
// force's parts turning with and against the input
Json harmonics_json(const Harmonics& h) {
  auto real = [](const core::Harmonic& x) {
    return Json{{"amplitude", x.amplitude}, {"phase", x.phase}};
  };
  Json orders = Json::array();
  for (const HarmonicOrder& o : h.orders) {
    orders.push_back(
        {{"order", o.order},
         {"Fshx", real(o.Fshx)},
         {"Fshy", real(o.Fshy)},
         {"Fsh_forward", {{"amplitude", o.Fsh.forward}, {"phase", o.Fsh.forward_phase}}},
         {"Fsh_backward", {{"amplitude", o.Fsh.backward}, {"phase", o.Fsh.backward_phase}}},
         {"Msh", real(o.Msh)},
         {"tau", real(o.tau)}});
  }
  return {{"input", h.input}, {"speed", h.speed}, {"samples", h.samples}, {"orders", orders}};
}

// a run's facts (status, counts), added to `j`
void add_run_fields(Json& j, const RunStatus& r) {
  j["samples"] = r.samples;
  j["status"] = core::to_string(r.status);
  j["ok"] = r.ok();
  j["message"] = r.message;
  j["steps"] = r.steps;
  j["rhs_evaluations"] = r.rhs_evaluations;
}

Json counterweight_json(const char* link, balance::CounterweightShape shape,
                        const balance::Counterweight& c) {
  return {{"link", link},
          {"shape", balance::to_string(shape)},
          {"mass", c.mass},
          {"position", vec(c.position)},
          {"distance", c.distance},
          {"radius", c.radius},
          {"thickness", c.thickness},
          {"inertia", c.inertia}};
}

// the balance section: what was asked, what was added, which conditions hold
Json balance_json(const balance::BalancedDesign& b) {
  Json j = {{"force", b.request.force ? "full" : "none"},
            {"moment", b.request.moment ? "full" : "none"}};
  Json cws = Json::array();
  if (b.crank_counterweight) {
    cws.push_back(
        counterweight_json("crank", b.request.crank_counterweight.shape, *b.crank_counterweight));
  }
  if (b.rocker_counterweight) {
    cws.push_back(counterweight_json("rocker", b.request.rocker_counterweight.shape,
                                     *b.rocker_counterweight));
  }
  j["counterweights"] = cws;
  Json discs = Json::array();
  const std::pair<const char*, const core::CounterRotation*> rotations[] = {
      {"crank", &b.model.counter_rotations.crank}, {"rocker", &b.model.counter_rotations.rocker}};
  for (const auto& [link, disc] : rotations) {
    if (disc->inertia > 0)
      discs.push_back({{"link", link}, {"inertia", disc->inertia}, {"at", vec(disc->at)}});
  }
  j["counter_rotations"] = discs;
  j["added_mass"] = b.added_mass;
  j["added_inertia"] = b.added_inertia;
  j["force_balanced"] = b.conditions.force_balanced();
  j["moment_balanced"] = b.conditions.moment_balanced();
  Json conditions = Json::array();
  // each condition with whether the study asked for its balance (a force-only study's moment
  // conditions are shown for what they are, not as failures)
  const std::pair<const std::vector<balance::Condition>*, bool> groups[] = {
      {&b.conditions.force, b.request.force}, {&b.conditions.moment, b.request.moment}};
  for (const auto& [group, asked] : groups) {
    for (const balance::Condition& c : *group) {
      conditions.push_back({{"name", c.name},
                            {"residual", c.residual},
                            {"scale", c.scale},
                            {"unit", c.unit},
                            {"holds", c.holds},
                            {"asked", asked}});
    }
  }
  j["conditions"] = conditions;
  return j;
}

// a counterweight on a planar linkage's link, with the node its position is measured from
Json planar_counterweight_json(const core::planar::Linkage& l,
                               const balance::planar::LinkCounterweight& c,
                               balance::CounterweightShape shape) {
  Json cw = counterweight_json(l.links[static_cast<std::size_t>(c.link)].name.c_str(), shape,
                               c.counterweight);
  cw["from_node"] = l.nodes[static_cast<std::size_t>(c.pivot)].name;
  return cw;
}

// a planar linkage's balance section: the counterweights added, whether full force balance is
// reached (else why not), and the inertial shaking force before and after
Json planar_balance_json(const Study& study, const BalancedRun& run) {
  const balance::planar::ForceBalance& b = *run.design;
  const core::planar::Linkage& l = study.planar();
  Json j = {{"force", "full"},
            {"moment", study.planar_balance->counter_rotations ? "full" : "none"}};
  if (b.balancing_factor) j["balancing_factor"] = *b.balancing_factor;
  Json cws = Json::array();
  for (const balance::planar::LinkCounterweight& c : b.added) {
    balance::CounterweightShape shape = balance::CounterweightShape::kPoint;
    for (const balance::planar::LinkCounterweightSpec& ask : study.planar_balance->counterweights) {
      if (ask.link == c.link) shape = ask.spec.shape;
    }
    cws.push_back(planar_counterweight_json(l, c, shape));
  }
  j["counterweights"] = cws;
  j["added_mass"] = b.added_mass;
  j["added_inertia"] = b.added_inertia;
  j["force_balanced"] = b.full;
  j["conditions"] = b.conditions;
  j["message"] = b.message;
  j["momentum_left"] = b.momentum_left;
  j["Fsh_inertial_rms_before"] = b.Fsh_rms_before;
  j["Fsh_inertial_rms_after"] = b.Fsh_rms_after;
  if (run.shafts) {
    Json shafts = Json::array();
    for (int i : run.shafts->added) {
      const core::planar::BalanceShaft& s = run.shafts->linkage.shafts[static_cast<std::size_t>(i)];
      shafts.push_back({{"name", s.name},
                        {"link", l.links[static_cast<std::size_t>(s.link)].name},
                        {"ratio", s.ratio},
                        {"at", {s.at.x(), s.at.y()}},
                        {"mass", s.mass},
                        {"eccentricity", {s.eccentricity.x(), s.eccentricity.y()}},
                        {"inertia", s.inertia}});
    }
    Json orders = Json::array();
    for (const balance::planar::ShaftBalance::Order& o : run.shafts->orders) {
      orders.push_back({{"order", o.order},
                        {"forward_before", o.forward_before},
                        {"backward_before", o.backward_before},
                        {"forward_after", o.forward_after},
                        {"backward_after", o.backward_after}});
    }
    j["shafts"] = {{"added", shafts}, {"orders", orders}};
  }
  if (study.planar_balance->counter_rotations) {
    j["moment_balanced"] = run.moment && run.moment->full;
    if (run.moment) {
      const balance::planar::MomentBalance& m = *run.moment;
      Json discs = Json::array();
      for (int i : m.added) {
        const core::planar::BalanceShaft& s = m.linkage.shafts[static_cast<std::size_t>(i)];
        discs.push_back({{"name", s.name},
                         {"link", l.links[static_cast<std::size_t>(s.link)].name},
                         {"ratio", s.ratio},
                         {"at", {s.at.x(), s.at.y()}},
                         {"inertia", s.inertia}});
      }
      j["counter_rotations"] = discs;
      j["angular_momentum_left"] = m.angular_momentum_left;
      j["Msh_inertial_rms_before"] = m.Msh_rms_before;
      j["Msh_inertial_rms_after"] = m.Msh_rms_after;
    }
  }
  return j;
}

// the optimum's counterweights, as the balance section writes them
Json optimum_counterweights_json(const OptimizeRequest& request,
                                 const std::vector<optimize::PlacedCounterweight>& cws) {
  Json items = Json::array();
  for (const optimize::PlacedCounterweight& p : cws) {
    balance::CounterweightShape shape = balance::CounterweightShape::kPoint;
    for (const optimize::CounterweightVariables& v : request.counterweights) {
      if (v.link == p.link) shape = v.shape;
    }
    items.push_back(counterweight_json(core::link_name(p.link), shape, p.counterweight));
  }
  return items;
}

// the problem as the study states it: solver, terms, constraints
Json problem_json(const OptimizeRequest& req, const MethodChoice& method) {
  Json j = {{"algorithm", optimize::to_string(req.options.algorithm)},
            {"formulation", to_string(method.method)}};
  Json terms = Json::array();
  for (const optimize::Term& t : req.objective) {
    terms.push_back({{"metric", optimize::to_string(t.metric)}, {"weight", t.weight}});
  }
  j["terms"] = terms;
  j["force_balance"] = req.force_balance;
  Json limits = Json::array();
  for (const optimize::Limit& l : req.limits) {
    const bool kg = l.metric == optimize::Metric::kAddedMass;
    limits.push_back({{"metric", optimize::to_string(l.metric)},
                      {"value", l.value},
                      {"unit", kg ? "kg" : "fraction of the original"}});
  }
  j["limits"] = limits;
  return j;
}

// how the solver ended and where (a four-bar's or a planar linkage's result)
template <class Result>
void add_solver_fields(Json& j, const Result& r, const OptimizedRun& o) {
  j["termination"] = optimize::to_string(r.termination);
  j["message"] = r.message;
  j["iterations"] = r.iterations;
  j["evaluations"] = r.evaluations;
  j["seconds"] = r.seconds;
  const bool found = o.found();
  j["objective"] = found ? Json(r.objective) : Json(nullptr);
  j["constraint_violation"] = found ? Json(r.constraint_violation) : Json(nullptr);
  // whether the optimum is proven global, and why (or why that is not proven)
  j["global"] = found && r.global;
  j["optimality"] = r.optimality;
  // a lower bound of the objective over every feasible design, and the optimum's gap above it
  const bool bounded = found && std::isfinite(r.lower_bound);
  j["lower_bound"] = bounded ? Json(r.lower_bound) : Json(nullptr);
  j["gap"] = bounded ? Json(r.objective - r.lower_bound) : Json(nullptr);
  j["lower_bound_source"] = r.lower_bound_source;
  // a multistart's local runs and how many reached the best value
  j["multistart"] = r.starts > 0 ? Json{{"starts", r.starts}, {"reaching_best", r.starts_at_best}}
                                 : Json(nullptr);
  Json variables = Json::array();
  if (static_cast<std::size_t>(r.x.size()) == o.variable_names.size()) {
    const auto value = [&](std::size_t k) { return r.x[static_cast<Eigen::Index>(k)]; };
    // the links whose counterweight the optimum left without mass: its position is no design
    std::vector<std::string> massless;
    constexpr std::string_view kMass = " counterweight mass [kg]";
    for (std::size_t k = 0; found && k < o.variable_names.size(); ++k) {
      const std::string& n = o.variable_names[k];
      if (n.ends_with(kMass) && value(k) == 0)
        massless.push_back(n.substr(0, n.size() - kMass.size()));
    }
    for (std::size_t k = 0; k < o.variable_names.size(); ++k) {
      const std::string& n = o.variable_names[k];
      const bool placeless =
          std::any_of(massless.begin(), massless.end(), [&](const std::string& l) {
            return n.starts_with(l + " counterweight x") || n.starts_with(l + " counterweight y");
          });
      if (placeless) {
        variables.push_back({{"name", n},
                             {"value", nullptr},
                             {"note", "no counterweight (its mass is 0): no position"}});
      } else {
        variables.push_back(
            {{"name", n}, {"value", found ? Json(value(k)) : value_or_null(value(k))}});
      }
    }
  }
  j["variables"] = variables;
}

// the optimize section: the problem, how the solver ended, the optimum
Json optimize_json(const Study& study, const RunResult& result) {
  const OptimizeRequest& req = *study.optimize;
  const OptimizedRun& o = *result.optimized;
  const optimize::OptimizeResult& r = o.result;
  Json j = problem_json(req, result.method);
  add_solver_fields(j, r, o);
  const bool found = o.found();
  // how the peaks were bounded, and the crank angles besides the samples where they were
  j["peaks"] = req.resolve_peaks ? "resolved" : "sampled";
  j["peak_angles"] = r.peak_angles;
  j["counterweights"] = found ? optimum_counterweights_json(req, r.counterweights) : Json::array();
  if (found) {
    j["added_mass"] = added_mass(study.fourbar(), r.design);
    j["added_inertia"] = added_inertia(study.fourbar(), r.design);
    j["verified_with"] = r.verified_by();
    // null where the re-simulation failed (the message says why)
    j["verification_error"] = value_or_null(r.verification_error);
  }
  if (req.pareto) {
    j["pareto"] = {{"first", optimize::to_string(req.pareto->first)},
                   {"second", optimize::to_string(req.pareto->second)},
                   {"points", o.pareto.size()}};
  }
  j["brief_report"] = r.brief_report();
  return j;
}

// a planar study's optimize section: the problem, how the solver ended, the optimum
Json planar_optimize_json(const Study& study, const RunResult& result) {
  const PlanarOptimizeRequest& req = *study.planar_optimize;
  const OptimizedRun& o = *result.optimized;
  const optimize::planar::Result& r = o.planar_result;
  const core::planar::Linkage& l = study.planar();
  Json j = {{"algorithm", optimize::to_string(req.options.algorithm)},
            {"formulation", to_string(result.method.method)}};
  Json terms = Json::array();
  for (const optimize::planar::Term& t : req.objective)
    terms.push_back({{"metric", t.metric}, {"weight", t.weight}});
  j["terms"] = terms;
  j["force_balance"] = req.force_balance;
  Json limits = Json::array();
  for (const optimize::planar::Limit& lim : req.limits) {
    limits.push_back({{"metric", lim.metric},
                      {"value", lim.value},
                      {"unit", lim.metric == "added_mass" ? "kg" : "fraction of the original"}});
  }
  j["limits"] = limits;
  add_solver_fields(j, r, o);
  // how the peaks were bounded, and the times besides the samples where they were
  j["peaks"] = req.resolve_peaks ? "resolved" : "sampled";
  j["peak_times"] = r.peak_times;
  const bool found = o.found();
  Json cws = Json::array();
  if (found) {
    for (const balance::planar::LinkCounterweight& c : r.counterweights) {
      balance::CounterweightShape shape = balance::CounterweightShape::kPoint;
      for (const optimize::planar::CounterweightVariables& v : req.counterweights)
        if (v.link == c.link) shape = v.shape;
      cws.push_back(planar_counterweight_json(l, c, shape));
    }
    j["added_mass"] = r.added_mass;
    j["added_inertia"] = added_inertia(l, r.design);
    // a driven scene: the optimum simulated against the regressor's values; a free scene: the
    // other route of the engine (dae) against the reduced route's
    j["verified_with"] = is_free(study.scene) ? "truss-dae" : "the optimum simulated";
    j["verification_error"] = value_or_null(r.verification_error);       // null: the run failed
    j["inertial_verification_error"] = value_or_null(r.inertial_error);  // null: not computed
  }
  j["counterweights"] = cws;
  if (req.pareto) {
    j["pareto"] = {{"first", req.pareto->first},
                   {"second", req.pareto->second},
                   {"points", o.planar_pareto.size()}};
  }
  j["brief_report"] = r.brief_report();
  return j;
}

// the keys of a second design's run (the balanced or the optimised one): `<what>_run`,
// `<what>_metrics`, and `reduction` (second / original per metric)
void add_second_run(Json& j, const Study& study, const std::string& what,
                    const MethodChoice& method, const RunStatus& status, const MetricList& original,
                    const MetricList& second) {
  Json run = {{"study", study.name + "-" + what}, {"method", method_json(study, method)}};
  add_run_fields(run, status);
  j[what + "_run"] = run;
  j[what + "_metrics_partial"] = !status.ok();
  j[what + "_metrics"] = metrics_json(second);
  j[what + "_peaks"] = peaks_json(study, second);
  j["reduction"] = reduction_json(original, second);
  // the second design's own metrics (balance shafts, counter-rotations) have their units too
  for (const MetricValue& m : second)
    if (!j["metric_units"].contains(m.name)) j["metric_units"][m.name] = m.unit;
}

}  // namespace

std::string summary_json(const Study& study, const RunResult& result) {
  Json j = {{"format", "balance-design summary v1"},
            {"study", study.name},
            {"source", study.source},
            {"method", method_json(study, result.method)},
            {"scene", scene_json(study.scene)},
            {"tolerance", study.tolerance},
            {"units_read", study.units_read}};
  add_run_fields(j, result.status());
  // a run that stopped early: its metrics cover the samples before the stop only
  j["metrics_partial"] = !result.status().ok();
  j["metrics"] = metrics_json(result.metric_list);
  // each metric's unit, from the linkage's own table (a slider's drive effort is a force)
  Json units = Json::object();
  for (const MetricValue& m : result.metric_list) units[m.name] = m.unit;
  j["metric_units"] = units;
  j["peaks"] = peaks_json(study, result.metric_list);
  if (result.harmonics) j["harmonics"] = harmonics_json(*result.harmonics);
  if (study.balance && result.balanced) {
    const BalancedRun& b = *result.balanced;
    j["balance"] = balance_json(*study.balance);
    add_second_run(j, study, "balanced", b.method, b.status(), result.metric_list, b.metric_list);
    if (b.harmonics) j["balanced_harmonics"] = harmonics_json(*b.harmonics);
  }
  if (study.planar_balance && result.balanced) {
    const BalancedRun& b = *result.balanced;
    if (b.design) {
      j["balance"] = planar_balance_json(study, b);
      add_second_run(j, study, "balanced", b.method, b.status(), result.metric_list, b.metric_list);
      if (b.harmonics) j["balanced_harmonics"] = harmonics_json(*b.harmonics);
    } else {
      j["balance"] = {{"force", "full"}, {"moment", "none"}, {"message", b.status().message}};
    }
  }
  if (study.optimizes() && result.optimized) {
    const OptimizedRun& o = *result.optimized;
    j["optimize"] =
        o.is_planar ? planar_optimize_json(study, result) : optimize_json(study, result);
    if (o.found()) {
      add_second_run(j, study, "optimized", o.method, o.status(), result.metric_list,
                     o.metric_list);
      if (o.harmonics) j["optimized_harmonics"] = harmonics_json(*o.harmonics);
    }
  }
  check_json_numbers(j, "summary.json");
  // invalid UTF-8 in a message (a key copied from a study file) is replaced, never a failure
  return j.dump(2, ' ', false, Json::error_handler_t::replace) + "\n";
}

}  // namespace bd::studies
