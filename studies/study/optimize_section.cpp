// The optimize section of a study: a four-bar's (objective, constraints, variables, solver and
// Pareto front) and a planar linkage's (objective, constraints, variables on links by name,
// solver), checked by the optimize layer (validate(), check_algorithm(), the normalisers), each
// complaint at the key whose field it names.
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/planar/metrics.hpp"
#include "optimize/nlp.hpp"
#include "optimize/optimize.hpp"
#include "optimize/planar.hpp"
#include "studies/study/sections.hpp"
#include "studies/study/yaml_reader.hpp"

namespace bd::studies::detail {

namespace {

class OptimizeReader {
 public:
  explicit OptimizeReader(const Reporter& r) : r_(r) {}

  // optimize: {algorithm, objective, constraints, variables, max_evaluations, starts, tolerance,
  // peaks, pareto}
  OptimizeRequest read_optimize(const MapReader::Entry& e, const Study& study) {
    OptimizeRequest req;
    const MapReader o(r_, e.value, "optimize", e.key_mark,
                      "(algorithm, objective, constraints, variables, max_evaluations, starts, "
                      "tolerance, peaks, pareto)");
    o.check_keys({"algorithm", "objective", "constraints", "variables", "max_evaluations",
                  "starts", "tolerance", "peaks", "pareto"});
    const SolverMarks marks = read_solver(o, e.key_mark, is_free(study.scene), req.options);
    req.resolve_peaks = read_peaks(o);
    read_objective(o.require("objective", "the metrics to minimise, each with a weight"), study,
                   req);
    if (const MapReader::Entry* c = o.find("constraints")) read_constraints(*c, study, req);
    read_variables(o.require("variables",
                             "what may change: counterweights on crank and rocker, links' "
                             "mass parameters"),
                   study.fourbar(), req);
    if (const MapReader::Entry* p = o.find("pareto")) req.pareto = read_pareto(*p, study.scene);

    // the optimize layer's own checks of the whole problem and of the options, at the section
    Study with = study;
    with.optimize = req;
    const optimize::DesignProblem problem = design_problem(with);
    if (const Problem p = problem.validate()) r_.fail(e.key_mark, "optimize: " + p->text());
    check_options(req.options, marks);
    check_evaluation(problem, req, e.key_mark);
    check_algorithm(problem, req, marks.algorithm);
    return req;
  }

