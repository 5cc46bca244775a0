// A planar linkage's study page: its tables and the charts of its run, read from the folder's
// timeseries.csv by column name (core/planar/simulate.hpp lists the columns).
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "studies/report/pages.hpp"
#include "studies/report/report.hpp"
#include "studies/report/study_parts.hpp"
#include "studies/run/files.hpp"
#include "studies/study/load_study.hpp"

namespace bd::studies::report_support {

namespace fs = std::filesystem;

namespace {

using core::planar::Linkage;

std::string node_name(const Linkage& l, int i) { return l.nodes[static_cast<std::size_t>(i)].name; }

std::string nodes_of(const Linkage& l, const std::vector<int>& nodes) {
  std::string s;
  for (int n : nodes) s += (s.empty() ? "" : ", ") + node_name(l, n);
  return s;
}

std::string effort_text(const core::planar::TimeFunction& f, const char* unit) {
  using K = core::planar::TimeFunction::Kind;
  if (f.kind == K::kConstant) return f.value == 0 ? "none" : fmt(f.value) + " " + unit;
  if (f.kind == K::kTable)
    return "table of " + std::to_string(f.times.size()) + " values [" + unit + "]";
  return fmt(f.mean) + " + " + fmt(f.amplitude) + " sin(2π " + fmt(f.frequency) + " Hz t + " +
         fmt(f.phase) + ") " + unit;
}

// the gnuplot column (1-based) of `name` in the timeseries header; 0 when absent
int gp_column(const Csv& ts, const std::string& name) {
  const auto it = std::find(ts.header.begin(), ts.header.end(), name);
  return it == ts.header.end() ? 0 : static_cast<int>(it - ts.header.begin()) + 1;
}

// one line per column over t, `expr` the gnuplot expression of a column index (magnitude or value)
std::string lines_over_t(const std::string& file,
                         const std::vector<std::pair<std::string, std::string>>& items) {
  std::string plot;
  for (std::size_t k = 0; k < items.size(); ++k) {
    plot += (k ? ", " : "") + (k ? std::string("''") : file) +
            " skip 1 using 1:" + items[k].second + " with lines lw 2 title " +
            gp_string(items[k].first);
  }
  return plot;
}

// |(x, y)| of the columns <name>x, <name>y as a gnuplot expression
std::string magnitude(const Csv& ts, const std::string& name) {
  const int cx = gp_column(ts, name + "x"), cy = gp_column(ts, name + "y");
  return "(sqrt($" + std::to_string(cx) + "**2+$" + std::to_string(cy) + "**2))";
}

// a counterweight drawn on its link: where it sits in the link's axes from its pivot node
struct CounterweightPart {
  int link{}, pivot{};
  Vec2 position{0, 0};
};

// the counterweights of a balanced or optimised design, from summary.json's balance or
// optimize section
std::vector<CounterweightPart> counterweight_parts(const Linkage& l, const Json& summary) {
  std::vector<CounterweightPart> parts;
  const Json* b = member(summary, "balance");
  if (!b) b = member(summary, "optimize");
  const Json* cws = b ? member(*b, "counterweights") : nullptr;
  if (!cws || !cws->is_array()) return parts;
  for (const Json& c : *cws) {
    const int link = core::planar::link_index(l, text(c, "link"));
    const int pivot = core::planar::node_index(l, text(c, "from_node"));
    const Json* at = member(c, "position");
    if (link < 0 || pivot < 0 || !at || !at->is_array() || at->size() != 2) continue;
    if (!(*at)[0].is_number() || !(*at)[1].is_number()) continue;
    parts.push_back({link, pivot, Vec2((*at)[0].get<double>(), (*at)[1].get<double>())});
  }
  return parts;
}

// the linkage at four samples evenly spread over the run: links through their nodes, the ground
// nodes, the frame guides, and the counterweights `parts` (a balanced design's); `tag` names the
// chart's data blocks apart from another linkage's on the page
Chart linkage_chart(const Linkage& l, const Csv& ts, std::string& datablocks,
                    const std::string& what = "linkage", const std::string& tag = "p",
                    const std::vector<CounterweightPart>& parts = {}) {
  const std::size_t n = ts.rows.size();
  std::vector<std::size_t> picks;
  for (std::size_t k = 0; k < 4 && k < n; ++k) picks.push_back(k * n / std::min<std::size_t>(4, n));
  auto node_at = [&](const std::vector<double>& row, int i) {
    const core::planar::Node& node = l.nodes[static_cast<std::size_t>(i)];
    if (node.ground) return node.position;
    return Vec2(row[static_cast<std::size_t>(gp_column(ts, "x_" + node.name) - 1)],
                row[static_cast<std::size_t>(gp_column(ts, "y_" + node.name) - 1)]);
  };
  // where a counterweight sits at a sample: pivot + R(theta) position
  auto weight_at = [&](const std::vector<double>& row, const CounterweightPart& part) {
    const int column = gp_column(ts, "theta_" + l.links[static_cast<std::size_t>(part.link)].name);
    const double theta = column ? row[static_cast<std::size_t>(column - 1)] : 0.0;
    const Vec2 u(std::cos(theta), std::sin(theta)), v(-u.y(), u.x());
    return Vec2(node_at(row, part.pivot) + part.position.x() * u + part.position.y() * v);
  };
  datablocks += "$" + tag + "links << EOD\n";
  std::string entries;
  for (std::size_t k = 0; k < picks.size(); ++k) {
    const std::vector<double> row = numbers(ts.rows[picks[k]]);
    for (const core::planar::Link& link : l.links) {
      for (int i : link.nodes) datablocks += xy(node_at(row, i)) + "\n";
      if (link.nodes.size() > 2) datablocks += xy(node_at(row, link.nodes[0])) + "\n";
      datablocks += "\n";
    }
    for (const CounterweightPart& part : parts) {  // its arm from the pivot
      datablocks += xy(node_at(row, part.pivot)) + "\n" + xy(weight_at(row, part)) + "\n\n";
    }
    datablocks += "\n";  // a new data set per sample (index k)
    entries += std::string(k ? ", " : "") + "$" + tag + "links index " + std::to_string(k) +
               " using 1:2 with linespoints lw 2 pt 7 ps 0.6 lt " + std::to_string(k + 1) +
               " title " + gp_string("t = " + fmt(row[0], "%.3g") + " s");
  }
  // each counterweight where its link carries it, in its sample's colour
  datablocks += "EOD\n$" + tag + "weights << EOD\n";
  for (std::size_t k = 0; k < picks.size(); ++k) {
    const std::vector<double> row = numbers(ts.rows[picks[k]]);
    for (const CounterweightPart& part : parts) {
      datablocks += xy(weight_at(row, part)) + "," + std::to_string(k + 1) + "\n";
    }
  }
  // balance shafts: each shaft on the frame, its drive from its link's pivot, and its
  // eccentric mass where it is at each sample, in that sample's colour
  datablocks += "EOD\n$" + tag + "shafts << EOD\n";
  for (const core::planar::BalanceShaft& b : l.shafts) datablocks += xy(b.at) + "\n";
  datablocks += "EOD\n$" + tag + "drives << EOD\n";
  for (const core::planar::BalanceShaft& b : l.shafts) {
    datablocks +=
        xy(l.nodes[static_cast<std::size_t>(core::planar::pivot_of(l, b.link))].position) + "\n" +
        xy(b.at) + "\n\n";
  }
  datablocks += "EOD\n$" + tag + "eccentrics << EOD\n";
  bool eccentric = false;
  for (std::size_t k = 0; k < picks.size(); ++k) {
    const std::vector<double> row = numbers(ts.rows[picks[k]]);
    for (const core::planar::BalanceShaft& b : l.shafts) {
      if (b.mass == 0 || b.eccentricity.norm() == 0) continue;
      const core::planar::Link& link = l.links[static_cast<std::size_t>(b.link)];
      const Vec2 d = l.nodes[static_cast<std::size_t>(link.nodes[1])].position -
                     l.nodes[static_cast<std::size_t>(link.nodes[0])].position;
      const int column = gp_column(ts, "theta_" + link.name);
      const double turn =
          column ? row[static_cast<std::size_t>(column - 1)] - std::atan2(d.y(), d.x()) : 0.0;
      datablocks +=
          xy(b.at + core::planar::shaft_centre(b, turn)) + "," + std::to_string(k + 1) + "\n";
      eccentric = true;
    }
  }
  datablocks += "EOD\n$" + tag + "ground << EOD\n";
  for (const core::planar::Node& node : l.nodes) {
    if (node.ground) datablocks += xy(node.position) + "\n";
  }
  datablocks += "EOD\n$" + tag + "guides << EOD\n";
  // a frame guide over the stretch its node travels, and a little more (the line the study
  // gives may be far longer: a cylinder axis given as [0, 0] to [1, 0])
  for (const core::planar::Slider& s : l.sliders) {
    if (s.link >= 0) continue;
    const Vec2 u = (s.to - s.from).normalized();
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const auto& text_row : ts.rows) {
      const double along = u.dot(node_at(numbers(text_row), s.node) - s.from);
      lo = std::min(lo, along);
      hi = std::max(hi, along);
    }
    if (!(hi >= lo)) lo = hi = 0;
    const double margin = std::max(0.25 * (hi - lo), 1e-3);
    datablocks += xy(s.from + (lo - margin) * u) + "\n" + xy(s.from + (hi + margin) * u) + "\n\n";
  }
  datablocks += "EOD\n";
  std::string cmd = "set title " +
                    gp_string("The " + what + " at " + std::to_string(picks.size()) + " samples") +
                    "\nset size ratio -1\nset xlabel 'x [m]'\nset ylabel 'y [m]'\n"
                    "set offsets graph 0.05, graph 0.05, graph 0.05, graph 0.05\n"
                    "set key outside right top vertical Left reverse\n";
  for (const core::planar::Node& node : l.nodes) {
    if (node.ground)
      cmd +=
          "set label " + gp_string(node.name) + " at " + xy(node.position) + " offset 0.6,-0.8\n";
  }
  // one label per shaft position (a Lanchester pair may share one)
  std::vector<std::pair<Vec2, std::string>> shaft_labels;
  for (const core::planar::BalanceShaft& b : l.shafts) {
    auto same = std::find_if(shaft_labels.begin(), shaft_labels.end(),
                             [&](const auto& x) { return x.first == b.at; });
    if (same == shaft_labels.end()) {
      shaft_labels.emplace_back(b.at, b.name);
    } else {
      same->second += ", " + b.name;
    }
  }
  for (const auto& [at, names] : shaft_labels)
    cmd += "set label " + gp_string(names) + " at " + xy(at) + " offset 0.8,0.6\n";
  cmd += "plot " + entries + ", $" + tag +
         "ground using 1:2 with points pt 9 ps 1.8 lc 'gray30' title 'ground nodes'";
  const bool guides = std::any_of(l.sliders.begin(), l.sliders.end(),
                                  [](const core::planar::Slider& s) { return s.link < 0; });
  if (guides) {
    cmd += ", $" + tag + "guides using 1:2 with lines lw 1 dt 2 lc 'gray30' title 'frame guides'";
  }
  if (!parts.empty()) {
    cmd += ", $" + tag +
           "weights using 1:2:3 with points pt 7 ps 2.2 lc variable title 'counterweights'";
  }
  if (!l.shafts.empty()) {
    cmd += ", $" + tag + "drives using 1:2 with lines dt 3 lw 1 lc 'gray50' notitle, $" + tag +
           "shafts using 1:2 with points pt 6 ps 2.4 lw 2 lc 'black' title 'balance shafts'";
    if (eccentric) {
      cmd += ", $" + tag +
             "eccentrics using 1:2:3 with points pt 5 ps 1.2 lc variable title 'shaft masses'";
    }
  }
  Chart c;
  c.id = "linkage";
  c.heading = "The linkage";
  c.caption =
      "Links through their nodes (a ternary link as a closed outline) at samples spread "
      "evenly over the run, one colour per sample; ground nodes as triangles, guides fixed "
      "in the frame dashed; balance shafts as open circles, dotted to the pivot of the link "
      "that drives them, with their eccentric masses in each sample's colour. From the node "
      "columns of timeseries.csv.";
  c.commands = cmd;
  c.square = true;
  return c;
}

// the balanced design beside the original: its samples' file, its linkage and counterweights
struct Second {
  SecondDesign design;
  std::string file;  // its samples as a gnuplot string
  std::optional<Linkage> linkage;
  std::vector<CounterweightPart> parts;
  Csv ts;
};

// one line of the original over t, and the second design's (dashed) when there is one
std::string with_second(const std::string& file, const Second& second, const std::string& name,
                        const std::string& expr) {
  std::string plot = file + " skip 1 using 1:" + expr + " with lines lw 2 title " +
                     gp_string(second.file.empty() ? name : name + ", original");
  if (!second.file.empty()) {
    plot += ", " + second.file + " skip 1 using 1:" + expr + " with lines lw 2 dt 2 title " +
            gp_string(name + ", " + second.design.label);
  }
  return plot;
}

std::vector<Chart> planar_charts(const Study& study, const fs::path& dir, const Csv& ts,
                                 const Second& second, std::string& datablocks) {
  const Linkage& l = study.planar();
  const std::string file = gp_string((fs::absolute(dir) / "timeseries.csv").string());
  const std::string taxis = "\nset xlabel " + gp_string(time_axis(study.scene)) + "\n";
  std::vector<Chart> charts;
  if (ts.rows.empty()) return charts;
  std::vector<std::pair<std::string, std::string>> angles, supports, drives, joints;
  for (const core::planar::Link& link : l.links) {
    angles.push_back({"θ " + link.name, std::to_string(gp_column(ts, "theta_" + link.name))});
  }
  for (const std::string& c : ts.header) {
    if (c.size() > 2 && c[0] == 'R' && c.back() == 'x') {
      supports.push_back(
          {"|" + c.substr(0, c.size() - 1) + "|", magnitude(ts, c.substr(0, c.size() - 1))});
    }
    if (c.size() > 2 && c[0] == 'F' && c.back() == 'x' && c.rfind("Fsh", 0) != 0) {
      joints.push_back(
          {"|" + c.substr(0, c.size() - 1) + "|", magnitude(ts, c.substr(0, c.size() - 1))});
    }
    if (c.rfind("tau", 0) == 0) drives.push_back({c, std::to_string(gp_column(ts, c))});
  }
  std::string drive_plot;
  for (const auto& [name, expr] : drives) {
    drive_plot += (drive_plot.empty() ? "" : ", ") + with_second(file, second, name, expr);
  }
  // the second design has the original's columns (the same links, nodes and joints)
  const std::string fsh = " skip 1 using " + std::to_string(gp_column(ts, "Fshx")) + ":" +
                          std::to_string(gp_column(ts, "Fshy"));
  std::string hodograph = file + fsh + " with lines lw 2 title " +
                          gp_string(second.file.empty() ? "shaking force" : "original");
  if (!second.file.empty()) {
    hodograph += ", " + second.file + fsh + " with linespoints lw 2 pt 7 ps 0.5 pi 10 title " +
                 gp_string(second.design.label);
  }
  charts.push_back({"angles", "Link angles",
                    "Every link's angle (its first-to-second node direction) over the run.",
                    "set title 'Link angles'" + taxis + "set ylabel 'angle [rad]'\nplot " +
                        lines_over_t(file, angles)});
  charts.push_back({"reactions", "Support reactions",
                    "Magnitudes of the forces of the mechanism on the frame at each ground node "
                    "and frame guide.",
                    "set title 'Support reactions'" + taxis +
                        "set ylabel 'force on the frame [N]'\nplot " +
                        lines_over_t(file, supports)});
  charts.push_back(
      {"hodograph", "Shaking-force hodograph",
       "The tip of the shaking force over the run, equal axes.",
       "set title 'Shaking-force hodograph'\nset size ratio -1\nset xlabel 'Fshx [N]'\n"
       "set ylabel 'Fshy [N]'\nplot " +
           hodograph,
       true});
  charts.push_back(
      {"shaking-moment", "Shaking moment", "Shaking moment on the frame about the origin.",
       "set title 'Shaking moment about the origin'" + taxis + "set ylabel 'Msh [N m]'\nplot " +
           with_second(file, second, "Msh", std::to_string(gp_column(ts, "Msh")))});
  charts.push_back({"drive", "Drive efforts",
                    "The drives' torques [N m] or forces [N] on their inputs, from the frame.",
                    "set title 'Drive efforts'" + taxis +
                        "set ylabel 'torque [N m] or force [N]'\nplot " + drive_plot});
  if (!joints.empty()) {
    charts.push_back({"joints", "Joint forces", "Magnitudes of the joint forces on their links.",
                      "set title 'Joint forces'" + taxis + "set ylabel 'joint force [N]'\nplot " +
                          lines_over_t(file, joints)});
  }
  charts.push_back(linkage_chart(l, ts, datablocks));
  if (second.linkage && !second.ts.rows.empty()) {
    Chart c = linkage_chart(*second.linkage, second.ts, datablocks,
                            second.design.label + " linkage", "b", second.parts);
    c.id = "linkage-" + second.design.key;
    c.heading = "The " + second.design.label + " linkage";
    c.caption =
        "The " + second.design.label + " design drawn as the original above, from " +
        second.design.file +
        ", with each counterweight as a filled circle on an arm from its link's pivot, in its "
        "sample's colour; the links' masses include them.";
    charts.push_back(c);
  }
  return charts;
}

}  // namespace

