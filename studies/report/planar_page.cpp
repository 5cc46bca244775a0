// A planar linkage's study page: its tables and the charts of its run, read from the folder's
// timeseries.csv by column name (core/planar/simulate.hpp lists the columns).
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
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

// one line per column over the run's axis `x` (a gnuplot using expression), `expr` the gnuplot
// expression of a column index (magnitude or value)
std::string lines_over(const std::string& file, const std::string& x,
                       const std::vector<std::pair<std::string, std::string>>& items) {
  std::string plot;
  for (std::size_t k = 0; k < items.size(); ++k) {
    plot += (k ? ", " : "") + (k ? std::string("''") : file) + " skip 1 using " + x + ":" +
            items[k].second + " with lines lw 2 title " + gp_string(items[k].first);
  }
  return plot;
}

// |(x, y)| of the columns <name>x, <name>y as a gnuplot expression
std::string magnitude(const Csv& ts, const std::string& name) {
  const int cx = gp_column(ts, name + "x"), cy = gp_column(ts, name + "y");
  return "(sqrt($" + std::to_string(cx) + "**2+$" + std::to_string(cy) + "**2))";
}

// the counterweights of a balanced or optimised design, from summary.json's balance or
// optimize section (mass, place in the link's axes from its pivot node)
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
    const Json* mass = member(c, "mass");
    if (link < 0 || pivot < 0 || !at || !at->is_array() || at->size() != 2) continue;
    if (!(*at)[0].is_number() || !(*at)[1].is_number() || !mass || !mass->is_number()) continue;
    if (!(mass->get<double>() > 0)) continue;  // an optimum's unused counterweight
    CounterweightPart part;
    part.link = link;
    part.pivot = pivot;
    part.counterweight.mass = mass->get<double>();
    part.counterweight.position = Vec2((*at)[0].get<double>(), (*at)[1].get<double>());
    part.counterweight.distance = part.counterweight.position.norm();
    parts.push_back(part);
  }
  return parts;
}