  // a planar linkage's optimize: {algorithm, objective, constraints, variables, max_evaluations,
  // starts, tolerance, peaks, pareto}
  PlanarOptimizeRequest read_planar_optimize(const MapReader::Entry& e, const Study& study) {
    namespace op = optimize::planar;
    PlanarOptimizeRequest req;
    const core::planar::Linkage& linkage = study.planar();
    const MapReader o(r_, e.value, "optimize", e.key_mark,
                      "(algorithm, objective, constraints, variables, max_evaluations, starts, "
                      "tolerance, peaks, pareto)");
    o.check_keys({"algorithm", "objective", "constraints", "variables", "max_evaluations",
                  "starts", "tolerance", "peaks", "pareto"});
    const SolverMarks marks = read_solver(o, e.key_mark, is_free(study.scene), req.options);
    req.resolve_peaks = read_peaks(o);
    table_ = core::planar::metric_table(core::planar::Model(linkage));

    // objective: {metric: weight}
    const MapReader::Entry& objective =
        o.require("objective", "the metrics to minimise, each with a weight");
    const MapReader terms(r_, objective.value, "optimize.objective", objective.key_mark,
                          "of metric: weight (e.g. Msh_rms: 1.0)");
    bool positive = false;
    for (const MapReader::Entry& x : terms.entries()) {
      const std::string path = "optimize.objective." + x.key;
      check_planar_metric(x.key, x.key_mark, "optimize.objective");
      const double w = read_number(r_, x, path, "");
      if (w < 0) {
        r_.fail(mark_of(x.value, x.key_mark),
                path + " must be >= 0 (a weight), got " + text::shortest(w));
      }
      positive = positive || w > 0;
      req.objective.push_back({x.key, w});
      term_marks_.push_back(x.key_mark);
    }
    if (!positive) {
      r_.fail(objective.key_mark, "optimize.objective needs at least one metric with a weight > 0");
    }

    // constraints: {force_balance: bool, metric: fraction, added_mass: kg}
    const MapReader::Entry* constraints = o.find("constraints");
    if (constraints && !constraints->value.IsNull()) {
      const MapReader m(r_, constraints->value, "optimize.constraints", constraints->key_mark,
                        "(force_balance, and metric: bound)");
      for (const MapReader::Entry& x : m.entries()) {
        const std::string path = "optimize.constraints." + x.key;
        if (x.key == "force_balance") {
          req.force_balance = read_bool(r_, x, path);
          force_balance_mark_ = x.key_mark;
          continue;
        }
        check_planar_metric(x.key, x.key_mark, "optimize.constraints", "force_balance or ");
        req.limits.push_back({x.key, read_limit(x, path, x.key == "added_mass")});
        limit_marks_.push_back(x.key_mark);
      }
    }

    // variables: {counterweights: {<link>: {...}}, links: {<link>: {mass, e, f, inertia}}}
    const MapReader::Entry& variables =
        o.require("variables", "what may change: counterweights on links, links' mass parameters");
    const MapReader v(r_, variables.value, "optimize.variables", variables.key_mark,
                      "(counterweights, links)");
    v.check_keys({"counterweights", "links"});
    std::map<std::pair<std::string, int>, YAML::Mark> marks_of;  // (list, index) -> its key
    auto link_of = [&](const MapReader::Entry& x, const std::string& path) {
      const int link = core::planar::link_index(linkage, x.key);
      if (link < 0)
        r_.fail(x.key_mark, path + ": no link of that name (links: " + links(linkage) + ")");
      return link;
    };
    if (const MapReader::Entry* cw = v.find("counterweights"); cw && !cw->value.IsNull()) {
      const MapReader m(r_, cw->value, "optimize.variables.counterweights", cw->key_mark,
                        "(a link's name and its counterweight's envelope: {} or mass_max, "
                        "distance_max, shape, thickness, density)");
      for (const MapReader::Entry& x : m.entries()) {
        const std::string path = "optimize.variables.counterweights." + x.key;
        const int link = link_of(x, path);
        marks_of[{"counterweights", static_cast<int>(req.counterweights.size())}] = x.key_mark;
        req.counterweights.push_back(read_counterweight_variables<op::CounterweightVariables>(
            x, path, link, core::planar::element_length(linkage, link)));
      }
    }
    if (const MapReader::Entry* lk = v.find("links"); lk && !lk->value.IsNull()) {
      const MapReader m(r_, lk->value, "optimize.variables.links", lk->key_mark,
                        "(a link's name and its parameters: mass, e, f, inertia, each [lower, "
                        "upper])");
      for (const MapReader::Entry& x : m.entries()) {
        const std::string path = "optimize.variables.links." + x.key;
        const int link = link_of(x, path);
        const std::size_t first = req.link_parameters.size();
        read_link_parameters(x, path, link, req.link_parameters);
        for (std::size_t i = first; i < req.link_parameters.size(); ++i)
          marks_of[{"link_parameters", static_cast<int>(i)}] = x.key_mark;
      }
    }
    if (req.counterweights.empty() && req.link_parameters.empty()) {
      r_.fail(variables.key_mark,
              "optimize.variables: no design variable; give counterweights (on links by name) "
              "or links (mass, e, f, inertia within bounds)");
    }
    marks_of[{"force_balance", -1}] = force_balance_mark_;
    for (std::size_t i = 0; i < term_marks_.size(); ++i)
      marks_of[{"objective", static_cast<int>(i)}] = term_marks_[i];
    for (std::size_t i = 0; i < limit_marks_.size(); ++i)
      marks_of[{"limits", static_cast<int>(i)}] = limit_marks_[i];

    if (const MapReader::Entry* p = o.find("pareto")) req.pareto = read_planar_pareto(*p);

    // the optimize layer's own checks, at the key whose field they name
    Study with = study;
    with.planar_optimize = req;
    const op::DesignProblem problem = planar_design_problem(with);
    auto at = [&](const FieldError& f) -> std::optional<YAML::Mark> {
      if (const auto it = marks_of.find({f.field, f.index}); it != marks_of.end())
        return it->second;
      return std::nullopt;
    };
    auto path_of = [&](const FieldError& f) -> std::string {
      if (f.field == "force_balance") return "optimize.constraints.force_balance";
      if (f.field == "objective") return "optimize.objective." + req.objective[f.index].metric;
      if (f.field == "limits") return "optimize.constraints." + req.limits[f.index].metric;
      if (f.field == "counterweights") {
        return "optimize.variables.counterweights." +
               linkage.links[static_cast<std::size_t>(req.counterweights[f.index].link)].name;
      }
      if (f.field == "link_parameters") {
        const op::LinkParameterVariable& p = req.link_parameters[f.index];
        return "optimize.variables.links." + linkage.links[static_cast<std::size_t>(p.link)].name +
               "." + to_string(p.parameter);
      }
      return "optimize";
    };
    if (const Problem p = problem.validate()) {
      if (const auto mark = at(*p)) r_.fail(*mark, p->joined(path_of(*p)));
      r_.fail(e.key_mark, "optimize: " + p->text());
    }
    check_options(req.options, marks);
    if (const Problem p = op::check_algorithm(problem, req.options)) {
      r_.fail(marks.algorithm, "optimize.algorithm: " + p->text());
    }
    try {
      op::PlanarNlp::check(problem);  // the original run; its metrics are the normalisers
    } catch (const InputError& err) {
      if (const auto& f = err.field()) {
        if (const auto mark = at(*f)) r_.fail(*mark, f->joined(path_of(*f)));
      }
      r_.fail(e.key_mark, "optimize: " + std::string(err.what()));
    }
    if (req.pareto) {
      // each point minimises `first` with a bound on `second`: that problem checked and set up
      op::DesignProblem p = problem;
      p.objective = {op::Term{req.pareto->first, 1.0}};
      p.limits.push_back(op::Limit{req.pareto->second, 1.0});
      auto fail_at = [&](const FieldError& f, const std::string& text) {
        if (f.field == "objective") r_.fail(pareto_marks_[0], f.joined("optimize.pareto.first"));
        if (f.field == "limits" && f.index == static_cast<int>(p.limits.size()) - 1) {
          r_.fail(pareto_marks_[1], f.joined("optimize.pareto.second"));
        }
        r_.fail(e.key_mark, "optimize: " + text);
      };
      if (const Problem f = p.validate()) fail_at(*f, f->text());
      try {
        op::PlanarNlp::check(p);
      } catch (const InputError& err) {
        if (err.field()) fail_at(*err.field(), err.what());
        r_.fail(e.key_mark, "optimize: " + std::string(err.what()));
      }
      // the front's other end minimises `second` alone
      op::DesignProblem q = problem;
      q.objective = {op::Term{req.pareto->second, 1.0}};
      try {
        op::PlanarNlp::check(q);
      } catch (const InputError& err) {
        const auto& f = err.field();
        if (f && f->field == "objective") {
          r_.fail(pareto_marks_[1], f->joined("optimize.pareto.second"));
        }
        r_.fail(e.key_mark, "optimize: " + std::string(err.what()));
      }
    }
    return req;
  }