std::string planar_linkage_tables(const Linkage& l) {
  std::string h = "<table><tr><th>node</th><th>drawn at [m]</th><th></th></tr>";
  for (const core::planar::Node& n : l.nodes) {
    h += "<tr><th>" + esc(n.name) + "</th><td>" + vec_text(n.position) + "</td><td>" +
         (n.ground ? "ground" : "") + "</td></tr>";
  }
  h += "</table><table><tr><th>link</th><th>nodes</th><th>mass m [kg]</th><th>e [m]</th>"
       "<th>f [m]</th><th>inertia I [kg m&sup2;]</th></tr>";
  for (const core::planar::Link& k : l.links) {
    h += "<tr><th>" + esc(k.name) + "</th><td>" + esc(nodes_of(l, k.nodes)) +
         "</td><td class=\"n\">" + fmt(k.mass) + "</td><td class=\"n\">" + fmt(k.e) +
         "</td><td class=\"n\">" + fmt(k.f) + "</td><td class=\"n\">" + fmt(k.inertia) +
         "</td></tr>";
  }
  h += "</table>";
  if (!l.point_masses.empty()) {
    h += "<table><tr><th>point mass at</th><th>mass [kg]</th></tr>";
    for (const core::planar::PointMass& p : l.point_masses) {
      h += "<tr><th>" + esc(node_name(l, p.node)) + "</th><td class=\"n\">" + fmt(p.mass) +
           "</td></tr>";
    }
    h += "</table>";
  }
  if (!l.sliders.empty()) {
    h += "<table><tr><th>slider</th><th>node</th><th>guide</th></tr>";
    for (const core::planar::Slider& s : l.sliders) {
      const std::string guide =
          s.link < 0 ? "fixed in the frame, " + vec_text(s.from) + " to " + vec_text(s.to)
                     : "on link " + l.links[static_cast<std::size_t>(s.link)].name + ", " +
                           node_name(l, s.from_node) + " to " + node_name(l, s.to_node);
      h += "<tr><th>" + esc(s.name) + "</th><td>" + esc(node_name(l, s.node)) + "</td><td>" +
           esc(guide) + "</td></tr>";
    }
    h += "</table>";
  }
  if (!l.springs.empty()) {
    h += "<table><tr><th>spring</th><th>between</th><th>k [N/m]</th><th>free length [m]</th>"
         "<th>c [N s/m]</th></tr>";
    for (const core::planar::Spring& s : l.springs) {
      h += "<tr><th>" + esc(s.name) + "</th><td>" +
           esc(node_name(l, s.a) + ", " + node_name(l, s.b)) + "</td><td class=\"n\">" +
           fmt(s.stiffness) + "</td><td class=\"n\">" + fmt(s.free_length) +
           "</td><td class=\"n\">" + fmt(s.damping) + "</td></tr>";
    }
    h += "</table>";
  }
  if (!l.shafts.empty()) {
    h += "<table><tr><th>balance shaft</th><th>geared to</th><th>ratio</th><th>at [m]</th>"
         "<th>mass [kg]</th><th>eccentricity [m]</th><th>inertia [kg m&sup2;]</th></tr>";
    for (const core::planar::BalanceShaft& b : l.shafts) {
      h += "<tr><th>" + esc(b.name) + "</th><td>" +
           esc(l.links[static_cast<std::size_t>(b.link)].name) + "</td><td class=\"n\">" +
           std::to_string(b.ratio) + "</td><td>" + vec_text(b.at) + "</td><td class=\"n\">" +
           fmt(b.mass) + "</td><td>" + vec_text(b.eccentricity) + "</td><td class=\"n\">" +
           fmt(b.inertia) + "</td></tr>";
    }
    h += "</table>";
  }
  h += "<table><tr><th>input</th><th>what moves</th><th>drive effort (free scenes)</th></tr>";
  for (const core::planar::Input& in : l.inputs) {
    const bool angle = in.kind == core::planar::Input::Kind::kAngle;
    const std::string what =
        angle ? "angle of link " + l.links[static_cast<std::size_t>(in.link)].name
              : "position of slider " + l.sliders[static_cast<std::size_t>(in.slider)].name;
    h += "<tr><th>" + esc(in.name) + "</th><td>" + esc(what) + "</td><td>" +
         esc(effort_text(in.effort, angle ? "N m" : "N")) + "</td></tr>";
  }
  h += "</table><p>Gravity " + vec_text(l.loads.gravity) + " m/s&sup2;; total mass " +
       fmt(core::planar::total_mass(l)) + " kg.</p>";
  return h;
}