// the linkage animated over the first revolution of its driven input (a driven scene given in
// revolutions) or over the run: links through their nodes (a ternary link as a closed outline),
// ground nodes, frame guides, the counterweights `parts` as discs on arms from their pivots,
// balance shafts with their eccentric masses
AnimationFigure planar_animation(const Linkage& l, const Csv& ts, const Scene& scene,
                                 const std::vector<CounterweightPart>& parts, const std::string& id,
                                 const std::string& what) {
  AnimationFigure fig;
  fig.animation.id = id;
  std::vector<std::vector<double>> rows;
  for (const auto& r : ts.rows) {
    std::vector<double> x = numbers(r);
    if (x.size() == ts.header.size()) rows.push_back(std::move(x));
  }
  if (rows.empty()) return fig;
  auto node_at = [&](const std::vector<double>& row, int i) {
    const core::planar::Node& node = l.nodes[static_cast<std::size_t>(i)];
    if (node.ground) return node.position;
    return Vec2(row[static_cast<std::size_t>(gp_column(ts, "x_" + node.name) - 1)],
                row[static_cast<std::size_t>(gp_column(ts, "y_" + node.name) - 1)]);
  };
  auto link_angle = [&](const std::vector<double>& row, int link) {
    const int column = gp_column(ts, "theta_" + l.links[static_cast<std::size_t>(link)].name);
    return column ? row[static_cast<std::size_t>(column - 1)] : 0.0;
  };
  // the first revolution of a driven input, or the run
  const auto* driven = std::get_if<core::planar::DrivenScene>(&scene);
  // (a run that stopped before the revolution's end is shown as the run it was)
  const bool revolution = driven && driven->duration == 0 && driven->revolutions >= 1 &&
                          driven->speeds.size() == 1 && driven->speeds[0] != 0 &&
                          rows.size() >= static_cast<std::size_t>(driven->samples);
  std::size_t last = rows.size() - 1;
  if (revolution) {
    const double period = 2 * std::numbers::pi / std::abs(driven->speeds[0]);
    while (last > 0 && rows[last][0] - rows[0][0] >= period * (1 - 1e-12)) --last;
  }
  std::vector<std::size_t> picks = frame_indices(0, last, 120);
  if (revolution && last > 0) picks.push_back(0);  // the periodic end: the first pose again
  fig.animation.seconds = revolution ? 4.0 : 8.0;

  using K = AnimatedShape::Kind;
  const char* colours[] = {"#1f4e99", "#d0731c", "#2e8b3d", "#8e3b9e",
                           "#b8860b", "#c03030", "#2a9d9d", "#555555"};
  std::vector<AnimatedShape>& shapes = fig.animation.shapes;
  // frame guides: the stretch each slider's node travels, and a little more
  for (const core::planar::Slider& sl : l.sliders) {
    if (sl.link >= 0) continue;
    const Vec2 u = (sl.to - sl.from).normalized();
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const auto& row : rows) {
      const double along = u.dot(node_at(row, sl.node) - sl.from);
      lo = std::min(lo, along);
      hi = std::max(hi, along);
    }
    const double margin = std::max(0.25 * (hi - lo), 1e-3);
    shapes.push_back({K::kLine,
                      "#909090",
                      2,
                      false,
                      true,
                      "guide of slider " + sl.name,
                      {{sl.from + (lo - margin) * u, sl.from + (hi + margin) * u}}});
  }
  // balance shafts' drives, counterweights' arms, links, weights, shafts
  std::vector<AnimatedShape> links, arms, weights, eccentrics;
  for (std::size_t k = 0; k < l.links.size(); ++k) {
    const core::planar::Link& link = l.links[k];
    links.push_back(
        {K::kLine, colours[k % 8], 6, link.nodes.size() > 2, false, "link " + link.name, {}});
  }
  double heaviest = 0;
  for (const CounterweightPart& p : parts) heaviest = std::max(heaviest, p.counterweight.mass);
  for (const CounterweightPart& p : parts) {
    const std::string colour = colours[static_cast<std::size_t>(p.link) % 8];
    arms.push_back({K::kLine, colour, 2, false, true, "", {}});
    weights.push_back({K::kDot,
                       colour,
                       7 + 9 * std::sqrt(p.counterweight.mass / heaviest),
                       false,
                       false,
                       "counterweight on " + l.links[static_cast<std::size_t>(p.link)].name + ": " +
                           fmt(p.counterweight.mass, "%.4g") + " kg at " +
                           fmt(p.counterweight.distance, "%.4g") + " m from " +
                           l.nodes[static_cast<std::size_t>(p.pivot)].name,
                       {}});
  }
  for (const core::planar::BalanceShaft& b : l.shafts) {
    if (b.mass == 0 || b.eccentricity.norm() == 0) continue;
    eccentrics.push_back({K::kDot, "#606060", 6, false, false, "eccentric mass of " + b.name, {}});
  }
  for (std::size_t i : picks) {
    const std::vector<double>& row = rows[i];
    for (std::size_t k = 0; k < l.links.size(); ++k) {
      std::vector<Vec2> pts;
      for (int n : l.links[k].nodes) pts.push_back(node_at(row, n));
      links[k].frames.push_back(pts);
    }
    for (std::size_t k = 0; k < parts.size(); ++k) {
      const double theta = link_angle(row, parts[k].link);
      const Vec2 u(std::cos(theta), std::sin(theta)), n(-u.y(), u.x());
      const Vec2 pivot = node_at(row, parts[k].pivot);
      const Vec2& at = parts[k].counterweight.position;
      const Vec2 w = pivot + at.x() * u + at.y() * n;
      arms[k].frames.push_back({pivot, w});
      weights[k].frames.push_back({w});
    }
    std::size_t e = 0;
    for (const core::planar::BalanceShaft& b : l.shafts) {
      if (b.mass == 0 || b.eccentricity.norm() == 0) continue;
      const core::planar::Link& link = l.links[static_cast<std::size_t>(b.link)];
      const Vec2 d = l.nodes[static_cast<std::size_t>(link.nodes[1])].position -
                     l.nodes[static_cast<std::size_t>(link.nodes[0])].position;
      const double turn = link_angle(row, b.link) - std::atan2(d.y(), d.x());
      eccentrics[e++].frames.push_back({b.at + core::planar::shaft_centre(b, turn)});
    }
  }
  for (const core::planar::BalanceShaft& b : l.shafts) {
    const Vec2 pivot =
        l.nodes[static_cast<std::size_t>(core::planar::pivot_of(l, b.link))].position;
    shapes.push_back({K::kLine, "#a0a0a0", 1.5, false, true, "", {{pivot, b.at}}});
  }
  for (const AnimatedShape& a : arms) shapes.push_back(a);
  for (const AnimatedShape& k : links) shapes.push_back(k);
  for (const AnimatedShape& w : weights) shapes.push_back(w);
  for (const core::planar::BalanceShaft& b : l.shafts) {
    shapes.push_back({K::kDot, "white", 9, false, false, "balance shaft " + b.name, {{b.at}}});
  }
  for (const AnimatedShape& e : eccentrics) shapes.push_back(e);
  for (const core::planar::Node& node : l.nodes) {
    if (!node.ground) continue;
    shapes.push_back({K::kGround, "", 11, false, false, node.name, {{node.position}}});
    fig.animation.labels.push_back({node.position, node.name});
  }
  fig.heading = "The " + what + " linkage in motion";
  fig.caption =
      std::string(revolution ? "One revolution of the driven input, slowed to 4 s and looping"
                             : "The run, shown in 8 s and looping") +
      " (" + std::to_string(picks.size() - (revolution && last > 0 ? 1 : 0)) +
      " samples of the run; printed, the first pose): each link through its nodes in a colour of "
      "its own (a ternary link as a closed outline; hover for its name), ground nodes as "
      "triangles, guides fixed in the frame dashed" +
      (parts.empty() ? std::string()
                     : ", each counterweight as a disc on its link (area in proportion to its "
                       "mass; hover for its values) on a dashed arm from its pivot") +
      (l.shafts.empty() ? std::string()
                        : ", balance shafts as open circles with their eccentric masses") +
      ". From the node columns of the samples.";
  return fig;
}