  // a planar linkage's optimize.pareto: {first, second, points}
  PlanarParetoRequest read_planar_pareto(const MapReader::Entry& e) {
    PlanarParetoRequest p;
    const MapReader m(r_, e.value, "optimize.pareto", e.key_mark, "(first, second, points)");
    m.check_keys({"first", "second", "points"});
    const MapReader::Entry& first = m.require("first", "the metric minimised along the front");
    const MapReader::Entry& second = m.require("second", "the metric bounded along the front");
    pareto_marks_[0] = mark_of(first.value, first.key_mark);
    pareto_marks_[1] = mark_of(second.value, second.key_mark);
    p.first = read_text(r_, first, "optimize.pareto.first");
    check_planar_metric(p.first, pareto_marks_[0], "optimize.pareto.first");
    p.second = read_text(r_, second, "optimize.pareto.second");
    check_planar_metric(p.second, pareto_marks_[1], "optimize.pareto.second");
    if (p.first == p.second) {
      r_.fail(pareto_marks_[1],
              "optimize.pareto.second must differ from first (both are " + p.first + ")");
    }
    if (const MapReader::Entry* n = m.find("points")) {
      p.points = read_count(r_, *n, "optimize.pareto.points", 2, 1000);
    }
    return p;
  }

  // a planar linkage's metric by name (or added_mass); `or_else` leads the list in the message
  void check_planar_metric(const std::string& name, const YAML::Mark& mark,
                           const std::string& where, const std::string& or_else = "") {
    std::string names;
    for (const core::planar::ColumnMetric& m : table_) {
      if (m.name == name) return;
      names += m.name + ", ";
    }
    if (name == "added_mass") return;
    r_.fail(mark, "unknown " +
                      std::string(where == "optimize.constraints" ? "constraint" : "metric") +
                      " '" + name + "' in " + where + "; expected " + or_else + "one of " + names +
                      "added_mass");
  }

