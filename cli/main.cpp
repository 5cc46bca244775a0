// balance-design: the command-line program. A thin layer over bd::studies: parse the command
// line, load the study, run it, print a short summary, and map outcomes to exit codes.
#include <signal.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <iterator>
#include <optional>
#include <string>
#include <thread>
#include <variant>
#include <vector>

#include "cli/mpi_sweep.hpp"
#include "cli/sweep_display.hpp"
#include "core/fourbar/metrics.hpp"
#include "core/number_text.hpp"
#include "core/printable.hpp"
#include "studies/report/report.hpp"
#include "studies/studies.hpp"
#include "studies/study/load_study.hpp"

#ifndef BD_VERSION
#define BD_VERSION "unknown"
#endif

namespace {

namespace fs = std::filesystem;
namespace st = bd::studies;

// exit codes (documented in --help and docs/study-format.md)
constexpr int kExitOk = 0;
constexpr int kExitInternal = 1;
constexpr int kExitBadInput = 2;
constexpr int kExitStoppedEarly = 3;
constexpr int kExitNoOptimum = 4;
constexpr int kExitInterrupted = 5;

constexpr const char* kFooter = R"(
Outputs (in DIR, default results/<name>/ with <name> the study's `name`):
  timeseries.csv  one row per sample: t, the link angles, rates and accelerations, the
                  support reactions, the total shaking force and moment, the drive torque, their
                  inertial and static parts, the shafts' forces and the pin forces (SI, %.17g)
  summary.json    study name, method used and why, scene, samples, status, metrics (of the
                  inertial shaking force and moment, torque, reactions; the total shaking force
                  and moment; the pin forces' peaks) and where each peak lies; with a balance
                  section also balance, balanced_run, balanced_metrics and reduction (the ratio
                  balanced / original: below 1 a reduction); in a driven scene the harmonic
                  orders of the shaking force and moment (harmonics)
  harmonics.csv   a driven scene: design,order, amplitude and phase of Fshx, Fshy, Msh, and
                  the force's parts turning with and against the input, orders 0 to 8
  A planar linkage's timeseries.csv and metrics name its links, nodes, joints and inputs
  (docs/study-format.md). With a `balance:` section, besides (for the balanced design, same scene):
  balanced-timeseries.csv  the balanced design's samples, columns as timeseries.csv
  balanced.yaml            a complete study file of the balanced design
  comparison.csv           metric,before,after,ratio for the main metrics, added mass and inertia
  With an `optimize:` section, besides (for the optimum, same scene):
  optimized-timeseries.csv the optimum's samples, columns as timeseries.csv
  optimized.yaml           a complete study file of the optimum
  comparison.csv           metric,before,after,ratio as above (optimum vs original)
  pareto.csv               with optimize.pareto: epsilon,<first>,<second>,termination,
                           verification_error and the design variables, one row per point
  summary.json then also has optimize, optimized_run, optimized_metrics and reduction.
  report.html     the page to look at: the study's inputs, the method and why, the status,
                  the metrics and comparison tables and charts (angles, reactions, shaking-force
                  hodograph, shaking moment, drive torque and bearing loads, the linkage with its
                  principal points and centre of mass, the Pareto front); self-contained, no
                  network. Charts need gnuplot (BD_GNUPLOT names another program); without it
                  the page has the tables and says so. A report that cannot be written is one
                  warning line on stderr and does not change the exit code.
  With a `sweep:` section the study runs once per point of the sweep, in parallel, and DIR has:
  sweep.csv       one row per point, in point order: point, the swept values, the metrics (and
                  balanced_ / optimized_ metrics, added_mass, added_inertia), status (ok,
                  stopped-early, no-optimum, bad-input, error) and message; appended as points
                  finish, so an interrupted sweep keeps its rows (run again with --resume)
  sweep.json      the study, the design (points, parameters), status and counts
  report.html     charts of the metrics against the parameters
  Options of a sweep run: --resume, --threads N, --progress auto|bar|lines|none.
  mpirun -np N balance-design run STUDY.yaml shares a sweep's points among N processes (on one
  machine or a cluster; --threads is then per process) with the same sweep.csv, byte for byte;
  --resume works with any N (docs/scaling.md).
  Files are written under a temporary name and renamed, so none is ever half-written; only
  sweep.csv grows row by row, and a sweep killed mid-row may leave its last line cut short,
  which the page shows and --resume drops.

The study-file format is described in docs/study-format.md; examples are in studies/examples/.
)";

constexpr const char* kExitCodes = R"(
Exit codes:
  0  the study ran to the end
  1  unexpected internal error (or the output files could not be written)
  2  bad input: the study file or the command line is wrong; one line FILE:LINE:COLUMN: message
     on stderr, and nothing is written
  3  a simulation stopped early (e.g. a dead-centre position), the original's or the balanced
     design's; the samples computed so far and summary.json are kept, and the reason (with time
     and crank angle) is printed on stderr
  4  the optimiser found no design (infeasible, or it failed); the original's files and
     summary.json (with the optimiser's message) are kept, and one line naming the binding
     constraint is printed on stderr
  5  sweep interrupted (Ctrl-C or SIGTERM): the rows of the points finished are kept in
     sweep.csv; run again with --resume to compute the rest. A sweep whose points fail still
     exits 0: each failure is its row's status
)";

// one line on stderr: control characters in `text` (from a file, a key, a message) escaped
// this process's MPI job, when mpirun started it as one of several ranks (cli/mpi_sweep.hpp);
// ranks other than 0 say nothing: rank 0 speaks for the job
bd::cli::MpiWorld* g_mpi = nullptr;
bool quiet_rank() { return g_mpi != nullptr && g_mpi->rank() > 0; }

void say_error(const std::string& text) {
  if (quiet_rank()) return;
  std::fprintf(stderr, "%s\n", bd::text::printable(text).c_str());
}

