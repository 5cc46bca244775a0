// balance-design: the command-line program. A thin layer over bd::studies: parse the command
// line, load the study, run it, print a short summary, and map outcomes to exit codes.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "studies/load_study.hpp"
#include "studies/report.hpp"
#include "studies/runner.hpp"

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

constexpr const char* kFooter = R"(
Outputs (in DIR, default results/<name>/ with <name> the study's `name`):
  timeseries.csv  one row per sample: t,theta1,theta2,theta3,omega1,omega2,omega3,
                  alpha1,alpha2,alpha3,RA0x,RA0y,RA3x,RA3y,Fshx,Fshy,Msh,tau (SI units, %.17g)
  summary.json    study name, method used and why, scene, samples, status, metrics
                  (Fsh_rms, Fsh_max, Msh_rms, Msh_max, tau_rms, tau_max, RA0_max, RA3_max,
                  RA0_rms, RA3_rms); with a balance section also balance, balanced_run,
                  balanced_metrics and reduction (balanced / original)
  With a `balance:` section, besides (for the balanced design, same scene):
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
  Files are written under a temporary name and renamed, so none is ever half-written.

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

The study-file format is described in docs/study-format.md; examples are in studies/examples/.
)";

// `validate STUDY.yaml`: load and check only, write nothing
int validate(const std::string& file) {
  try {
    const st::Study study = st::load_study(file);
    std::printf("%s: ok (study %s, %s scene, method %s)\n", file.c_str(), study.name.c_str(),
                st::scene_type(study.scene), study.method_name().c_str());
    return kExitOk;
  } catch (const bd::InputError& e) {
    std::fprintf(stderr, "%s\n", e.what());
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

// `report DIR`: rebuild DIR/report.html from DIR's data files and the study they came from
int report(const std::string& dir) {
  const fs::path summary = fs::path(dir) / "summary.json";
  if (!fs::exists(summary)) {
    std::fprintf(stderr, "%s: no summary.json here: not the output folder of a run\n", dir.c_str());
    return kExitBadInput;
  }
  const std::string source = summary_source(summary);
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
  const fs::path written = st::write_report(study, dir);  // errors: exit 1 with the message
  const std::string gnuplot = st::find_gnuplot();
  std::printf("wrote %s%s\n", written.c_str(),
              gnuplot.empty() ? " (without charts: gnuplot not found)" : "");
  return kExitOk;
}

struct RunArgs {
  std::string study;
  std::string out;
};

// before / after / ratio of the main metrics, added mass and inertia
void print_comparison(const st::Study& study, const st::RunResult& r) {
  std::printf("  %-14s %14s %14s %12s\n", "metric", "before", "after", "ratio");
  for (const st::ComparisonRow& row : st::comparison(study, r)) {
    if (row.ratio) {
      std::printf("  %-14s %14.6g %14.6g %12.4g\n", row.metric.c_str(), row.before, row.after,
                  *row.ratio);
    } else {
      std::printf("  %-14s %14.6g %14.6g %12s\n", row.metric.c_str(), row.before, row.after, "-");
    }
  }
}

// the balanced design: what was added, and before / after / ratio of the main metrics
void print_balance(const st::Study& study, const st::RunResult& r) {
  const st::BalancedDesign& b = *study.balance;
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
    const bd::balance::Counterweight& c = **cws[i];
    std::printf("  %-7s  counterweight (%s) %.6g kg at [%.6g, %.6g] m from %s (%.6g m)", sides[i],
                st::to_string(specs[i]->shape), c.mass, c.position.x(), c.position.y(), pivots[i],
                c.distance);
    if (c.radius > 0) std::printf(", radius %.6g m", c.radius);
    std::printf("\n");
  }
  const bd::core::CounterRotation* discs[] = {&b.model.counter_rotations.crank,
                                              &b.model.counter_rotations.rocker};
  for (int i = 0; i < 2; ++i) {
    if (discs[i]->inertia <= 0) continue;
    std::printf("  %-7s  counter-rotation J = %.6g kg m^2 on a shaft at [%.6g, %.6g] m\n", sides[i],
                discs[i]->inertia, discs[i]->at.x(), discs[i]->at.y());
  }
  if (run.method.formulation == r.method.formulation && run.method.reason == r.method.reason) {
    std::printf("  balanced design: method %s as above",
                bd::core::to_string(run.method.formulation));
  } else {
    std::printf("  balanced design: method %s (%s%s)", bd::core::to_string(run.method.formulation),
                study.formulation ? "" : "auto: ", run.method.reason.c_str());
  }
  std::printf(", %zu samples, status %s\n", run.trajectory.samples.size(),
              bd::core::to_string(run.trajectory.status));
  print_comparison(study, r);
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
  for (const bd::optimize::PlacedCounterweight& p : o.counterweights) {
    const bd::balance::Counterweight& c = p.counterweight;
    std::printf("  %-7s  counterweight %.6g kg at [%.6g, %.6g] m from %s (%.6g m)",
                bd::core::link_name(p.link), c.mass, c.position.x(), c.position.y(),
                p.link == 1 ? "A0" : "A3", c.distance);
    if (c.radius > 0) std::printf(", radius %.6g m", c.radius);
    std::printf("\n");
  }
  std::printf("  verified with %s: largest relative difference %.3g\n",
              bd::core::to_string(o.verified_with), o.verification_error);
  std::printf("  optimum: method %s, %zu samples, status %s\n",
              bd::core::to_string(run.method.formulation), run.trajectory.samples.size(),
              bd::core::to_string(run.trajectory.status));
  if (!run.pareto.empty()) {
    std::size_t found = 0;
    for (const bd::optimize::ParetoPoint& p : run.pareto) found += p.result.ok() ? 1 : 0;
    std::printf("  pareto   %s vs %s: %zu of %zu points found\n",
                bd::optimize::to_string(req.pareto->first),
                bd::optimize::to_string(req.pareto->second), found, run.pareto.size());
  }
  print_comparison(study, r);
}

void print_summary(const st::Study& study, const st::RunResult& r) {
  const bd::core::Metrics& m = r.metrics;
  if (const auto* free = std::get_if<bd::core::FreeScene>(&study.scene)) {
    std::printf("%s: free motion over %g s from theta1 = %g rad, omega1 = %g rad/s\n",
                study.name.c_str(), free->duration, free->theta1, free->omega1);
  } else {
    const auto& d = std::get<bd::core::DrivenScene>(study.scene);
    std::printf("%s: driven at omega1 = %g rad/s for %d revolution%s from theta1 = %g rad\n",
                study.name.c_str(), d.omega1, d.revolutions, d.revolutions == 1 ? "" : "s",
                d.theta1);
  }
  std::printf("  method   %s (%s%s)\n", bd::core::to_string(r.method.formulation),
              study.formulation ? "" : "auto: ", r.method.reason.c_str());
  std::printf("  samples  %zu, status %s", r.trajectory.samples.size(),
              bd::core::to_string(r.trajectory.status));
  if (std::holds_alternative<bd::core::FreeScene>(study.scene)) {
    std::printf(", %ld integrator steps, %ld dynamics evaluations", r.trajectory.steps,
                r.trajectory.rhs_evaluations);
  }
  std::printf("\n");
  std::printf("  |Fsh|    rms %.6g N, max %.6g N\n", m.Fsh_rms, m.Fsh_max);
  std::printf("  |Msh|    rms %.6g N m, max %.6g N m\n", m.Msh_rms, m.Msh_max);
  if (std::holds_alternative<bd::core::DrivenScene>(study.scene)) {
    std::printf("  |tau|    rms %.6g N m, max %.6g N m\n", m.tau_rms, m.tau_max);
  }
  std::printf("  |RA0|    max %.6g N;  |RA3| max %.6g N\n", m.RA0_max, m.RA3_max);
  if (study.balance && r.balanced) print_balance(study, r);
  if (study.optimize && r.optimized) print_optimize(study, r);
  std::printf("  wrote    %s\n", r.timeseries.string().c_str());
  if (r.balanced) {
    for (const fs::path& p :
         {r.balanced->timeseries, r.balanced->study_file, r.balanced->comparison}) {
      std::printf("           %s\n", p.string().c_str());
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

int run(const RunArgs& args) {
  // load and validate: any mistake is one line on stderr, and nothing is written
  st::Study study;
  try {
    study = st::load_study(args.study);
  } catch (const bd::InputError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return kExitBadInput;
  }

  const fs::path out = args.out.empty() ? fs::path("results") / study.name : fs::path(args.out);
  st::RunResult result;
  try {
    result = st::run_study(study, out);
  } catch (const bd::InputError& e) {
    std::fprintf(stderr, "%s: %s\n", args.study.c_str(), e.what());
    return kExitBadInput;
  }

  std::fflush(stderr);
  print_summary(study, result);
  std::fflush(stdout);
  if (result.stopped_early()) {
    // one line per run that stopped
    if (!result.trajectory.ok()) {
      std::fprintf(stderr, "%s: simulation stopped early: %s\n", args.study.c_str(),
                   result.trajectory.message.c_str());
    }
    if (result.balanced && !result.balanced->trajectory.ok()) {
      std::fprintf(stderr, "%s: simulation of the balanced design stopped early: %s\n",
                   args.study.c_str(), result.balanced->trajectory.message.c_str());
    }
    if (result.optimized && result.optimized->found() && !result.optimized->trajectory.ok()) {
      std::fprintf(stderr, "%s: simulation of the optimised design stopped early: %s\n",
                   args.study.c_str(), result.optimized->trajectory.message.c_str());
    }
    return kExitStoppedEarly;
  }
  if (result.optimized && result.optimized->failed()) {
    // one line: the optimiser's message names the binding constraint
    std::string message = result.optimized->result.message;
    std::replace(message.begin(), message.end(), '\n', ' ');
    std::fprintf(stderr, "%s: no optimum (%s): %s\n", args.study.c_str(),
                 bd::optimize::to_string(result.optimized->result.termination), message.c_str());
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
}

// `balance-design STUDY.yaml ...` is short for `balance-design run STUDY.yaml ...`
std::vector<std::string> with_default_command(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (!args.empty()) {
    const std::string& first = args.front();
    const bool top_level = first == "run" || first == "validate" || first == "report" ||
                           first == "-h" || first == "--help" || first == "--version";
    if (!top_level) args.insert(args.begin(), "run");
  }
  return args;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    CLI::App app{
        "balance-design " BD_VERSION
        ": shaking-force and shaking-moment balancing of planar four-bar linkages.\n"
        "Simulates the linkage of a study file (free motion or a driven crank) and writes its\n"
        "reaction forces, shaking force and moment and drive torque; with a balance section it\n"
        "also synthesises the balanced design (counterweights, counter-rotations), simulates\n"
        "it in the same scene and compares the two; with an optimize section it searches for\n"
        "the best design (NLopt, Ipopt) under constraints and does the same with it.\n\n"
        "Commands:\n"
        "  balance-design run STUDY.yaml [--out DIR]   run a study, write its outputs into DIR\n"
        "  balance-design STUDY.yaml [--out DIR]       the same: run is the default command\n"
        "  balance-design validate STUDY.yaml          load and check the study only; prints\n"
        "                                              an ok line (exit 0) or the error (exit 2)\n"
        "  balance-design report DIR                   rebuild DIR/report.html from the data\n"
        "                                              files of a run (and its study file)\n"
        "  balance-design run --help                   the options of run\n",
        "balance-design"};
    app.footer(kFooter);
    app.set_version_flag("--version", std::string("balance-design ") + BD_VERSION);
    app.require_subcommand(1);

    RunArgs args;
    CLI::App* run_cmd = app.add_subcommand(
        "run", "load STUDY.yaml, check it, simulate its scene and write the outputs into DIR");
    add_run_options(*run_cmd, args);
    run_cmd->footer(kFooter);

    std::string validate_file;
    CLI::App* validate_cmd = app.add_subcommand(
        "validate", "load STUDY.yaml and check it; write nothing (exit 0 ok, 2 bad input)");
    validate_cmd->add_option("STUDY", validate_file, "the study file")
        ->required()
        ->type_name("FILE");
    std::string report_dir;
    CLI::App* report_cmd =
        app.add_subcommand("report", "rebuild DIR/report.html from the data files of a run in DIR");
    report_cmd->add_option("DIR", report_dir, "the output folder of a run (has summary.json)")
        ->required()
        ->type_name("DIR");

    std::vector<std::string> argv_rest = with_default_command(argc, argv);
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
    if (validate_cmd->parsed()) return validate(validate_file);
    if (report_cmd->parsed()) return report(report_dir);
    return run(args);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "balance-design: error: %s\n", e.what());
    return kExitInternal;
  } catch (...) {
    std::fprintf(stderr, "balance-design: unexpected internal error\n");
    return kExitInternal;
  }
}
