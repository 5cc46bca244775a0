#include "studies/report/study_parts.hpp"

#include <algorithm>
#include <iterator>
#include <variant>

#include "studies/run/runner.hpp"

namespace bd::studies::report_support {

namespace fs = std::filesystem;

SecondDesign second_design(const Json& summary, const fs::path& dir) {
  if (member(summary, "balanced_run") && fs::exists(dir / "balanced-timeseries.csv")) {
    return {"balanced", "balanced", "balanced-timeseries.csv"};
  }
  if (member(summary, "optimized_run") && fs::exists(dir / "optimized-timeseries.csv")) {
    return {"optimized", "optimised", "optimized-timeseries.csv"};
  }
  return {};
}

std::string page_start(const Study& study, const Json& summary) {
  const std::string name = text(summary, "study").empty() ? study.name : text(summary, "study");
  std::string h =
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
      "<title>" +
      esc(name) + " &mdash; balance-design report</title>\n<style>" + kStyle +
      "</style>\n</head>\n<body>\n";
  h += "<h1>" + esc(name) + "</h1>\n<p>balance-design report of the study <code>" +
       esc(text(summary, "source").empty() ? std::string("(built in code)")
                                           : text(summary, "source")) +
       "</code>. Every number below is read from the data files of this folder; hover over a "
       "number to see it as written there.</p>\n";
  return h;
}

std::string run_table(const Json& run, const std::string& what) {
  std::string h = "<table>";
  if (const Json* method = member(run, "method")) {
    h += "<tr><th>method</th><td><b>" + esc(text(*method, "used")) + "</b> (requested " +
         esc(text(*method, "requested")) + ")<br>" + esc(text(*method, "reason")) + "</td></tr>";
  }
  const bool ok = text(run, "ok") == "true";
  h += "<tr><th>status</th><td class=\"" + std::string(ok ? "good" : "bad") + "\">" +
       esc(text(run, "status")) + "</td></tr>";
  h += "<tr><th>message</th><td>" + esc(text(run, "message")) + "</td></tr>";
  h += "<tr><th>samples</th><td>" + esc(text(run, "samples")) + "</td></tr>";
  h += "<tr><th>integrator steps, dynamics evaluations</th><td>" + esc(text(run, "steps")) + ", " +
       esc(text(run, "rhs_evaluations")) + "</td></tr>";
  if (!ok) {
    h += "<tr><td colspan=\"2\" class=\"bad\">The " + what +
         " simulation stopped early: the charts and metrics cover the samples computed.</td></tr>";
  }
  return h + "</table>";
}

std::string simulation_section(const Json& summary) {
  // status first: whether the run can be trusted
  std::string h = "<h2>Simulation</h2>\n";
  if (text(summary, "ok") != "true") {
    h += "<p class=\"notice bad\">The simulation stopped early: " + esc(text(summary, "message")) +
         "</p>\n";
  }
  h += run_table(summary, "original design's");
  if (const Json* scene = member(summary, "scene")) {
    h += "<h3>Scene</h3>" + json_table(*scene);
    h += "<p>Integrator relative tolerance " + esc(text(summary, "tolerance")) + ".</p>\n";
  }
  return h;
}

std::string metrics_section(const Json& summary, const SecondDesign& second,
                            const std::string& notes) {
  std::string h = "<h2>Metrics</h2>\n<table><tr><th>metric</th><th>original</th>";
  const Json* metrics = member(summary, "metrics");
  const Json* second_metrics =
      second.present() ? member(summary, second.key + "_metrics") : nullptr;
  const Json* reduction = member(summary, "reduction");
  if (second_metrics) h += "<th>" + esc(second.label) + "</th><th>ratio</th>";
  h += "</tr>";
  if (metrics) {
    for (const auto& [k, v] : metrics->items()) {
      h += "<tr><th>" + esc(k) + "</th>" + json_cell(v);
      if (second_metrics) {
        const Json* s = member(*second_metrics, k);
        const Json* r = reduction ? member(*reduction, k) : nullptr;
        h += (s ? json_cell(*s) : "<td></td>") + (r ? json_cell(*r) : "<td></td>");
      }
      h += "</tr>";
    }
  }
  return h + "</table>\n<p>" + notes + "</p>\n";
}

std::string comparison_section(const fs::path& dir, const SecondDesign& second) {
  if (!second.present() || !fs::exists(dir / "comparison.csv")) return "";
  return "<h2>Comparison</h2>\n<p>From <a href=\"comparison.csv\">comparison.csv</a>: the original "
         "(before) and the " +
         second.label + " design (after), ratio after/before.</p>" +
         csv_table(read_csv(dir / "comparison.csv"));
}

std::string harmonics_section(const fs::path& dir) {
  if (!fs::exists(dir / "harmonics.csv")) return "";
  const Csv csv = read_csv(dir / "harmonics.csv");
  // the amplitudes, one row per design and order; the phases are in the file
  const char* columns[] = {"design",      "order",        "Fshx_amplitude", "Fshy_amplitude",
                           "Fsh_forward", "Fsh_backward", "Msh_amplitude"};
  std::vector<std::size_t> at;
  for (const char* c : columns) {
    const auto it = std::find(csv.header.begin(), csv.header.end(), c);
    if (it == csv.header.end()) return "";
    at.push_back(static_cast<std::size_t>(it - csv.header.begin()));
  }
  std::string h =
      "<h2>Harmonic orders</h2>\n<p>From <a href=\"harmonics.csv\">harmonics.csv</a>: the shaking "
      "force and moment over the first revolution of the driven input, by the discrete Fourier "
      "transform of the exact samples; order k repeats k times per revolution. Amplitudes of Fshx, "
      "Fshy [N] and Msh [N m]; the force's parts turning with the input (forward: a counterweight "
      "on the input's link cancels order 1) and against it (backward) [N]. Phases are in the "
      "file.</p><table><tr><th>design</th><th>order</th><th>Fshx</th><th>Fshy</th>"
      "<th>forward</th><th>backward</th><th>Msh</th></tr>";
  for (const std::vector<std::string>& row : csv.rows) {
    if (row.size() < csv.header.size() || row[at[1]] == "0") continue;  // the mean: in the file
    h += "<tr><td>" + esc(row[at[0]]) + "</td><td class=\"n\">" + esc(row[at[1]]) + "</td>";
    for (std::size_t k = 2; k < at.size(); ++k)
      h += "<td class=\"n\">" + num_cell(row[at[k]]) + "</td>";
    h += "</tr>";
  }
  return h + "</table>\n";
}

std::string charts_section(const std::string& gnuplot, const std::string& datablocks,
                           const std::vector<Chart>& charts) {
  std::string h = "<h2>Charts</h2>\n";
  if (gnuplot.empty()) {
    return h +
           "<p class=\"notice\">The charts need gnuplot, which was not found on this machine "
           "(install it, e.g. <code>apt-get install gnuplot-nox</code>, then rebuild this page "
           "with <code>balance-design report DIR</code>). The tables and the data files below "
           "hold every number.</p>\n";
  }
  const std::vector<std::string> svgs = draw(gnuplot, datablocks, charts);
  for (std::size_t i = 0; i < charts.size(); ++i) {
    h += "<h3>" + esc(charts[i].heading) + "</h3>\n<figure class=\"chart\" id=\"chart-" +
         charts[i].id + "\">\n" + svgs[i] + "\n<figcaption>" + esc(charts[i].caption) +
         "</figcaption>\n</figure>\n";
  }
  return h;
}

std::vector<std::string> data_files() {
  std::vector<std::string> names(std::begin(kRunFiles), std::end(kRunFiles));
  names.insert(names.end(), {"work-precision.csv", "driven-convergence.csv"});
  return names;
}

std::vector<Chart> pareto_charts(const fs::path& dir) {
  if (!fs::exists(dir / "pareto.csv")) return {};
  const Csv pareto = read_csv(dir / "pareto.csv");
  if (pareto.header.size() < 3) return {};
  return {{"pareto", "Pareto front",
           "Each point a design found by the epsilon-constraint method (pareto.csv); points "
           "without a design are left out.",
           "set title 'Pareto front'\nset xlabel " + gp_string(pareto.header[1]) + "\nset ylabel " +
               gp_string(pareto.header[2]) + "\nplot " +
               gp_string((fs::absolute(dir) / "pareto.csv").string()) +
               " skip 1 using 2:3 with linespoints lw 2 pt 7 title 'front'"}};
}

std::string pareto_section(const fs::path& dir) {
  if (!fs::exists(dir / "pareto.csv")) return "";
  return "<h2>Pareto front</h2>\n<p>From <a href=\"pareto.csv\">pareto.csv</a>.</p>" +
         csv_table(read_csv(dir / "pareto.csv"));
}

std::string time_axis(const Scene& scene) {
  if (std::holds_alternative<core::DrivenScene>(scene))
    return "t [s] (crank driven at constant speed)";
  if (std::holds_alternative<core::planar::DrivenScene>(scene)) {
    return "t [s] (inputs driven at constant speed)";
  }
  return "t [s]";
}

std::string second_design_section(const Json& summary, const SecondDesign& sd) {
  std::string h;
  const std::string second = sd.key, second_label = sd.label;
  if (sd.present()) {
    const char* section = second == "balanced" ? "balance" : "optimize";
    h += std::string("<h2>") + (second == "balanced" ? "Balanced design" : "Optimised design") +
         "</h2>\n";
    if (const Json* s = member(summary, section)) h += json_table(*s);
    if (const Json* run = member(summary, second + "_run")) {
      h += "<h3>Its simulation (same scene)</h3>" + run_table(*run, second_label + " design's");
    }
  } else if (const Json* s = member(summary, "optimize")) {
    h +=
        "<h2>Optimisation</h2>\n<p class=\"notice bad\">No optimum was found.</p>" + json_table(*s);
  } else if (const Json* b = member(summary, "balance")) {
    h += "<h2>Balanced design</h2>\n<p class=\"notice bad\">The balanced design was not "
         "simulated.</p>" +
         json_table(*b);
  }
  return h;
}

}  // namespace bd::studies::report_support