// a sweep's design: how many points, and each parameter's values or range
void print_sweep_design(const st::SweepRequest& sweep) {
  const auto points = static_cast<std::size_t>(st::sweep_size(sweep));
  std::printf("  sweep    %s design, %zu point%s, %zu parameter%s", st::to_string(sweep.design),
              points, points == 1 ? "" : "s", sweep.parameters.size(),
              sweep.parameters.size() == 1 ? "" : "s");
  if (sweep.design != st::SweepDesign::kGrid) {
    std::printf(", seed %llu", static_cast<unsigned long long>(sweep.seed));
  }
  std::printf("\n");
  for (const st::SweepParameter& p : sweep.parameters) {
    std::printf("    %s: ", p.path.c_str());
    if (sweep.design == st::SweepDesign::kGrid) {
      std::printf("%zu value%s", p.values.size(), p.values.size() == 1 ? "" : "s");
      for (std::size_t i = 0; i < p.values.size(); ++i) {
        if (i == 3 && p.values.size() > 5) {  // first three, ..., last
          std::printf(", ..., %g", p.values.back());
          break;
        }
        std::printf("%s%g", i == 0 ? " (" : ", ", p.values[i]);
      }
      std::printf("%s", p.values.empty() ? "" : ")");
    } else {
      std::printf("drawn from %g to %g", p.from, p.to);
    }
    std::printf("%s\n", p.log_scale ? ", log scale" : "");
  }
}

// the study in `file`, or nothing after its mistake was said on stderr (one line)
std::optional<st::Study> load_or_say(const std::string& file) {
  try {
    return st::load_study(file);
  } catch (const bd::InputError& e) {
    say_error(e.what());
    return std::nullopt;
  }
}

// `validate STUDY.yaml`: load and check only, write nothing
int validate(const std::string& file) {
  try {
    const st::Study study = st::load_study(file);
    std::printf("%s: ok (study %s, %s scene, method %s)\n", file.c_str(), study.name.c_str(),
                st::scene_type(study.scene), study.method_name().c_str());
    if (study.sweep) print_sweep_design(*study.sweep);
    return kExitOk;
  } catch (const bd::InputError& e) {
    say_error(e.what());
    return kExitBadInput;
  }
}

// the "source" of a run's summary.json (the study file as named when it ran), else empty
std::string summary_source(const fs::path& summary) {
  std::FILE* f = std::fopen(summary.c_str(), "rb");
  if (!f) return {};
  std::string text;
  char buf[4096];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;) text.append(buf, n);
  std::fclose(f);
  const std::size_t key = text.find("\"source\":");
  if (key == std::string::npos) return {};
  std::size_t i = text.find('"', key + 9);
  if (i == std::string::npos) return {};
  std::string out;
  for (++i; i < text.size() && text[i] != '"'; ++i) {
    if (text[i] == '\\' && i + 1 < text.size()) ++i;  // the JSON escape of \\ or \"
    out += text[i];
  }
  return out;
}

// `report DIR`: rebuild DIR/report.html from DIR's data files and the study they came from (a
// sweep's page when DIR holds sweep.json)
int report(const std::string& dir) {
  const bool sweep = fs::exists(fs::path(dir) / "sweep.json");
  const fs::path summary = fs::path(dir) / (sweep ? "sweep.json" : "summary.json");
  if (!fs::exists(summary)) {
    std::fprintf(stderr, "%s: no summary.json here: not the output folder of a run\n", dir.c_str());
    return kExitBadInput;
  }
  // the study as the run read it: its copy in DIR (written by every run), else the file
  // summary.json names
  const fs::path copy = fs::path(dir) / "study.yaml";
  const std::string source = fs::exists(copy) ? copy.string() : summary_source(summary);
  if (source.empty()) {
    std::fprintf(stderr,
                 "%s: summary.json names no study file (\"source\"), so the report "
                 "cannot be rebuilt\n",
                 summary.c_str());
    return kExitBadInput;
  }
  st::Study study;
  try {
    study = st::load_study(source);
  } catch (const bd::InputError& e) {
    std::fprintf(stderr, "%s (the study file of %s)\n", e.what(), summary.c_str());
    return kExitBadInput;
  }
  if (sweep && !study.sweep) {
    std::fprintf(stderr, "%s: the study has no sweep section now (the study file of %s)\n",
                 source.c_str(), summary.c_str());
    return kExitBadInput;
  }
  // a data file cut short (a copy interrupted, a full disk): said before drawing from it, as
  // bad input (exit 2) like a folder that holds no run
  if (const std::string problem = sweep ? st::sweep_folder_problem(dir) : st::run_folder_problem(dir);
      !problem.empty()) {
    say_error(problem + ": the folder holds no whole run; run the study again");
    return kExitBadInput;
  }
  // errors: exit 1 with the message
  const fs::path written =
      sweep ? st::write_sweep_report(study, dir) : st::write_report(study, dir);
  const std::string gnuplot = st::find_gnuplot();
  std::printf("wrote %s%s\n", written.c_str(),
              gnuplot.empty() ? " (without charts: gnuplot not found)" : "");
  return kExitOk;
}

struct RunArgs {
  std::string study;
  std::string out;
  bool resume = false;            // sweeps: continue the sweep in the output folder
  int threads = -1;  // sweeps: parallel points (0: one per core; -1, not given: the study's)
  std::string progress = "auto";  // sweeps: auto | bar | lines | none
};

// before / after / ratio of the main metrics, added mass and inertia
// true when the study has weights or applied loads, so that the total shaking force and moment
// differ from their inertial parts (without, the terminal leaves the equal totals out)
bool has_static_part(const st::Study& study) {
  if (study.is_fourbar()) {
    const bd::core::Loads& l = study.fourbar().loads;
    for (const bd::core::LinkLoad* k : {&l.crank, &l.coupler, &l.rocker}) {
      if (k->force != bd::Vec2(0, 0) || k->moment != 0) return true;
    }
    return l.gravity != bd::Vec2(0, 0);
  }
  const bd::core::planar::Loads& l = study.planar().loads;
  return l.gravity != bd::Vec2(0, 0) || !l.node_forces.empty() || !l.link_loads.empty();
}

bool is_total(const std::string& metric) {
  return metric.rfind("Fsh_total", 0) == 0 || metric.rfind("Msh_total", 0) == 0;
}

// the natural scales of the run's values for the display rule of round-off: the linkage's size,
// the largest force and moment of every design of the run (st::DisplayScales)
st::DisplayScales display_scales(const st::Study& study, const st::RunResult& r) {
  st::DisplayScales s;
  s.length = st::linkage_size(study);
  s.add(r.metric_list);
  if (r.balanced) s.add(r.balanced->metric_list);
  if (r.optimized) s.add(r.optimized->metric_list);
  return s;
}

