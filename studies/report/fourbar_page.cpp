#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include "core/fourbar/kinematics.hpp"
#include "core/fourbar/model.hpp"
#include "core/fourbar/principal_vectors.hpp"
#include "studies/bench/work_precision.hpp"
#include "studies/report/pages.hpp"
#include "studies/report/report.hpp"
#include "studies/report/report_support.hpp"
#include "studies/report/study_parts.hpp"
#include "studies/run/runner.hpp"
#include "studies/study/load_study.hpp"

namespace bd::studies::report_support {

namespace fs = std::filesystem;

namespace {

// ---------------------------------------------------------------------------------------------
// the linkage drawn at a few samples

struct PoseSample {
  std::size_t index{};
  double t{};
  core::Pose pose;
  core::Joints joints;
  core::PrincipalPoints principal;
  Vec2 S{0, 0};
  Vec2 G[3];  // centres of mass of crank, coupler, rocker
};

core::FourBarState state_of(const std::vector<double>& x) {
  core::FourBarState s;
  s.theta1 = x[1];
  s.theta2 = x[2];
  s.theta3 = x[3];
  s.omega1 = x[4];
  s.omega2 = x[5];
  s.omega3 = x[6];
  s.alpha1 = x[7];
  s.alpha2 = x[8];
  s.alpha3 = x[9];
  return s;
}

PoseSample pose_sample(const core::FourBar& model, const std::vector<double>& x, std::size_t i) {
  PoseSample p;
  p.index = i;
  p.t = x[0];
  const core::FourBarState s = state_of(x);
  p.pose = core::pose_of(s);
  p.joints = core::joint_positions(model, p.pose);
  p.principal = core::opened_loop_principal_points(model, p.pose);
  p.S = core::centre_of_mass_frame(model, s).r;
  for (int k = 1; k <= 3; ++k) p.G[k - 1] = core::centre_of_mass(model, k, p.pose);
  return p;
}

// a design drawn at four samples spread evenly over its run, and the path S traces over all
struct Drawing {
  std::vector<PoseSample> poses;
  std::vector<Vec2> s_path;
};

Drawing drawing(const core::FourBar& model, const Csv& timeseries) {
  std::vector<std::vector<double>> rows;
  for (const auto& r : timeseries.rows) rows.push_back(numbers(r));
  Drawing d;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (rows[i].size() < 18) continue;
    d.s_path.push_back(pose_sample(model, rows[i], i).S);
  }
  const std::size_t n = rows.size();
  for (std::size_t k = 0; k < 4 && k < n; ++k) {
    const std::size_t i = k * n / std::min<std::size_t>(4, n);
    if (rows[i].size() >= 18) d.poses.push_back(pose_sample(model, rows[i], i));
  }
  return d;
}

// The linkage chart of one design: joints and link lines per sample, the links' centres of mass
// G1, G2, G3 (marker area in proportion to the link's mass, `mass_ref` [kg] drawn at a fixed
// size so two designs compare) on thin lines from the joint they are measured from (A0, A1, A2),
// the opened-loop principal points P1, P2, P3, the system centre of mass S and its path, and any
// counter-rotation shafts. Each sample's markers are drawn in that sample's colour and each kind
// has its own legend entry per sample, so the legend shows every marker as drawn (a filled
// circle of the legend's own size for G). Data blocks are named $<tag>...
Chart linkage_chart(const core::FourBar& model, const Drawing& d, const std::string& tag,
                    double mass_ref, std::string& datablocks) {
  const std::vector<PoseSample>& poses = d.poses;
  const std::string b = "$" + tag;
  datablocks += b + "links << EOD\n";
  for (const PoseSample& p : poses) {
    const core::Joints& j = p.joints;
    for (const Vec2* q : {&j.A0, &j.A1, &j.A2, &j.A3}) datablocks += xy(*q) + "\n";
    datablocks += "\n\n";  // a new data set per pose (index k)
  }
  datablocks += "EOD\n" + b + "principal << EOD\n";
  for (const PoseSample& p : poses) {
    for (const Vec2* q : {&p.principal.P1, &p.principal.P2, &p.principal.P3})
      datablocks += xy(*q) + "\n";
    datablocks += "\n\n";
  }
  datablocks += "EOD\n" + b + "S << EOD\n";
  for (const PoseSample& p : poses) datablocks += xy(p.S) + "\n\n\n";
  datablocks += "EOD\n" + b + "G << EOD\n";
  const double m[3] = {model.crank.mass, model.coupler.mass, model.rocker.mass};
  for (const PoseSample& p : poses) {
    for (int k = 0; k < 3; ++k) {
      datablocks +=
          xy(p.G[k]) + "," + fmt(std::max(0.4, 2.6 * std::sqrt(m[k] / mass_ref)), "%.4g") + "\n";
    }
    datablocks += "\n\n";
  }
  // s̄k: from the joint each centre of mass is measured from to the centre of mass
  datablocks += "EOD\n" + b + "arms << EOD\n";
  for (const PoseSample& p : poses) {
    const Vec2* from[3] = {&p.joints.A0, &p.joints.A1, &p.joints.A2};
    for (int k = 0; k < 3; ++k) datablocks += xy(*from[k]) + "\n" + xy(p.G[k]) + "\n\n";
    datablocks += "\n";
  }
  datablocks += "EOD\n" + b + "Spath << EOD\n";
  for (const Vec2& v : d.s_path) datablocks += xy(v) + "\n";
  datablocks +=
      "EOD\n" + b + "frame << EOD\n0,0\n" + fmt(model.frame_length, "%.10g") + ",0\nEOD\n";
  const bool shafts = core::has_counter_rotations(model);
  if (shafts) {
    datablocks += b + "shafts << EOD\n";
    for (const core::CounterRotation* c :
         {&model.counter_rotations.crank, &model.counter_rotations.rocker})
      if (c->inertia > 0) datablocks += xy(c->at) + "\n";
    datablocks += "EOD\n";
  }

  std::string cmd =
      "set size ratio -1\nset xlabel 'x [m]'\nset ylabel 'y [m]'\n"
      "set offsets graph 0.05, graph 0.05, graph 0.05, graph 0.05\n"
      "set key outside right top vertical Left reverse\n";
  const core::Joints& j0 = poses.front().joints;
  const char* jn[] = {"A0", "A1", "A2", "A3"};
  const Vec2* jp[] = {&j0.A0, &j0.A1, &j0.A2, &j0.A3};
  for (int i = 0; i < 4; ++i) {
    cmd += "set label " + gp_string(jn[i]) + " at " + xy(*jp[i]) + " offset 0.6,0.6\n";
  }
  const core::PrincipalPoints& p0 = poses.front().principal;
  const char* pn[] = {"P1", "P2", "P3"};
  const Vec2* pp[] = {&p0.P1, &p0.P2, &p0.P3};
  for (int i = 0; i < 3; ++i) {
    cmd += "set label " + gp_string(pn[i]) + " at " + xy(*pp[i]) + " offset 0.6,-0.8 tc lt 1\n";
  }
  // the legend: per sample its links, P, S, G; then the one-off entries
  std::string entries, arms;
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const std::string index = " index " + std::to_string(k);
    const std::string lt = " lt " + std::to_string(k + 1);
    entries += b + "links" + index + " using 1:2 with linespoints lw 2 pt 7 ps 0.6" + lt +
               " title " +
               gp_string("θ1 = " + fmt(poses[k].pose.theta1, "%.3g") +
                         " rad, t = " + fmt(poses[k].t, "%.3g") + " s") +
               ", ";
    arms += b + "arms" + index + " using 1:2 with lines lw 1 dt 3" + lt + " notitle, ";
    entries += b + "principal" + index + " using 1:2 with points pt 6 ps 1.4" + lt +
               " title '  P1 P2 P3', ";
    entries += b + "S" + index + " using 1:2 with points pt 5 ps 1.2" + lt + " title '  S', ";
    entries += b + "G" + index + " using 1:2:3 with points pt 7 ps variable" + lt +
               " title '  G1 G2 G3', ";
  }
  cmd += "plot " + arms + entries + b +
         "frame using 1:2 with lines lw 3 lc 'gray40' title 'frame A0-A3', " + b +
         "Spath using 1:2 with lines lw 1.5 lc 'black' dt 3 title 'path of S'";
  if (shafts) {
    cmd += ", " + b +
           "shafts using 1:2 with points pt 4 ps 2.2 lw 2 lc 'black' "
           "title 'counter-rotation shafts'";
  }
  Chart c;
  c.commands = cmd;
  c.square = true;
  return c;
}

