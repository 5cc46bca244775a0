#include "studies/run/runner.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cassert>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <system_error>
#include <utility>
#include <variant>

#include "balance/planar_shafts.hpp"
#include "core/number_text.hpp"
#include "optimize/nlp.hpp"
#include "studies/run/files.hpp"
#include "studies/study/study_yaml.hpp"

namespace bd::studies {

namespace fs = std::filesystem;

namespace {

// A solver's "found" design whose objective is not a finite number (a bound so wide that a
// metric overflows) is no design: failed, with the reason (issue 17: it "converged" at inf).
template <class Result>
void refuse_non_finite(Result& r) {
  if (!optimize::found_design(r.termination) || std::isfinite(r.objective)) return;
  r.termination = optimize::Termination::kFailed;
  r.message = "the objective at the solver's design is " + text::shortest(r.objective) +
              ", not a finite number: a design variable's bounds reach beyond the range the "
              "metrics can be computed in; narrow them";
}

// solves an optimize study's problem and simulates the optimum; not run when the original's
// simulation stopped early (its metrics are the normalisers)
OptimizedRun optimize_study(const Study& study, const RunResult& original,
                            const ComputeParts& parts) {
  OptimizedRun o;
  if (!original.status().ok()) {
    o.result.message = "not run: the original design's simulation stopped early (" +
                       original.trajectory.message + ")";
    return o;
  }
  const OptimizeRequest& req = *study.optimize;
  const optimize::DesignProblem problem = design_problem(study);
  o.result = optimize::optimize(problem, req.options);
  refuse_non_finite(o.result);
  {
    const optimize::Nlp nlp(problem);
    o.variable_names = nlp.variable_names();
  }
  o.design_variables = std::min(static_cast<int>(o.variable_names.size()),
                                3 * static_cast<int>(req.counterweights.size()) +
                                    static_cast<int>(req.link_parameters.size()));
  if (!o.found()) return o;
  const Study best = optimized_study(study, o.result.design);
  const Simulation sim = simulate(best);
  o.method = sim.method;
  o.trajectory = sim.fourbar;
  core::PeakList peaks;
  o.metrics = fourbar_metrics(best, sim, &peaks);
  o.metric_list = metric_list(best.fourbar(), o.metrics, &peaks);
  without_samples_none(o.metric_list, sim);
  if (parts.harmonics) o.harmonics = harmonics(best, o.trajectory, o.planar);
  if (req.pareto) {
    o.pareto = optimize::pareto_front(problem, req.pareto->first, req.pareto->second,
                                      req.pareto->points, req.options);
  }
  return o;
}

// a planar study's optimum: solved in its driven scene (the regressor comes from the original's
// run), then simulated; not run when the original stopped early
OptimizedRun planar_optimize_study(const Study& study, const RunResult& original,
                                   const ComputeParts& parts) {
  OptimizedRun o;
  o.is_planar = true;
  if (!original.status().ok()) {
    o.planar_result.message = "not run: the original design's simulation stopped early (" +
                              original.status().message + ")";
    return o;
  }
  o.planar_result =
      optimize::planar::optimize(planar_design_problem(study), study.planar_optimize->options);
  refuse_non_finite(o.planar_result);
  o.variable_names = o.planar_result.variable_names;
  o.design_variables = o.planar_result.design_variables;
  if (!o.found()) return o;
  const Study best = planar_optimized_study(study, o.planar_result.design);
  Simulation sim = simulate(best);
  o.method = sim.method;
  o.metric_list = metric_list(best, sim);
  without_samples_none(o.metric_list, sim);
  o.planar = std::move(sim.planar);
  if (parts.harmonics) o.harmonics = harmonics(best, o.trajectory, o.planar);
  if (const std::optional<PlanarParetoRequest>& p = study.planar_optimize->pareto) {
    o.planar_pareto =
        optimize::planar::pareto_front(planar_design_problem(study), p->first, p->second, p->points,
                                       study.planar_optimize->options);
  }
  return o;
}

}  // namespace

RunStatus OptimizedRun::status() const {
  return is_planar ? run_status(planar) : run_status(trajectory);
}

void write_table(const core::Series& table, const fs::path& file) {
  AtomicFile out(file);
  fmt::memory_buffer line;
  for (std::size_t k = 0; k < table.width(); ++k) {
    fmt::format_to(std::back_inserter(line), "{}{}", k ? "," : "", table.columns[k]);
  }
  line.push_back('\n');
  for (std::size_t i = 0; i < table.rows(); ++i) {
    const std::span<const double> row = table.row(i);
    for (std::size_t k = 0; k < row.size(); ++k) {
      if (k) line.push_back(',');
      // a zero is written "0", never "-0" (a force with a sign of round-off; equal as numbers)
      text::append_exact(line, row[k] == 0 ? 0.0 : row[k]);
    }
    line.push_back('\n');
    if (line.size() > (1 << 16)) {  // written in blocks of about 64 kB
      if (std::fwrite(line.data(), 1, line.size(), out.get()) != line.size()) break;
      line.clear();
    }
  }
  std::fwrite(line.data(), 1, line.size(), out.get());
  out.commit();  // a failed write shows here, as the file's error state
}

core::Series timeseries_table(const core::Trajectory& trajectory) {
  core::Series table;
  for (std::string_view names = kTimeseriesHeader; !names.empty();) {
    const std::size_t comma = std::min(names.find(','), names.size());
    table.columns.emplace_back(names.substr(0, comma));
    names.remove_prefix(std::min(comma + 1, names.size()));
  }
  table.values.reserve(trajectory.samples.size() * table.width());
  for (std::size_t i = 0; i < trajectory.samples.size(); ++i) {
    const core::DynamicsSample& d = trajectory.samples[i];
    const core::FourBarState& s = d.state;
    const double t = i < trajectory.t.size() ? trajectory.t[i] : std::nan("");
    table.values.insert(
        table.values.end(),
        {t, s.theta1, s.theta2, s.theta3, s.omega1, s.omega2, s.omega3, s.alpha1, s.alpha2,
         s.alpha3, d.RA0.x(), d.RA0.y(), d.RA3.x(), d.RA3.y(), d.Fsh.x(), d.Fsh.y(), d.Msh, d.tau,
         d.Fsh_inertial.x(), d.Fsh_inertial.y(), d.Msh_inertial, d.Fsh_static.x(), d.Fsh_static.y(),
         d.Msh_static, d.RC1.x(), d.RC1.y(), d.RC3.x(), d.RC3.y(), d.FA1.x(), d.FA1.y(), d.FA2.x(),
         d.FA2.y()});
  }
  return table;
}

void write_timeseries(const core::Trajectory& trajectory, const fs::path& file) {
  const core::Series table = timeseries_table(trajectory);
  AtomicFile out(file);
  std::FILE* f = out.get();
  std::fputs(kTimeseriesHeader, f);
  std::fputc('\n', f);
  for (std::size_t i = 0; i < table.rows(); ++i) {
    const std::span<const double> row = table.row(i);
    for (std::size_t k = 0; k < row.size(); ++k) {
      std::fprintf(f, k == 0 ? "%.17g" : ",%.17g", row[k]);
    }
    std::fputc('\n', f);
  }
  out.commit();
}

std::vector<ComparisonRow> comparison(const Study& study, const RunResult& result) {
  assert((result.balanced && (study.balance || result.balanced->design)) ||
         (result.optimized && result.optimized->found()));
  const MetricList& a = result.metric_list;
  MetricList b;
  double mass = 0, inertia = 0;
  if (const std::optional<BalancedRun>& run = result.balanced) {
    b = run->metric_list;
    mass = run->design ? run->design->added_mass : study.balance->added_mass;
    inertia = run->design ? run->design->added_inertia : study.balance->added_inertia;
  } else if (const OptimizedRun& o = *result.optimized; o.is_planar) {
    b = o.metric_list;
    mass = o.planar_result.added_mass;
    inertia = added_inertia(study.planar(), o.planar_result.design);
  } else {
    b = o.metric_list;
    mass = added_mass(study.fourbar(), o.result.design);
    inertia = added_inertia(study.fourbar(), o.result.design);
  }
  std::vector<ComparisonRow> rows = compare_metrics(a, b);
  rows.push_back({"added_mass", 0.0, mass, std::nullopt});
  rows.push_back({"added_inertia", 0.0, inertia, std::nullopt});
  return rows;
}

std::vector<ComparisonRow> compare_metrics(const MetricList& a, const MetricList& b) {
  std::vector<ComparisonRow> rows;
  // by name: a balanced design's new parts (a balance shaft's bearing) add metrics, 0 before
  std::vector<bool> matched(b.size(), false);
  for (const auto& m : a) {
    for (std::size_t k = 0; k < b.size(); ++k) {
      if (matched[k] || b[k].name != m.name) continue;
      rows.push_back({m.name, m.value, b[k].value, std::nullopt});
      matched[k] = true;
      break;
    }
  }
  for (std::size_t k = 0; k < b.size(); ++k) {
    if (!matched[k]) rows.push_back({b[k].name, 0.0, b[k].value, std::nullopt});
  }
  for (ComparisonRow& row : rows) {
    if (row.before != 0) row.ratio = row.after / row.before;
  }
  return rows;
}

std::string comparison_csv(const Study& study, const RunResult& result) {
  std::string text = std::string(kComparisonHeader) + "\n";
  for (const ComparisonRow& row : comparison(study, result)) {
    text += row.metric + "," + text::exact(row.before) + "," + text::exact(row.after) + "," +
            (row.ratio ? text::exact(*row.ratio) : std::string()) + "\n";
  }
  return text;
}

namespace {

// a link's mass and inertia properties, the ones a counterweight or a link parameter changes
const core::Link& link_at(const core::FourBar& m, int k) {
  return k == 1 ? m.crank : k == 2 ? m.coupler : m.rocker;
}
core::Link& link_at(core::FourBar& m, int k) {
  return k == 1 ? m.crank : k == 2 ? m.coupler : m.rocker;
}
const core::planar::Link& link_at(const core::planar::Linkage& l, int k) {
  return l.links[static_cast<std::size_t>(k)];
}
core::planar::Link& link_at(core::planar::Linkage& l, int k) {
  return l.links[static_cast<std::size_t>(k)];
}
std::vector<int> link_indices(const core::FourBar&) { return {1, 2, 3}; }
std::vector<int> link_indices(const core::planar::Linkage& l) {
  std::vector<int> k(l.links.size());
  for (std::size_t i = 0; i < k.size(); ++i) k[i] = static_cast<int>(i);
  return k;
}
template <class L>
bool same_link(const L& a, const L& b) {
  return a.mass == b.mass && a.e == b.e && a.f == b.f && a.inertia == b.inertia;
}
template <class L>
double& parameter_of(L& link, optimize::LinkParameterVariable::Parameter p) {
  using P = optimize::LinkParameterVariable::Parameter;
  return p == P::kMass ? link.mass : p == P::kE ? link.e : p == P::kF ? link.f : link.inertia;
}

// The design's counterweights as parts of its links, for its study file: the links each was
// merged into (`base`: the study's links, with the link parameters an optimiser set) without
// them, and the study's own parts kept on the links nothing else changed. Empty when there is
// no part to write, or when the parts would not give back `design`'s links bit for bit (the file
// then has the merged links, as a study without parts).
template <class T>
std::optional<LinkageParts> design_parts(const Study& study, const T& base,
                                         const std::vector<CounterweightPart>& added,
                                         const T& design) {
  const T& study_model = std::get<T>(study.linkage);
  const T* study_bare = study.parts ? &std::get<T>(study.parts->bare) : nullptr;
  auto touched = [&](int k) {
    for (const CounterweightPart& p : added)
      if (p.link == k) return true;
    return !same_link(link_at(base, k), link_at(study_model, k));
  };
  LinkageParts out{design, {}};
  T& bare = std::get<T>(out.bare);
  for (int k : link_indices(study_model)) {
    if (touched(k)) {
      link_at(bare, k) = link_at(base, k);
    } else if (study_bare) {
      link_at(bare, k) = link_at(*study_bare, k);
    }
  }
  if (study.parts) {
    for (const CounterweightPart& p : study.parts->counterweights)
      if (!touched(p.link)) out.counterweights.push_back(p);
  }
  out.counterweights.insert(out.counterweights.end(), added.begin(), added.end());
  if (out.counterweights.empty()) return std::nullopt;
  const T merged = std::get<T>(with_counterweights(out));
  for (int k : link_indices(merged)) {
    if (!same_link(link_at(merged, k), link_at(design, k))) return std::nullopt;
  }
  return out;
}

// the study of a design with its counterweights as parts, when they reproduce it
Study with_parts(Study design, std::optional<LinkageParts> parts) {
  design.parts = std::move(parts);
  return design;
}

// where the header says a counterweight is
const char* where_written(const Study& design) {
  return design.parts ? "linkage.counterweights below" : "merged into the link below";
}

// a planar design's counterweight in the header comment: 6 digits, a component that is
// round-off of the linkage's size (text::is_round_off()) written as 0
std::string counterweight_line(const core::planar::Linkage& l,
                               const balance::planar::LinkCounterweight& c, const Study& written) {
  const balance::Counterweight& w = c.counterweight;
  const double size = std::max(w.position.norm(), linkage_size(l));
  auto shown = [&](double v) { return text::scaled(v, size); };
  return fmt::format(
      "Link {} carries a counterweight of {:.6g} kg at ({}, {}) m from node {} in the "
      "link's axes ({}).\n",
      l.links[static_cast<std::size_t>(c.link)].name, w.mass, shown(w.position.x()),
      shown(w.position.y()), l.nodes[static_cast<std::size_t>(c.pivot)].name,
      where_written(written));
}

}  // namespace

std::string balanced_yaml(const Study& study) {
  assert(study.balance.has_value());
  const balance::BalancedDesign& b = *study.balance;
  std::string header = "The balanced design of study '" + study.name + "', synthesised by\n";
  header += "balance-design from its balance section (force: " +
            std::string(b.request.force ? "full" : "none") +
            ", moment: " + (b.request.moment ? "full" : "none") + ")";
  header += study.source.empty() ? std::string(".\n") : " in\n  " + study.source + "\n";
  const std::optional<balance::Counterweight>* cws[] = {&b.crank_counterweight,
                                                        &b.rocker_counterweight};
  std::vector<CounterweightPart> added;
  for (int i = 0; i < 2; ++i) {
    if (cws[i]->has_value()) added.push_back({i == 0 ? 1 : 3, -1, **cws[i]});
  }
  const Study design =
      with_parts(balanced_study(study), design_parts(study, study.fourbar(), added, b.model));
  const char* sides[] = {"crank", "rocker"};
  const char* pivots[] = {"A0", "A3"};
  for (int i = 0; i < 2; ++i) {
    if (!cws[i]->has_value()) continue;
    const balance::Counterweight& c = **cws[i];
    char line[256];
    std::snprintf(line, sizeof line,
                  "The %s carries a counterweight of %.6g kg at %.6g m from %s (%s).\n",
                  sides[i], c.mass, c.distance, pivots[i], where_written(design));
    header += line;
  }
  if (b.request.moment) {
    header +=
        "Counter-rotating discs on frame shafts cancel the shaking moment "
        "(linkage.counter_rotations).\n";
  }
  header +=
      "Every number is written exactly (links by e, f; s, sigma as comments).\n"
      "Run it with\n  balance-design balanced.yaml";
  return study_yaml(design, header);
}

std::string balanced_yaml(const Study& study, const balance::planar::ForceBalance& design) {
  const core::planar::Linkage& l = study.planar();
  std::vector<CounterweightPart> added;
  for (const balance::planar::LinkCounterweight& c : design.added)
    added.push_back({c.link, c.pivot, c.counterweight});
  const Study written = with_parts(planar_balanced_study(study, design.linkage),
                                   design_parts(study, l, added, design.linkage));  std::string header = "The balanced design of study '" + study.name + "', synthesised by\n";
  header += design.balancing_factor
                ? fmt::format("balance-design from its balance section (balancing factor {:g})",
                              *design.balancing_factor)
                : std::string("balance-design from its balance section (force: full)");
  header += study.source.empty() ? std::string(".\n") : " in\n  " + study.source + "\n";
  header += design.full ? "It is fully force balanced over the motion.\n"
                        : (design.balancing_factor ? "" : "Full force balance is not reached: ") +
                              design.message + "\n";
  for (const balance::planar::LinkCounterweight& c : design.added)
    header += counterweight_line(l, c, written);
  for (const core::planar::BalanceShaft& s : design.linkage.shafts) {
    bool had = false;
    for (const core::planar::BalanceShaft& o : l.shafts) had = had || o.name == s.name;
    if (had) continue;
    header += fmt::format(
        "Balance shaft {} at ({:.6g}, {:.6g}) m turns {} times link {}: {:.6g} kg at {:.6g} m "
        "(balance_shafts below).\n",
        s.name, s.at.x(), s.at.y(), s.ratio, l.links[static_cast<std::size_t>(s.link)].name, s.mass,
        s.eccentricity.norm());
  }
  header += "Run it with\n  balance-design balanced.yaml";
  return study_yaml(written, header);
}

namespace {

// a planar study's optimized.yaml
std::string planar_optimized_yaml(const Study& study, const OptimizedRun& run) {
  assert(study.planar_optimize.has_value() && run.found());
  const PlanarOptimizeRequest& req = *study.planar_optimize;
  const optimize::planar::Result& r = run.planar_result;
  const core::planar::Linkage& l = study.planar();
  // the links the counterweights were merged into: the study's, with the link parameters set
  core::planar::Linkage base = l;
  for (std::size_t i = 0; i < req.link_parameters.size(); ++i) {
    const optimize::planar::LinkParameterVariable& v = req.link_parameters[i];
    parameter_of(link_at(base, v.link), v.parameter) =
        r.x[static_cast<Eigen::Index>(3 * req.counterweights.size() + i)];
  }
  std::vector<CounterweightPart> added;
  for (const balance::planar::LinkCounterweight& c : r.counterweights)
    if (c.counterweight.mass > 0) added.push_back({c.link, c.pivot, c.counterweight});
  const Study written = with_parts(planar_optimized_study(study, r.design),
                                   design_parts(study, base, added, r.design));  std::string header = "The optimised design of study '" + study.name + "', found by\n";
  header += "balance-design from its optimize section";
  header += study.source.empty() ? std::string(".\n") : " in\n  " + study.source + "\n";
  header += "Objective: minimise " + objective_text(req) + ".\n";
  header += "Constraints: " + constraints_text(req) + ".\n";
  header += fmt::format(
      "Solver: {}, {} after {} evaluations; objective {:.6g}; verified by simulating it (largest "
      "relative difference {:.3g}).\n",
      optimize::to_string(req.options.algorithm), optimize::to_string(r.termination), r.evaluations,
      r.objective, r.verification_error);
  for (const balance::planar::LinkCounterweight& c : r.counterweights)
    if (c.counterweight.mass > 0) header += counterweight_line(l, c, written);
  for (int k = 3 * static_cast<int>(req.counterweights.size()); k < r.design_variables; ++k) {
    header += fmt::format("Link parameter {} = {:.6g} (a variable).\n",
                          r.variable_names[static_cast<std::size_t>(k)], r.x[k]);
  }
  header += "Run it with\n  balance-design optimized.yaml";
  return study_yaml(written, header);
}

}  // namespace

std::string optimized_yaml(const Study& study, const OptimizedRun& run) {
  if (run.is_planar) return planar_optimized_yaml(study, run);
  assert(study.optimize.has_value() && run.found());
  const OptimizeRequest& req = *study.optimize;
  const optimize::OptimizeResult& r = run.result;
  // the links the counterweights were merged into: the study's, with the link parameters set
  core::FourBar base = study.fourbar();
  for (std::size_t i = 0; i < req.link_parameters.size(); ++i) {
    const optimize::LinkParameterVariable& v = req.link_parameters[i];
    parameter_of(link_at(base, v.link), v.parameter) =
        r.x[static_cast<Eigen::Index>(3 * req.counterweights.size() + i)];
  }
  std::vector<CounterweightPart> added;
  for (const optimize::PlacedCounterweight& p : r.counterweights)
    if (p.counterweight.mass > 0) added.push_back({p.link, -1, p.counterweight});
  const Study written =
      with_parts(optimized_study(study, r.design), design_parts(study, base, added, r.design));  std::string header = "The optimised design of study '" + study.name + "', found by\n";
  header += "balance-design from its optimize section";
  header += study.source.empty() ? std::string(".\n") : " in\n  " + study.source + "\n";
  header += "Objective: minimise " + objective_text(req) + ".\n";
  header += "Constraints: " + constraints_text(req) + ".\n";
  char line[512];
  std::snprintf(line, sizeof line, "Solver: %s, %s after %d evaluations; objective %.6g; ",
                optimize::to_string(req.options.algorithm), optimize::to_string(r.termination),
                r.evaluations, r.objective);
  header += line;
  header += std::isfinite(r.verification_error)
                ? "verified with " + r.verified_by() + " (largest relative difference " +
                      text::digits(r.verification_error, 3) + ").\n"
                : "its verification with " + r.verified_by() + " failed (see summary.json).\n";
  const char* pivots[] = {"", "A0", "", "A3"};
  for (const optimize::PlacedCounterweight& p : r.counterweights) {
    const balance::Counterweight& c = p.counterweight;
    if (!(c.mass > 0)) {
      std::snprintf(line, sizeof line, "The %s carries no counterweight (its mass is 0).\n",
                    core::link_name(p.link));
    } else {
      std::snprintf(line, sizeof line,
                    "The %s carries a counterweight of %.6g kg at %.6g m from %s (%s).\n",
                    core::link_name(p.link), c.mass, c.distance,
                    p.link == 1 || p.link == 3 ? pivots[p.link] : "its pivot",
                    where_written(written));
    }
    header += line;
  }
  header +=
      "Every number is written exactly (links by e, f; s, sigma as comments).\n"
      "Run it with\n  balance-design optimized.yaml";
  return study_yaml(written, header);
}

namespace {

// a planar study's pareto.csv
std::string planar_pareto_csv(const Study& study, const OptimizedRun& run) {
  assert(study.planar_optimize && study.planar_optimize->pareto);
  const PlanarParetoRequest& p = *study.planar_optimize->pareto;
  std::string text = "epsilon," + p.first + "," + p.second + ",termination,verification_error";
  const auto n = static_cast<std::size_t>(run.design_variables);
  for (std::size_t k = 0; k < n; ++k) text += "," + csv_field(run.variable_names[k]);
  text += "\n";
  // a metric's value at a design: from the optimiser's evaluation, as the four-bar's
  auto value = [](const optimize::planar::Result& r, const std::string& m) {
    if (m == "added_mass") return r.added_mass;
    for (std::size_t k = 0; k < r.metric_table.size(); ++k)
      if (r.metric_table[k].name == m) return r.metrics[k];
    return std::nan("");
  };
  for (const optimize::planar::ParetoPoint& point : run.planar_pareto) {
    const optimize::planar::Result& r = point.result;
    text += text::exact(point.epsilon);
    text += r.ok() ? "," + text::exact(value(r, p.first)) + "," + text::exact(value(r, p.second))
                   : std::string(",,");
    text += std::string(",") + optimize::to_string(r.termination) + "," +
            (r.ok() ? text::exact(r.verification_error) : std::string());
    // a point without a design has no variables: empty cells, as its metrics
    for (std::size_t k = 0; k < n; ++k) {
      text += "," + (r.ok() && static_cast<Eigen::Index>(k) < r.x.size()
                         ? text::exact(r.x[static_cast<Eigen::Index>(k)])
                         : std::string());
    }
    text += "\n";
  }
  return text;
}

}  // namespace

std::string pareto_csv(const Study& study, const OptimizedRun& run) {
  if (run.is_planar) return planar_pareto_csv(study, run);
  assert(study.optimize && study.optimize->pareto);
  const ParetoRequest& p = *study.optimize->pareto;
  std::string text = std::string("epsilon,") + optimize::to_string(p.first) + "," +
                     optimize::to_string(p.second) + ",termination,verification_error";
  const int n = run.design_variables;
  for (int k = 0; k < n; ++k)
    text += "," + csv_field(run.variable_names[static_cast<std::size_t>(k)]);
  text += "\n";
  for (const optimize::ParetoPoint& point : run.pareto) {
    const optimize::OptimizeResult& r = point.result;
    text += text::exact(point.epsilon);
    if (r.ok()) {
      const double mass = added_mass(study.fourbar(), r.design);
      text += "," + text::exact(metric_value(r.metrics, p.first, mass)) + "," +
              text::exact(metric_value(r.metrics, p.second, mass));
    } else {
      text += ",,";
    }
    text += std::string(",") + optimize::to_string(r.termination) + "," +
            (r.ok() ? text::exact(r.verification_error) : std::string());
    // a point without a design has no variables: empty cells, as its metrics
    for (int k = 0; k < n; ++k) {
      text += "," + (r.ok() && k < r.x.size() ? text::exact(r.x[k]) : std::string());
    }
    text += "\n";
  }
  return text;
}

namespace {

// Full force balance holds in every configuration the linkage can take, not only in those a
// scene passes through: where the scene's motion shows fewer of its conditions than a full
// revolution of the crank does (a linkage at rest), the revolution's configurations (at unit
// speed) are added to k, so that the conditions are the linkage's own; a design that cannot
// meet them all is then the least-squares one over both. Returns what was done, in words, or
// nothing.
std::string with_every_condition(const core::planar::Linkage& l, const core::planar::Model& model,
                                 balance::planar::Kinematics& k) {
  namespace bp = balance::planar;
  if (l.inputs.size() != 1 || l.inputs[0].kind != core::planar::Input::Kind::kAngle) return {};
  const auto revolution = bp::crank_revolution(model, 360);
  if (!revolution) return {};
  const int seen = bp::force_balance_conditions(l, k);
  const int all = bp::force_balance_conditions(l, *revolution);
  if (seen >= all) return {};
  k.samples.insert(k.samples.end(), revolution->samples.begin(), revolution->samples.end());
  return "the scene's motion shows " + std::to_string(seen) + " of the " + std::to_string(all) +
         " conditions of force balance, so they are taken from a full revolution of " +
         l.inputs[0].name;
}

// a planar study's balanced design: synthesised from the original's motion (its configurations
// give the balance conditions), then simulated in the same scene; not run when the original
// stopped early
BalancedRun planar_balanced_run(const Study& study, const RunResult& original,
                                const ComputeParts& parts) {
  namespace bp = balance::planar;
  BalancedRun b;
  b.is_planar = true;
  if (!original.status().ok()) {
    b.planar.message = "not run: the original design's simulation stopped early (" +
                       original.status().message + ")";
    return b;
  }
  const core::planar::Model model(study.planar());
  const bp::InputSeries in = bp::input_series(model, original.planar.table);
  auto k = bp::kinematics(model, in.values, in.rates, in.accelerations);
  if (!k) {
    b.planar.message = "not run: the original's motion cannot be evaluated for balancing (" +
                       k.error().detail + ")";
    return b;
  }
  const bp::BalanceRequest& ask = *study.planar_balance;
  // (a driven revolution too: at 1 or 2 samples per turn it shows too few of them)
  const std::string shown = with_every_condition(study.planar(), model, *k);
  b.design = bp::force_balance(study.planar(), *k, ask.counterweights, ask.balancing_factor);
  if (!shown.empty()) b.design->message += (b.design->message.empty() ? "" : "; ") + shown;
  if (ask.shafts) {
    b.shafts = bp::balance_shafts(b.design->linkage, *ask.shafts);
    bp::add_shafts(*b.design, *b.shafts, *k, study.planar());
  }
  if (ask.counter_rotations) {
    if (b.design->full) {
      b.moment = bp::moment_balance(b.design->linkage, *k, *ask.counter_rotations);
      bp::add_counter_rotations(*b.design, *b.moment);
    } else {
      b.design->message +=
          "; no counter-rotations: a moment balance starts from full force "
          "balance, which is not reached";
    }
  }
  const Study balanced = planar_balanced_study(study, b.design->linkage);
  Simulation sim = simulate(balanced);
  b.method = sim.method;
  b.metric_list = metric_list(balanced, sim);
  without_samples_none(b.metric_list, sim);
  b.planar = std::move(sim.planar);
  if (parts.harmonics) b.harmonics = harmonics(balanced, b.trajectory, b.planar);
  return b;
}

}  // namespace

RunStatus BalancedRun::status() const {
  return is_planar ? run_status(planar) : run_status(trajectory);
}

RunStatus simulation_status(const RunResult& r) {
  if (!r.planar.table.columns.empty()) return run_status(r.planar);
  return run_status(r.trajectory);
}

RunResult compute_study(const Study& study, const ComputeParts& parts) {
  RunResult result;
  Simulation sim = simulate(study);
  result.method = sim.method;
  if (study.is_fourbar()) {
    core::PeakList peaks;
    result.metrics = fourbar_metrics(study, sim, &peaks);
    result.metric_list = metric_list(study.fourbar(), result.metrics, &peaks);
  } else {
    result.metric_list = metric_list(study, sim);
  }
  without_samples_none(result.metric_list, sim);
  result.trajectory = std::move(sim.fourbar);
  result.planar = std::move(sim.planar);
  if (parts.harmonics) result.harmonics = harmonics(study, result.trajectory, result.planar);
  if (study.balance) {
    const Study design = balanced_study(study);
    const Simulation balanced = simulate(design);
    BalancedRun b;
    b.method = balanced.method;
    b.trajectory = balanced.fourbar;
    core::PeakList peaks;
    b.metrics = fourbar_metrics(design, balanced, &peaks);
    b.metric_list = metric_list(design.fourbar(), b.metrics, &peaks);
    without_samples_none(b.metric_list, balanced);
    if (parts.harmonics) b.harmonics = harmonics(design, b.trajectory, b.planar);
    result.balanced = std::move(b);
  }
  if (study.planar_balance) result.balanced = planar_balanced_run(study, result, parts);
  if (study.optimize) result.optimized = optimize_study(study, result, parts);
  if (study.planar_optimize) result.optimized = planar_optimize_study(study, result, parts);
  return result;
}

void write_run(const Study& study, RunResult& result, const fs::path& out_dir) {
  // summary last: a summary.json means the other files are complete
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) {
    throw std::runtime_error("cannot create the output directory " + out_dir.string() + ": " +
                             ec.message());
  }
  remove_stale_temporaries(out_dir);  // of a run killed here before
  // an earlier run's files in the folder would be read as this run's (a report listing the
  // Pareto front of another design)
  // and its page: a run that fails midway (a full disk) must not leave the old report beside
  // the new data files (issue 17)
  // summary.json and the page first: if a later removal fails (a folder in the way), no
  // summary.json is left to vouch for the files that remain
  std::vector<std::string> names = {"summary.json", "report.html"};
  for (const char* name : kRunFiles) {
    if (names.front() != name) names.emplace_back(name);
  }
  // a finished sweep's files (run_study() refuses a folder holding an unfinished one)
  names.emplace_back("sweep.json");
  names.emplace_back("sweep.csv");
  for (const std::string& name : names) {
    if (fs::remove(out_dir / name, ec); ec) {
      throw std::runtime_error("cannot remove the earlier run's " + (out_dir / name).string() +
                               ": " + ec.message());
    }
  }
  // the study file itself, so that the folder holds everything its report is built from
  // (`balance-design report DIR` reads it from there, wherever it is run from)
  if (!study.source.empty()) {
    std::ifstream in(study.source, std::ios::binary);
    std::ostringstream text;
    if (in) text << in.rdbuf();
    if (in && !in.bad()) write_text_file(text.str(), out_dir / "study.yaml");
  }
  result.timeseries = out_dir / "timeseries.csv";
  result.summary = out_dir / "summary.json";
  if (study.is_fourbar()) {
    write_timeseries(result.trajectory, result.timeseries);
  } else {
    write_table(result.planar.table, result.timeseries);
  }
  if (result.balanced && (!result.balanced->is_planar || result.balanced->design)) {
    BalancedRun& b = *result.balanced;
    b.timeseries = out_dir / "balanced-timeseries.csv";
    b.study_file = out_dir / "balanced.yaml";
    b.comparison = out_dir / "comparison.csv";
    if (b.is_planar) {
      write_table(b.planar.table, b.timeseries);
      write_text_file(balanced_yaml(study, *b.design), b.study_file);
    } else {
      write_timeseries(b.trajectory, b.timeseries);
      write_text_file(balanced_yaml(study), b.study_file);
    }
    write_text_file(comparison_csv(study, result), b.comparison);
  }
  if (result.harmonics) {
    std::string text =
        std::string(kHarmonicsHeader) + "\n" + harmonics_rows("original", *result.harmonics);
    if (result.balanced && result.balanced->harmonics) {
      text += harmonics_rows("balanced", *result.balanced->harmonics);
    }
    if (result.optimized && result.optimized->found() && result.optimized->harmonics) {
      text += harmonics_rows("optimized", *result.optimized->harmonics);
    }
    result.harmonics_file = out_dir / "harmonics.csv";
    write_text_file(text, result.harmonics_file);
  }
  if (result.optimized && result.optimized->found()) {
    OptimizedRun& o = *result.optimized;
    o.timeseries = out_dir / "optimized-timeseries.csv";
    o.study_file = out_dir / "optimized.yaml";
    o.comparison = out_dir / "comparison.csv";
    if (o.is_planar) {
      write_table(o.planar.table, o.timeseries);
    } else {
      write_timeseries(o.trajectory, o.timeseries);
    }
    write_text_file(optimized_yaml(study, o), o.study_file);
    write_text_file(comparison_csv(study, result), o.comparison);
    if ((study.optimize && study.optimize->pareto) ||
        (study.planar_optimize && study.planar_optimize->pareto)) {
      o.pareto_file = out_dir / "pareto.csv";
      write_text_file(pareto_csv(study, o), o.pareto_file);
    }
  }
  write_text_file(summary_json(study, result), result.summary);
}

}  // namespace bd::studies
