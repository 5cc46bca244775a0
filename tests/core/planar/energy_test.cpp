// Energy, work, power and momentum balances of the general planar engine, from its own samples
// only (no referee): what any correct rigid-body dynamics must satisfy, whatever the method.
//
//  * Free runs (both routes) of random linkages with a spring-damper and a constant, harmonic or
//    tabulated drive effort: E(t) - E(0) = W_in - W_damp + W_app at every sample, E = kinetic +
//    gravity + spring energy, the works integrated from the samples' powers by the composite
//    Boole rule.
//  * Driven revolutions: at every sample, the drives' power sum(effort * rate) equals
//    dT/dt - P_applied - P_gravity - P_springs, dT/dt = sum m v_G . a_G + I omega alpha over the
//    links plus m v . a over the point masses (exact in a driven scene: no integration).
//  * Both: Fsh - Fsh_inertial = the applied forces and the weights (springs anchored to the frame
//    do not appear: their pull on the frame is in Fsh and their pull on the linkage cancels it),
//    and Msh - Msh_inertial = their moments about the origin (and the load moments): the
//    momentum balance of the whole linkage.
//
// Everything is computed from the table's columns: node positions, link angles, rates and
// accelerations, slider rates and accelerations; node velocities and accelerations follow from
// them link by link from the ground nodes and the frame guides (rigid-body kinematics).
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "core/planar/simulate.hpp"
#include "tests/support/planar_balance.hpp"
#include "tests/support/planar_glue.hpp"
#include "tests/support/planar_mechanisms.hpp"

