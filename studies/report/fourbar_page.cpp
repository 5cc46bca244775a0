#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <numbers>
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

// the drawn samples of a design as a table
std::string poses_table(const Drawing& d, double size) {
  std::string h =
      "<table><tr><th>t [s]</th><th>&theta;1 [rad]</th><th>A1 [m]</th>"
      "<th>A2 [m]</th><th>G1 [m]</th><th>G2 [m]</th><th>G3 [m]</th><th>P1 [m]</th><th>P2 [m]</th>"
      "<th>P3 [m]</th><th>S [m]</th></tr>";
  for (const PoseSample& p : d.poses) {
    h += "<tr><td class=\"n\">" + fmt(p.t) + "</td><td class=\"n\">" + fmt(p.pose.theta1) +
         "</td><td>" + vec_text(p.joints.A1, size) + "</td><td>" + vec_text(p.joints.A2, size) +
         "</td>";
    for (const Vec2& g : p.G) h += "<td>" + vec_text(g, size) + "</td>";
    h += "<td>" + vec_text(p.principal.P1, size) + "</td><td>" + vec_text(p.principal.P2, size) +
         "</td><td>" + vec_text(p.principal.P3, size) + "</td><td>" + vec_text(p.S, size) +
         "</td></tr>";
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
    // e, f, s: round-off of the link's length shows as 0; sigma of a full turn
    h += "<tr><th>" + std::to_string(k) + " " + core::link_name(k) + "</th><td class=\"n\">" +
         fmt(l.length) + "</td><td class=\"n\">" + fmt(l.mass) + "</td><td class=\"n\">" +
         fmt_scaled(l.s(), l.length) + "</td><td class=\"n\">" + fmt_scaled(l.sigma(), 1) +
         "</td><td class=\"n\">" + fmt_scaled(l.e, l.length) + "</td><td class=\"n\">" +
         fmt_scaled(l.f, l.length) + "</td><td class=\"n\">" + fmt(l.inertia) + "</td></tr>";
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
// bearing loads over the run (over the crank angle in a driven scene), and the linkage animated;
// the second design's dashed over the original's. Returns the drawings of both designs too.
struct FourBarCharts {
  std::vector<Chart> charts;
  std::string datablocks;
  std::vector<AnimationFigure> animations;
  Drawing original, second;
};

// the counterweights a design's model carries as parts: a balance study's synthesis (`balanced`:
// the balanced design's), or the parts its study file gives
std::vector<CounterweightPart> fourbar_parts(const Study& design, bool balanced) {
  if (balanced && design.balance) {
    std::vector<CounterweightPart> parts;
    if (design.balance->crank_counterweight)
      parts.push_back({1, -1, *design.balance->crank_counterweight});
    if (design.balance->rocker_counterweight)
      parts.push_back({3, -1, *design.balance->rocker_counterweight});
    return parts;
  }
  return design.parts ? design.parts->counterweights : std::vector<CounterweightPart>{};
}

// the linkage animated over the first revolution (driven) or the run (free), from the samples
// `ts` (decimated), with its counterweights as parts on their links and the centre of mass S
AnimationFigure fourbar_animation(const core::FourBar& model,
                                  const std::vector<CounterweightPart>& parts, const Csv& ts,
                                  const Scene& scene, const std::string& id,
                                  const std::string& what) {
  std::vector<std::vector<double>> rows;
  for (const auto& r : ts.rows) {
    std::vector<double> x = numbers(r);
    if (x.size() >= 18) rows.push_back(std::move(x));
  }
  AnimationFigure fig;
  fig.animation.id = id;
  if (rows.empty()) return fig;
  // a driven run's first revolution; a run that stopped before its end is shown as the run it was
  const core::DrivenScene* driven = std::get_if<core::DrivenScene>(&scene);
  if (driven && rows.size() < static_cast<std::size_t>(driven->samples)) driven = nullptr;
  std::size_t last = rows.size() - 1;
  if (driven && driven->omega1 != 0) {  // the first revolution
    const double period = 2 * std::numbers::pi / std::abs(driven->omega1);
    while (last > 0 && rows[last][0] - rows[0][0] >= period * (1 - 1e-12)) --last;
  }
  std::vector<std::size_t> picks = frame_indices(0, last, 120);
  const bool loop = driven && std::abs(rows[last][0] - rows[0][0]) > 0;
  if (loop) picks.push_back(0);  // the periodic end: the first pose again
  fig.animation.seconds = driven ? 4.0 : 8.0;

  using K = AnimatedShape::Kind;
  AnimatedShape frame{K::kLine, "#909090", 3, false, true, "frame A0-A3",
                      {{Vec2(0, 0), Vec2(model.frame_length, 0)}}};
  AnimatedShape links[3] = {{K::kLine, "#1f4e99", 6, false, false, "crank A0-A1", {}},
                            {K::kLine, "#d0731c", 6, false, false, "coupler A1-A2", {}},
                            {K::kLine, "#2e8b3d", 6, false, false, "rocker A2-A3", {}}};
  AnimatedShape joints{K::kDot, "white", 4.5, false, false, "joints A1, A2", {}};
  AnimatedShape joint2 = joints;
  AnimatedShape S{K::kDot, "#000000", 5, false, false,
                  "S, the centre of mass of the moving links", {}};
  AnimatedShape s_path{K::kLine, "#606060", 1.2, false, true, "path of S", {{}}};
  std::vector<AnimatedShape> arms, weights;
  double heaviest = 0;
  for (const CounterweightPart& p : parts) heaviest = std::max(heaviest, p.counterweight.mass);
  for (const CounterweightPart& p : parts) {
    const char* link = p.link == 1 ? "crank" : "rocker";
    const std::string colour = p.link == 1 ? "#1f4e99" : "#2e8b3d";
    arms.push_back({K::kLine, colour, 2, false, true, "", {}});
    weights.push_back({K::kDot, colour, 7 + 9 * std::sqrt(p.counterweight.mass / heaviest),
                       false, false,
                       std::string("counterweight on the ") + link + ": " +
                           fmt(p.counterweight.mass, "%.4g") + " kg at " +
                           fmt(p.counterweight.distance, "%.4g") + " m from " +
                           (p.link == 1 ? "A0" : "A3"),
                       {}});
  }
  for (const auto& row : rows) s_path.frames[0].push_back(pose_sample(model, row, 0).S);
  for (std::size_t i : picks) {
    const PoseSample p = pose_sample(model, rows[i], i);
    const core::Joints& j = p.joints;
    links[0].frames.push_back({j.A0, j.A1});
    links[1].frames.push_back({j.A1, j.A2});
    links[2].frames.push_back({j.A2, j.A3});
    joints.frames.push_back({j.A1});
    joint2.frames.push_back({j.A2});
    S.frames.push_back({p.S});
    for (std::size_t k = 0; k < parts.size(); ++k) {
      const bool crank = parts[k].link == 1;
      const double angle = crank ? p.pose.theta1 : p.pose.theta3;
      const Vec2 pivot = crank ? j.A0 : j.A3;
      const Vec2 u(std::cos(angle), std::sin(angle)), n(-u.y(), u.x());
      const Vec2& at = parts[k].counterweight.position;
      const Vec2 w = pivot + at.x() * u + at.y() * n;
      arms[k].frames.push_back({pivot, w});
      weights[k].frames.push_back({w});
    }
  }
  std::vector<AnimatedShape>& shapes = fig.animation.shapes;
  shapes.push_back(frame);
  shapes.push_back(s_path);
  for (const AnimatedShape& a : arms) shapes.push_back(a);
  for (const AnimatedShape& l : links) shapes.push_back(l);
  for (const AnimatedShape& w : weights) shapes.push_back(w);
  shapes.push_back(joints);
  shapes.push_back(joint2);
  for (const core::CounterRotation* c :
       {&model.counter_rotations.crank, &model.counter_rotations.rocker}) {
    if (c->inertia > 0) {
      shapes.push_back({K::kDot, "#b0b0b0", 9, false, false,
                        "counter-rotating disc, J = " + fmt(c->inertia, "%.4g") + " kg m²",
                        {{c->at}}});
    }
  }
  shapes.push_back({K::kGround, "", 11, false, false, "A0", {{Vec2(0, 0)}}});
  shapes.push_back({K::kGround, "", 11, false, false, "A3", {{Vec2(model.frame_length, 0)}}});
  shapes.push_back(S);
  fig.animation.labels = {{Vec2(0, 0), "A0"}, {Vec2(model.frame_length, 0), "A3"}};
  fig.heading = "The " + what + " linkage in motion";
  fig.caption =
      std::string(driven ? "One revolution of the crank, slowed to 4 s and looping"
                         : "The run, shown in 8 s and looping") +
      " (" + std::to_string(picks.size() - (loop ? 1 : 0)) +
      " samples of the run; printed, the first pose): crank blue, coupler orange, rocker green" +
      (parts.empty() ? std::string()
                     : ", each counterweight as a disc on its link (area in proportion to its "
                       "mass; hover for its values) on a dashed arm from the pivot") +
      "; S, the centre of mass of the moving links, black, with its path dashed (where the "
      "shaking force is balanced, S stays in one place).";
  return fig;
}

FourBarCharts fourbar_charts(const Study& study, const fs::path& dir, const SecondDesign& sd,
                             const Csv& ts, const Json& summary, const Scales& scales) {
  FourBarCharts out;
  const std::string second = sd.key, second_label = sd.label, second_file = sd.file;
  std::vector<Chart>& charts = out.charts;
  std::string& datablocks = out.datablocks;
  out.original = drawing(study.fourbar(), ts);
  // the second design's model (counterweights merged into its links) and its parts
  std::optional<Study> second_study;
  if (second == "balanced" && study.balance) {
    second_study = balanced_study(study);
    second_study->balance = study.balance;  // its counterweights, for the drawing
  } else if (second == "optimized" && fs::exists(dir / "optimized.yaml")) {
    try {
      second_study = load_study((dir / "optimized.yaml").string());
    } catch (const std::exception& e) {
      throw std::runtime_error("cannot draw the optimised design: " + std::string(e.what()));
    }
  }
  Csv ts2;
  if (second_study) {
    ts2 = read_csv_decimated(dir / second_file, kChartRows, nullptr);
    out.second = drawing(second_study->fourbar(), ts2);
  }

  if (!ts.rows.empty()) {
    // the samples as data blocks (at most kChartRows rows each: the page stays small)
    datablocks += datablock("ts", ts);
    if (second_study) datablocks += datablock("ts2", ts2);
    // the shaking force and moment: the inertial part, as the metrics (round-off of the run's
    // forces: 0)
    const bool closed = periodic_run(study.scene, summary);
    const ShakingColumns shaking = shaking_columns(ts);
    datablocks += xy_block("hodo", ts, shaking.x, shaking.y, closed, scales.force);
    if (second_study) {
      const ShakingColumns shaking2 = shaking_columns(ts2);
      datablocks += xy_block("hodo2", ts2, shaking2.x, shaking2.y, closed, scales.force);
    }
    const std::string msh_column = std::to_string(shaking.moment);
    const RunAxis axis = run_axis(study.scene, 2);
    const std::string u = " skip 1 using " + axis.x + ":";
    const std::string xl = "\nset xlabel " + gp_string(axis.label) + "\n";
    charts.push_back({"angles", "Link angles",
                      "theta1, theta2, theta3 over the run (cf. paper Fig. 7), from timeseries.csv.",
                      "set title 'Link angles'" + xl + "set ylabel 'angle [rad]'\nplot $ts" + u +
                          "2 with lines lw 2 title 'θ1 crank', ''" + u +
                          "3 with lines lw 2 title 'θ2 coupler', ''" + u +
                          "4 with lines lw 2 title 'θ3 rocker'"});
    charts.push_back({"reactions", "Support reactions",
                      "Forces of the mechanism on the ground at A0 and A3 (cf. paper Fig. 8), "
                      "original design.",
                      "set title 'Support reactions (original design)'" + xl +
                          "set ylabel 'force on the ground [N]'\nplot $ts" + u +
                          "11 with lines lw 2 title 'RA0x', ''" + u +
                          "12 with lines lw 2 title 'RA0y', ''" + u +
                          "13 with lines lw 2 title 'RA3x', ''" + u +
                          "14 with lines lw 2 title 'RA3y'"});
    std::string hodo =
        "set title 'Shaking-force hodograph (inertial part)'\nset size ratio -1\n"
        "set xlabel 'Fshx inertial [N]'\nset ylabel 'Fshy inertial [N]'\n"
        "plot $hodo skip 1 using 1:2 with lines lw 2 title 'original'";
    std::string msh = "set title 'Shaking moment about A0 (inertial part)'" + xl +
                      "set ylabel 'Msh inertial [N m]'\nplot $ts" + u + msh_column +
                      " with lines lw 2 title 'original'";
    // a free scene has no drive: its chart is the bearing loads alone (a torque of 0 on a right
    // axis of its own would read as a constant load)
    const bool driven = !is_free(study.scene);
    std::string drive = std::string("set title '") +
                        (driven ? "Drive torque and bearing loads" : "Bearing loads") + "'" + xl +
                        "set ylabel 'bearing load [N]'\n" +
                        (driven ? "set y2label 'drive torque τ [N m]'\nset ytics nomirror\n"
                                  "set y2tics\n"
                                : "") +
                        "plot $ts" + u + "(sqrt($11**2+$12**2)) with lines lw 2 lt 1 title "
                        "'|RA0|', ''" + u + "(sqrt($13**2+$14**2)) with lines lw 2 lt 2 title "
                        "'|RA3|'" +
                        (driven ? ", ''" + u + "18 axes x1y2 with lines lw 2 lt 3 title 'τ'" : "");
    if (second_study) {
      hodo += ", $hodo2 skip 1 using 1:2 with linespoints lw 2 dt 2 pt 6 pi 25 title " +
              gp_string(second_label);
      msh += ", $ts2" + u + msh_column + " with lines lw 2 dt 2 title " + gp_string(second_label);
      drive += ", $ts2" + u + "(sqrt($11**2+$12**2)) with lines lw 2 lt 1 dt 2 title '|RA0| " +
               second_label + "', ''" + u +
               "(sqrt($13**2+$14**2)) with lines lw 2 lt 2 dt 2 title '|RA3| " + second_label +
               "'" +
               (driven ? ", ''" + u + "18 axes x1y2 with lines lw 2 lt 3 dt 2 title 'τ " +
                             second_label + "'"
                       : std::string());
    }
    const std::string overlay =
        second_study ? " The " + second_label + " design is dashed (" + second_file + ")." : "";
    charts.push_back({"hodograph", "Shaking-force hodograph, inertial part",
                      "The tip of the shaking force over the run, equal axes" +
                          std::string(closed ? ", closed by the periodic end (the first sample "
                                               "again)."
                                             : ".") +
                          shaking.force_note + overlay,
                      hodo, true});
    charts.push_back(
        {"shaking-moment", "Shaking moment, inertial part",
         "Shaking moment on the frame about A0 over the run." + shaking.moment_note + overlay,
         msh});
    charts.push_back(
        {"drive", driven ? "Drive torque and bearing loads" : "Bearing loads",
         driven ? "Magnitudes of the bearing forces at A0 and A3 (left axis) and the drive "
                  "torque (right axis)." + overlay
                : "Magnitudes of the bearing forces at A0 and A3 (free motion: no drive)." +
                      overlay,
         drive});
    out.animations.push_back(fourbar_animation(study.fourbar(), fourbar_parts(study, false), ts,
                                               study.scene, "animation-original", "original"));
    if (second_study && !ts2.rows.empty()) {
      out.animations.push_back(fourbar_animation(second_study->fourbar(),
                                                 fourbar_parts(*second_study, second == "balanced"),
                                                 ts2, study.scene,
                                                 "animation-" + second,
                                                 second == "balanced" ? "balanced" : "optimised"));
    }
  }
  return out;
}

}  // namespace

std::string fourbar_report_html(const Study& study, const fs::path& dir, const std::string& gnuplot,
                                const Json& summary) {
  std::size_t samples = 0;
  const Csv ts = read_csv_decimated(dir / "timeseries.csv", kChartRows, &samples);
  const SecondDesign second = second_design(summary, dir);
  std::string h = page_start(study, summary) + simulation_section(summary);
  h += "<h2>Linkage</h2>\n" + fourbar_linkage_tables(study.fourbar());
  const double size = linkage_size(study);
  const Scales scales = run_scales(summary, size);
  h += metrics_section(study, summary, second,
                       shaking_metrics_note("A0") +
                           " tau: drive torque; RA0, RA3: forces on the ground at the bearings. "
                           "RMS over the samples, max of magnitudes.",
                       scales);
  h += comparison_section(dir, summary, second, scales);
  h += harmonics_section(dir, scales);
  FourBarCharts c = fourbar_charts(study, dir, second, ts, summary, scales);
  h += animations_section(c.animations);
  for (Chart& chart : harmonic_charts(dir, c.datablocks, scales))
    c.charts.push_back(std::move(chart));
  for (Chart& chart : pareto_charts(dir, c.datablocks)) c.charts.push_back(std::move(chart));
  h += charts_section(gnuplot, c.datablocks, c.charts, samples, ts.rows.size());
  if (!c.original.poses.empty()) {
    h += "<h3>The linkage at four samples</h3>" + poses_table(c.original, size);
  }
  if (!c.second.poses.empty()) {
    h += "<h3>The " + std::string(second.key == "balanced" ? "balanced" : "optimised") +
         " linkage at four samples</h3>" + poses_table(c.second, size);
  }
  h += second_design_section(summary, second, scales);
  h += pareto_section(dir, scales);
  // the measurements of `balance-design bench` when the folder has them (work_precision.hpp)
  h += work_precision_section(study, dir, gnuplot);
  return h + data_files_html(dir, data_files());
}

}  // namespace bd::studies::report_support
