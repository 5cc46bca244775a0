// The library API in twenty lines: build the paper's four-bar, solve one instant, print it.
#include <cstdio>

#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/model.hpp"

int main() {
  using namespace bd::core;
  FourBar model;
  model.crank = link_from_polar(1.0, 2.1, 0.6, 0.3, 1.1);  // length, mass, s, sigma, inertia
  model.coupler = link_from_polar(3.0, 3.0, 1.45, 0.4, 3.1);
  model.rocker = link_from_polar(2.0, 2.2, 1.66, -0.4, 2.1);
  model.frame_length = 3.2;
  model.branch = Branch::kPlus;
  model = make_fourbar(model);  // throws bd::InputError on a non-physical value

  // crank driven at 2 pi rad/s through theta1 = 1 rad: drive torque and support reactions
  const auto s = inverse_dynamics(model, 1.0, 2 * 3.141592653589793, 0.0);
  if (!s) return std::fprintf(stderr, "%s\n", s.error().what().c_str()), 1;
  std::printf("theta2 = %.6f rad, theta3 = %.6f rad\n", s->state.theta2, s->state.theta3);
  std::printf("tau = %.6f N m, RA0 = (%.6f, %.6f) N, RA3 = (%.6f, %.6f) N\n", s->tau, s->RA0.x(),
              s->RA0.y(), s->RA3.x(), s->RA3.y());
  std::printf("shaking force = (%.6f, %.6f) N, shaking moment = %.6f N m\n", s->Fsh.x(),
              s->Fsh.y(), s->Msh);
}