// the balanced or optimised design beside the original: its samples, its linkage and
// counterweights
struct Second {
  SecondDesign design;
  std::string file;  // its samples as a gnuplot data block ("" when there is no second design)
  std::optional<Linkage> linkage;
  std::vector<CounterweightPart> parts;
  Csv ts;  // decimated
};

// one line of the original over the run's axis, and the second design's (dashed) when there is
// one
std::string with_second(const std::string& file, const std::string& x, const Second& second,
                        const std::string& name, const std::string& expr) {
  std::string plot = file + " skip 1 using " + x + ":" + expr + " with lines lw 2 title " +
                     gp_string(second.file.empty() ? name : name + ", original");
  if (!second.file.empty()) {
    plot += ", " + second.file + " skip 1 using " + x + ":" + expr +
            " with lines lw 2 dt 2 title " + gp_string(name + ", " + second.design.label);
  }
  return plot;
}

// the column of the driven input's angle, for the crank-angle axis (0: none, e.g. a slide input)
int driven_angle_column(const Linkage& l, const Csv& ts) {
  if (l.inputs.empty() || l.inputs[0].kind != core::planar::Input::Kind::kAngle) return 0;
  return gp_column(ts, "theta_" + l.links[static_cast<std::size_t>(l.inputs[0].link)].name);
}

// a free scene whose drives push with nothing (every effort 0): it has no drive chart
bool drives_act(const Linkage& l, const Scene& scene) {
  if (!is_free(scene)) return true;
  for (const core::planar::Input& in : l.inputs) {
    const core::planar::TimeFunction& f = in.effort;
    if (f.kind != core::planar::TimeFunction::Kind::kConstant || f.value != 0) return true;
  }
  return false;
}

