// A fixed amount of dynamics work for instruction counting under callgrind (docs/performance.md,
// "Dynamics evaluation"); wall-clock timings are bench_dynamics' job. Usage:
//   dynamics_instructions KIND N
// KIND: none, or mass-matrix / opened-loop / complex-masses followed by :forward or :inverse
// (N evaluations on the paper's four-bar, theta1 from 1 rad in steps of 1e-3 rad, omega1 2 rad/s,
// alpha1 0.5 rad/s^2), or driven (N driven revolutions of 360 samples, as BM_DrivenRevolution).
// Instructions per evaluation = (count(KIND, N) - count(none, 0)) / N.
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/dynamics.hpp"
#include "core/samples.hpp"
#include "core/simulate.hpp"

int main(int argc, char** argv) {
  using namespace bd::core;
  if (argc != 3) {
    std::fprintf(stderr, "usage: dynamics_instructions KIND N\n");
    return 2;
  }
  const std::string kind = argv[1];
  const int n = std::atoi(argv[2]);
  double checksum = 0.0;  // printed, so that no evaluation is optimised away
  if (kind == "driven") {
    const FourBar model = samples::paper_fourbar_unloaded();
    const DrivenScene scene{
        .theta1 = 0.0, .omega1 = 6.283185307179586, .revolutions = 1, .samples = 360};
    for (int i = 0; i < n; ++i) checksum += simulate_driven(model, scene).samples.back().tau;
  } else if (kind != "none") {
    const FourBar model = samples::paper_fourbar();
    const std::string name = kind.substr(0, kind.find(':'));
    const bool inverse = kind.ends_with(":inverse");
    Formulation f = Formulation::kMassMatrix;
    for (Formulation g : kFormulations) {
      if (name == to_string(g)) f = g;
    }
    double theta1 = 1.0;
    for (int i = 0; i < n; ++i) {
      const auto s = inverse ? inverse_dynamics(model, theta1, 2.0, 0.5, f)
                             : forward_dynamics(model, theta1, 2.0, f);
      if (s) checksum += s->RA0.x();
      theta1 += 1e-3;
    }
  }
  std::printf("%.17g\n", checksum);
  return 0;
}
