#include "studies/report/study_parts.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iterator>
#include <numbers>
#include <variant>

#include "core/number_text.hpp"
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

namespace {
bool free_scene(const Json& summary) {
  const Json* scene = member(summary, "scene");
  return scene && text(*scene, "type") == "free";
}
}  // namespace

std::string run_table(const Json& run, const std::string& what, bool free) {
  std::string h = "<table>";
  if (const Json* method = member(run, "method")) {
    h += "<tr><th>method</th><td><b>" + esc(text(*method, "used")) + "</b> (requested " +
         esc(text(*method, "requested")) + ")<br>" + esc(text(*method, "reason")) + "</td></tr>";
    if (const std::string numerics = text(*method, "numerics"); !numerics.empty()) {
      h += "<tr><th>numerics</th><td>" + esc(numerics) + "</td></tr>";
    }
  }
  const bool ok = text(run, "ok") == "true";
  h += "<tr><th>status</th><td class=\"" + std::string(ok ? "good" : "bad") + "\">" +
       esc(text(run, "status")) + "</td></tr>";
  h += "<tr><th>message</th><td>" + esc(text(run, "message")) + "</td></tr>";
  h += "<tr><th>samples</th><td>" + esc(text(run, "samples")) + "</td></tr>";
  // a driven run integrates nothing: it has no integrator steps to show
  if (free) h += "<tr><th>integrator steps</th><td>" + esc(text(run, "steps")) + "</td></tr>";
  h += "<tr><th>dynamics evaluations</th><td>" + esc(text(run, "rhs_evaluations")) + "</td></tr>";
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
  h += run_table(summary, "original design's", free_scene(summary));
  if (const Json* scene = member(summary, "scene")) {
    h += "<h3>Scene</h3>" + json_table(*scene);
    if (free_scene(summary))  // a driven scene integrates nothing
      h += "<p>Integrator relative tolerance " + esc(text(summary, "tolerance")) + ".</p>\n";
  }
  // the units: SI on the page; what the study file gave in units of its own
  h += "<p>Units on this page and in the data files: SI (m, kg, s, rad, N, N m). ";
  const Json* units = member(summary, "units_read");
  if (units && units->is_array() && !units->empty()) {
    h += "The study file gave these values in units of their own, converted on reading:</p><ul>";
    for (const Json& u : *units) h += "<li>" + esc(text(u)) + "</li>";
    h += "</ul>\n";
  } else {
    h += "The study file gave every value as a plain number, read as SI.</p>\n";
  }
  return h;
}

namespace {

// the ratio after/before as written: round-off of 1 shows as 0, and so does the ratio of an
// `after` that is round-off of its scale (0 on the page, so its ratio is 0 too)
std::string ratio_cell(const std::string& written, const std::string& after, double scale) {
  const double a = std::strtod(after.c_str(), nullptr);
  if (!after.empty() && text::is_round_off(a, scale) && !written.empty()) {
    return "<td class=\"n\" title=\"" + esc(written) + "\">0</td>";
  }
  return num_cell(written, 1.0);
}

}  // namespace

namespace {

// where the original's peak `name` lies (summary.json's peaks): its time and the inputs there,
// e.g. "t = 0.0125 s, θ1 = 1.2 rad"; "" for a metric that is no peak
std::string peak_place(const Study& study, const Json& summary, const std::string& name,
                       const std::string& key = "peaks") {
  const Json* peaks = member(summary, key);
  const Json* p = peaks ? member(*peaks, name) : nullptr;
  const Json* t = p ? member(*p, "t") : nullptr;
  if (!t || !t->is_number()) return "";
  std::string s = "t = " + fmt(t->get<double>()) + " s";
  // an angle as the charts' crank-angle axes have it: degrees within the turn (summary.json
  // keeps the continuous angle in rad)
  const auto angle = [](double rad) {
    const double deg = std::fmod(rad * 180 / std::numbers::pi, 360.0);
    return fmt(deg < 0 ? deg + 360 : deg) + "°";
  };
  if (const Json* theta1 = member(*p, "theta1"); theta1 && theta1->is_number()) {
    s += ", θ1 = " + angle(theta1->get<double>());
  } else if (const Json* inputs = member(*p, "inputs");
             inputs && inputs->is_array() && !study.is_fourbar()) {
    const auto& in = study.planar().inputs;
    for (std::size_t k = 0; k < inputs->size() && k < in.size(); ++k) {
      if (!(*inputs)[k].is_number()) continue;
      const double v = (*inputs)[k].get<double>();
      s += ", " + in[k].name + " = " +
           (in[k].kind == core::planar::Input::Kind::kAngle ? angle(v) : fmt(v) + " m");
    }
  }
  return s;
}

}  // namespace