// the drawn samples of a design as a table
std::string poses_table(const Drawing& d) {
  std::string h =
      "<table><tr><th>sample</th><th>t [s]</th><th>&theta;1 [rad]</th><th>A1</th>"
      "<th>A2</th><th>G1</th><th>G2</th><th>G3</th><th>P1</th><th>P2</th>"
      "<th>P3</th><th>S</th></tr>";
  for (const PoseSample& p : d.poses) {
    h += "<tr><td class=\"n\">" + std::to_string(p.index + 1) + "</td><td class=\"n\">" + fmt(p.t) +
         "</td><td class=\"n\">" + fmt(p.pose.theta1) + "</td><td>" + vec_text(p.joints.A1) +
         "</td><td>" + vec_text(p.joints.A2) + "</td>";
    for (const Vec2& g : p.G) h += "<td>" + vec_text(g) + "</td>";
    h += "<td>" + vec_text(p.principal.P1) + "</td><td>" + vec_text(p.principal.P2) + "</td><td>" +
         vec_text(p.principal.P3) + "</td><td>" + vec_text(p.S) + "</td></tr>";
  }
  return h + "</table>\n";
}

// ---------------------------------------------------------------------------------------------

const char* branch_text(core::Branch b) { return b == core::Branch::kPlus ? "+1" : "-1"; }

}  // namespace

