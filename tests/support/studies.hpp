#pragma once
// Test support: study-file texts the tests share.
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace bd::testing {

/// The path of an example study in the source tree, e.g. "watt-sixbar.yaml".
inline std::string example_path(const std::string& file) {
  return std::string(BD_SOURCE_DIR) + "/studies/examples/" + file;
}

/// The text of the example study `file` with each edit's first text replaced, once, by its
/// second. Throws std::runtime_error where a text to replace is not found (the example changed).
inline std::string edited_example(const std::string& file,
                                  const std::vector<std::pair<std::string, std::string>>& edits) {
  std::ifstream in(example_path(file));
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  for (const auto& [from, to] : edits) {
    const auto at = yaml.find(from);
    if (at == std::string::npos) throw std::runtime_error(file + " has no '" + from + "' to edit");
    yaml.replace(at, from.size(), to);
  }
  return yaml;
}

/// The RMS over samples of the magnitude of (x, y).
inline double rms_norm(const std::vector<double>& x, const std::vector<double>& y) {
  double s = 0;
  for (std::size_t i = 0; i < x.size(); ++i) s += x[i] * x[i] + y[i] * y[i];
  return std::sqrt(s / static_cast<double>(x.size()));
}

/// The paper's loaded four-bar in free motion (20 s, 201 samples) with an LHS sweep of `points`
/// points over coupler mass [1, 5] kg and initial crank speed [-2, 2] rad/s; `extra` (e.g.
/// "  seed: 7\n") is added to the sweep section before its parameters.
inline std::string paper_free_lhs_sweep(int points, const std::string& extra) {
  return "name: free\n"
         "linkage:\n"
         "  type: fourbar\n"
         "  frame: 3.2\n"
         "  branch: 1\n"
         "  crank:   {length: 1.0, mass: 2.1, s: 0.6, sigma: 0.3, inertia: 1.1}\n"
         "  coupler: {length: 3.0, mass: 3.0, s: 1.45, sigma: 0.4, inertia: 3.1}\n"
         "  rocker:  {length: 2.0, mass: 2.2, s: 1.66, sigma: -0.4, inertia: 2.1}\n"
         "loads:\n"
         "  crank:   {force: [1.1, 1.2],  moment: 0.37}\n"
         "  coupler: {force: [1.3, -1.4], moment: 0.28}\n"
         "  rocker:  {force: [1.5, 1.6],  moment: 0.19}\n"
         "scene: {type: free, theta1: 1.0, omega1: 0.0, duration: 20.0, samples: 201}\n"
         "sweep:\n"
         "  design: lhs\n"
         "  points: " +
         std::to_string(points) + "\n" + extra +
         "  parameters:\n"
         "    - {path: linkage.coupler.mass, from: 1.0, to: 5.0}\n"
         "    - {path: scene.omega1, from: -2.0, to: 2.0}\n";
}

/// A single-cylinder engine's slider-crank (crank 40 mm, rod 140 mm, piston 0.35 kg on a
/// horizontal axis) driven by its piston at 0.05 m/s from mid-stroke (crank at 90 degrees) over
/// `duration` seconds with `samples` samples: a planar driven scene given by a duration. The
/// piston reaches the top dead centre at t = 0.92 s; past it the linkage cannot be assembled.
inline std::string piston_driven_slider_crank(double duration, int samples) {
  return "name: piston\n"
         "linkage:\n"
         "  type: planar\n"
         "  nodes:\n"
         "    O: {at: [0, 0], ground: true}\n"
         "    A: [0, 0.04]\n"
         "    B: [0.1341640786499874, 0]\n"
         "  links:\n"
         "    crank: {nodes: [O, A], mass: 1.2, e: 0.012, f: 0, inertia: 0.0009}\n"
         "    rod:   {nodes: [A, B], mass: 0.45, e: 0.035, f: 0, inertia: 0.0012}\n"
         "  point_masses: {B: 0.35}\n"
         "  sliders:\n"
         "    piston: {node: B, guide: [[0, 0], [1, 0]]}\n"
         "  inputs:\n"
         "    piston: {slider: piston}\n"
         "scene: {type: driven, speeds: [0.05], duration: " +
         std::to_string(duration) + ", samples: " + std::to_string(samples) + "}\n";
}

/// A single-cylinder engine's slider-crank (crank 40 mm, rod 140 mm, piston 0.35 kg on a
/// horizontal axis) driven by its crank at 3000 rpm over one revolution with `samples` samples,
/// no loads. Tests that quote line numbers refer to this text: `samples` is line 19, the last.
inline std::string engine_study(int samples) {
  return "name: e\n"                                                                 // 1
         "linkage:\n"                                                                // 2
         "  type: planar\n"                                                          // 3
         "  nodes:\n"                                                                // 4
         "    O: {at: [0, 0], ground: true}\n"                                       // 5
         "    A: [0.04, 0]\n"                                                        // 6
         "    B: [0.18, 0]\n"                                                        // 7
         "  links:\n"                                                                // 8
         "    crank: {nodes: [O, A], mass: 1.2, e: 0.012, f: 0, inertia: 0.0009}\n"  // 9
         "    rod: {nodes: [A, B], mass: 0.45, e: 0.035, f: 0, inertia: 0.0012}\n"   // 10
         "  point_masses: {B: 0.35}\n"                                               // 11
         "  sliders:\n"                                                              // 12
         "    piston: {node: B, guide: [[0, 0], [1, 0]]}\n"                          // 13
         "  inputs:\n"                                                               // 14
         "    crank: {link: crank}\n"                                                // 15
         "scene:\n"                                                                  // 16
         "  type: driven\n"                                                          // 17
         "  speeds: [314.1592653589793]\n"                                           // 18
         "  samples: " +
         std::to_string(samples) + "\n";  // 19
}

}  // namespace bd::testing