std::string metrics_section(const Study& study, const Json& summary, const SecondDesign& second,
                            const std::string& notes, const Scales& scales) {
  // a run that stopped early: its metrics cover the motion before the stop only (a free run's
  // peaks up to the stop itself, a driven run's the samples before it)
  const auto partial = [&](const std::string& key) {
    return text(summary, key) == "true"
               ? std::string("<br><span class=\"bad\">partial: the motion up to the stop</span>")
               : std::string();
  };
  std::string h = "<h2>Metrics</h2>\n<table><tr><th>metric</th><th>original" +
                  partial("metrics_partial") + "</th>";
  const Json* metrics = member(summary, "metrics");
  const Json* second_metrics =
      second.present() ? member(summary, second.key + "_metrics") : nullptr;
  const Json* reduction = member(summary, "reduction");
  if (second_metrics) {
    h += "<th>" + esc(second.label) + partial(second.key + "_metrics_partial") +
         "</th><th>ratio after/before</th>";
  }
  h += "<th>unit</th><th>where the original's peak lies</th>";
  if (second_metrics) h += "<th>where the " + esc(second.label) + " design's lies</th>";
  h += "</tr>";
  auto value = [](const Json* v) { return v && v->is_number() ? std::abs(v->get<double>()) : 0.0; };
  if (metrics) {
    for (const auto& [k, v] : metrics->items()) {
      const Json* s = second_metrics ? member(*second_metrics, k) : nullptr;
      // round-off of the larger of the two designs' values, or of the run's scale of the
      // metric's unit (the largest force of the run), shows as 0
      const double scale = std::max({value(&v), value(s), scales.of(metric_unit(summary, k))});
      h += "<tr><th>" + esc(k) + "</th>" + num_cell(text(v), scale);
      if (second_metrics) {
        const Json* r = reduction ? member(*reduction, k) : nullptr;
        h += (s ? num_cell(text(*s), scale) : "<td></td>") +
             (r ? ratio_cell(text(*r), s ? text(*s) : "", scale) : "<td></td>");
      }
      // a value shown as 0 (round-off) has no place to name
      const auto place = [&](const Json* x, const std::string& key) {
        const bool zero = !x || !x->is_number() || text::is_round_off(x->get<double>(), scale);
        return "<td>" + (zero ? std::string() : esc(peak_place(study, summary, k, key))) + "</td>";
      };
      h += "<td>" + esc(metric_unit(summary, k)) + "</td>" + place(&v, "peaks");
      if (second_metrics) h += place(s, second.key + "_peaks");
      h += "</tr>";
    }
  }
  return h + "</table>\n<p>" + notes + "</p>\n";
}

std::string comparison_section(const fs::path& dir, const Json& summary, const SecondDesign& second,
                               const Scales& scales) {
  if (!second.present() || !fs::exists(dir / "comparison.csv")) return "";
  const Csv csv = read_csv(dir / "comparison.csv");
  std::string h =
      "<h2>Comparison</h2>\n<p>From <a href=\"comparison.csv\">comparison.csv</a>: the "
      "original (before) and the " +
      second.label +
      " design (after), ratio after/before.</p><table><tr><th>metric</th>"
      "<th>before</th><th>after</th><th>ratio after/before</th><th>unit</th></tr>";
  for (const auto& row : csv.rows) {
    if (row.size() < 4) continue;
    // before and after: round-off of the larger, or of the run's scale of the unit, shows as 0
    const double scale = std::max({std::abs(std::strtod(row[1].c_str(), nullptr)),
                                   std::abs(std::strtod(row[2].c_str(), nullptr)),
                                   scales.of(metric_unit(summary, row[0]))});
    h += "<tr><th>" + esc(row[0]) + "</th>" + num_cell(row[1], scale) + num_cell(row[2], scale) +
         ratio_cell(row[3], row[2], scale) + "<td>" + esc(metric_unit(summary, row[0])) +
         "</td></tr>";
  }
  return h + "</table>\n";
}