  static std::string links(const core::planar::Linkage& linkage) {
    std::string names;
    for (const core::planar::Link& l : linkage.links) names += (names.empty() ? "" : ", ") + l.name;
    return names;
  }

  struct SolverMarks {
    YAML::Mark section, algorithm, evaluations, starts, tolerance;
    bool starts_given = false;  // optimize.starts written (else mlsl's default)
  };

  // algorithm, max_evaluations, starts, tolerance; each mark defaults to the section's
  // optimize.peaks: resolved (true, the default) or sampled (false)
  bool read_peaks(const MapReader& o) {
    const MapReader::Entry* k = o.find("peaks");
    if (!k) return true;
    const std::string how = read_text(r_, *k, "optimize.peaks");
    if (how != "resolved" && how != "sampled") {
      r_.fail(mark_of(k->value, k->key_mark),
              "optimize.peaks must be resolved or sampled, got '" + how + "'");
    }
    return how == "resolved";
  }

  SolverMarks read_solver(const MapReader& o, const YAML::Mark& section, bool free_scene,
                          optimize::OptimizeOptions& options) {
    SolverMarks marks{section, section, section, section, section, false};
    // without the key, the method that suits the scene: a free scene's evaluations are
    // simulations without derivatives
    options.algorithm = optimize::default_algorithm(free_scene);
    if (const MapReader::Entry* a = o.find("algorithm")) {
      const std::string name = read_text(r_, *a, "optimize.algorithm");
      marks.algorithm = mark_of(a->value, a->key_mark);
      const auto alg = optimize::algorithm_named(name);
      if (!alg) {
        std::vector<std::string> all;
        for (optimize::Algorithm x : kAlgorithms) all.emplace_back(optimize::to_string(x));
        r_.fail(marks.algorithm, "unknown algorithm '" + name +
                                     "' in optimize.algorithm; expected one of " + join(all));
      }
      options.algorithm = *alg;
    }
    if (const MapReader::Entry* n = o.find("max_evaluations")) {
      options.max_evaluations = read_count(r_, *n, "optimize.max_evaluations", 1, 1e9);
      marks.evaluations = mark_of(n->value, n->key_mark);
    }
    if (const MapReader::Entry* k = o.find("starts")) {
      options.starts = read_count(r_, *k, "optimize.starts", 1, 1e6);
      marks.starts = mark_of(k->value, k->key_mark);
      marks.starts_given = true;
      if (options.algorithm != optimize::Algorithm::kMlsl) {
        r_.fail(marks.starts, std::string("optimize.starts is the number of local runs of the "
                                          "multistart mlsl; algorithm ") +
                                  optimize::to_string(options.algorithm) + " runs once");
      }
    }
    if (const MapReader::Entry* t = o.find("tolerance")) {
      const double tol = read_number(r_, *t, "optimize.tolerance", "");
      marks.tolerance = mark_of(t->value, t->key_mark);
      if (!(tol > 0 && tol < 1)) {
        r_.fail(marks.tolerance,
                "optimize.tolerance must be > 0 and < 1 (relative, on the variables and the "
                "objective), got " +
                    text::shortest(tol));
      }
      options.relative_tolerance = tol;
    }
    return marks;
  }

