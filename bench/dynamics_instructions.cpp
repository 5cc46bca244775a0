// A fixed amount of dynamics work for instruction counting under callgrind (docs/performance.md,
// "Dynamics evaluation"); wall-clock timings are bench_dynamics' job. Usage:
//   dynamics_instructions KIND N
// KIND:
//   none                      nothing (the program's own start-up, to subtract)
//   position                  N position solves (core::solve_position)
//   F:forward, F:inverse      N evaluations by formulation F (mass-matrix, opened-loop,
//                             complex-masses) through the one-instant calls, which compute the
//                             model's constants each time
//   F:forward:constants, F:inverse:constants
//                             the same with core::detail::DynamicsConstants computed once, as a
//                             simulation or a sweep calls them
//   driven                    N driven revolutions of 360 samples (as BM_DrivenRevolution)
//   planar:forward, planar:inverse
//                             N instants of the general engine on the same four-bar: a position
//                             solve from the previous instant's nodes, then forward or inverse
//                             dynamics with every force (core::planar)
//   planar:driven             N driven revolutions of 360 samples on the general engine
//   free, planar:free, planar:free-dae
//                             N of the paper's free runs (5 s, 501 samples, CVODE Adams at 1e-10,
//                             as BM_FreeRun): closed form, general engine reduced and dae route
// The instants: the paper's four-bar, theta1 from 1 rad in steps of 1e-3 rad, omega1 2 rad/s,
// alpha1 0.5 rad/s^2. Instructions per evaluation = (count(KIND, N) - count(none, 0)) / N.
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/fourbar/detail/dynamics_constants.hpp"
#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/kinematics.hpp"
#include "core/fourbar/samples.hpp"
#include "core/fourbar/simulate.hpp"
#include "core/planar/dynamics.hpp"
#include "core/planar/from_fourbar.hpp"
#include "core/planar/simulate.hpp"

int main(int argc, char** argv) {
  using namespace bd::core;
  if (argc != 3) {
    std::fprintf(stderr, "usage: dynamics_instructions KIND N\n");
    return 2;
  }
  const std::string kind = argv[1];
  const int n = std::atoi(argv[2]);
  double checksum = 0.0;  // printed, so that no evaluation is optimised away
  if (kind == "planar:driven") {
    const planar::Model model(planar::linkage_of(samples::paper_fourbar_unloaded(), 0.0));
    const planar::DrivenScene scene{{0.0}, {6.283185307179586}, 1, 0, 360};
    for (int i = 0; i < n; ++i) {
      const planar::Trajectory t = planar::simulate_driven(model, scene);
      checksum += t.table.values.back();
    }
  } else if (kind == "planar:free" || kind == "planar:free-dae") {
    const planar::Model model(planar::linkage_of(samples::paper_fourbar(), 1.0));
    planar::SimulateOptions o;
    o.route = kind == "planar:free-dae" ? planar::Route::kDae : planar::Route::kReduced;
    for (int i = 0; i < n; ++i) {
      const planar::Trajectory t =
          planar::simulate_free(model, planar::FreeScene{{1.0}, {0.0}, 5.0, 501}, o);
      checksum += t.table.values.back();
    }
  } else if (kind == "free") {
    for (int i = 0; i < n; ++i) {
      checksum += simulate_free(samples::paper_fourbar(), FreeScene{1.0, 0.0, 5.0, 501})
                      .samples.back()
                      .tau;
    }
  } else if (kind == "planar:forward" || kind == "planar:inverse") {
    const planar::Model model(planar::linkage_of(samples::paper_fourbar(), 1.0));
    planar::Workspace ws(model);
    std::vector<bd::Vec2> guess = ws.instant.x;
    std::vector<double> z{1.0};
    const std::vector<double> rate{2.0}, acceleration{0.5}, effort{0.0};
    for (int i = 0; i < n; ++i) {
      bool ok = static_cast<bool>(planar::solve_position(model, ws, guess, z));
      ok = ok && (kind == "planar:inverse"
                      ? static_cast<bool>(planar::inverse_dynamics(model, ws, 0.0, rate, acceleration))
                      : static_cast<bool>(planar::forward_dynamics(model, ws, 0.0, rate, effort)));
      if (ok) checksum += ws.instant.ground_reaction[0].x();
      guess = ws.instant.x;
      z[0] += 1e-3;
    }
  } else if (kind == "driven") {
    const FourBar model = samples::paper_fourbar_unloaded();
    const DrivenScene scene{
        .theta1 = 0.0, .omega1 = 6.283185307179586, .revolutions = 1, .samples = 360};
    for (int i = 0; i < n; ++i) checksum += simulate_driven(model, scene).samples.back().tau;
  } else if (kind == "position") {
    const FourBar model = samples::paper_fourbar();
    double theta1 = 1.0;
    for (int i = 0; i < n; ++i) {
      const auto pose = solve_position(model, theta1);
      if (pose) checksum += pose->theta2;
      theta1 += 1e-3;
    }
  } else if (kind != "none") {
    const FourBar model = samples::paper_fourbar();
    const std::string name = kind.substr(0, kind.find(':'));
    const bool inverse = kind.find(":inverse") != std::string::npos;
    const bool with_constants = kind.ends_with(":constants");
    Formulation f = Formulation::kMassMatrix;
    bool known = false;
    for (Formulation g : kFormulations) {
      if (name == to_string(g)) f = g, known = true;
    }
    if (!known) {
      std::fprintf(stderr, "dynamics_instructions: unknown KIND %s\n", kind.c_str());
      return 2;
    }
    const detail::DynamicsConstants constants = detail::dynamics_constants(model);
    double theta1 = 1.0;
    for (int i = 0; i < n; ++i) {
      const auto s = with_constants
                         ? (inverse ? inverse_dynamics(model, constants, theta1, 2.0, 0.5, f)
                                    : forward_dynamics(model, constants, theta1, 2.0, f))
                         : (inverse ? inverse_dynamics(model, theta1, 2.0, 0.5, f)
                                    : forward_dynamics(model, theta1, 2.0, f));
      if (s) checksum += s->RA0.x();
      theta1 += 1e-3;
    }
  }
  std::printf("%.17g\n", checksum);
  return 0;
}