// a number as the terminal shows it: 6 digits, or 0 where it is round-off of `scale`
std::string shown(double v, double scale) { return bd::text::scaled(v, scale); }

// a point "[x, y]" in m, a coordinate that is round-off of the linkage's `size` as 0
std::string point_text(const bd::Vec2& p, double size) {
  return "[" + shown(p.x(), size) + ", " + shown(p.y(), size) + "]";
}

// the unit of metric `name` of the run (any of its designs), "" when it is none
std::string unit_of_metric(const st::RunResult& r, const std::string& name) {
  for (const st::MetricList* list :
       {&r.metric_list, r.balanced ? &r.balanced->metric_list : nullptr,
        r.optimized ? &r.optimized->metric_list : nullptr}) {
    if (!list) continue;
    for (const st::MetricValue& m : *list)
      if (m.name == name) return m.unit;
  }
  return "";
}

void print_comparison(const st::Study& study, const st::RunResult& r) {
  const std::vector<st::ComparisonRow> rows = st::comparison(study, r);
  const st::DisplayScales scales = display_scales(study, r);
  int width = 14;  // the metric column, as wide as the longest name (a shaft's bearing force)
  for (const st::ComparisonRow& row : rows)
    width = std::max(width, static_cast<int>(row.metric.size()));
  std::printf("  %-*s %14s %14s %12s\n", width, "metric", "before", "after", "ratio");
  const bool totals = has_static_part(study);
  for (const st::ComparisonRow& row : rows) {
    if (!totals && is_total(row.metric)) continue;
    // round-off of the larger of the two, or of the run's scale of the unit, as 0, and the
    // ratio of such an after as 0 too
    const double scale = std::max(
        {std::abs(row.before), std::abs(row.after), scales.of(unit_of_metric(r, row.metric))});
    std::string ratio = "-";
    if (row.ratio) {
      ratio = bd::text::is_round_off(row.after, scale) ? "0" : bd::text::scaled(*row.ratio, 1, 4);
    }
    std::printf("  %-*s %14s %14s %12s\n", width, row.metric.c_str(),
                shown(row.before, scale).c_str(), shown(row.after, scale).c_str(), ratio.c_str());
  }
}

// warnings of a run (the report page not written), one line each on stderr
void print_warnings(const std::vector<std::string>& warnings) {
  for (const std::string& w : warnings)
    std::fprintf(stderr, "balance-design: warning: %s\n", w.c_str());
}

// one counterweight's line: "  NAME  counterweight[ (SHAPE)] M kg at [x, y] m from PIVOT (d m)[,
// radius r m]", or "  NAME  no counterweight (0 kg)" for none; NAME in a column `width` wide
void print_counterweight(const std::string& name, int width, const bd::balance::Counterweight& c,
                         const std::string& pivot, double size, const char* shape = nullptr) {
  if (!(c.mass > 0)) {
    std::printf("  %-*s  no counterweight (0 kg)\n", width, name.c_str());
    return;
  }
  std::printf("  %-*s  counterweight%s%s%s %.6g kg at %s m from %s (%.6g m)", width, name.c_str(),
              shape ? " (" : "", shape ? shape : "", shape ? ")" : "", c.mass + 0.0,
              point_text(c.position, size).c_str(), pivot.c_str(), c.distance);
  if (c.radius > 0) std::printf(", radius %.6g m", c.radius);
  std::printf("\n");
}

// the balanced design: what was added, and before / after / ratio of the main metrics
void print_balance(const st::Study& study, const st::RunResult& r) {
  const bd::balance::BalancedDesign& b = *study.balance;
  const st::BalancedRun& run = *r.balanced;
  std::printf("  balance  force %s, moment %s: the balanced design is %s\n",
              b.request.force ? "full" : "none", b.request.moment ? "full" : "none",
              b.conditions.moment_balanced()  ? "force and moment balanced"
              : b.conditions.force_balanced() ? "force balanced"
                                              : "not balanced");
  const std::optional<bd::balance::Counterweight>* cws[] = {&b.crank_counterweight,
                                                            &b.rocker_counterweight};
  const bd::balance::CounterweightSpec* specs[] = {&b.request.crank_counterweight,
                                                   &b.request.rocker_counterweight};
  const char* sides[] = {"crank", "rocker"};
  const char* pivots[] = {"A0", "A3"};
  for (int i = 0; i < 2; ++i) {
    if (!cws[i]->has_value()) continue;
    print_counterweight(sides[i], 7, **cws[i], pivots[i], st::linkage_size(study),
                        bd::balance::to_string(specs[i]->shape));
  }
  const bd::core::CounterRotation* discs[] = {&b.model.counter_rotations.crank,
                                              &b.model.counter_rotations.rocker};
  for (int i = 0; i < 2; ++i) {
    if (discs[i]->inertia <= 0) continue;
    std::printf("  %-7s  counter-rotation J = %.6g kg m² on a shaft at %s m\n", sides[i],
                discs[i]->inertia, point_text(discs[i]->at, st::linkage_size(study)).c_str());
  }
  if (run.method.method == r.method.method && run.method.reason == r.method.reason) {
    std::printf("  balanced design: method %s as above", st::to_string(run.method.method));
  } else {
    std::printf("  balanced design: method %s (%s%s)", st::to_string(run.method.method),
                study.method == st::Method::kAuto ? "auto: " : "", run.method.reason.c_str());
  }
  std::printf(", %zu samples, status %s\n", run.trajectory.samples.size(),
              bd::core::to_string(run.trajectory.status));
  print_comparison(study, r);
}

// a planar linkage's counterweights, one line each, names in a column `width` wide
void print_planar_counterweights(const bd::core::planar::Linkage& l,
                                 const std::vector<bd::balance::planar::LinkCounterweight>& cws,
                                 int width) {
  for (const bd::balance::planar::LinkCounterweight& c : cws) {
    print_counterweight(l.links[static_cast<std::size_t>(c.link)].name, width, c.counterweight,
                        l.nodes[static_cast<std::size_t>(c.pivot)].name, st::linkage_size(l));
  }
}

