#include "studies/run/runner.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cassert>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <system_error>
#include <utility>
#include <variant>

#include "core/number_text.hpp"
#include "optimize/nlp.hpp"
#include "studies/report/report.hpp"
#include "studies/study/study_yaml.hpp"

namespace bd::studies {

namespace fs = std::filesystem;

namespace {

// a file written under a temporary name in the target's directory and renamed into place by
// commit(); removed if never committed, so readers see the whole file or none
class AtomicFile {
 public:
  explicit AtomicFile(fs::path target) : target_(std::move(target)) {
    static std::atomic<unsigned> counter{0};
    // appended piece by piece: GCC 12 at -O3 warns falsely on `"." + std::string&&` (GCC bug
    // 105329, -Wrestrict)
    std::string name = ".";
    name.append(target_.filename().string()).append(".").append(std::to_string(::getpid()));
    name.append(".").append(std::to_string(counter++)).append(".tmp");
    temp_ = target_.parent_path() / name;
    file_ = std::fopen(temp_.c_str(), "wbx");
    if (!file_) fail("cannot create", temp_);
  }
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  ~AtomicFile() {
    if (file_) std::fclose(file_);
    if (!committed_) {
      std::error_code ec;
      fs::remove(temp_, ec);
    }
  }

  std::FILE* get() { return file_; }

  void commit() {
    const bool write_error = std::fflush(file_) != 0 || std::ferror(file_) != 0;
    const int saved = errno;
    const bool close_error = std::fclose(file_) != 0;
    file_ = nullptr;
    if (write_error || close_error) {
      errno = write_error ? saved : errno;
      fail("cannot write", temp_);
    }
    std::error_code ec;
    fs::rename(temp_, target_, ec);
    if (ec) {
      throw std::runtime_error("cannot rename " + temp_.string() + " to " + target_.string() +
                               ": " + ec.message());
    }
    committed_ = true;
  }

 private:
  [[noreturn]] static void fail(const char* what, const fs::path& p) {
    throw std::runtime_error(std::string(what) + " " + p.string() + ": " + std::strerror(errno));
  }