namespace {

// the scale of each column `at` of harmonics.csv for the display rule of round-off: the
// force columns' (`forces`) one scale, the largest amplitude of any of them over every design and
// order or the run's force scale, whichever is larger; the moment columns' (`moments`) the same
// with the run's moment scale
std::vector<double> harmonic_scales(const Csv& csv, const std::vector<std::size_t>& at,
                                    const std::vector<std::size_t>& forces,
                                    const std::vector<std::size_t>& moments, const Scales& scales) {
  double force = scales.force, moment = scales.moment;
  for (const std::vector<std::string>& row : csv.rows) {
    if (row.size() < csv.header.size()) continue;
    for (std::size_t k : forces)
      force = std::max(force, std::abs(std::strtod(row[at[k]].c_str(), nullptr)));
    for (std::size_t k : moments)
      moment = std::max(moment, std::abs(std::strtod(row[at[k]].c_str(), nullptr)));
  }
  std::vector<double> scale(at.size(), 0.0);
  for (std::size_t k : forces) scale[k] = force;
  for (std::size_t k : moments) scale[k] = moment;
  return scale;
}

}  // namespace

std::string harmonics_section(const fs::path& dir, const Scales& scales) {
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
      "<h2>Harmonic orders</h2>\n<p>From <a href=\"harmonics.csv\">harmonics.csv</a>: the "
      "inertial shaking force and moment (what balancing acts on; weights and applied loads are "
      "not in them) over the first revolution of the driven input, by the discrete Fourier "
      "transform of the exact samples; order k repeats k times per revolution. Amplitudes of "
      "Fshx, Fshy [N] and Msh [N m]; the "
      "force's parts turning with the input (forward: a counterweight on the input's link "
      "cancels order 1) and against it (backward) [N]. An amplitude that is round-off of the "
      "run's forces or moments (at most 1e-12 of the largest) shows as 0. Phases are in the "
      "file.</p><table><tr><th>design</th><th>order</th><th>Fshx [N]</th><th>Fshy [N]</th>"
      "<th>forward [N]</th><th>backward [N]</th><th>Msh [N m]</th></tr>";
  const std::vector<double> scale = harmonic_scales(csv, at, {2, 3, 4, 5}, {6}, scales);
  for (const std::vector<std::string>& row : csv.rows) {
    if (row.size() < csv.header.size() || row[at[1]] == "0") continue;  // the mean: in the file
    h += "<tr><td>" + esc(row[at[0]]) + "</td><td class=\"n\">" + esc(row[at[1]]) + "</td>";
    for (std::size_t k = 2; k < at.size(); ++k) h += num_cell(row[at[k]], scale[k]);
    h += "</tr>";
  }
  return h + "</table>\n";
}