std::vector<Chart> planar_charts(const Study& study, const Csv& ts, const Second& second,
                                 const Scales& scales, const Json& summary,
                                 std::string& datablocks) {
  const Linkage& l = study.planar();
  std::vector<Chart> charts;
  if (ts.rows.empty()) return charts;
  // the samples as data blocks (at most kChartRows rows each: the page stays small)
  const std::string file = "$ts";
  datablocks += datablock("ts", ts);
  if (!second.file.empty()) datablocks += datablock("ts2", second.ts);
  const RunAxis axis = run_axis(study.scene, driven_angle_column(l, ts));
  const std::string x = axis.x;
  const std::string taxis = "\nset xlabel " + gp_string(axis.label) + "\n";
  std::vector<std::pair<std::string, std::string>> angles, supports, drives, joints;
  for (const core::planar::Link& link : l.links) {
    angles.push_back({"θ " + link.name, std::to_string(gp_column(ts, "theta_" + link.name))});
  }
  // a ground node no link holds (a spring's anchor) has no bearing: its R column is 0 (the
  // spring's pull is its own column)
  std::vector<std::string> no_bearing;
  for (const core::planar::Node& n : l.nodes) {
    const int id = static_cast<int>(&n - l.nodes.data());
    const bool held = std::any_of(l.links.begin(), l.links.end(), [&](const core::planar::Link& k) {
      return std::find(k.nodes.begin(), k.nodes.end(), id) != k.nodes.end();
    });
    if (n.ground && !held) no_bearing.push_back("R" + n.name + "x");
  }
  for (const std::string& c : ts.header) {
    if (std::find(no_bearing.begin(), no_bearing.end(), c) != no_bearing.end()) continue;
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
    drive_plot += (drive_plot.empty() ? "" : ", ") + with_second(file, x, second, name, expr);
  }
  // the hodograph, closed by the periodic end when the run is whole revolutions; the second
  // design has the original's columns (the same links, nodes and joints)
  // the inertial part, as the metrics (round-off of the run's forces: 0)
  const bool closed = periodic_run(study.scene, summary);
  const ShakingColumns shaking = shaking_columns(ts);
  datablocks += xy_block("hodo", ts, shaking.x, shaking.y, closed, scales.force);
  std::string hodograph = "$hodo skip 1 using 1:2 with lines lw 2 title " +
                          gp_string(second.file.empty() ? "shaking force" : "original");
  if (!second.file.empty()) {
    const ShakingColumns shaking2 = shaking_columns(second.ts);
    datablocks += xy_block("hodo2", second.ts, shaking2.x, shaking2.y, closed, scales.force);
    hodograph += ", $hodo2 skip 1 using 1:2 with linespoints lw 2 pt 7 ps 0.5 pi 10 title " +
                 gp_string(second.design.label);
  }
  charts.push_back({"angles", "Link angles",
                    "Every link's angle (its first-to-second node direction) over the run.",
                    "set title 'Link angles'" + taxis + "set ylabel 'angle [rad]'\nplot " +
                        lines_over(file, x, angles)});
  charts.push_back({"reactions", "Support reactions",
                    "Magnitudes of the forces of the mechanism on the frame at each ground node "
                    "and frame guide.",
                    "set title 'Support reactions'" + taxis +
                        "set ylabel 'force on the frame [N]'\nplot " +
                        lines_over(file, x, supports)});
  charts.push_back({"hodograph", "Shaking-force hodograph, inertial part",
                    std::string("The tip of the shaking force over the run, equal axes") +
                        (closed ? ", closed by the periodic end (the first sample again)." : ".") +
                        shaking.force_note,
                    "set title 'Shaking-force hodograph (inertial part)'\nset size ratio -1\n"
                    "set xlabel 'Fshx inertial [N]'\nset ylabel 'Fshy inertial [N]'\nplot " +
                        hodograph,
                    true});
  charts.push_back({"shaking-moment", "Shaking moment, inertial part",
                    "Shaking moment on the frame about the origin." + shaking.moment_note,
                    "set title 'Shaking moment about the origin (inertial part)'" + taxis +
                        "set ylabel 'Msh inertial [N m]'\nplot " +
                        with_second(file, x, second, "Msh", std::to_string(shaking.moment))});
  if (!drives.empty() && drives_act(l, study.scene)) {
    charts.push_back({"drive", "Drive efforts",
                      "The drives' torques [N m] or forces [N] on their inputs, from the frame.",
                      "set title 'Drive efforts'" + taxis +
                          "set ylabel 'torque [N m] or force [N]'\nplot " + drive_plot});
  }
  if (!joints.empty()) {
    charts.push_back({"joints", "Joint forces", "Magnitudes of the joint forces on their links.",
                      "set title 'Joint forces'" + taxis + "set ylabel 'joint force [N]'\nplot " +
                          lines_over(file, x, joints)});
  }
  return charts;
}

}  // namespace