  // the optimize layer's check of the options, at the key it names
  void check_options(const optimize::OptimizeOptions& options, const SolverMarks& marks) {
    const Problem p = options.validate();
    if (!p) return;
    YAML::Mark where = marks.section;
    if (p->field == "max_evaluations") where = marks.evaluations;
    if (p->field == "starts") where = marks.starts;
    if (p->field == "relative_tolerance" || p->field == "constraint_tolerance") {
      where = marks.tolerance;
    }
    if (p->field == "algorithm") where = marks.algorithm;
    // mlsl's default number of starts, not written: say so, and where to change it
    const bool default_starts = p->field == "starts" && !marks.starts_given;
    r_.fail(where, "optimize: " + p->text() +
                       (default_starts ? " (the default; give optimize.starts)" : ""));
  }

  // a limit's bound: added_mass in kg (may be 0 or negative: keep the mass as it is, or take
  // some away), else a fraction of the original's value (> 0)
  double read_limit(const MapReader::Entry& x, const std::string& path, bool kg) {
    if (kg) return read_number(r_, x, path, "kg");
    const double v = read_number(r_, x, path, "");
    if (!(v > 0)) {
      r_.fail(mark_of(x.value, x.key_mark),
              path + " must be > 0 (a fraction of the original design's value), got " +
                  text::shortest(v));
    }
    return v;
  }

  // the optimize layer sets up the problem as it will solve it: the original simulated in the
  // scene (its metrics are the normalisers, which must not vanish); its complaint is reported at
  // the objective term or constraint whose field it names, else at the section
  void check_evaluation(const optimize::DesignProblem& problem, const OptimizeRequest& req,
                        const YAML::Mark& section) {
    struct Named {
      YAML::Mark mark;
      std::string path;
    };
    std::vector<Named> terms, limits;
    for (std::size_t i = 0; i < problem.objective.size(); ++i) {
      terms.push_back({term_marks_[i], std::string("optimize.objective.") +
                                           optimize::to_string(problem.objective[i].metric)});
    }
    for (std::size_t i = 0; i < problem.limits.size(); ++i) {
      limits.push_back({limit_marks_[i], std::string("optimize.constraints.") +
                                             optimize::to_string(problem.limits[i].metric)});
    }
    auto set_up = [&](const optimize::DesignProblem& p, const std::vector<Named>& t,
                      const std::vector<Named>& l) {
      try {
        const optimize::Nlp nlp(p);
      } catch (const InputError& err) {
        if (const auto& f = err.field(); f && f->index >= 0) {
          const std::vector<Named>* named = f->field == "objective" ? &t
                                            : f->field == "limits"  ? &l
                                                                    : nullptr;
          const auto i = static_cast<std::size_t>(f->index);
          if (named && i < named->size()) r_.fail((*named)[i].mark, f->joined((*named)[i].path));
        }
        r_.fail(section, "optimize: " + std::string(err.what()));
      }
    };
    set_up(problem, terms, limits);
    // each point of a Pareto front minimises `first` with a bound on `second`
    if (req.pareto) {
      optimize::DesignProblem p = problem;
      p.objective = {optimize::Term{req.pareto->first, 1.0}};
      p.limits.push_back(optimize::Limit{req.pareto->second, 1.0});
      limits.push_back({pareto_marks_[1], "optimize.pareto.second"});
      set_up(p, {{pareto_marks_[0], "optimize.pareto.first"}}, limits);
    }
  }