std::string fourbar_linkage_tables(const core::FourBar& m) {
  std::string h =
      "<table><tr><th>link</th><th>length l [m]</th><th>mass m [kg]</th>"
      "<th>s [m]</th><th>&sigma; [rad]</th><th>e [m]</th><th>f [m]</th>"
      "<th>inertia I [kg m&sup2;]</th></tr>";
  for (int k = 1; k <= 3; ++k) {
    const core::Link& l = core::link(m, k);
    h += "<tr><th>" + std::to_string(k) + " " + core::link_name(k) + "</th><td class=\"n\">" +
         fmt(l.length) + "</td><td class=\"n\">" + fmt(l.mass) + "</td><td class=\"n\">" +
         fmt(l.s()) + "</td><td class=\"n\">" + fmt(l.sigma()) + "</td><td class=\"n\">" +
         fmt(l.e) + "</td><td class=\"n\">" + fmt(l.f) + "</td><td class=\"n\">" + fmt(l.inertia) +
         "</td></tr>";
  }
  h += "<tr><th>4 frame</th><td class=\"n\">" + fmt(m.frame_length) +
       "</td><td colspan=\"6\">A0 at the origin, A3 at (l4, 0)</td></tr></table>";
  h += "<p>Branch " + std::string(branch_text(m.branch)) + "; Grashof class " +
       core::to_string(core::classify_grashof(m)) + " (the crank " +
       (core::crank_turns_fully(m) ? "turns fully" : "cannot turn fully") +
       "); total moving mass " + fmt(core::total_mass(m)) + " kg.</p>";
  const core::CounterRotation* discs[] = {&m.counter_rotations.crank, &m.counter_rotations.rocker};
  if (core::has_counter_rotations(m)) {
    h += "<table><tr><th>counter-rotation</th><th>J [kg m&sup2;]</th><th>shaft at [m]</th></tr>";
    const char* names[] = {"crank", "rocker"};
    for (int i = 0; i < 2; ++i) {
      if (discs[i]->inertia <= 0) continue;
      h += std::string("<tr><th>") + names[i] + "</th><td class=\"n\">" + fmt(discs[i]->inertia) +
           "</td><td>" + vec_text(discs[i]->at) + "</td></tr>";
    }
    h += "</table>";
  }
  h += "<h3>Loads</h3><table><tr><th></th><th>force at the centre of mass [N]</th>"
       "<th>moment [N m]</th></tr>";
  h += "<tr><th>gravity g [m/s&sup2;]</th><td>" + vec_text(m.loads.gravity) + "</td><td></td></tr>";
  for (int k = 1; k <= 3; ++k) {
    const core::LinkLoad& l = core::link_load(m, k);
    h += std::string("<tr><th>") + core::link_name(k) + "</th><td>" + vec_text(l.force) +
         "</td><td class=\"n\">" + fmt(l.moment) + "</td></tr>";
  }
  return h + "</table>";
}