std::string planar_linkage_tables(const Linkage& l) {
  std::string h = "<table><tr><th>node</th><th>drawn at [m]</th><th></th></tr>";
  const double size = linkage_size(l);  // a coordinate that is round-off of it: 0
  for (const core::planar::Node& n : l.nodes) {
    h += "<tr><th>" + esc(n.name) + "</th><td>" + vec_text(n.position, size) + "</td><td>" +
         (n.ground ? "ground" : "") + "</td></tr>";
  }
  h += "</table><table><tr><th>link</th><th>nodes</th><th>mass m [kg]</th><th>e [m]</th>"
       "<th>f [m]</th><th>inertia I [kg m&sup2;]</th></tr>";
  for (const core::planar::Link& k : l.links) {
    // e, f: round-off of the link's length (its first two nodes, as drawn) shows as 0
    const double length = (l.nodes[static_cast<std::size_t>(k.nodes[1])].position -
                           l.nodes[static_cast<std::size_t>(k.nodes[0])].position)
                              .norm();
    h += "<tr><th>" + esc(k.name) + "</th><td>" + esc(nodes_of(l, k.nodes)) +
         "</td><td class=\"n\">" + fmt(k.mass) + "</td><td class=\"n\">" + fmt_scaled(k.e, length) +
         "</td><td class=\"n\">" + fmt_scaled(k.f, length) + "</td><td class=\"n\">" +
         fmt(k.inertia) + "</td></tr>";
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
  std::size_t samples = 0;
  const Csv ts = read_csv_decimated(dir / "timeseries.csv", kChartRows, &samples);
  Second second;
  second.design = second_design(summary, dir);
  if (second.design.present()) {
    second.file = "$ts2";
    second.ts = read_csv_decimated(dir / second.design.file, kChartRows, nullptr);
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
  const Scales scales = run_scales(summary, linkage_size(study));
  h += metrics_section(study, summary, second.design,
                       shaking_metrics_note("the origin") +
                           " tau: drive torques (a slide input's: a force in N); R&lt;name&gt;: "
                           "forces on the frame at a ground node or guide; F&lt;joint&gt;: joint "
                           "forces on their links. RMS over the samples, max of magnitudes.",
                       scales);
  h += comparison_section(dir, summary, second.design, scales);
  h += harmonics_section(dir, scales);
  std::vector<AnimationFigure> animations;
  const std::vector<CounterweightPart> own =
      study.parts ? study.parts->counterweights : std::vector<CounterweightPart>{};
  animations.push_back(
      planar_animation(study.planar(), ts, study.scene, own, "animation-original", "original"));
  if (second.linkage && !second.ts.rows.empty()) {
    animations.push_back(planar_animation(*second.linkage, second.ts, study.scene, second.parts,
                                          "animation-" + second.design.key, second.design.label));
  }
  h += animations_section(animations);
  std::string datablocks;
  std::vector<Chart> charts = planar_charts(study, ts, second, scales, summary, datablocks);
  for (Chart& chart : harmonic_charts(dir, datablocks, scales)) charts.push_back(std::move(chart));
  for (Chart& chart : pareto_charts(dir, datablocks)) charts.push_back(std::move(chart));
  h += charts_section(gnuplot, datablocks, charts, samples, ts.rows.size());
  h += second_design_section(summary, second.design, scales);
  h += pareto_section(dir, scales);
  // the measurements of `balance-design bench` when the folder has them (work_precision.hpp)
  h += work_precision_section(study, dir, gnuplot);
  return h + data_files_html(dir, data_files());
}

}  // namespace bd::studies::report_support
