// Every joint force is an output, and the shaking force is the sum of the columns that make it.
// The four-bar's pin forces FA1, FA2 come from Newton's law on the crank and the rocker; the
// checks here are the equations they were not taken from: the coupler's force balance and every
// link's moment balance about its centre of mass (supports, pins, gears, loads, weights and the
// drive torque), closed to round-off, on every formulation, with counter-rotating discs. For a
// planar linkage: the frame's forces (pins, guides, balance shafts, springs anchored on it, slide
// drives on its guides) sum to Fsh, column by column.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>

#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/kinematics.hpp"
#include "core/fourbar/samples.hpp"
#include "core/planar/simulate.hpp"
#include "studies/run/runner.hpp"
#include "studies/study/load_study.hpp"
#include "tests/support/csv.hpp"
#include "tests/support/planar_mechanisms.hpp"

namespace bd {
namespace {

namespace cp = core::planar;
using testing::planar::Rng;
using testing::planar::uniform;

double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

TEST(JointForces, FourBarFreeBodiesCloseOnEveryLink) {
  Rng rng(1616);
  for (int trial = 0; trial < 6; ++trial) {
    core::FourBar fb = core::samples::paper_fourbar();
    fb.loads.gravity = Vec2(uniform(rng, -3, 3), -9.81);
    fb.loads.coupler.force = Vec2(uniform(rng, -30, 30), uniform(rng, -30, 30));
    fb.loads.rocker.moment = uniform(rng, -10, 10);
    if (trial % 2) {
      fb.counter_rotations.crank = {uniform(rng, 0.2, 2), Vec2(0.1, -1.2)};
      fb.counter_rotations.rocker = {uniform(rng, 0.2, 2), Vec2(3.4, -1.5)};
    }
    fb = core::make_fourbar(fb);
    const Vec2 A0(0, 0), A3(fb.frame_length, 0);
    for (core::Formulation form : core::kFormulations) {
      const double theta1 = uniform(rng, 0, 2 * std::numbers::pi);
      const double omega1 = uniform(rng, -10, 10), alpha1 = uniform(rng, -20, 20);
      // driven (a torque) and free (none)
      const auto driven = core::inverse_dynamics(fb, theta1, omega1, alpha1, form);
      const auto free = core::forward_dynamics(fb, theta1, omega1, form);
      ASSERT_TRUE(driven && free);
      for (const core::DynamicsSample& s : {*driven, *free}) {
        const core::Pose pose = core::pose_of(s.state);
        const core::Joints j = core::joint_positions(fb, pose);
        const double alpha[] = {s.state.alpha1, s.state.alpha2, s.state.alpha3};
        Vec2 c[3], F[3];
        double M[3], scale = s.FA1.norm() + s.FA2.norm() + s.RA0.norm() + s.RA3.norm();
        for (int k = 1; k <= 3; ++k) {
          const core::Link& l = core::link(fb, k);
          c[k - 1] = core::centre_of_mass(fb, k, pose);
          // applied load and weight minus m a; applied moment minus I α
          F[k - 1] = core::link_load(fb, k).force + l.mass * fb.loads.gravity -
                     l.mass * core::centre_of_mass_acceleration(fb, k, s.state);
          M[k - 1] = core::link_load(fb, k).moment - l.inertia * alpha[k - 1];
          scale += (l.mass * core::centre_of_mass_acceleration(fb, k, s.state)).norm();
        }
        // the gears' mesh forces act on the links at the pitch points, midway to the shafts
        const Vec2 p1 = (A0 + fb.counter_rotations.crank.at) / 2;
        const Vec2 p3 = (A3 + fb.counter_rotations.rocker.at) / 2;
        const double length = fb.frame_length;
        // crank: -RA0 at A0, -FA1 at A1, -RC1 at p1, tau
        const Vec2 f1 = F[0] - s.RA0 - s.FA1 - s.RC1;
        const double m1 = M[0] + s.tau + cross2(A0 - c[0], -s.RA0) + cross2(j.A1 - c[0], -s.FA1) +
                          cross2(p1 - c[0], -s.RC1);
        // coupler: FA1 at A1, -FA2 at A2
        const Vec2 f2 = F[1] + s.FA1 - s.FA2;
        const double m2 = M[1] + cross2(j.A1 - c[1], s.FA1) + cross2(j.A2 - c[1], -s.FA2);
        // rocker: FA2 at A2, -RA3 at A3, -RC3 at p3
        const Vec2 f3 = F[2] + s.FA2 - s.RA3 - s.RC3;
        const double m3 = M[2] + cross2(j.A2 - c[2], s.FA2) + cross2(A3 - c[2], -s.RA3) +
                          cross2(p3 - c[2], -s.RC3);
        EXPECT_LT(f1.norm(), 1e-12 * scale) << "trial " << trial;
        EXPECT_LT(f2.norm(), 1e-12 * scale) << "trial " << trial;
        EXPECT_LT(f3.norm(), 1e-12 * scale) << "trial " << trial;
        EXPECT_LT(std::abs(m1), 1e-12 * scale * length) << "trial " << trial;
        EXPECT_LT(std::abs(m2), 1e-12 * scale * length) << "trial " << trial;
        EXPECT_LT(std::abs(m3), 1e-12 * scale * length) << "trial " << trial;
        // the frame: Fsh is the sum of its supports and shafts
        EXPECT_LT((s.Fsh - s.RA0 - s.RA3 - s.RC1 - s.RC3).norm(), 1e-13 * scale);
      }
    }
  }
}

// timeseries.csv of a four-bar with discs: the columns that make Fsh are there and add up to it
TEST(JointForces, FourBarTimeseriesHasEveryForceOnTheFrame) {
  const studies::Study study = studies::load_study(std::string(BD_SOURCE_DIR) +
                                                   "/studies/examples/berkof-inline-moment-balanced.yaml");
  studies::RunResult r = studies::compute_study(study);
  ASSERT_TRUE(r.ok());
  const std::filesystem::path dir =
      std::filesystem::path(BD_BINARY_DIR) / "test-output" / "joint-forces";
  studies::write_run(study, r, dir);
  for (const char* file : {"timeseries.csv", "balanced-timeseries.csv"}) {
    const auto rows = testing::read_csv_numbers(dir / file);
    ASSERT_GT(rows.size(), 10u);
    const std::vector<std::string> header = [&] {
      std::vector<std::string> h;
      std::string text = studies::kTimeseriesHeader, field;
      for (char ch : text + ",") {
        if (ch == ',') {
          h.push_back(field);
          field.clear();
        } else {
          field += ch;
        }
      }
      return h;
    }();
    auto col = [&](const std::string& name) {
      for (std::size_t k = 0; k < header.size(); ++k)
        if (header[k] == name) return k;
      ADD_FAILURE() << name;
      return std::size_t{0};
    };
    double largest = 0;
    for (const auto& row : rows) largest = std::max(largest, std::hypot(row[col("RA0x")], row[col("RA0y")]));
    for (const auto& row : rows) {
      for (const char* axis : {"x", "y"}) {
        const std::string a = axis;
        const double sum = row[col("RA0" + a)] + row[col("RA3" + a)] + row[col("RC1" + a)] +
                           row[col("RC3" + a)];
        EXPECT_NEAR(row[col("Fsh" + a)], sum, 1e-13 * largest) << file;
      }
    }
    // the counter-rotation shafts' bearing forces are metrics where the disc is: the balanced
    // design's (the original has none), their RMS that of the columns, their peak at least the
    // largest sample's (resolved between the samples)
    const studies::MetricList& list =
        std::string(file) == "timeseries.csv" ? r.metric_list : r.balanced->metric_list;
    for (const char* side : {"RC1", "RC3"}) {
      const std::string s = side;
      const auto of = [&](const std::string& name) -> const studies::MetricValue* {
        for (const studies::MetricValue& m : list)
          if (m.name == name) return &m;
        return nullptr;
      };
      if (std::string(file) == "timeseries.csv") {
        EXPECT_FALSE(of(s + "_rms")) << side;
        continue;
      }
      ASSERT_TRUE(of(s + "_rms") && of(s + "_max")) << side;
      double squares = 0, most = 0;
      for (const auto& row : rows) {
        const double f = std::hypot(row[col(s + "x")], row[col(s + "y")]);
        squares += f * f;
        most = std::max(most, f);
      }
      EXPECT_NEAR(of(s + "_rms")->value, std::sqrt(squares / static_cast<double>(rows.size())),
                  1e-12 * largest)
          << side;
      EXPECT_GE(of(s + "_max")->value, most) << side;
      EXPECT_LE(of(s + "_max")->value, most * 1.01) << side;
      EXPECT_EQ(of(s + "_max")->unit, "N");
    }
  }
}

// a planar linkage with a spring anchored on the frame and a slide drive on a frame guide: Fsh is
// the sum of its R columns
TEST(JointForces, PlanarShakingForceIsTheSumOfItsColumns) {
  Rng rng(61);
  for (int trial = 0; trial < 6; ++trial) {
    cp::Linkage l = testing::planar::slider_crank(rng, trial % 2 == 0);
    l.loads.gravity = Vec2(0, -9.81);
    if (l.springs.empty()) testing::planar::maybe_spring(l, rng, 1.0);
    const bool piston = trial >= 3;
    if (piston) l = testing::planar::driven_by_piston(l);
    l = cp::make_linkage(l);
    const cp::Model model(l);
    cp::DrivenScene scene;
    scene.speeds = {piston ? 0.0 : uniform(rng, 5, 20)};
    if (piston) {
      scene.speeds = {uniform(rng, 0.1, 0.3)};
      scene.duration = 0.2;
    }
    scene.samples = 30;
    const cp::Trajectory t = cp::simulate_driven(model, scene);
    if (!t.ok()) continue;  // a piston stroke may reach a dead centre: nothing to check past it
    const core::Series& s = t.table;
    std::vector<std::size_t> rx;
    for (std::size_t k = 0; k < s.columns.size(); ++k) {
      const std::string& c = s.columns[k];
      if (c.size() > 2 && c[0] == 'R' && c.back() == 'x') rx.push_back(k);
    }
    if (piston) {
      bool drive = false;
      for (const std::string& c : s.columns) drive = drive || c.ends_with("_drivex");
      EXPECT_TRUE(drive);
    }
    EXPECT_GE(s.column("RS_springx"), 0);  // the spring's pull where it is anchored
    const std::size_t fx = static_cast<std::size_t>(s.column("Fshx"));
    for (std::size_t i = 0; i < s.rows(); ++i) {
      Vec2 sum(0, 0);
      double scale = 0;
      for (std::size_t k : rx) {
        sum += Vec2(s.at(i, k), s.at(i, k + 1));
        scale += Vec2(s.at(i, k), s.at(i, k + 1)).norm();
      }
      EXPECT_LT((Vec2(s.at(i, fx), s.at(i, fx + 1)) - sum).norm(), 1e-13 * scale)
          << "trial " << trial;
    }
  }
}

// A slider on a moving guide (quick returns and shapers: a block on the crank pin A sliding along
// the rocker): F<slider>_guide, the force on the guide's link from the block, closes the block's
// free body with the crank pin's joint force FA (the force on the crank from the joint) and the
// block's weight and inertia, the pin's acceleration taken from the crank's angle, rate and
// acceleration: F_guide = -FA + m (g - a_A); and it is normal to the guide (no friction, no drive
// along it).
TEST(JointForces, AGuideOnALinkCarriesTheBlocksNormalForce) {
  Rng rng(62);
  for (int trial = 0; trial < 8; ++trial) {
    cp::Linkage l = testing::planar::quick_return(rng, trial % 2 == 0, trial >= 4);
    // the block's node carries only its point mass (no spring or node force there)
    l.springs.clear();
    std::erase_if(l.loads.node_forces, [](const cp::NodeForce& f) { return f.node == 1; });
    l.loads.gravity = Vec2(uniform(rng, -2, 2), -9.81);
    l = cp::make_linkage(l);
    const cp::Model model(l);
    cp::DrivenScene scene;
    scene.speeds = {uniform(rng, 5, 20)};
    scene.samples = 60;
    const cp::Trajectory t = cp::simulate_driven(model, scene);
    ASSERT_TRUE(t.ok()) << t.message;
    const core::Series& s = t.table;
    auto col = [&](const char* name) { return s.column_values(name); };
    const auto th = col("theta_crank"), w = col("omega_crank"), al = col("alpha_crank");
    const auto fax = col("FAx"), fay = col("FAy");
    const auto gx = col("Fblock_guidex"), gy = col("Fblock_guidey");
    const auto xa = col("x_A"), ya = col("y_A");
    double m = 0;
    for (const cp::PointMass& pm : l.point_masses) m += pm.node == 1 ? pm.mass : 0.0;
    const Vec2 O = l.nodes[0].position, Q = l.nodes[2].position;
    const double r = (l.nodes[1].position - O).norm();
    double scale = 0, worst = 0, along = 0;
    for (std::size_t i = 0; i < th.size(); ++i) {
      const Vec2 u(std::cos(th[i]), std::sin(th[i]));
      const Vec2 a = r * (-w[i] * w[i] * u + al[i] * Vec2(-u.y(), u.x()));
      const Vec2 fa(fax[i], fay[i]), guide(gx[i], gy[i]);
      const Vec2 expected = -fa + m * (l.loads.gravity - a);
      scale = std::max({scale, fa.norm(), guide.norm()});
      worst = std::max(worst, (guide - expected).norm());
      const Vec2 line = (Vec2(xa[i], ya[i]) - Q).normalized();  // the guide runs through Q and A
      along = std::max(along, std::abs(guide.dot(line)));
    }
    EXPECT_GT(scale, 0.0);
    EXPECT_LT(worst, 1e-12 * scale) << "trial " << trial;
    EXPECT_LT(along, 1e-12 * scale) << "trial " << trial;
  }
}

}  // namespace
}  // namespace bd