  // a gradient method in a free scene on the opened loop (whose DAE has no sensitivities) is
  // reported at `algorithm` in optimize()'s own words (optimize() refuses what
  // check_algorithm() refuses). In a free scene every complaint is reported here; in a driven
  // scene (mma with force_balance) the run reports it, as before.
  void check_algorithm(const optimize::DesignProblem& problem, const OptimizeRequest& req,
                       const YAML::Mark& algorithm_mark) {
    if (!std::holds_alternative<core::FreeScene>(problem.scene)) return;
    if (const Problem p = optimize::check_algorithm(problem, req.options)) {
      r_.fail(algorithm_mark, "optimize.algorithm: " + p->text());
    }
  }

  // "Fsh_rms, Fsh_max, ..., added_mass"
  static std::string metric_names() {
    std::vector<std::string> names;
    for (optimize::Metric m : optimize::kMetrics) names.emplace_back(optimize::to_string(m));
    return join(names);
  }

  // a metric named by a key or a value; `where` names the map or key in the message
  optimize::Metric read_metric(const std::string& name, const YAML::Mark& mark,
                               const std::string& where) {
    if (const auto m = optimize::metric_named(name)) return *m;
    r_.fail(mark,
            "unknown metric '" + name + "' in " + where + "; expected one of " + metric_names());
  }

  // a metric that is zero in every free scene cannot be normalised by the original's value
  void check_metric_in_scene(optimize::Metric m, const Scene& scene, const YAML::Mark& mark,
                             const std::string& path) {
    const bool tau = m == optimize::Metric::kTauRms || m == optimize::Metric::kTauMax;
    if (tau && std::holds_alternative<core::FreeScene>(scene)) {
      r_.fail(mark, path +
                        ": a free scene has no drive torque (tau is 0 throughout), so there is "
                        "nothing to minimise or bound; use a driven scene");
    }
  }

  // optimize.objective: {metric: weight, ...}
  void read_objective(const MapReader::Entry& e, const Study& study, OptimizeRequest& req) {
    const MapReader m(r_, e.value, "optimize.objective", e.key_mark,
                      "of metric: weight (e.g. Msh_rms: 1.0)");
    bool positive = false;
    for (const MapReader::Entry& x : m.entries()) {
      const optimize::Metric metric = read_metric(x.key, x.key_mark, "optimize.objective");
      const std::string path = "optimize.objective." + x.key;
      check_metric_in_scene(metric, study.scene, x.key_mark, path);
      const double w = read_number(r_, x, path, "");
      if (w < 0) {
        r_.fail(mark_of(x.value, x.key_mark),
                path + " must be >= 0 (a weight), got " + text::shortest(w));
      }
      positive = positive || w > 0;
      req.objective.push_back({metric, w});
      term_marks_.push_back(x.key_mark);
    }
    if (!positive) {
      r_.fail(e.key_mark, "optimize.objective needs at least one metric with a weight > 0");
    }
  }

  // optimize.constraints: {force_balance: bool, metric: fraction, added_mass: kg}
  void read_constraints(const MapReader::Entry& e, const Study& study, OptimizeRequest& req) {
    if (e.value.IsNull()) return;  // `constraints:` with nothing under it: none
    const MapReader m(r_, e.value, "optimize.constraints", e.key_mark,
                      "(force_balance, and metric: bound)");
    for (const MapReader::Entry& x : m.entries()) {
      const std::string path = "optimize.constraints." + x.key;
      if (x.key == "force_balance") {
        req.force_balance = read_bool(r_, x, path);
        continue;
      }
      if (!optimize::metric_named(x.key)) {
        r_.fail(x.key_mark, "unknown constraint '" + x.key +
                                "' in optimize.constraints; expected force_balance or one of " +
                                metric_names());
      }
      const optimize::Metric metric = *optimize::metric_named(x.key);
      check_metric_in_scene(metric, study.scene, x.key_mark, path);
      req.limits.push_back({metric, read_limit(x, path, metric == optimize::Metric::kAddedMass)});
      limit_marks_.push_back(x.key_mark);
    }
  }