// a planar linkage's balanced design: the counterweights, whether full force balance is
// reached (else why not), and before / after / ratio of every metric
void print_planar_balance(const st::Study& study, const st::RunResult& r) {
  const st::BalancedRun& run = *r.balanced;
  if (!run.design) {
    std::printf("  balance  force full: %s\n", run.status().message.c_str());
    return;
  }
  const bd::balance::planar::ForceBalance& b = *run.design;
  const bd::core::planar::Linkage& l = study.planar();
  if (b.balancing_factor) {
    std::printf("  balance  crank counterweight by the balancing factor %g\n", *b.balancing_factor);
  } else {
    std::printf("  balance  force full: the balanced design is %s\n",
                b.full ? "force balanced" : "not force balanced");
  }
  if (!b.message.empty()) std::printf("           %s\n", b.message.c_str());
  // the name column: as wide as the longest link or shaft name
  int width = 7;
  for (const bd::core::planar::Link& k : b.linkage.links)
    width = std::max(width, static_cast<int>(k.name.size()));
  for (const bd::core::planar::BalanceShaft& s : b.linkage.shafts)
    width = std::max(width, static_cast<int>(s.name.size()));
  print_planar_counterweights(l, b.added, width);
  if (run.shafts) {
    for (int i : run.shafts->added) {
      const bd::core::planar::BalanceShaft& s =
          run.shafts->linkage.shafts[static_cast<std::size_t>(i)];
      std::printf(
          "  %-*s  balance shaft at %s m turning %d times the %s: %.6g kg at "
          "%.6g m\n",
          width, s.name.c_str(), point_text(s.at, st::linkage_size(l)).c_str(), s.ratio,
          l.links[static_cast<std::size_t>(s.link)].name.c_str(), s.mass, s.eccentricity.norm());
    }
  }
  if (run.moment) {
    for (int i : run.moment->added) {
      const bd::core::planar::BalanceShaft& s =
          run.moment->linkage.shafts[static_cast<std::size_t>(i)];
      std::printf("  %-*s  counter-rotation J = %.6g kg m² on a shaft at %s m, ratio %d\n", width,
                  l.links[static_cast<std::size_t>(s.link)].name.c_str(), s.inertia,
                  point_text(s.at, st::linkage_size(l)).c_str(), s.ratio);
    }
    std::printf("  balance  moment full: the balanced design is %s\n",
                run.moment->full ? "moment balanced" : "not moment balanced");
  }
  const st::RunStatus status = run.status();
  std::printf("  balanced design: method %s, %zu samples, status %s\n",
              st::to_string(run.method.method), status.samples, bd::core::to_string(status.status));
  print_comparison(study, r);
}

// how good the optimum is (either linkage type's result): proven global or why not, the lower
// bound of the objective and the optimum's gap above it (or why there is none), and a
// multistart's local runs that reached the best value
template <class Result>
void print_optimality(const Result& o) {
  std::printf("           %s\n", o.optimality.c_str());
  if (o.starts > 0) {
    std::printf("           multistart: %d local runs, %d of them reaching the best value\n",
                o.starts, o.starts_at_best);
  }
  const std::string& source = o.lower_bound_source;
  if (source.empty()) return;
  if (!std::isfinite(o.lower_bound)) {
    std::printf("           %s\n", source.c_str());
    return;
  }
  std::printf("           lower bound %.6g (the optimum is %.3g above it), %s\n", o.lower_bound,
              o.objective - o.lower_bound, source.c_str());
}

// the optimum: how the solver ended, what it added, and before / after / ratio
void print_optimize(const st::Study& study, const st::RunResult& r) {
  const st::OptimizeRequest& req = *study.optimize;
  const st::OptimizedRun& run = *r.optimized;
  const bd::optimize::OptimizeResult& o = run.result;
  std::printf("  optimize %s: minimise %s\n", bd::optimize::to_string(req.options.algorithm),
              st::objective_text(req).c_str());
  std::printf("           subject to %s\n", st::constraints_text(req).c_str());
  std::printf("           %s\n", o.brief_report().c_str());
  if (!run.found()) return;
  print_optimality(o);
  for (const bd::optimize::PlacedCounterweight& p : o.counterweights) {
    print_counterweight(bd::core::link_name(p.link), 7, p.counterweight, p.link == 1 ? "A0" : "A3",
                        st::linkage_size(study));
  }
  std::printf("  verified with %s: largest relative difference %.3g\n", o.verified_by().c_str(),
              o.verification_error);
  std::printf("  optimum: method %s, %zu samples, status %s\n", st::to_string(run.method.method),
              run.trajectory.samples.size(), bd::core::to_string(run.trajectory.status));
  if (!run.pareto.empty()) {
    std::size_t found = 0;
    for (const bd::optimize::ParetoPoint& p : run.pareto) found += p.result.ok() ? 1 : 0;
    std::printf("  pareto   %s vs %s: %zu of %zu points found\n",
                bd::optimize::to_string(req.pareto->first),
                bd::optimize::to_string(req.pareto->second), found, run.pareto.size());
  }
  print_comparison(study, r);
}

// a planar linkage's optimum: how the solver ended, its counterweights, and before / after /
// ratio
void print_planar_optimize(const st::Study& study, const st::RunResult& r) {
  const st::PlanarOptimizeRequest& req = *study.planar_optimize;
  const st::OptimizedRun& run = *r.optimized;
  const bd::optimize::planar::Result& o = run.planar_result;
  std::printf("  optimize %s: minimise %s\n", bd::optimize::to_string(req.options.algorithm),
              st::objective_text(req).c_str());
  std::printf("           subject to %s\n", st::constraints_text(req).c_str());
  std::printf("           %s\n", o.termination == bd::optimize::Termination::kNotRun
                                     ? o.message.c_str()
                                     : o.brief_report().c_str());
  if (!run.found()) return;
  print_optimality(o);
  int width = 7;
  for (const bd::core::planar::Link& k : study.planar().links)
    width = std::max(width, static_cast<int>(k.name.size()));
  print_planar_counterweights(study.planar(), o.counterweights, width);
  // the links' own parameters that were variables: after the counterweights' three each
  for (int k = 3 * static_cast<int>(req.counterweights.size()); k < o.design_variables; ++k) {
    std::printf("  %s = %.6g\n", o.variable_names[static_cast<std::size_t>(k)].c_str(), o.x[k]);
  }
  const st::RunStatus status = run.status();
  std::printf("  optimum: method %s, %zu samples, status %s\n", st::to_string(run.method.method),
              status.samples, bd::core::to_string(status.status));
  if (req.pareto) {
    std::size_t found = 0;
    for (const bd::optimize::planar::ParetoPoint& p : run.planar_pareto)
      found += p.result.ok() ? 1 : 0;
    std::printf("  pareto   %s vs %s: %zu of %zu points found\n", req.pareto->first.c_str(),
                req.pareto->second.c_str(), found, run.planar_pareto.size());
  }
  print_comparison(study, r);
}