namespace bd::testing::planar {
namespace {

// ---------------------------------------------------------------------------------------------
// Driven: power balance and momentum at every sample

constexpr double kDrivenPower = 1e-11;  // both sides exact to round-off (~1e-14 measured)
constexpr double kMomentum = 1e-11;

template <class Make>
void driven_balances(const char* family, std::uint64_t seed, int count, Make make) {
  Rng rng(seed);
  double worst_power = 0, worst_force = 0, worst_moment = 0;
  for (int i = 0; i < count; ++i) {
    const cp::Linkage l = make(rng);
    const cp::Model model(l);
    cp::DrivenScene scene;
    for (std::size_t k = 0; k < l.inputs.size(); ++k)
      scene.speeds.push_back((coin(rng) ? 1 : -1) * uniform(rng, 5, 40));
    scene.samples = 90;
    if (l.inputs[0].kind == cp::Input::Kind::kSlide) {  // a piston: 80 % of the way to a dead centre
      const Stroke st = stroke_of(l);
      const double to = st.hi - st.drawn > st.drawn - st.lo ? st.hi : st.lo;
      scene.speeds = {(to > st.drawn ? 1 : -1) * uniform(rng, 0.5, 2.0)};
      scene.duration = 0.8 * std::abs(to - st.drawn) / std::abs(scene.speeds[0]);
    }
    const cp::Trajectory tr = cp::simulate_driven(model, scene);
    ASSERT_TRUE(tr.ok()) << tr.message;
    std::vector<Balance> bs;
    std::vector<Row> rows;
    double scale = 0;
    for (std::size_t j = 0; j < tr.table.rows(); ++j) {
      rows.push_back(row_of(model, tr.table, j));
      const Balance& b = bs.emplace_back(balance_of(model, rows.back()));
      scale = std::max({scale, std::abs(b.input_power), std::abs(b.kinetic_rate),
                        std::abs(b.applied_power), std::abs(b.gravity_power), std::abs(b.spring_power)});
    }
    for (std::size_t j = 0; j < bs.size(); ++j) {
      const Balance& b = bs[j];
      const double gap = std::abs(b.input_power - (b.kinetic_rate - b.applied_power -
                                                   b.gravity_power - b.spring_power)) / scale;
      worst_power = std::max(worst_power, gap);
      EXPECT_LE(gap, kDrivenPower) << family << " #" << i << " at t = " << rows[j].t;
      const MomentumGap m = momentum_gap(rows[j], b, model.length_scale());
      worst_force = std::max(worst_force, m.force);
      worst_moment = std::max(worst_moment, m.moment);
      EXPECT_LE(m.force, kMomentum) << family << " #" << i << ": Fsh at t = " << rows[j].t;
      EXPECT_LE(m.moment, kMomentum) << family << " #" << i << ": Msh at t = " << rows[j].t;
    }
  }
  std::printf("%s, %d driven revolutions: power balance %.1e, Fsh %.1e, Msh %.1e (worst, relative)\n",
              family, count, worst_power, worst_force, worst_moment);
}

// a linkage with a spring-damper always
template <class Make>
auto with_spring(Make make) {
  return [make](Rng& rng) {
    cp::Linkage l = make(rng);
    if (l.springs.empty()) {
      maybe_spring(l, rng, 1.0);
      l = cp::make_linkage(l);
    }
    return l;
  };
}

TEST(Energy, DrivenPowerAndMomentumBalances) {
  driven_balances("slider-crank", 301, 12, with_spring([](Rng& r) { return slider_crank(r, coin(r)); }));
  driven_balances("slider-crank driven by its piston", 305, 12,
                  with_spring([](Rng& r) { return driven_by_piston(slider_crank(r, coin(r))); }));
  driven_balances("quick return / shaper", 302, 12,
                  with_spring([](Rng& r) { return quick_return(r, coin(r), coin(r)); }));
  driven_balances("six-bar", 303, 12, with_spring([](Rng& r) { return six_bar_or_retry(r, coin(r)); }));
  driven_balances("five-bar", 304, 12, with_spring([](Rng& r) { return five_bar(r); }));
}

// ---------------------------------------------------------------------------------------------
// Free: energy and work

// The composite Boole rule over f at evenly spaced samples: the cumulative integral at every
// fourth sample (index 4 m), from sample 0. Error per panel -(8/945) h^7 f^(6).
std::vector<double> boole_cumulative(const std::vector<double>& f, double h) {
  std::vector<double> out = {0.0};
  for (std::size_t i = 0; i + 4 < f.size() + 0 && i + 4 <= f.size() - 1; i += 4) {
    out.push_back(out.back() + 2 * h / 45 *
                                   (7 * f[i] + 32 * f[i + 1] + 12 * f[i + 2] + 32 * f[i + 3] + 7 * f[i + 4]));
  }
  return out;
}

// A tabulated effort with its breakpoints at Boole panel boundaries (so that each panel's power
// is smooth and the rule keeps its order).
cp::TimeFunction tabulated(Rng& rng, double size, double duration, int panels) {
  cp::TimeFunction f;
  f.kind = cp::TimeFunction::Kind::kTable;
  const int points = 6;
  for (int i = 0; i < points; ++i) {
    const int panel = panels * i / (points - 1);
    f.times.push_back(duration * panel / panels);
    f.values.push_back(uniform(rng, -size, size));
  }
  return f;
}

struct FreeEnergy {
  double balance = 0;     // the worst |E - E0 - W| over the samples / the energy scale
  double quadrature = 0;  // the Richardson estimate of the rule's error, same scale
};

FreeEnergy free_energy(const cp::Model& model, const cp::Trajectory& tr) {
  const std::size_t n = tr.table.rows();
  const std::vector<double> t = tr.table.column_values("t");
  const double h = t[1] - t[0];
  std::vector<double> energy, work_rate;
  double scale = 0;
  for (std::size_t j = 0; j < n; ++j) {
    const Balance b = balance_of(model, row_of(model, tr.table, j));
    energy.push_back(b.kinetic + b.gravity + b.spring);
    work_rate.push_back(b.input_power - b.damper_power + b.applied_power);
    scale = std::max({scale, std::abs(energy.back()), b.kinetic});
  }
  const std::vector<double> work = boole_cumulative(work_rate, h);
  // the same rule on every other sample (panels of 8 h): the difference is ~63 times the error
  std::vector<double> coarse_rate;
  for (std::size_t j = 0; j < n; j += 2) coarse_rate.push_back(work_rate[j]);
  const std::vector<double> coarse = boole_cumulative(coarse_rate, 2 * h);
  for (const double w : work) scale = std::max(scale, std::abs(w));
  FreeEnergy out;
  for (std::size_t m = 0; m < work.size(); ++m) {
    out.balance = std::max(out.balance, std::abs(energy[4 * m] - energy[0] - work[m]) / scale);
    if (m % 2 == 0 && m / 2 < coarse.size())
      out.quadrature = std::max(out.quadrature, std::abs(work[m] - coarse[m / 2]) / 63 / scale);
  }
  return out;
}

// Engine tolerance 1e-12 (absolute 1e-14). The balance holds to the motion's accuracy: the
// states are off by up to some 1e-8 relative at this tolerance (tests/core/planar/
// referee_free_test.cpp), which puts E and W off by up to a few 1e-9 (measured: 3.2e-9, in a
// six-bar whose output link swings at up to 230 rad/s); the Boole rule over 2000 panels adds
// its error, estimated by Richardson from the rule on every other sample and required below a
// tenth of the balance's own limit, so that the rule cannot take up more than a tenth of it
// (measured: 7e-11 where links swing at 200 rad/s, 1e-15 elsewhere; 1.9e-10 in the clang build
// under the sanitizers, whose other round-off moves the integrator's steps, and the estimate
// differences the samples, so it carries the integration error too; at 1000 panels it was 8e-9,
// hence the 8001 samples). A power left out or mis-signed (a damper, a load, the drive) breaks
// the balance at 1e-3 or more.
constexpr double kFreeBalance = 1e-8;
constexpr double kQuadrature = kFreeBalance / 10;

template <class Make>
void free_balances(const char* family, std::uint64_t seed, int count, Make make) {
  Rng rng(seed);
  const double duration = 0.4;
  const int samples = 8001;  // h = 5e-5 s: 2000 Boole panels
  FreeEnergy worst[2];
  for (int i = 0; i < count; ++i) {
    cp::Linkage l = make(rng);
    std::vector<double> rates;
    for (cp::Input& in : l.inputs) {
      const double size = 0.005 * energy_of(l);
      const int kind = static_cast<int>(uniform(rng, 0, 3));
      in.effort = kind == 0   ? constant(uniform(rng, -size, size))
                  : kind == 1 ? harmonic(uniform(rng, -size, size), size, uniform(rng, 2, 10), 0)
                              : tabulated(rng, size, duration, (samples - 1) / 4);
      rates.push_back((coin(rng) ? 1 : -1) * uniform(rng, 10, 30));
    }
    const cp::Model model(l);
    for (int r = 0; r < 2; ++r) {
      cp::SimulateOptions o;
      o.route = r == 0 ? cp::Route::kReduced : cp::Route::kDae;
      o.tolerance = 1e-12;
      o.absolute_tolerance = 1e-14;
      const cp::Trajectory tr = cp::simulate_free(model, cp::FreeScene{{}, rates, duration, samples}, o);
      ASSERT_TRUE(tr.ok()) << family << " #" << i << ": " << tr.message;
      const FreeEnergy e = free_energy(model, tr);
      EXPECT_LE(e.balance, kFreeBalance) << family << " #" << i << " (" << cp::to_string(o.route) << ")";
      EXPECT_LE(e.quadrature, kQuadrature) << family << " #" << i << ": the rule is too coarse";
      worst[r].balance = std::max(worst[r].balance, e.balance);
      worst[r].quadrature = std::max(worst[r].quadrature, e.quadrature);
      // the momentum balance at every sample
      for (std::size_t j = 0; j < tr.table.rows(); j += 10) {
        const Row row = row_of(model, tr.table, j);
        const MomentumGap m = momentum_gap(row, balance_of(model, row), model.length_scale());
        EXPECT_LE(m.force, kMomentum) << family << " #" << i << ": Fsh at t = " << row.t;
        EXPECT_LE(m.moment, kMomentum) << family << " #" << i << ": Msh at t = " << row.t;
      }
    }
  }
  std::printf("%s, %d free runs: energy-work balance %.1e (reduced), %.1e (dae); Boole's error "
              "estimate %.1e (relative to the energies)\n",
              family, count, worst[0].balance, worst[1].balance,
              std::max(worst[0].quadrature, worst[1].quadrature));
}

TEST(Energy, FreeEnergyWorkBalances) {
  free_balances("slider-crank", 311, 4, with_spring([](Rng& r) { return slider_crank(r, coin(r)); }));
  free_balances("quick return / shaper", 312, 4,
                with_spring([](Rng& r) { return quick_return(r, coin(r), coin(r)); }));
  free_balances("six-bar", 313, 4, with_spring([](Rng& r) { return six_bar_or_retry(r, coin(r)); }));
  free_balances("five-bar", 314, 4, with_spring([](Rng& r) { return five_bar(r); }));
}

}  // namespace
}  // namespace bd::testing::planar