namespace {

// the four-bar's charts: its angles, reactions, shaking force and moment, drive torque and
// bearing loads over the run, the linkage drawn at a few samples, and the Pareto front; the
// second design's dashed over the original's. Returns the drawings of both designs too.
struct FourBarCharts {
  std::vector<Chart> charts;
  std::string datablocks;
  Drawing original, second;
};

FourBarCharts fourbar_charts(const Study& study, const fs::path& dir, const SecondDesign& sd,
                             const Csv& ts) {
  FourBarCharts out;
  const std::string second = sd.key, second_label = sd.label, second_file = sd.file;
  std::vector<Chart>& charts = out.charts;
  std::string& datablocks = out.datablocks;
  // the linkage at four samples evenly spread over the run, and the path of S; the second
  // design's alike, from its own model (counterweights merged into its links) and samples
  out.original = drawing(study.fourbar(), ts);
  const Drawing& original = out.original;
  const std::vector<PoseSample>& poses = original.poses;
  std::optional<core::FourBar> second_model;
  if (second == "balanced" && study.balance) {
    second_model = study.balance->model;
  } else if (second == "optimized" && fs::exists(dir / "optimized.yaml")) {
    try {
      second_model = load_study((dir / "optimized.yaml").string()).fourbar();
    } catch (const std::exception& e) {
      throw std::runtime_error("cannot draw the optimised design: " + std::string(e.what()));
    }
  }
  if (second_model) out.second = drawing(*second_model, read_csv(dir / second_file));
  const Drawing& second_drawing = out.second;

  // charts
  const fs::path abs_dir = fs::absolute(dir);
  const std::string ts_file = gp_string((abs_dir / "timeseries.csv").string());
  const std::string ts2_file = second.empty() ? "" : gp_string((abs_dir / second_file).string());
  const std::string drive_x = time_axis(study.scene);
  if (!ts.rows.empty()) {
    charts.push_back(
        {"angles", "Link angles",
         "theta1, theta2, theta3 over the run (cf. paper Fig. 7), from timeseries.csv.",
         "set title 'Link angles'\nset xlabel " + gp_string(drive_x) +
             "\nset ylabel 'angle [rad]'\n"
             "plot " +
             ts_file +
             " skip 1 using 1:2 with lines lw 2 title 'θ1 crank', "
             "'' skip 1 using 1:3 with lines lw 2 title 'θ2 coupler', "
             "'' skip 1 using 1:4 with lines lw 2 title 'θ3 rocker'"});
    charts.push_back({"reactions", "Support reactions",
                      "Forces of the mechanism on the ground at A0 and A3 (cf. paper Fig. 8), "
                      "original design.",
                      "set title 'Support reactions (original design)'\nset xlabel " +
                          gp_string(drive_x) +
                          "\nset ylabel 'force on the ground [N]'\n"
                          "plot " +
                          ts_file +
                          " skip 1 using 1:11 with lines lw 2 title 'RA0x', "
                          "'' skip 1 using 1:12 with lines lw 2 title 'RA0y', "
                          "'' skip 1 using 1:13 with lines lw 2 title 'RA3x', "
                          "'' skip 1 using 1:14 with lines lw 2 title 'RA3y'"});
    std::string hodo =
        "set title 'Shaking-force hodograph'\nset size ratio -1\n"
        "set xlabel 'Fshx [N]'\nset ylabel 'Fshy [N]'\n"
        "plot " +
        ts_file + " skip 1 using 15:16 with lines lw 2 title 'original'";
    std::string msh = "set title 'Shaking moment about A0'\nset xlabel " + gp_string(drive_x) +
                      "\nset ylabel 'Msh [N m]'\nplot " + ts_file +
                      " skip 1 using 1:17 with lines lw 2 title 'original'";
    // a free scene has no drive: its chart is the bearing loads alone (a torque of 0 on a right
    // axis of its own would read as a constant load)
    const bool driven = !is_free(study.scene);
    std::string drive = std::string("set title '") +
                        (driven ? "Drive torque and bearing loads" : "Bearing loads") +
                        "'\nset xlabel " + gp_string(drive_x) +
                        "\nset ylabel 'bearing load [N]'\n" +
                        (driven ? "set y2label 'drive torque τ [N m]'\nset ytics nomirror\n"
                                  "set y2tics\n"
                                : "") +
                        "plot " + ts_file +
                        " skip 1 using 1:(sqrt($11**2+$12**2)) with lines lw 2 "
                        "lt 1 title '|RA0|', '' skip 1 using 1:(sqrt($13**2+$14**2)) with lines "
                        "lw 2 lt 2 title '|RA3|'" +
                        (driven ? ", '' skip 1 using 1:18 axes x1y2 with lines lw 2 lt 3 title 'τ'"
                                : "");
    if (!second.empty()) {
      hodo += ", " + ts2_file + " skip 1 using 15:16 with linespoints lw 2 dt 2 pt 6 pi 25 title " +
              gp_string(second_label);
      msh += ", " + ts2_file + " skip 1 using 1:17 with lines lw 2 dt 2 title " +
             gp_string(second_label);
      drive += ", " + ts2_file +
               " skip 1 using 1:(sqrt($11**2+$12**2)) with lines lw 2 lt 1 dt 2 "
               "title '|RA0| " +
               second_label +
               "', '' skip 1 using 1:(sqrt($13**2+$14**2)) with "
               "lines lw 2 lt 2 dt 2 title '|RA3| " +
               second_label +
               "'" +
               (driven ? ", '' skip 1 using 1:18 axes x1y2 with lines lw 2 lt 3 dt 2 title 'τ " +
                             second_label + "'"
                       : std::string());
    }
    const std::string overlay =
        second.empty() ? "" : " The " + second_label + " design is dashed (" + second_file + ").";
    charts.push_back(
        {"hodograph", "Shaking-force hodograph",
         "The tip of the shaking force F̄sh = R̄A0 + R̄A3 over the run, equal axes." + overlay, hodo,
         true});
    charts.push_back({"shaking-moment", "Shaking moment",
                      "Shaking moment on the frame about A0 over the run." + overlay, msh});
    charts.push_back(
        {"drive", driven ? "Drive torque and bearing loads" : "Bearing loads",
         driven ? "Magnitudes of the bearing forces at A0 and A3 (left axis) and the drive "
                  "torque (right axis)." + overlay
                : "Magnitudes of the bearing forces at A0 and A3 (free motion: no drive)." +
                      overlay,
         drive});
  }
  // one scale of marker size for the links' masses of both designs
  double mass_ref = std::max(
      {study.fourbar().crank.mass, study.fourbar().coupler.mass, study.fourbar().rocker.mass});
  if (second_model) {
    mass_ref = std::max({mass_ref, second_model->crank.mass, second_model->coupler.mass,
                         second_model->rocker.mass});
  }
  const std::string masses_caption =
      ", the links' centres of mass G1, G2, G3 (filled circles, area in proportion to the "
      "link's mass, on dotted lines from the joint each is measured from: A0, A1, A2), the "
      "opened-loop principal points P1, P2, P3 (open circles) and the system centre of mass S "
      "(filled squares), with the path S traces over all ";
  if (!poses.empty()) {
    Chart c = linkage_chart(study.fourbar(), original, "o", mass_ref, datablocks);
    c.id = "linkage";
    c.heading = "The linkage";
    c.commands = "set title 'The linkage at " + std::to_string(poses.size()) +
                 " samples: joints, centres of mass, principal points and S'\n" + c.commands;
    c.caption = "Joints and link lines at " + std::to_string(poses.size()) +
                " samples spread evenly over the run (one colour per sample)" + masses_caption +
                std::to_string(original.s_path.size()) +
                " samples; computed from the model and timeseries.csv (original design).";
    charts.push_back(c);
  }
  if (!second_drawing.poses.empty()) {
    const std::string what = second == "balanced" ? "balanced" : "optimised";
    Chart c = linkage_chart(*second_model, second_drawing, "s", mass_ref, datablocks);
    c.id = "linkage-" + second;
    c.heading = "The " + what + " linkage";
    c.commands =
        "set title " +
        gp_string("The " + what + " design at " + std::to_string(second_drawing.poses.size()) +
                  (second == "balanced" ? " samples: its counterweights merged into its links"
                                        : " samples: counterweights and link changes merged")) +
        "\n" + c.commands;
    c.caption = "The " + what + " design drawn as the original above, from " + second_file +
                ": joints and link lines at " + std::to_string(second_drawing.poses.size()) +
                " samples" + masses_caption + std::to_string(second_drawing.s_path.size()) +
                " samples. A counterweight shows as its link's centre of mass moved towards or "
                "past the pivot and grown with the added mass; where the shaking force is "
                "balanced, S stays in one place.";
    charts.push_back(c);
  }
  return out;
}

}  // namespace