  fs::path target_, temp_;
  std::FILE* file_ = nullptr;
  bool committed_ = false;
};

// JSON has no inf or nan: those become null
std::string json_number(double v) { return std::isfinite(v) ? text::exact(v) : "null"; }

std::string json_vec(const Vec2& v) {
  return "[" + json_number(v.x()) + ", " + json_number(v.y()) + "]";
}

// the metrics in the table's order, with their names
std::vector<std::pair<const char*, double>> metric_items(const core::Metrics& m) {
  std::vector<std::pair<const char*, double>> items;
  for (const core::MetricInfo& info : core::kMetricTable)
    items.emplace_back(info.name, m.*info.field);
  return items;
}

// `"key": {...}` with one metric per line, indented by two spaces; `last` drops the comma
std::string metrics_json(const char* key, const core::Metrics& m, bool last) {
  std::string j = std::string("  \"") + key + "\": {\n";
  const auto items = metric_items(m);
  for (std::size_t k = 0; k < items.size(); ++k) {
    j += std::string("    \"") + items[k].first + "\": " + json_number(items[k].second) +
         (k + 1 < items.size() ? ",\n" : "\n");
  }
  return j + (last ? "  }\n" : "  },\n");
}

std::string method_json(const Study& study, const MethodChoice& method) {
  return "{\"requested\": " + json_string(study.method_name()) +
         ", \"used\": " + json_string(core::to_string(method.formulation)) +
         ", \"reason\": " + json_string(method.reason) + "}";
}

// the balance section of summary.json: what was asked, what was added, which conditions hold
std::string balance_json(const balance::BalancedDesign& b) {
  std::string j = "  \"balance\": {\n";
  j += std::string("    \"force\": ") + (b.request.force ? "\"full\"" : "\"none\"") + ",\n";
  j += std::string("    \"moment\": ") + (b.request.moment ? "\"full\"" : "\"none\"") + ",\n";

  // counterweights actually added, crank first
  std::vector<std::string> items;
  const std::optional<balance::Counterweight>* cws[] = {&b.crank_counterweight,
                                                        &b.rocker_counterweight};
  const balance::CounterweightSpec* specs[] = {&b.request.crank_counterweight,
                                               &b.request.rocker_counterweight};
  const char* sides[] = {"crank", "rocker"};
  for (int i = 0; i < 2; ++i) {
    if (!cws[i]->has_value()) continue;
    const balance::Counterweight& c = **cws[i];
    items.push_back(
        std::string("{\"link\": \"") + sides[i] + "\", \"shape\": \"" + balance::to_string(specs[i]->shape) +
        "\", \"mass\": " + json_number(c.mass) + ", \"position\": " + json_vec(c.position) +
        ", \"distance\": " + json_number(c.distance) + ", \"radius\": " + json_number(c.radius) +
        ", \"thickness\": " + json_number(c.thickness) +
        ", \"inertia\": " + json_number(c.inertia) + "}");
  }
  auto list = [](const std::vector<std::string>& xs) {
    if (xs.empty()) return std::string("[]");
    std::string out = "[\n";
    for (std::size_t k = 0; k < xs.size(); ++k) {
      out += "      " + xs[k] + (k + 1 < xs.size() ? ",\n" : "\n");
    }
    return out + "    ]";
  };
  j += "    \"counterweights\": " + list(items) + ",\n";

  // counter-rotations of the balanced design
  items.clear();
  const core::CounterRotation* discs[] = {&b.model.counter_rotations.crank,
                                          &b.model.counter_rotations.rocker};
  for (int i = 0; i < 2; ++i) {
    if (discs[i]->inertia <= 0) continue;
    items.push_back(std::string("{\"link\": \"") + sides[i] + "\", \"inertia\": " +
                    json_number(discs[i]->inertia) + ", \"at\": " + json_vec(discs[i]->at) + "}");
  }
  j += "    \"counter_rotations\": " + list(items) + ",\n";
  j += "    \"added_mass\": " + json_number(b.added_mass) + ",\n";
  j += "    \"added_inertia\": " + json_number(b.added_inertia) + ",\n";
  j += std::string("    \"force_balanced\": ") +
       (b.conditions.force_balanced() ? "true" : "false") + ",\n";
  j += std::string("    \"moment_balanced\": ") +
       (b.conditions.moment_balanced() ? "true" : "false") + ",\n";

  // check_balance of the balanced design, force conditions first
  items.clear();
  for (const auto* group : {&b.conditions.force, &b.conditions.moment}) {
    for (const balance::Condition& c : *group) {
      items.push_back(
          "{\"name\": " + json_string(c.name) + ", \"residual\": " + json_number(c.residual) +
          ", \"scale\": " + json_number(c.scale) + ", \"unit\": " + json_string(c.unit) +
          ", \"holds\": " + (c.holds ? "true" : "false") + "}");
    }
  }
  j += "    \"conditions\": " + list(items) + "\n";
  return j + "  },\n";
}

// `"reduction": {...}`: after / before per metric; null where before is 0; `last` drops the comma
std::string reduction_json(const core::Metrics& before_m, const core::Metrics& after_m, bool last) {
  std::string j = "  \"reduction\": {\n";
  const auto before = metric_items(before_m);
  const auto after = metric_items(after_m);
  for (std::size_t k = 0; k < before.size(); ++k) {
    const double ratio = after[k].second / before[k].second;
    j += std::string("    \"") + before[k].first +
         "\": " + (before[k].second != 0 ? json_number(ratio) : std::string("null")) +
         (k + 1 < before.size() ? ",\n" : "\n");
  }
  return j + (last ? "  }\n" : "  },\n");
}

// a JSON list of pre-formatted items, one per line at `indent` + 2 spaces
std::string json_list(const std::vector<std::string>& xs, const std::string& indent) {
  if (xs.empty()) return "[]";
  std::string out = "[\n";
  for (std::size_t k = 0; k < xs.size(); ++k) {
    out += indent + "  " + xs[k] + (k + 1 < xs.size() ? ",\n" : "\n");
  }
  return out + indent + "]";
}

// the counterweights of an optimum, as balance_json writes them
std::vector<std::string> counterweights_json(
    const OptimizeRequest& request, const std::vector<optimize::PlacedCounterweight>& cws) {
  std::vector<std::string> items;
  for (const optimize::PlacedCounterweight& p : cws) {
    balance::CounterweightShape shape = balance::CounterweightShape::kPoint;
    for (const optimize::CounterweightVariables& v : request.counterweights) {
      if (v.link == p.link) shape = v.shape;
    }
    const balance::Counterweight& c = p.counterweight;
    items.push_back(
        std::string("{\"link\": \"") + core::link_name(p.link) + "\", \"shape\": \"" +
        balance::to_string(shape) + "\", \"mass\": " + json_number(c.mass) +
        ", \"position\": " + json_vec(c.position) + ", \"distance\": " + json_number(c.distance) +
        ", \"radius\": " + json_number(c.radius) + ", \"thickness\": " + json_number(c.thickness) +
        ", \"inertia\": " + json_number(c.inertia) + "}");
  }
  return items;
}

// the optimize section of summary.json: the problem, how the solver ended, the optimum
std::string optimize_json(const Study& study, const RunResult& result) {
  const OptimizeRequest& req = *study.optimize;
  const OptimizedRun& o = *result.optimized;
  const optimize::OptimizeResult& r = o.result;
  std::string j = "  \"optimize\": {\n";
  j += std::string("    \"algorithm\": \"") + optimize::to_string(req.options.algorithm) + "\",\n";
  j += "    \"formulation\": " + json_string(core::to_string(result.method.formulation)) + ",\n";
  std::vector<std::string> items;
  for (const optimize::Term& t : req.objective) {
    items.push_back(std::string("{\"metric\": \"") + optimize::to_string(t.metric) +
                    "\", \"weight\": " + json_number(t.weight) + "}");
  }
  j += "    \"terms\": " + json_list(items, "    ") + ",\n";
  j += std::string("    \"force_balance\": ") + (req.force_balance ? "true" : "false") + ",\n";
  items.clear();
  for (const optimize::Limit& l : req.limits) {
    const bool kg = l.metric == optimize::Metric::kAddedMass;
    items.push_back(std::string("{\"metric\": \"") + optimize::to_string(l.metric) +
                    "\", \"value\": " + json_number(l.value) + ", \"unit\": \"" +
                    (kg ? "kg" : "fraction of the original") + "\"}");
  }
  j += "    \"limits\": " + json_list(items, "    ") + ",\n";
  j += std::string("    \"termination\": \"") + optimize::to_string(r.termination) + "\",\n";
  j += "    \"message\": " + json_string(r.message) + ",\n";
  j += "    \"iterations\": " + std::to_string(r.iterations) + ",\n";
  j += "    \"evaluations\": " + std::to_string(r.evaluations) + ",\n";
  j += "    \"seconds\": " + json_number(r.seconds) + ",\n";
  const bool found = o.found();
  j += "    \"objective\": " + (found ? json_number(r.objective) : std::string("null")) + ",\n";
  j += "    \"constraint_violation\": " +
       (found ? json_number(r.constraint_violation) : std::string("null")) + ",\n";
  items.clear();
  if (static_cast<std::size_t>(r.x.size()) == o.variable_names.size()) {
    for (std::size_t k = 0; k < o.variable_names.size(); ++k) {
      items.push_back("{\"name\": " + json_string(o.variable_names[k]) +
                      ", \"value\": " + json_number(r.x[static_cast<Eigen::Index>(k)]) + "}");
    }
  }
  j += "    \"variables\": " + json_list(items, "    ") + ",\n";
  j += "    \"counterweights\": " +
       json_list(found ? counterweights_json(req, r.counterweights) : std::vector<std::string>{},
                 "    ") +
       ",\n";
  if (found) {
    j += "    \"added_mass\": " + json_number(added_mass(study.model, r.design)) + ",\n";
    j += "    \"added_inertia\": " + json_number(added_inertia(study.model, r.design)) + ",\n";
    j += "    \"verified_with\": " + json_string(core::to_string(r.verified_with)) + ",\n";
    j += "    \"verification_error\": " + json_number(r.verification_error) + ",\n";
  }
  if (req.pareto) {
    j += std::string("    \"pareto\": {\"first\": \"") + optimize::to_string(req.pareto->first) +
         "\", \"second\": \"" + optimize::to_string(req.pareto->second) +
         "\", \"points\": " + std::to_string(o.pareto.size()) + "},\n";
  }
  j += "    \"brief_report\": " + json_string(r.brief_report()) + "\n";
  return j + "  },\n";
}

// a trajectory's run facts (status, counts), without the braces
std::string run_json_fields(const core::Trajectory& tr, const std::string& indent) {
  std::string j;
  j += indent + "\"samples\": " + std::to_string(tr.samples.size()) + ",\n";
  j += indent + "\"status\": " + json_string(core::to_string(tr.status)) + ",\n";
  j += indent + "\"ok\": " + (tr.ok() ? "true" : "false") + ",\n";
  j += indent + "\"message\": " + json_string(tr.message) + ",\n";
  j += indent + "\"steps\": " + std::to_string(tr.steps) + ",\n";
  j += indent + "\"rhs_evaluations\": " + std::to_string(tr.rhs_evaluations);
  return j;
}

core::Trajectory simulate(const Study& study, const MethodChoice& method) {
  core::SimulateOptions options;
  options.formulation = method.formulation;
  options.integrator = method.integrator;
  options.tolerance = study.tolerance;
  if (const auto* free = std::get_if<core::FreeScene>(&study.scene)) {
    return core::simulate_free(study.model, *free, options);
  }
  return core::simulate_driven(study.model, std::get<core::DrivenScene>(study.scene), options);
}

void write_text(const std::string& text, const fs::path& file) {
  AtomicFile out(file);
  if (std::fwrite(text.data(), 1, text.size(), out.get()) != text.size()) {
    throw std::runtime_error("cannot write " + file.string() + ": " + std::strerror(errno));
  }
  out.commit();
}

// solves an optimize study's problem and simulates the optimum; not run when the original's
// simulation stopped early (its metrics are the normalisers)
OptimizedRun optimize_study(const Study& study, const RunResult& original) {
  OptimizedRun o;
  if (!original.trajectory.ok()) {
    o.result.message = "not run: the original design's simulation stopped early (" +
                       original.trajectory.message + ")";
    return o;
  }
  const OptimizeRequest& req = *study.optimize;
  const optimize::DesignProblem problem = design_problem(study);
  o.result = optimize::optimize(problem, req.options);
  {
    const optimize::Nlp nlp(problem);
    o.variable_names = nlp.variable_names();
  }
  o.design_variables = std::min(static_cast<int>(o.variable_names.size()),
                                3 * static_cast<int>(req.counterweights.size()) +
                                    static_cast<int>(req.link_parameters.size()));
  if (!o.found()) return o;
  const Study best = optimized_study(study, o.result.design);
  o.method = choose_method(best);
  o.trajectory = simulate(best, o.method);
  o.metrics = core::metrics(o.trajectory);
  if (req.pareto) {
    o.pareto = optimize::pareto_front(problem, req.pareto->first, req.pareto->second,
                                      req.pareto->points, req.options);
  }
  return o;
}

}  // namespace

std::string json_string(const std::string& text) {
  std::string out = "\"";
  for (char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\b':
        out += "\\b";
        break;
      case '\f':
        out += "\\f";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (c < 0x20 || c == 0x7f) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(c));
          out += buf;
        } else {
          out += ch;  // UTF-8 bytes pass through unchanged
        }
    }
  }
  return out + "\"";
}