  // optimize.variables: {counterweights: {crank, rocker}, links: {crank, coupler, rocker}}
  void read_variables(const MapReader::Entry& e, const core::FourBar& model, OptimizeRequest& req) {
    const MapReader v(r_, e.value, "optimize.variables", e.key_mark, "(counterweights, links)");
    v.check_keys({"counterweights", "links"});
    if (const MapReader::Entry* cw = v.find("counterweights"); cw && !cw->value.IsNull()) {
      const MapReader sides(r_, cw->value, "optimize.variables.counterweights", cw->key_mark,
                            "(crank, rocker)");
      sides.check_keys({"crank", "rocker"});
      for (int i = 0; i < 2; ++i) {
        if (const MapReader::Entry* x = sides.find(kSides[i])) {
          const int link = i == 0 ? 1 : 3;
          req.counterweights.push_back(
              read_counterweight_variables<optimize::CounterweightVariables>(
                  *x, "optimize.variables.counterweights." + std::string(kSides[i]), link,
                  core::link(model, link).length));
        }
      }
    }
    if (const MapReader::Entry* links = v.find("links"); links && !links->value.IsNull()) {
      const MapReader lk(r_, links->value, "optimize.variables.links", links->key_mark,
                         "(crank, coupler, rocker)");
      lk.check_keys({"crank", "coupler", "rocker"});
      for (const MapReader::Entry& x : lk.entries()) {
        const int link = x.key == "crank" ? 1 : x.key == "coupler" ? 2 : 3;
        read_link_parameters(x, "optimize.variables.links." + x.key, link, req.link_parameters);
      }
    }
    if (req.counterweights.empty() && req.link_parameters.empty()) {
      r_.fail(e.key_mark,
              "optimize.variables: no design variable; give counterweights (crank, rocker) or "
              "links (mass, e, f, inertia within bounds)");
    }
  }

  // {mass_max, distance_max, shape, thickness, density}
  template <class Variables>  // optimize::CounterweightVariables or its planar twin
  Variables read_counterweight_variables(const MapReader::Entry& e, const std::string& path,
                                         int link, double length) {
    Variables cw;
    cw.link = link;
    cw.distance_max = length;  // default: the envelope of the link itself
    if (e.value.IsNull()) return cw;
    const MapReader m(r_, e.value, path, e.key_mark,
                      "(mass_max, distance_max, shape, thickness, density)");
    m.check_keys({"mass_max", "distance_max", "shape", "thickness", "density"});
    if (const MapReader::Entry* shape = m.find("shape")) cw.shape = read_shape(*shape, path);
    for (const char* key : {"thickness", "density"}) {
      const MapReader::Entry* x = m.find(key);
      if (x && cw.shape != balance::CounterweightShape::kDisc) {
        r_.fail(x->key_mark, path + "." + key + " needs shape: disc (a point mass has no size)");
      }
    }
    auto positive = [&](const MapReader::Entry& x, const char* unit) {
      return read_positive(r_, x, path + "." + x.key, unit);
    };
    if (const MapReader::Entry* x = m.find("mass_max")) cw.mass_max = positive(*x, "kg");
    if (const MapReader::Entry* x = m.find("distance_max")) cw.distance_max = positive(*x, "m");
    if (const MapReader::Entry* x = m.find("thickness")) cw.thickness = positive(*x, "m");
    if (const MapReader::Entry* x = m.find("density")) cw.density = positive(*x, "kg/m^3");
    return cw;
  }