std::string fourbar_report_html(const Study& study, const fs::path& dir, const std::string& gnuplot,
                                const Json& summary) {
  const Csv ts = read_csv(dir / "timeseries.csv");
  const SecondDesign second = second_design(summary, dir);
  std::string h = page_start(study, summary) + simulation_section(summary);
  h += "<h2>Linkage</h2>\n" + fourbar_linkage_tables(study.fourbar());
  h +=
      metrics_section(summary, second,
                      "Fsh, Msh: shaking force [N] and moment about A0 [N m] on the frame; tau: "
                      "drive torque [N m]; RA0, RA3: forces on the ground at the bearings [N]. RMS "
                      "over the samples, max of magnitudes.");
  h += comparison_section(dir, second);
  h += harmonics_section(dir);
  FourBarCharts c = fourbar_charts(study, dir, second, ts);
  for (Chart& chart : pareto_charts(dir)) c.charts.push_back(std::move(chart));
  h += charts_section(gnuplot, c.datablocks, c.charts);
  if (!c.original.poses.empty()) {
    h += "<h3>The linkage at the drawn samples</h3>" + poses_table(c.original);
  }
  if (!c.second.poses.empty()) {
    h += "<h3>The " + std::string(second.key == "balanced" ? "balanced" : "optimised") +
         " linkage at the drawn samples</h3>" + poses_table(c.second);
  }
  h += second_design_section(summary, second);
  h += pareto_section(dir);
  // the measurements of `balance-design bench` when the folder has them (work_precision.hpp)
  h += work_precision_section(study, dir, gnuplot);
  return h + data_files_html(dir, data_files());
}

}  // namespace bd::studies::report_support