void write_timeseries(const core::Trajectory& trajectory, const fs::path& file) {
  AtomicFile out(file);
  std::FILE* f = out.get();
  std::fputs(kTimeseriesHeader, f);
  std::fputc('\n', f);
  for (std::size_t i = 0; i < trajectory.samples.size(); ++i) {
    const core::DynamicsSample& d = trajectory.samples[i];
    const core::FourBarState& s = d.state;
    const double t = i < trajectory.t.size() ? trajectory.t[i] : std::nan("");
    const double row[] = {t,         s.theta1,  s.theta2,  s.theta3,  s.omega1,  s.omega2,
                          s.omega3,  s.alpha1,  s.alpha2,  s.alpha3,  d.RA0.x(), d.RA0.y(),
                          d.RA3.x(), d.RA3.y(), d.Fsh.x(), d.Fsh.y(), d.Msh,     d.tau};
    for (std::size_t k = 0; k < std::size(row); ++k) {
      std::fprintf(f, k == 0 ? "%.17g" : ",%.17g", row[k]);
    }
    std::fputc('\n', f);
  }
  out.commit();
}

namespace {

// The keys of a second design's run (the balanced or the optimised one): `<what>_run`,
// `<what>_metrics`, and `reduction` (second / original per metric; null where the original is 0).
std::string second_run_json(const Study& study, const std::string& what, const MethodChoice& method,
                            const core::Trajectory& trajectory, const core::Metrics& original,
                            const core::Metrics& second) {
  std::string j = "  \"" + what + "_run\": {\n";
  j += "    \"study\": " + json_string(study.name + "-" + what) + ",\n";
  j += "    \"method\": " + method_json(study, method) + ",\n";
  j += run_json_fields(trajectory, "    ") + "\n";
  j += "  },\n";
  j += metrics_json((what + "_metrics").c_str(), second, false);
  j += reduction_json(original, second, true);
  return j;
}

}  // namespace