  // {mass: [lo, hi], e: [lo, hi], f: [lo, hi], inertia: [lo, hi]}, at least one
  template <class Variable>  // optimize::LinkParameterVariable or its planar twin
  void read_link_parameters(const MapReader::Entry& e, const std::string& path, int link,
                            std::vector<Variable>& out) {
    using P = optimize::LinkParameterVariable::Parameter;
    const MapReader m(r_, e.value, path, e.key_mark, "(mass, e, f, inertia, each [lower, upper])");
    m.check_keys({"mass", "e", "f", "inertia"});
    if (m.entries().empty()) {
      r_.fail(e.key_mark, path + ": give at least one of mass, e, f, inertia as [lower, upper]");
    }
    for (const MapReader::Entry& x : m.entries()) {
      const P p = x.key == "mass" ? P::kMass
                  : x.key == "e"  ? P::kE
                  : x.key == "f"  ? P::kF
                                  : P::kInertia;
      const char* unit = p == P::kMass ? "kg" : p == P::kInertia ? "kg m²" : "m";
      const std::string xp = path + "." + x.key;
      const YAML::Mark vm = mark_of(x.value, x.key_mark);
      if (!x.value.IsSequence() || x.value.size() != 2) {
        r_.fail(vm, xp + " must be a list of 2 numbers [lower, upper] in " + unit + ", got " +
                        (x.value.IsSequence() ? "a list of " + std::to_string(x.value.size())
                                              : describe(x.value)));
      }
      const double lo = read_number(r_, x.value[0], vm, xp + "[0]", unit);
      const double hi = read_number(r_, x.value[1], vm, xp + "[1]", unit);
      if (!(lo < hi)) {
        r_.fail(vm, xp + " must have lower < upper, got [" + text::shortest(lo) + ", " +
                        text::shortest(hi) + "]");
      }
      if (p == P::kMass && !(lo > 0)) {
        r_.fail(mark_of(x.value[0], vm),
                xp + " lower bound must be > 0 kg (a link has mass), got " + text::shortest(lo));
      }
      if (p == P::kInertia && lo < 0) {
        r_.fail(mark_of(x.value[0], vm),
                xp + " lower bound must be >= 0 kg m², got " + text::shortest(lo));
      }
      Variable v;
      v.link = link;
      v.parameter = p;
      v.lower = lo;
      v.upper = hi;
      out.push_back(v);
    }
  }

  // optimize.pareto: {first, second, points}
  ParetoRequest read_pareto(const MapReader::Entry& e, const Scene& scene) {
    ParetoRequest p;
    const MapReader m(r_, e.value, "optimize.pareto", e.key_mark, "(first, second, points)");
    m.check_keys({"first", "second", "points"});
    const MapReader::Entry& first = m.require("first", "the metric minimised along the front");
    const MapReader::Entry& second = m.require("second", "the metric bounded along the front");
    const YAML::Mark fm = mark_of(first.value, first.key_mark);
    const YAML::Mark sm = mark_of(second.value, second.key_mark);
    p.first =
        read_metric(read_text(r_, first, "optimize.pareto.first"), fm, "optimize.pareto.first");
    check_metric_in_scene(p.first, scene, fm, "optimize.pareto.first");
    p.second =
        read_metric(read_text(r_, second, "optimize.pareto.second"), sm, "optimize.pareto.second");
    check_metric_in_scene(p.second, scene, sm, "optimize.pareto.second");
    pareto_marks_[0] = fm;
    pareto_marks_[1] = sm;
    if (p.first == p.second) {
      r_.fail(sm, std::string("optimize.pareto.second must differ from first (both are ") +
                      optimize::to_string(p.first) + ")");
    }
    if (const MapReader::Entry* n = m.find("points")) {
      p.points = read_count(r_, *n, "optimize.pareto.points", 2, 1000);
    }
    return p;
  }

  balance::CounterweightShape read_shape(const MapReader::Entry& shape, const std::string& path) {
    return detail::read_shape(r_, shape, path);
  }

 private:
  const Reporter& r_;
  std::vector<YAML::Mark> term_marks_;   // optimize.objective's keys, one per term
  std::vector<YAML::Mark> limit_marks_;  // optimize.constraints' metric keys, one per limit
  YAML::Mark pareto_marks_[2];           // optimize.pareto.first and .second
  std::vector<core::planar::ColumnMetric> table_;  // a planar linkage's metrics
  YAML::Mark force_balance_mark_;                  // optimize.constraints.force_balance
};

}  // namespace

OptimizeRequest read_optimize(const Reporter& r, const MapReader::Entry& e, const Study& study) {
  return OptimizeReader(r).read_optimize(e, study);
}

PlanarOptimizeRequest read_planar_optimize(const Reporter& r, const MapReader::Entry& e,
                                           const Study& study) {
  return OptimizeReader(r).read_planar_optimize(e, study);
}

}  // namespace bd::studies::detail