std::string charts_section(const std::string& gnuplot, const std::string& datablocks,
                           const std::vector<Chart>& charts, std::size_t samples,
                           std::size_t drawn) {
  std::string h = "<h2>Charts</h2>\n";
  if (samples > drawn && drawn > 0) {
    h += "<p>The run has " + std::to_string(samples) + " samples; the charts over the run draw " +
         std::to_string(drawn) +
         " of them, evenly spread, the first and the last included, so that this page stays "
         "small. The data files below hold every sample, and the metrics are computed from all "
         "of them.</p>\n";
  }
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

namespace {

bool finite_number(const std::string& field, double& v) {
  if (field.empty()) return false;
  char* end = nullptr;
  v = std::strtod(field.c_str(), &end);
  return *end == '\0' && std::isfinite(v);
}

// the front's rows with a design: both metrics numbers
std::size_t designs_on_front(const Csv& pareto) {
  std::size_t n = 0;
  double x = 0, y = 0;
  for (const auto& row : pareto.rows)
    n += row.size() > 2 && finite_number(row[1], x) && finite_number(row[2], y);
  return n;
}

// before (the original) and after (the chosen optimum) of a metric in comparison.csv
bool compared(const Csv& comparison, const std::string& metric, double& before, double& after) {
  for (const auto& row : comparison.rows) {
    if (row.size() >= 3 && row[0] == metric)
      return finite_number(row[1], before) && finite_number(row[2], after);
  }
  return false;
}

}  // namespace

std::vector<Chart> pareto_charts(const fs::path& dir, std::string& datablocks) {
  if (!fs::exists(dir / "pareto.csv")) return {};
  const Csv pareto = read_csv(dir / "pareto.csv");
  if (pareto.header.size() < 3) return {};
  const std::string& first = pareto.header[1];
  const std::string& second = pareto.header[2];
  const std::size_t found = designs_on_front(pareto);
  // the original and the chosen optimum, from comparison.csv
  Csv comparison;
  if (fs::exists(dir / "comparison.csv")) comparison = read_csv(dir / "comparison.csv");
  double x0 = 0, x1 = 0, y0 = 0, y1 = 0;
  const bool marks = compared(comparison, first, x0, x1) && compared(comparison, second, y0, y1);
  if (found == 0 && !marks) return {};  // nothing to draw: the section says why
  std::string plot;
  if (found > 0) {
    datablocks += "$pareto << EOD\n";
    double x = 0, y = 0;
    for (const auto& row : pareto.rows) {
      if (row.size() > 2 && finite_number(row[1], x) && finite_number(row[2], y))
        datablocks += row[1] + "," + row[2] + "\n";
    }
    datablocks += "EOD\n";
    plot += "$pareto using 1:2 with linespoints lw 2 pt 7 title 'front'";
  }
  if (marks) {
    datablocks += "$pareto_marks << EOD\n" + text::exact(x0) + "," + text::exact(y0) + "\n" +
                  text::exact(x1) + "," + text::exact(y1) + "\nEOD\n";
    plot += std::string(plot.empty() ? "" : ", ") +
            "$pareto_marks every ::0::0 using 1:2 with points pt 5 ps 1.8 lc 'black' title "
            "'original design', $pareto_marks every ::1::1 using 1:2 with points pt 12 ps 2.4 "
            "lw 2 lc 'red' title 'chosen optimum'";
  }
  const std::size_t dropped = pareto.rows.size() - found;
  std::string caption = "Each point a design found by the epsilon-constraint method (pareto.csv)";
  caption += marks ? "; the original design and the optimum the study chose (comparison.csv) "
                     "marked."
                   : ".";
  if (dropped > 0) {
    caption += " " + std::to_string(dropped) + " of the " + std::to_string(pareto.rows.size()) +
               " points found no design (their rows in pareto.csv say why) and are not drawn.";
  }
  return {{"pareto", "Pareto front", caption,
           "set title 'Pareto front'\nset xlabel " + gp_string(with_unit(first)) + "\nset ylabel " +
               gp_string(with_unit(second)) + "\nplot " + plot}};
}

std::vector<Chart> harmonic_charts(const fs::path& dir, std::string& datablocks,
                                   const Scales& scales) {
  if (!fs::exists(dir / "harmonics.csv")) return {};
  const Csv csv = read_csv(dir / "harmonics.csv");
  const char* columns[] = {"design",       "order",         "Fsh_forward",
                           "Fsh_backward", "Msh_amplitude", "tau_amplitude"};
  std::vector<std::size_t> at;
  for (const char* c : columns) {
    const auto it = std::find(csv.header.begin(), csv.header.end(), c);
    if (it == csv.header.end()) return {};
    at.push_back(static_cast<std::size_t>(it - csv.header.begin()));
  }
  std::vector<std::string> designs;
  for (const auto& row : csv.rows) {
    if (row.size() < csv.header.size()) continue;
    if (std::find(designs.begin(), designs.end(), row[at[0]]) == designs.end())
      designs.push_back(row[at[0]]);
  }
  // a bar of round-off of the run's forces or moments (a balanced design's shaking force) is
  // drawn as 0, not as a chart of noise
  const std::vector<double> scale = harmonic_scales(csv, at, {2, 3}, {4, 5}, scales);
  // each panel's axis, shared by every design: the largest amplitude of orders 1..N of its kind
  // (the force's parts; the moment and the torque) on this page, round-off left out
  auto amplitude = [&](const std::vector<std::string>& row, std::size_t k) {
    const double v = std::abs(std::strtod(row[at[k]].c_str(), nullptr));
    return text::is_round_off(v, scale[k]) || !std::isfinite(v) ? 0.0 : v;
  };
  auto orders = [&](const std::vector<std::string>& row, const std::string* design) {
    return row.size() >= csv.header.size() && row[at[1]] != "0" &&
           (!design || row[at[0]] == *design);
  };
  double axis[2] = {0, 0};  // force [N], moment and torque [N m]
  for (const auto& row : csv.rows) {
    if (!orders(row, nullptr)) continue;
    for (std::size_t k = 2; k < 6; ++k) axis[k / 4] = std::max(axis[k / 4], amplitude(row, k));
  }
  std::vector<Chart> charts;
  for (const std::string& d : designs) {
    // orders 1..N of this design, the numbers as harmonics.csv has them (round-off: 0)
    const std::string block = "harmonics_" + d;
    datablocks += "$" + block + " << EOD\norder,Fsh_forward,Fsh_backward,Msh,tau\n";
    double largest[2] = {0, 0};  // this design's largest bar in each panel
    for (const auto& row : csv.rows) {
      if (!orders(row, &d)) continue;
      datablocks += row[at[1]];
      for (std::size_t k = 2; k < 6; ++k) {
        const double v = std::strtod(row[at[k]].c_str(), nullptr);
        datablocks += "," + (text::is_round_off(v, scale[k]) ? std::string("0") : row[at[k]]);
        largest[k / 4] = std::max(largest[k / 4], amplitude(row, k));
      }
      datablocks += "\n";
    }
    datablocks += "EOD\n";
    // a panel on the shared axis whose every bar is under a thousandth of it (under a pixel)
    // says so, with the size of its largest bar, instead of looking empty
    auto panel = [&](int kind, const char* unit) {
      std::string p;
      if (axis[kind] > 0)
        p += "set yrange [0:" + text::exact(1.05 * axis[kind]) + "]\n";
      else
        p += "set yrange [0:1]\n";
      std::string note;
      if (largest[kind] == 0) {
        note = "every order is 0 (round-off of the run's " +
               std::string(kind == 0 ? "forces" : "moments") + ")";
      } else if (largest[kind] < 1e-3 * axis[kind]) {
        note = "every order below " + text::digits(largest[kind], 2) + " " + unit +
               ": too small to see at this scale";
      }
      p += note.empty() ? "unset label 1\n"
                        : "set label 1 " + gp_string(note) + " at graph 0.5, graph 0.5 center\n";
      return p;
    };
    const std::string b = "$" + block;
    charts.push_back(
        {"harmonics-" + d, "Harmonic orders, " + d + " design",
         "Amplitudes of orders 1..N over a revolution of the driven input (harmonics.csv, " + d +
             " design) of the inertial shaking force and moment (what balancing acts on; "
             "weights and applied loads are not in them): left, the force's parts turning "
             "with the input (forward) and against it (backward) [N]; right, the shaking moment "
             "and the drive torque [N m]. Every design's chart has the same axes, the largest "
             "amplitude of their kind on this page; an amplitude that is round-off of the run's "
             "forces or moments (at most 1e-12 of the largest) is drawn as 0, and a side whose "
             "every bar is too small to see at this scale says how small.",
         "set multiplot layout 1,2 title " + gp_string("Harmonic orders, " + d + " design") +
             "\nset style data histogram\nset style histogram clustered gap 1\n"
             "set style fill solid 0.85 border -1\nset boxwidth 0.9\n"
             "set key inside top right\nset xlabel 'order'\n"
             "set ylabel 'amplitude [N]'\n" +
             panel(0, "N") + "plot " + b +
             " skip 1 using 2:xtic(1) title 'Fsh forward', '' skip 1 using 3 title "
             "'Fsh backward'\nset ylabel 'amplitude [N m]'\n" +
             panel(1, "N m") + "plot " + b +
             " skip 1 using 4:xtic(1) title 'Msh', '' skip 1 using 5 title 'τ'\n"
             "unset multiplot"});
  }
  return charts;
}

bool periodic_run(const Scene& scene, const Json& summary) {
  if (text(summary, "ok") != "true") return false;
  if (std::holds_alternative<core::DrivenScene>(scene)) return true;
  if (const auto* d = std::get_if<core::planar::DrivenScene>(&scene)) {
    return d->duration == 0 && d->revolutions >= 1 && d->speeds.size() == 1;
  }
  return false;
}

RunAxis run_axis(const Scene& scene, int angle_column) {
  if (!is_free(scene) && angle_column > 0) {
    return {"($" + std::to_string(angle_column) + "*180/pi)", "crank angle [deg]"};
  }
  return {"1", time_axis(scene)};
}

std::string xy_block(const std::string& name, const Csv& csv, int cx, int cy, bool close,
                     double scale) {
  std::string b = "$" + name + " << EOD\nx,y\n";
  const auto x = static_cast<std::size_t>(cx - 1), y = static_cast<std::size_t>(cy - 1);
  // a value that is round-off of `scale`: 0
  auto shown = [scale](const std::string& f) {
    return text::is_round_off(std::strtod(f.c_str(), nullptr), scale) ? std::string("0") : f;
  };
  std::string first;
  for (const auto& row : csv.rows) {
    if (row.size() <= std::max(x, y)) continue;
    const std::string line = shown(row[x]) + "," + shown(row[y]) + "\n";
    if (first.empty()) first = line;
    b += line;
  }
  if (close) b += first;
  return b + "EOD\n";
}

int gp_column(const Csv& ts, const std::string& name) {
  const auto it = std::find(ts.header.begin(), ts.header.end(), name);
  return it == ts.header.end() ? 0 : static_cast<int>(it - ts.header.begin()) + 1;
}

std::string shaking_metrics_note(const std::string& about) {
  return "Fsh, Msh: the inertial part of the shaking force and moment about " + about +
         " on the frame, &minus;&Sigma; m a and &minus;dH/dt: what balancing acts on, and what "
         "the ratios, verdicts and objectives take; Fsh_total, Msh_total: the total the frame "
         "feels, weights and applied loads included (without them the two are equal).";
}

ShakingColumns shaking_columns(const Csv& ts) {
  ShakingColumns c;
  c.x = gp_column(ts, "Fshx_inertial");
  c.y = gp_column(ts, "Fshy_inertial");
  c.moment = gp_column(ts, "Msh_inertial");
  if (c.x == 0 || c.y == 0 || c.moment == 0) {  // a timeseries.csv without the parts: the total
    c.x = gp_column(ts, "Fshx");
    c.y = gp_column(ts, "Fshy");
    c.moment = gp_column(ts, "Msh");
    c.force_note = " The total shaking force (the file has no inertial part).";
    c.moment_note = " The total shaking moment (the file has no inertial part).";
    return c;
  }
  c.force_note =
      " The inertial part, −Σ m a (what balancing acts on, as Fsh_rms and Fsh_max measure it).";
  c.moment_note =
      " The inertial part, −dH/dt (what balancing acts on, as Msh_rms and Msh_max measure it).";
  // the static part (weights, applied loads) of the original's samples: none, a constant, or
  // one that changes
  const int sx = gp_column(ts, "Fshx_static"), sy = gp_column(ts, "Fshy_static"),
            sm = gp_column(ts, "Msh_static");
  if (sx == 0 || sy == 0 || sm == 0) return c;
  bool force = false, moment = false, constant = true;
  std::vector<double> first;
  for (const auto& row : ts.rows) {
    const std::vector<double> v = numbers(row);
    if (v.size() < static_cast<std::size_t>(std::max({sx, sy, sm}))) continue;
    const double fx = v[static_cast<std::size_t>(sx - 1)], fy = v[static_cast<std::size_t>(sy - 1)];
    force = force || fx != 0 || fy != 0;
    moment = moment || v[static_cast<std::size_t>(sm - 1)] != 0;
    if (first.empty()) first = {fx, fy};
    constant = constant && fx == first[0] && fy == first[1];
  }
  if (force) {
    c.force_note += " The total the frame feels adds the weights and applied loads";
    c.force_note += constant ? ": here the original's is the same curve moved by (" +
                                   text::digits(first[0] + 0.0, 6) + ", " +
                                   text::digits(first[1] + 0.0, 6) + ") N"
                             : "";
    c.force_note += " (timeseries.csv: Fshx, Fshy; Fsh_total_rms, Fsh_total_max).";
  }
  if (moment) {
    c.moment_note +=
        " The total the frame feels adds the moments of the weights and applied "
        "loads (timeseries.csv: Msh; Msh_total_rms, Msh_total_max).";
  }
  return c;
}

std::string animations_section(const std::vector<AnimationFigure>& figures) {
  std::string h;
  for (const AnimationFigure& f : figures) {
    if (f.animation.shapes.empty()) continue;
    if (h.empty()) h = "<h2>The linkage in motion</h2>\n";
    h += "<h3>" + esc(f.heading) + "</h3>\n<figure class=\"animation\" id=\"figure-" +
         esc(f.animation.id) + "\">\n" + animation_svg(f.animation) + "\n<figcaption>" +
         esc(f.caption) + "</figcaption>\n</figure>\n";
  }
  return h;
}

std::string pareto_section(const fs::path& dir, const Scales& scales) {
  if (!fs::exists(dir / "pareto.csv")) return "";
  const Csv pareto = read_csv(dir / "pareto.csv");
  const std::size_t found = designs_on_front(pareto);
  std::string h = "<h2>Pareto front</h2>\n<p>From <a href=\"pareto.csv\">pareto.csv</a>";
  if (pareto.header.size() >= 3) {
    h += ": " + esc(with_unit(pareto.header[1])) + " against " + esc(with_unit(pareto.header[2]));
  }
  h += ". " + std::to_string(found) + " of its " + std::to_string(pareto.rows.size()) +
       " points found a design" +
       (found < pareto.rows.size() ? "; a point without one has empty metric and variable cells "
                                     "and its termination says why"
                                   : "") +
       ".</p>";
  return h + csv_table(pareto, scales);
}

std::string time_axis(const Scene& scene) {
  if (std::holds_alternative<core::DrivenScene>(scene))
    return "t [s] (crank driven at constant speed)";
  if (std::holds_alternative<core::planar::DrivenScene>(scene)) {
    return "t [s] (inputs driven at constant speed)";
  }
  return "t [s]";
}

std::string second_design_section(const Json& summary, const SecondDesign& sd,
                                  const Scales& scales) {
  std::string h;
  const std::string second = sd.key, second_label = sd.label;
  if (sd.present()) {
    const char* section = second == "balanced" ? "balance" : "optimize";
    h += std::string("<h2>") + (second == "balanced" ? "Balanced design" : "Optimised design") +
         "</h2>\n";
    if (const Json* s = member(summary, section)) h += json_table(*s, scales);
    if (const Json* run = member(summary, second + "_run")) {
      h += "<h3>Its simulation (same scene)</h3>" +
           run_table(*run, second_label + " design's", free_scene(summary));
    }
  } else if (member(summary, "balanced_run") || member(summary, "optimized_run")) {
    // simulated, but its time series is not in this folder (deleted or not copied with it)
    const bool balanced = member(summary, "balanced_run") != nullptr;
    h += std::string("<h2>") + (balanced ? "Balanced design" : "Optimised design") +
         "</h2>\n<p class=\"notice bad\">The " + (balanced ? "balanced" : "optimised") +
         " design was simulated, but its time series <code>" +
         (balanced ? "balanced" : "optimized") +
         "-timeseries.csv</code> is missing from this folder: its charts and metrics are left "
         "out. Run the study again to write it.</p>";
    if (const Json* s = member(summary, balanced ? "balance" : "optimize"))
      h += json_table(*s, scales);
  } else if (const Json* s = member(summary, "optimize")) {
    h += "<h2>Optimisation</h2>\n<p class=\"notice bad\">No optimum was found.</p>" +
         json_table(*s, scales);
  } else if (const Json* b = member(summary, "balance")) {
    h += "<h2>Balanced design</h2>\n<p class=\"notice bad\">The balanced design was not "
         "simulated.</p>" +
         json_table(*b, scales);
  }
  return h;
}

}  // namespace bd::studies::report_support