std::string summary_json(const Study& study, const RunResult& result) {
  const core::Trajectory& tr = result.trajectory;
  std::string j = "{\n";
  j += "  \"format\": \"balance-design summary v1\",\n";
  j += "  \"study\": " + json_string(study.name) + ",\n";
  j += "  \"source\": " + json_string(study.source) + ",\n";
  j += "  \"method\": " + method_json(study, result.method) + ",\n";
  if (const auto* free = std::get_if<core::FreeScene>(&study.scene)) {
    j += "  \"scene\": {\"type\": \"free\", \"theta1\": " + json_number(free->theta1) +
         ", \"omega1\": " + json_number(free->omega1) +
         ", \"duration\": " + json_number(free->duration) +
         ", \"samples\": " + std::to_string(free->samples) + "},\n";
  } else {
    const auto& driven = std::get<core::DrivenScene>(study.scene);
    j += "  \"scene\": {\"type\": \"driven\", \"theta1\": " + json_number(driven.theta1) +
         ", \"omega1\": " + json_number(driven.omega1) +
         ", \"revolutions\": " + std::to_string(driven.revolutions) +
         ", \"samples\": " + std::to_string(driven.samples) + "},\n";
  }
  j += "  \"tolerance\": " + json_number(study.tolerance) + ",\n";
  j += run_json_fields(tr, "  ") + ",\n";
  const bool balanced = study.balance && result.balanced;
  const bool optimized = study.optimize && result.optimized;
  j += metrics_json("metrics", result.metrics, !balanced && !optimized);
  if (balanced) {
    const BalancedRun& b = *result.balanced;
    j += balance_json(*study.balance);
    j += second_run_json(study, "balanced", b.method, b.trajectory, result.metrics, b.metrics);
  }
  if (optimized) {
    const OptimizedRun& o = *result.optimized;
    const bool found = o.found();
    std::string section = optimize_json(study, result);
    if (!found) section.replace(section.size() - 2, 1, "");  // the last key: no comma
    j += section;
    if (found) {
      j += second_run_json(study, "optimized", o.method, o.trajectory, result.metrics, o.metrics);
    }
  }
  j += "}\n";
  return j;
}