// the scene in one line
void print_scene(const st::Study& study) {
  if (const auto* free = std::get_if<bd::core::FreeScene>(&study.scene)) {
    std::printf("%s: free motion over %g s from theta1 = %g rad, omega1 = %g rad/s\n",
                study.name.c_str(), free->duration, free->theta1, free->omega1);
  } else if (const auto* d = std::get_if<bd::core::DrivenScene>(&study.scene)) {
    std::printf("%s: driven at omega1 = %g rad/s for %d revolution%s from theta1 = %g rad\n",
                study.name.c_str(), d->omega1, d->revolutions, d->revolutions == 1 ? "" : "s",
                d->theta1);
  } else if (const auto* pf = std::get_if<bd::core::planar::FreeScene>(&study.scene)) {
    // where it starts and how fast each input moves then
    const auto& inputs = study.planar().inputs;
    std::string rates;
    for (std::size_t k = 0; k < inputs.size(); ++k) {
      const double rate = k < pf->rates.size() ? pf->rates[k] : 0.0;
      rates += (k ? ", " : "") + inputs[k].name + " at " + bd::text::digits(rate, 6) +
               (inputs[k].kind == bd::core::planar::Input::Kind::kAngle ? " rad/s" : " m/s");
    }
    std::printf("%s: free motion over %g s from the %s, %s\n", study.name.c_str(), pf->duration,
                pf->start.empty() ? "drawn position" : "scene's start", rates.c_str());
  } else {
    const auto& pd = std::get<bd::core::planar::DrivenScene>(study.scene);
    std::string speeds;
    for (std::size_t k = 0; k < pd.speeds.size(); ++k) {
      speeds += (k ? ", " : "") + study.planar().inputs[k].name + " at " +
                bd::text::digits(pd.speeds[k], 6) +
                (study.planar().inputs[k].kind == bd::core::planar::Input::Kind::kAngle ? " rad/s"
                                                                                        : " m/s");
    }
    if (pd.duration > 0) {
      std::printf("%s: driven (%s) for %g s\n", study.name.c_str(), speeds.c_str(), pd.duration);
    } else {
      std::printf("%s: driven (%s) for %d revolution%s\n", study.name.c_str(), speeds.c_str(),
                  pd.revolutions, pd.revolutions == 1 ? "" : "s");
    }
  }
}

// the metrics in pairs (RMS, then peak, per quantity); a peak alone on its own line
void print_metrics(const st::MetricList& metrics, bool driven, bool totals,
                   const st::DisplayScales& scales) {
  for (std::size_t k = 0; k < metrics.size(); ++k) {
    const st::MetricValue& m = metrics[k];
    if (!totals && is_total(m.name)) continue;
    std::string symbol = m.name.substr(0, m.name.rfind('_'));
    if (symbol.rfind("tau", 0) == 0 && !driven) continue;  // 0 in free motion without a drive
    // Fsh, Msh: the inertial part (what balancing acts on, and what the metrics take);
    // Fsh_total, Msh_total: weights and loads included
    const bool total = symbol.ends_with("_total");
    if (total) symbol.resize(symbol.size() - 6);
    const char* what = total ? "total " : symbol == "Fsh" || symbol == "Msh" ? "inertial " : "";
    const bool pair = k + 1 < metrics.size() && m.name.size() > 4 &&
                      m.name.compare(m.name.size() - 4, 4, "_rms") == 0;
    // round-off of the run's largest force (moment) shows as 0
    const std::string value = shown(m.value, scales.of(m.unit));
    if (pair) {
      const st::MetricValue& peak = metrics[k + 1];
      std::printf("  %-8s %srms %s %s, max %s %s\n", ("|" + symbol + "|").c_str(), what,
                  value.c_str(), m.unit.c_str(), shown(peak.value, scales.of(peak.unit)).c_str(),
                  peak.unit.c_str());
      ++k;
    } else {
      std::printf("  %-8s %smax %s %s\n", ("|" + symbol + "|").c_str(), what, value.c_str(),
                  m.unit.c_str());
    }
  }
}

void print_summary(const st::Study& study, const st::RunResult& r) {
  print_scene(study);
  std::printf("  method   %s (%s%s)\n", st::to_string(r.method.method),
              study.method == st::Method::kAuto ? "auto: " : "", r.method.reason.c_str());
  const st::RunStatus status = r.status();
  std::printf("  samples  %zu, status %s", status.samples, bd::core::to_string(status.status));
  if (st::is_free(study.scene)) {
    std::printf(", %ld integrator steps, %ld dynamics evaluations", status.steps,
                status.rhs_evaluations);
  }
  std::printf("\n");
  if (status.samples == 0) {
    std::printf("  metrics  none: the run stopped before its first sample\n");
  } else {
    if (!status.ok() && st::is_free(study.scene)) {
      std::printf(
          "  partial  the metrics below cover only the motion up to the stop: the RMS values its "
          "%zu samples, the peaks up to the stop itself\n",
          status.samples);
    } else if (!status.ok()) {
      std::printf(
          "  partial  the metrics below cover only the %zu samples before the run stopped\n",
          status.samples);
    }
    print_metrics(r.metric_list, !st::is_free(study.scene), has_static_part(study),
                  display_scales(study, r));
  }
  if (study.balance && r.balanced) print_balance(study, r);
  if (study.planar_balance && r.balanced) print_planar_balance(study, r);
  if (study.optimize && r.optimized) print_optimize(study, r);
  if (study.planar_optimize && r.optimized) print_planar_optimize(study, r);
  std::printf("  wrote    %s\n", r.timeseries.string().c_str());
  if (!r.harmonics_file.empty()) std::printf("           %s\n", r.harmonics_file.string().c_str());
  if (r.balanced) {
    for (const fs::path& p :
         {r.balanced->timeseries, r.balanced->study_file, r.balanced->comparison}) {
      if (!p.empty()) std::printf("           %s\n", p.string().c_str());
    }
  }
  if (r.optimized && r.optimized->found()) {
    const st::OptimizedRun& o = *r.optimized;
    for (const fs::path& p : {o.timeseries, o.study_file, o.comparison, o.pareto_file}) {
      if (!p.empty()) std::printf("           %s\n", p.string().c_str());
    }
  }
  std::printf("           %s\n", r.summary.string().c_str());
  const fs::path page = r.summary.parent_path() / "report.html";
  if (fs::exists(page)) std::printf("  report   %s\n", page.string().c_str());
}

