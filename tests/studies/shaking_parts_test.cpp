// The shaking force and moment split into their inertial part (-Σ m a, -dH/dt: what balancing
// acts on) and their static part (weights and applied loads), on both engines and in a study's
// outputs. Each part is checked against a route of its own: the inertial part against the
// second derivative of the moving masses' centre of mass and angular momentum taken by finite
// differences of positions alone; the static part against the loads summed by hand; and the
// total (the reactions the formulations solve for) against their sum, which is Newton's law.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <type_traits>

#include "balance/synthesis.hpp"
#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/kinematics.hpp"
#include "core/fourbar/metrics.hpp"
#include "core/fourbar/samples.hpp"
#include "core/fourbar/simulate.hpp"
#include "core/planar/dynamics.hpp"
#include "core/planar/from_fourbar.hpp"
#include "core/planar/metrics.hpp"
#include "core/planar/simulate.hpp"
#include "studies/run/runner.hpp"
#include "studies/study/load_study.hpp"
#include "studies/study/study.hpp"
#include "tests/support/balance_motion.hpp"
#include "tests/support/planar_mechanisms.hpp"

namespace bd {
namespace {

namespace cp = core::planar;
using testing::planar::Rng;
using testing::planar::uniform;

constexpr double kG = 9.81;

core::FourBar loaded_fourbar(Rng& rng) {
  core::FourBar fb = testing::planar::random_fourbar(rng);
  fb.loads.gravity = Vec2(uniform(rng, -2, 2), -kG);
  for (core::LinkLoad* l : {&fb.loads.crank, &fb.loads.coupler, &fb.loads.rocker}) {
    l->force = Vec2(uniform(rng, -20, 20), uniform(rng, -20, 20));
    l->moment = uniform(rng, -5, 5);
  }
  return core::make_fourbar(fb);
}

// Σ m c and Σ (m c × ċ + I θ̇) terms need positions only: the centre of mass of link k at crank
// angle theta1 from the pose, and the link angles
struct MassState {
  Vec2 mc{0, 0};          // Σ m_k c_k [kg m]
  double angles[3]{};     // θ1, θ2, θ3
  Vec2 c[3];              // centres of mass
};

MassState mass_state(const core::FourBar& m, double theta1) {
  const auto pose = core::solve_position(m, theta1);
  EXPECT_TRUE(pose);
  MassState s;
  s.angles[0] = pose->theta1;
  s.angles[1] = pose->theta2;
  s.angles[2] = pose->theta3;
  for (int k = 1; k <= 3; ++k) {
    s.c[k - 1] = core::centre_of_mass(m, k, *pose);
    s.mc += core::link(m, k).mass * s.c[k - 1];
  }
  return s;
}

// a driven crank at constant ω: d/dt = ω d/dθ1. Inertial force -Σ m c̈ and moment -dH/dt by
// five-point central differences of positions in θ1 (step h: truncation ~h⁴, round-off
// ~eps/h²); H about A0 = Σ m c × ċ + I θ̇, differentiated once more by the same stencil
struct Inertial {
  Vec2 force;
  double moment;
};

Inertial by_differences(const core::FourBar& m, double theta1, double omega) {
  const double h = 2e-3;
  // the results evaluated (not Eigen expressions of temporaries)
  auto second = [&](auto f) -> std::decay_t<decltype(f(0.0))> {
    return (-f(theta1 + 2 * h) + 16.0 * f(theta1 + h) - 30.0 * f(theta1) + 16.0 * f(theta1 - h) -
            f(theta1 - 2 * h)) /
           (12 * h * h);
  };
  auto first = [&](auto f, double at) -> std::decay_t<decltype(f(0.0))> {
    return (-f(at + 2 * h) + 8.0 * f(at + h) - 8.0 * f(at - h) + f(at - 2 * h)) / (12 * h);
  };
  const Vec2 acc = omega * omega * second([&](double t) -> Vec2 { return mass_state(m, t).mc; });
  // angular momentum about A0 at crank angle t: Σ m c × dc/dt + I dθ/dt
  auto H = [&](double t) {
    double h_total = 0;
    for (int k = 0; k < 3; ++k) {
      const double mk = core::link(m, k + 1).mass, Ik = core::link(m, k + 1).inertia;
      const Vec2 c = mass_state(m, t).c[k];
      const Vec2 v = omega * first([&](double u) -> Vec2 { return mass_state(m, u).c[k]; }, t);
      const double w =
          omega * first([&](double u) { return mass_state(m, u).angles[k]; }, t);
      h_total += mk * (c.x() * v.y() - c.y() * v.x()) + Ik * w;
    }
    return h_total;
  };
  const double dH = omega * first(H, theta1);
  return {-acc, -dH};
}

TEST(ShakingParts, FourBarInertialPartIsMinusTheMassesAccelerationsStaticPartTheLoads) {
  Rng rng(16);
  for (int trial = 0; trial < 5; ++trial) {
    const core::FourBar fb = loaded_fourbar(rng);
    const double omega = uniform(rng, 3, 12) * (trial % 2 ? -1 : 1);
    // the loads by hand: Σ (F_k + m_k g), Σ (c_k × (F_k + m_k g) + M_k)
    for (double theta1 : {0.3, 1.7, 4.0}) {
      const MassState ms = mass_state(fb, theta1);
      Vec2 F(0, 0);
      double M = 0;
      for (int k = 1; k <= 3; ++k) {
        const Vec2 f = core::link_load(fb, k).force + core::link(fb, k).mass * fb.loads.gravity;
        F += f;
        M += ms.c[k - 1].x() * f.y() - ms.c[k - 1].y() * f.x() + core::link_load(fb, k).moment;
      }
      const Inertial ref = by_differences(fb, theta1, omega);
      for (core::Formulation form : core::kFormulations) {
        const auto s = core::inverse_dynamics(fb, theta1, omega, 0.0, form);
        ASSERT_TRUE(s);
        const double fscale = s->Fsh.norm() + F.norm() + s->Fsh_inertial.norm();
        const double mscale = std::abs(s->Msh) + std::abs(M) + std::abs(s->Msh_inertial);
        // the static part: the same sums, in another order
        EXPECT_NEAR((s->Fsh_static - F).norm(), 0.0, 1e-14 * fscale);
        EXPECT_NEAR(s->Msh_static, M, 1e-14 * mscale);
        // Newton's law: the total the formulation solved for is their sum
        EXPECT_NEAR((s->Fsh - s->Fsh_inertial - s->Fsh_static).norm(), 0.0, 1e-13 * fscale);
        EXPECT_NEAR(s->Msh, s->Msh_inertial + s->Msh_static, 1e-13 * mscale);
        // the inertial part against differences of positions (h = 2e-3: truncation h⁴ ω² ~ 1e-9
        // of the force, round-off eps/h² ~ 1e-10)
        EXPECT_NEAR((s->Fsh_inertial - ref.force).norm(), 0.0, 1e-7 * fscale);
        EXPECT_NEAR(s->Msh_inertial, ref.moment, 1e-7 * mscale);
      }
    }
  }
}

TEST(ShakingParts, ForceBalancedFourBarUnderGravityHasNoInertialShakingForce) {
  core::FourBar fb = core::samples::paper_fourbar_unloaded();
  fb.loads.gravity = Vec2(0, -kG);
  const balance::BalancedDesign b = balance::balance_design(core::make_fourbar(fb), {});
  ASSERT_TRUE(b.conditions.force_balanced());
  const double weight = core::total_mass(b.model) * kG;
  core::DrivenScene scene;
  scene.omega1 = 2 * std::numbers::pi;
  scene.samples = 90;
  for (core::Formulation form : core::kFormulations) {
    core::SimulateOptions options;
    options.formulation = form;
    const core::Trajectory t = core::simulate_driven(b.model, scene, options);
    ASSERT_TRUE(t.ok()) << t.message;
    for (const core::DynamicsSample& s : t.samples) {
      // zero to the round-off of reactions of about the weight and the inertia forces
      EXPECT_LT(s.Fsh_inertial.norm(), 1e-12 * weight);
      EXPECT_NEAR(s.Fsh_static.x(), 0.0, 1e-15 * weight);
      EXPECT_NEAR(s.Fsh_static.y(), -weight, 1e-14 * weight);
      // the frame still carries the weight
      EXPECT_NEAR(s.Fsh.y(), -weight, 1e-12 * weight);
    }
    const core::Metrics m = core::metrics(t);
    EXPECT_LT(m.Fsh_rms, 1e-12 * weight);
    EXPECT_LT(m.Fsh_max, 1e-12 * weight);
    EXPECT_NEAR(m.Fsh_total_rms, weight, 1e-12 * weight);
    EXPECT_NEAR(m.Fsh_total_max, weight, 1e-12 * weight);
  }
  // the general engine on the same design: the same split in its columns
  const cp::Model model(cp::linkage_of(b.model, 0.0));
  cp::DrivenScene ps;
  ps.speeds = {scene.omega1};
  ps.samples = 90;
  const cp::Trajectory pt = cp::simulate_driven(model, ps);
  ASSERT_TRUE(pt.ok()) << pt.message;
  const core::Trajectory back = cp::fourbar_trajectory(pt);
  for (const core::DynamicsSample& s : back.samples) {
    EXPECT_LT(s.Fsh_inertial.norm(), 1e-12 * weight);
    EXPECT_NEAR(s.Fsh_static.y(), -weight, 1e-14 * weight);
  }
  const std::vector<cp::ColumnMetric> table = cp::metric_table(model);
  const std::vector<double> values = cp::metric_values(table, pt.table);
  for (std::size_t k = 0; k < table.size(); ++k) {
    if (table[k].name == "Fsh_rms" || table[k].name == "Fsh_max") {
      EXPECT_LT(values[k], 1e-12 * weight) << table[k].name;
    }
    if (table[k].name == "Fsh_total_rms" || table[k].name == "Fsh_total_max") {
      EXPECT_NEAR(values[k], weight, 1e-12 * weight) << table[k].name;
    }
  }
}

TEST(ShakingParts, PlanarStaticPartIsTheLoadsAndTheTotalTheirSumWithTheInertialPart) {
  Rng rng(1616);
  for (int trial = 0; trial < 6; ++trial) {
    cp::Linkage l = testing::planar::slider_crank(rng, trial % 2 == 0);
    l.loads.gravity = Vec2(uniform(rng, -3, 3), -kG);
    if (l.springs.empty()) testing::planar::maybe_spring(l, rng, 1.0);  // (it has loads)
    l = cp::make_linkage(l);
    const cp::Model model(l);
    cp::DrivenScene scene;
    scene.speeds = {uniform(rng, 5, 20)};
    scene.samples = 40;
    const cp::Trajectory t = cp::simulate_driven(model, scene);
    ASSERT_TRUE(t.ok()) << t.message;
    const core::Series& s = t.table;
    auto col = [&](const char* name) { return static_cast<std::size_t>(s.column(name)); };
    for (std::size_t i = 0; i < s.rows(); ++i) {
      // the weights and loads by hand, from the row's own positions
      Vec2 F(0, 0);
      double M = 0;
      auto add = [&](const Vec2& f, const Vec2& at) {
        F += f;
        M += at.x() * f.y() - at.y() * f.x();
      };
      auto node_at = [&](int n) {
        const cp::Node& node = l.nodes[static_cast<std::size_t>(n)];
        if (node.ground) return node.position;
        return Vec2(s.at(i, col(("x_" + node.name).c_str())),
                    s.at(i, col(("y_" + node.name).c_str())));
      };
      for (std::size_t k = 0; k < l.links.size(); ++k) {
        const cp::Link& link = l.links[k];
        const Vec2 p = node_at(link.nodes[0]), q = node_at(link.nodes[1]);
        const Vec2 u = (q - p) / (q - p).norm();
        const Vec2 c = p + link.e * u + link.f * Vec2(-u.y(), u.x());
        add(link.mass * l.loads.gravity, c);
        for (const cp::LinkLoad& load : l.loads.link_loads) {
          if (load.link != static_cast<int>(k)) continue;
          add(load.force, c);
          M += load.moment;
        }
      }
      for (const cp::PointMass& pm : l.point_masses) add(pm.mass * l.loads.gravity, node_at(pm.node));
      for (const cp::NodeForce& nf : l.loads.node_forces) add(nf.force, node_at(nf.node));
      const Vec2 fs(s.at(i, col("Fshx_static")), s.at(i, col("Fshy_static")));
      const Vec2 fi(s.at(i, col("Fshx_inertial")), s.at(i, col("Fshy_inertial")));
      const Vec2 ft(s.at(i, col("Fshx")), s.at(i, col("Fshy")));
      const double ms = s.at(i, col("Msh_static")), mi = s.at(i, col("Msh_inertial")),
                   mt = s.at(i, col("Msh"));
      const double fscale = ft.norm() + fi.norm() + fs.norm();
      const double mscale = std::abs(mt) + std::abs(mi) + std::abs(ms);
      EXPECT_NEAR((fs - F).norm(), 0.0, 1e-13 * fscale);
      EXPECT_NEAR(ms, M, 1e-13 * mscale);
      // springs anchored to the frame and the drive's reaction cancel out of Newton's law
      EXPECT_NEAR((ft - fi - fs).norm(), 0.0, 1e-12 * fscale);
      EXPECT_NEAR(mt, mi + ms, 1e-12 * mscale);
    }
  }
}

// a study's outputs: the metrics, comparison rows and verdicts read the inertial part; the total
// is there beside it
TEST(ShakingParts, BalanceStudyUnderGravityComparesTheInertialShakingForce) {
  std::ifstream in(std::string(BD_SOURCE_DIR) +
                   "/studies/examples/paper-fourbar-driven-force-balanced.yaml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  text += "\nloads:\n  gravity: [0, -9.81]\n";
  const studies::Study study = studies::parse_study(text, "gravity.yaml");
  const studies::RunResult r = studies::compute_study(study);
  ASSERT_TRUE(r.ok());
  const double weight = core::total_mass(study.balance->model) * kG;
  auto value = [](const studies::MetricList& list, const std::string& name) {
    for (const studies::MetricValue& m : list)
      if (m.name == name) return m.value;
    ADD_FAILURE() << name << " missing";
    return std::nan("");
  };
  const studies::MetricList& after = r.balanced->metric_list;
  EXPECT_LT(value(after, "Fsh_rms"), 1e-12 * weight);
  EXPECT_LT(value(after, "Fsh_max"), 1e-12 * weight);
  EXPECT_NEAR(value(after, "Fsh_total_rms"), weight, 1e-12 * weight);
  // the original's inertial part is that of the same linkage without gravity
  const studies::RunResult r0 = studies::compute_study(studies::parse_study(
      text.substr(0, text.find("\nloads:")), "no-gravity.yaml"));
  EXPECT_NEAR(value(r.metric_list, "Fsh_rms"), value(r0.metric_list, "Fsh_rms"),
              1e-12 * value(r0.metric_list, "Fsh_rms"));
  EXPECT_NEAR(value(r.metric_list, "Msh_rms"), value(r0.metric_list, "Msh_rms"),
              1e-12 * value(r0.metric_list, "Msh_rms"));
  for (const studies::ComparisonRow& row : studies::comparison(study, r)) {
    if (row.metric == "Fsh_rms") {
      ASSERT_TRUE(row.ratio);
      EXPECT_LT(*row.ratio, 1e-12);
    }
  }
}

}  // namespace
}  // namespace bd