std::vector<ComparisonRow> comparison(const Study& study, const RunResult& result) {
  assert((study.balance && result.balanced) || (result.optimized && result.optimized->found()));
  std::vector<ComparisonRow> rows;
  const core::Metrics& a = result.metrics;
  const bool balanced = study.balance && result.balanced;
  const core::Metrics& b = balanced ? result.balanced->metrics : result.optimized->metrics;
  double mass = 0, inertia = 0;
  if (balanced) {
    mass = study.balance->added_mass;
    inertia = study.balance->added_inertia;
  } else {
    mass = added_mass(study.model, result.optimized->result.design);
    inertia = added_inertia(study.model, result.optimized->result.design);
  }
  std::vector<std::pair<std::string, std::pair<double, double>>> items;
  for (const core::MetricInfo& info : core::kMetricTable) {
    items.push_back({info.name, {a.*info.field, b.*info.field}});
  }
  items.push_back({"added_mass", {0.0, mass}});
  items.push_back({"added_inertia", {0.0, inertia}});
  for (const auto& [name, values] : items) {
    ComparisonRow row{name, values.first, values.second, std::nullopt};
    if (row.before != 0) row.ratio = row.after / row.before;
    rows.push_back(row);
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
  const char* sides[] = {"crank", "rocker"};
  const char* pivots[] = {"A0", "A3"};
  for (int i = 0; i < 2; ++i) {
    if (!cws[i]->has_value()) continue;
    const balance::Counterweight& c = **cws[i];
    char line[256];
    std::snprintf(line, sizeof line,
                  "The %s carries a counterweight of %.6g kg at %.6g m from %s (merged into the "
                  "link below).\n",
                  sides[i], c.mass, c.distance, pivots[i]);
    header += line;
  }
  if (b.request.moment) {
    header +=
        "Counter-rotating discs on frame shafts cancel the shaking moment "
        "(linkage.counter_rotations).\n";
  }
  header +=
      "Links are in the polar form {s, sigma} with every digit (%.17g; e, f as comments).\n"
      "Run it with\n  balance-design balanced.yaml";
  return study_yaml(balanced_study(study), header);
}

std::string optimized_yaml(const Study& study, const OptimizedRun& run) {
  assert(study.optimize.has_value() && run.found());
  const OptimizeRequest& req = *study.optimize;
  const optimize::OptimizeResult& r = run.result;
  std::string header = "The optimised design of study '" + study.name + "', found by\n";
  header += "balance-design from its optimize section";
  header += study.source.empty() ? std::string(".\n") : " in\n  " + study.source + "\n";
  header += "Objective: minimise " + objective_text(req) + ".\n";
  header += "Constraints: " + constraints_text(req) + ".\n";
  char line[512];
  std::snprintf(line, sizeof line,
                "Solver: %s, %s after %d evaluations; objective %.6g; verified with %s (largest "
                "relative difference %.3g).\n",
                optimize::to_string(req.options.algorithm), optimize::to_string(r.termination),
                r.evaluations, r.objective, core::to_string(r.verified_with), r.verification_error);
  header += line;
  const char* pivots[] = {"", "A0", "", "A3"};
  for (const optimize::PlacedCounterweight& p : r.counterweights) {
    const balance::Counterweight& c = p.counterweight;
    std::snprintf(line, sizeof line,
                  "The %s carries a counterweight of %.6g kg at %.6g m from %s (merged into the "
                  "link below).\n",
                  core::link_name(p.link), c.mass, c.distance,
                  p.link == 1 || p.link == 3 ? pivots[p.link] : "its pivot");
    header += line;
  }
  header +=
      "Links are in the polar form {s, sigma} with every digit (%.17g; e, f as comments).\n"
      "Run it with\n  balance-design optimized.yaml";
  return study_yaml(optimized_study(study, r.design), header);
}

namespace {

// a CSV header field, quoted when it holds a comma, a quote or a line break
std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
  std::string q = "\"";
  for (char c : text) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

}  // namespace

std::string pareto_csv(const Study& study, const OptimizedRun& run) {
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
      const double mass = added_mass(study.model, r.design);
      text += "," + text::exact(metric_value(r.metrics, p.first, mass)) + "," +
              text::exact(metric_value(r.metrics, p.second, mass));
    } else {
      text += ",,";
    }
    text += std::string(",") + optimize::to_string(r.termination) + "," +
            (r.ok() ? text::exact(r.verification_error) : std::string());
    for (int k = 0; k < n; ++k) {
      text += "," + (k < r.x.size() ? text::exact(r.x[k]) : std::string());
    }
    text += "\n";
  }
  return text;
}