// set by the first SIGINT or SIGTERM during a sweep: no new point starts, the running ones
// finish and are written
std::atomic<bool> g_stop_sweep{false};
static_assert(std::atomic<bool>::is_always_lock_free, "set from a signal handler");

extern "C" void on_stop_signal(int) {
  g_stop_sweep.store(true);
  // a second signal has the default action: the process ends at once (the rows written so far
  // are kept; at most a last line is cut short, which --resume drops)
  struct sigaction dfl {};
  dfl.sa_handler = SIG_DFL;
  sigemptyset(&dfl.sa_mask);
  sigaction(SIGINT, &dfl, nullptr);
  sigaction(SIGTERM, &dfl, nullptr);
  static const char kNote[] =
      "\nbalance-design: stopping once the points running are done (again to stop at once)\n";
  [[maybe_unused]] const ssize_t n = ::write(STDERR_FILENO, kNote, sizeof kNote - 1);
}

void catch_stop_signals() {
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

// whether the study's optimisation is a multistart (mlsl), whose local runs an MPI job shares
bool shares_starts(const st::Study& study) {
  const auto mlsl = [](const bd::optimize::OptimizeOptions& o) {
    return o.algorithm == bd::optimize::Algorithm::kMlsl;
  };
  return (study.optimize && mlsl(study.optimize->options)) ||
         (study.planar_optimize && mlsl(study.planar_optimize->options));
}

// a rank's threads in an MPI job: --threads, else sweep.threads, else its share of the machine
int sweep_threads(const st::Study& study, const RunArgs& args) {
  if (args.threads > 0) return args.threads;
  if (args.threads < 0 && study.sweep->threads > 0) return study.sweep->threads;
  return g_mpi->default_threads();
}

// a study with a sweep section: run_sweep() into `out`, then one line saying what was done
int run_sweep_study(const st::Study& study, const RunArgs& args, const fs::path& out) {
  st::SweepOptions options;
  options.resume = args.resume;
  // --threads 0, like sweep.threads: 0, is one per core, whatever the study says
  options.threads = args.threads == 0 ? std::max(1, static_cast<int>(std::thread::hardware_concurrency()))
                                      : std::max(args.threads, 0);
  bd::cli::SweepDisplay display(bd::cli::SweepDisplay::mode_named(args.progress));
  options.progress = [&display](const st::SweepProgress& p) { display.show(p); };
  options.stop = &g_stop_sweep;
  catch_stop_signals();
  st::SweepResult r;
  try {
    // in an MPI job, the other ranks take points too (their rows come back to this one)
    std::unique_ptr<st::SweepPeers> peers;
    if (g_mpi) {
      options.threads = sweep_threads(study, args);
      peers = g_mpi->peers(study, options.threads);
      options.peers = peers.get();
    }
    r = st::run_sweep(study, out, options);
  } catch (const bd::InputError& e) {
    say_error(args.study + ": " + e.what());
    return kExitBadInput;
  }

  print_warnings(r.warnings);
  std::fflush(stderr);
  std::string resumed;
  if (r.resumed > 0) resumed = " (" + std::to_string(r.resumed) + " resumed)";
  const fs::path page = out / "report.html";
  std::printf("%s: sweep %s, %d of %d points%s, %d failed, %.1f s; wrote %s, %s%s\n",
              study.name.c_str(), r.complete() ? "complete" : "interrupted", r.done, r.points,
              resumed.c_str(), r.failed, r.elapsed_s, r.csv.string().c_str(),
              r.summary.filename().string().c_str(), fs::exists(page) ? ", report.html" : "");
  std::fflush(stdout);
  if (r.interrupted) {
    std::fprintf(stderr,
                 "%s: sweep interrupted after %d of %d points: run again with --resume to "
                 "compute the rest\n",
                 args.study.c_str(), r.done, r.points);
    return kExitInterrupted;
  }
  return kExitOk;
}

int run(const RunArgs& args) {
  // load and validate: any mistake is one line on stderr, and nothing is written
  std::optional<st::Study> loaded = load_or_say(args.study);
  if (!loaded) return kExitBadInput;
  // in an MPI job, a multistart's local runs are shared among the ranks: each rank runs the
  // study (a sweep's points share the ranks instead)
  std::unique_ptr<bd::optimize::StartPool> start_pool;
  if (g_mpi && !loaded->sweep && shares_starts(*loaded)) {
    start_pool = g_mpi->start_pool();
    if (loaded->optimize) loaded->optimize->options.start_pool = start_pool.get();
    if (loaded->planar_optimize) loaded->planar_optimize->options.start_pool = start_pool.get();
  }
  const st::Study& study = *loaded;
  if (quiet_rank()) {
    // another rank of an MPI job: compute the points rank 0 hands out, or run the study with
    // rank 0 for its multistarts' sake (rank 0 alone writes its outputs); else rank 0 alone
    // runs the study
    if (study.sweep) {
      g_mpi->work(study, sweep_threads(study, args));
    } else if (start_pool) {
      try {
        st::compute_study(study);
      } catch (const bd::InputError&) {
        // rank 0 meets the same and says it
      }
    }
    return kExitOk;
  }

  const fs::path out = args.out.empty() ? fs::path("results") / study.name : fs::path(args.out);
  if (study.sweep) return run_sweep_study(study, args, out);
  if (args.resume) {
    std::fprintf(stderr, "%s: --resume continues a sweep, and this study has no sweep section\n",
                 args.study.c_str());
    return kExitBadInput;
  }
  st::RunResult result;
  try {
    result = st::run_study(study, out);
  } catch (const bd::InputError& e) {
    say_error(args.study + ": " + e.what());
    return kExitBadInput;
  }

  print_warnings(result.warnings);
  std::fflush(stderr);
  print_summary(study, result);
  std::fflush(stdout);
  if (result.stopped_early()) {
    // one line, naming each run that stopped (the original's, the balanced or optimised
    // design's)
    std::string line;
    auto add = [&line](const char* what, const std::string& message) {
      line += (line.empty() ? "" : "; ") + std::string(what) + message;
    };
    if (const st::RunStatus status = result.status(); !status.ok()) add("", status.message);
    const bool balanced_ran =
        result.balanced && (!result.balanced->is_planar || result.balanced->design);
    if (balanced_ran && !result.balanced->ok()) {
      add("the balanced design's: ", result.balanced->status().message);
    }
    if (result.optimized && result.optimized->found() && !result.optimized->status().ok()) {
      add("the optimised design's: ", result.optimized->status().message);
    }
    say_error(args.study + ": simulation stopped early: " + line);
    return kExitStoppedEarly;
  }
  if (result.optimized && result.optimized->failed()) {
    // one line: the optimiser's message names the binding constraint
    std::string message = result.optimized->message();
    std::replace(message.begin(), message.end(), '\n', ' ');
    say_error(args.study + ": no optimum (" +
              bd::optimize::to_string(result.optimized->termination()) + "): " + message);
    return kExitNoOptimum;
  }
  return kExitOk;
}

void add_run_options(CLI::App& cmd, RunArgs& args) {
  cmd.add_option("STUDY", args.study, "the study file, e.g. studies/examples/paper-fourbar.yaml")
      ->required()
      ->type_name("FILE");
  cmd.add_option("-o,--out", args.out,
                 "output directory, created if needed (default: results/<name>/)")
      ->type_name("DIR");
  cmd.add_flag("--resume", args.resume,
               "sweeps: continue the sweep in DIR where it stopped (its rows are kept, the "
               "missing points run)");
  cmd.add_option("--threads", args.threads,
                 "sweeps: points run in parallel, 0 for one per core (default: the study's "
                 "sweep.threads, else one per core)")
      ->check(CLI::Range(0, 1024))
      ->type_name("N");
  cmd.add_option("--progress", args.progress,
                 "sweeps: progress on stderr: auto (a bar on a terminal, else a line every 10 s), "
                 "bar, lines or none")
      ->check(CLI::IsMember({"auto", "bar", "lines", "none"}))
      ->type_name("MODE");
}

struct BenchArgs {
  std::string study;
  std::string out;
  bool quick = false;
  int repeats = 0;  // 0: 5, or 1 with --quick
};

// `bench STUDY.yaml`: run the study as `run` does, then measure speed against accuracy
// (studies/bench/work_precision.hpp): work-precision.csv or driven-convergence.csv, and report.html
// with its section "Speed against accuracy". Progress on stderr, one line per method.
int bench(const BenchArgs& args) {
  std::optional<st::Study> loaded = load_or_say(args.study);
  if (!loaded) return kExitBadInput;
  const st::Study& study = *loaded;
  if (study.sweep) {
    std::fprintf(stderr, "%s: bench measures one scene, and this study has a sweep section\n",
                 args.study.c_str());
    return kExitBadInput;
  }
  st::BenchOptions options = args.quick ? st::BenchOptions::quick() : st::BenchOptions{};
  if (args.repeats > 0) options.repeats = args.repeats;
  options.progress = [](const std::string& line) {
    std::fprintf(stderr, "%s\n", line.c_str());
    std::fflush(stderr);
  };
  const fs::path out = args.out.empty() ? fs::path("results") / study.name : fs::path(args.out);
  st::BenchResult result;
  try {
    result = st::run_bench(study, out, options);
  } catch (const bd::InputError& e) {
    say_error(args.study + ": " + e.what());
    return kExitBadInput;
  }
  print_warnings(result.run.warnings);
  std::fflush(stderr);
  print_summary(study, result.run);
  const std::size_t rows =
      result.free_rows.empty() ? result.driven_rows.size() : result.free_rows.size();
  std::printf("  bench    %zu rows (%s, %d repeat%s): %s\n", rows, args.quick ? "quick" : "full",
              options.repeats, options.repeats == 1 ? "" : "s", result.csv.string().c_str());
  if (const std::size_t stopped = result.stopped_early(); stopped > 0) {
    std::printf(
        "  bench    %zu of %zu runs stopped before the end of the scene (their rows keep "
        "what they computed, with the status and message)\n",
        stopped, rows);
  }
  std::fflush(stdout);
  if (const st::RunStatus status = result.run.status(); !status.ok()) {
    std::fprintf(stderr, "%s: simulation stopped early: %s\n", args.study.c_str(),
                 status.message.c_str());
    return kExitStoppedEarly;
  }
  return kExitOk;
}

// the program's commands, which `help COMMAND` explains
constexpr const char* kCommands[] = {"run", "validate", "report", "bench"};

bool is_command(const std::string& word) {
  return std::find(std::begin(kCommands), std::end(kCommands), word) != std::end(kCommands);
}

// `balance-design STUDY.yaml ...` is short for `balance-design run STUDY.yaml ...`; nothing
// after the one-line error on stderr for `help TOPIC` of a topic that is no command
std::optional<std::vector<std::string>> with_default_command(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  // `balance-design help` (and `help help`) is --help; `balance-design help COMMAND` is
  // COMMAND --help
  if (!args.empty() && args.front() == "help") {
    args.erase(args.begin());
    if (args.empty() || args.front() == "help") return std::vector<std::string>{"--help"};
    if (!is_command(args.front())) {
      say_error("balance-design: no help on \"" + args.front() +
                "\": the commands are run, validate, report and bench (balance-design help)");
      return std::nullopt;
    }
    args.resize(1);
    args.push_back("--help");
    return args;
  }
  if (!args.empty()) {
    const std::string& first = args.front();
    const bool top_level =
        is_command(first) || first == "-h" || first == "--help" || first == "--version";
    if (!top_level) args.insert(args.begin(), "run");
  }
  return args;
}

// the program's description, after its name and version
constexpr const char* kDescription =
    ": shaking-force and shaking-moment balancing of planar linkages.\n"
    "Simulates the linkage of a study file (a four-bar or any planar linkage of links, pins and\n"
    "sliders; free motion or driven inputs) and writes its reaction and joint forces, shaking\n"
    "force and moment and drive efforts; with a balance section it also synthesises the\n"
    "balanced design (counterweights, counter-rotations, balance shafts), simulates it in the\n"
    "same scene and compares the two; with an optimize section it searches for the best design\n"
    "(NLopt, Ipopt) under constraints and does the same with it.\n\n"
    "Commands:\n"
    "  balance-design run STUDY.yaml [--out DIR]   run a study, write its outputs into DIR\n"
    "  balance-design STUDY.yaml [--out DIR]       the same: run is the default command\n"
    "  balance-design run STUDY.yaml --resume      continue an interrupted sweep (a study\n"
    "                                              with a sweep section) where it stopped\n"
    "  balance-design validate STUDY.yaml          load and check the study only; prints\n"
    "                                              an ok line (exit 0) or the error (exit 2)\n"
    "  balance-design report DIR                   rebuild DIR/report.html from the data\n"
    "                                              files of a run or sweep (and its study\n"
    "                                              file)\n"
    "  balance-design bench STUDY.yaml [--out DIR] [--quick] [--repeats N]\n"
    "                                              run the study, then measure speed\n"
    "                                              against accuracy (work-precision.csv or\n"
    "                                              driven-convergence.csv, report.html)\n"
    "  balance-design run --help                   the options of run\n";

// the bench command and its options
CLI::App* add_bench_command(CLI::App& app, BenchArgs& bench_args) {
  CLI::App* bench_cmd = app.add_subcommand(
      "bench",
      "run STUDY.yaml as run does, then time every method (a four-bar's formulations, the "
      "general engine's truss and truss-dae) and integrator against its accuracy (free scene: "
      "tolerances 1e-3 ... 1e-13, work-precision.csv; driven scene: 4 ... 720 samples per "
      "revolution, driven-convergence.csv) and rewrite report.html");
  bench_cmd->add_option("STUDY", bench_args.study, "the study file (free or driven scene)")
      ->required()
      ->type_name("FILE");
  bench_cmd
      ->add_option("-o,--out", bench_args.out,
                   "output directory, created if needed (default: results/<name>/)")
      ->type_name("DIR");
  bench_cmd->add_flag("--quick", bench_args.quick,
                      "tolerances 1e-4, 1e-7, 1e-10 only, one repeat (a few seconds)");
  bench_cmd
      ->add_option("--repeats", bench_args.repeats,
                   "timed runs per point, the median reported (default 5; 1 with --quick)")
      ->check(CLI::Range(1, 1000))
      ->type_name("N");
  return bench_cmd;
}

}  // namespace