std::string planar_report_html(const Study& study, const fs::path& dir, const std::string& gnuplot,
                               const Json& summary) {
  const Csv ts = read_csv(dir / "timeseries.csv");
  Second second;
  second.design = second_design(summary, dir);
  if (second.design.present()) {
    second.file = gp_string((fs::absolute(dir) / second.design.file).string());
    second.ts = read_csv(dir / second.design.file);
    second.parts = counterweight_parts(study.planar(), summary);
    try {
      second.linkage = load_study((dir / (second.design.key + ".yaml")).string()).planar();
    } catch (const std::exception& e) {
      throw std::runtime_error("cannot draw the " + second.design.label +
                               " design: " + std::string(e.what()));
    }
  }
  std::string h = page_start(study, summary) + simulation_section(summary);
  h += "<h2>Linkage</h2>\n" + planar_linkage_tables(study.planar());
  h +=
      metrics_section(summary, second.design,
                      "Fsh, Msh: shaking force [N] and moment about the origin [N m] on the frame; "
                      "tau: drive torques [N m] or forces [N]; R&lt;name&gt;: forces on the frame "
                      "at a ground node or guide [N]; F&lt;joint&gt;: joint forces on their links "
                      "[N]. RMS over the samples, max of magnitudes.");
  h += comparison_section(dir, second.design);
  h += harmonics_section(dir);
  std::string datablocks;
  std::vector<Chart> charts = planar_charts(study, dir, ts, second, datablocks);
  for (Chart& chart : pareto_charts(dir)) charts.push_back(std::move(chart));
  h += charts_section(gnuplot, datablocks, charts);
  h += second_design_section(summary, second.design);
  h += pareto_section(dir);
  // the measurements of `balance-design bench` when the folder has them (work_precision.hpp)
  h += work_precision_section(study, dir, gnuplot);
  return h + data_files_html(dir, data_files());
}

}  // namespace bd::studies::report_support