RunResult compute_study(const Study& study) {
  RunResult result;
  result.method = choose_method(study);
  result.trajectory = simulate(study, result.method);
  result.metrics = core::metrics(result.trajectory);
  std::optional<Study> balanced;
  if (study.balance) {
    balanced = balanced_study(study);
    BalancedRun b;
    b.method = choose_method(*balanced);
    b.trajectory = simulate(*balanced, b.method);
    b.metrics = core::metrics(b.trajectory);
    result.balanced = std::move(b);
  }
  if (study.optimize) result.optimized = optimize_study(study, result);
  return result;
}

void write_text_file(const std::string& text, const fs::path& file) { write_text(text, file); }

void write_run(const Study& study, RunResult& result, const fs::path& out_dir) {
  // summary last: a summary.json means the other files are complete
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) {
    throw std::runtime_error("cannot create the output directory " + out_dir.string() + ": " +
                             ec.message());
  }
  result.timeseries = out_dir / "timeseries.csv";
  result.summary = out_dir / "summary.json";
  write_timeseries(result.trajectory, result.timeseries);
  if (result.balanced) {
    BalancedRun& b = *result.balanced;
    b.timeseries = out_dir / "balanced-timeseries.csv";
    b.study_file = out_dir / "balanced.yaml";
    b.comparison = out_dir / "comparison.csv";
    write_timeseries(b.trajectory, b.timeseries);
    write_text(balanced_yaml(study), b.study_file);
    write_text(comparison_csv(study, result), b.comparison);
  }
  if (result.optimized && result.optimized->found()) {
    OptimizedRun& o = *result.optimized;
    o.timeseries = out_dir / "optimized-timeseries.csv";
    o.study_file = out_dir / "optimized.yaml";
    o.comparison = out_dir / "comparison.csv";
    write_timeseries(o.trajectory, o.timeseries);
    write_text(optimized_yaml(study, o), o.study_file);
    write_text(comparison_csv(study, result), o.comparison);
    if (study.optimize->pareto) {
      o.pareto_file = out_dir / "pareto.csv";
      write_text(pareto_csv(study, o), o.pareto_file);
    }
  }
  write_text(summary_json(study, result), result.summary);
  // the report is read back from the files just written; it never fails the run
  try {
    write_report(study, out_dir);
  } catch (const std::exception& e) {
    std::error_code remove_ec;
    fs::remove(out_dir / "report.html", remove_ec);  // never a stale page of an earlier run
    std::fprintf(stderr, "balance-design: warning: report.html not written: %s\n", e.what());
  }
}

RunResult run_study(const Study& study, const fs::path& out_dir) {
  // compute first: an invalid scene throws before anything is created on disk
  RunResult result = compute_study(study);
  write_run(study, result, out_dir);
  return result;
}

}  // namespace bd::studies