int main(int argc, char** argv) {
  std::unique_ptr<bd::cli::MpiWorld> mpi;  // MPI_Finalize when main returns
  // a file-size limit reached (ulimit -f) ends a write with EFBIG, which the writers report as
  // one line (exit 1), instead of SIGXFSZ killing the program with a core dump
  ::signal(SIGXFSZ, SIG_IGN);
  try {
    mpi = bd::cli::mpi_world(argc, argv);
    g_mpi = mpi.get();
    if (quiet_rank()) std::freopen("/dev/null", "w", stdout);
    CLI::App app{std::string("balance-design ") + BD_VERSION + kDescription, "balance-design"};
    // each command's help says what that command does: the outputs belong to run's, the exit
    // codes to the program's and run's (CLI11 copies a footer set now into every subcommand)
    app.set_version_flag("--version", std::string("balance-design ") + BD_VERSION);
    app.require_subcommand(1);

    RunArgs args;
    CLI::App* run_cmd = app.add_subcommand(
        "run", "load STUDY.yaml, check it, simulate its scene and write the outputs into DIR");
    add_run_options(*run_cmd, args);
    run_cmd->footer(std::string(kFooter) + kExitCodes);

    std::string validate_file;
    CLI::App* validate_cmd = app.add_subcommand(
        "validate", "load STUDY.yaml and check it; write nothing (exit 0 ok, 2 bad input)");
    validate_cmd->add_option("STUDY", validate_file, "the study file")
        ->required()
        ->type_name("FILE");
    std::string report_dir;
    CLI::App* report_cmd = app.add_subcommand(
        "report", "rebuild DIR/report.html from the data files of a run or a sweep in DIR");
    report_cmd
        ->add_option("DIR", report_dir,
                     "the output folder of a run (has summary.json) or of a sweep (has "
                     "sweep.json)")
        ->required()
        ->type_name("DIR");

    BenchArgs bench_args;
    CLI::App* bench_cmd = add_bench_command(app, bench_args);
    app.footer(std::string(kFooter) + kExitCodes +
               "\nbalance-design COMMAND --help (or balance-design help COMMAND) says what one "
               "command does.\n");
    // the description's list says what each command does: CLI11's own list of them would
    // repeat it (an empty group keeps a command out of the program's help, not its own)
    for (CLI::App* command : {run_cmd, validate_cmd, report_cmd, bench_cmd}) command->group("");
    validate_cmd->footer("\nExit codes: 0 the study is valid (one ok line), 2 it is not (one "
                         "line FILE:LINE:COLUMN: message on stderr).\n");
    report_cmd->footer("\nDIR may be given from anywhere. Exit codes: 0 the page was written, "
                       "1 it could not be, 2 DIR holds no run or a data file of it is cut short.\n");

    std::optional<std::vector<std::string>> parsed_words = with_default_command(argc, argv);
    if (!parsed_words) return kExitBadInput;
    std::vector<std::string>& argv_rest = *parsed_words;
    if (argv_rest.empty()) {
      std::fputs(app.help().c_str(), stderr);
      return kExitBadInput;
    }
    std::reverse(argv_rest.begin(), argv_rest.end());  // CLI11 takes the arguments reversed
    try {
      app.parse(argv_rest);
    } catch (const CLI::ParseError& e) {
      const int code = app.exit(e);
      return code == 0 ? kExitOk : kExitBadInput;
    }
    if (quiet_rank() && !run_cmd->parsed()) return kExitOk;  // rank 0 does it for the job
    if (validate_cmd->parsed()) return validate(validate_file);
    if (report_cmd->parsed()) return report(report_dir);
    if (bench_cmd->parsed()) return bench(bench_args);
    return run(args);
  } catch (const std::exception& e) {
    if (quiet_rank()) std::fprintf(stderr, "balance-design (MPI rank %d): ", g_mpi->rank());
    g_mpi = nullptr;  // said by every rank
    say_error(std::string("balance-design: error: ") + e.what());
    return kExitInternal;
  } catch (...) {
    std::fprintf(stderr, "balance-design: unexpected internal error\n");
    return kExitInternal;
  }
}
