// Where each formulation of the four-bar dynamics degrades (docs/failure-domains.md).
//
//   failure_domains [OUT_DIR] [--svg DIR]
//
// Measures every available formulation against a long-double Newton-Euler reference
// (bench/reference_ld.hpp) in three families of cases and prints markdown tables:
//   1. the reference itself against the double referee (tests/reference) on ordinary states;
//   2. the approach to a limit (dead-centre) position, sin(theta3 - theta2) -> 0, for a triple
//      rocker (|A1A3| -> l2 + l3) and a folding linkage (|A1A3| -> |l2 - l3|), at distances
//      d = 1e-1 .. 1e-15 rad in the crank angle, and what happens at the limit itself;
//   3. vanishing masses m_k -> 0, zero inertias, centres of mass on a joint.
// CSVs go to OUT_DIR (default build/failure-domains/), the charts (gnuplot) to
// docs/figures/failure-*.svg (or --svg DIR).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "tests/reference/reference_ld.hpp"
#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/kinematics.hpp"
#include "core/fourbar/mass_matrix.hpp"
#include "core/fourbar/model.hpp"
#include "core/fourbar/principal_vectors.hpp"
#include "core/fourbar/samples.hpp"
#include "tests/reference/newton_euler.hpp"
#include "core/fourbar/opened_loop.hpp"
#include "core/fourbar/complex_masses.hpp"

namespace {

using namespace bd;
using namespace bd::core;
using reference::RefPose;
using reference::RefSample;
using ld = long double;
using Result = Expected<DynamicsSample, DynamicsError>;

constexpr double kEps = std::numeric_limits<double>::epsilon();

// ---------------------------------------------------------------------------------------------
// the formulations under test

struct Method {
  const char* name;
  std::function<Result(const FourBar&, double, double)> forward;
  std::function<Result(const FourBar&, double, double, double)> inverse;
};

std::vector<Method> methods() {
  std::vector<Method> out;
  out.push_back({"mass-matrix", forward_dynamics_mass_matrix, inverse_dynamics_mass_matrix});
  out.push_back({"opened-loop",
                 [](const FourBar& m, double t1, double w1) {
                   return forward_dynamics_opened_loop(m, t1, w1);
                 },
                 [](const FourBar& m, double t1, double w1, double a1) {
                   return inverse_dynamics_opened_loop(m, t1, w1, a1);
                 }});
  out.push_back({"complex-masses",
                 [](const FourBar& m, double t1, double w1) {
                   return forward_dynamics_complex_masses(m, t1, w1);
                 },
                 [](const FourBar& m, double t1, double w1, double a1) {
                   return inverse_dynamics_complex_masses(m, t1, w1, a1);
                 }});
  // the reference's own algorithm at working precision: what a plain double computation of the
  // same physics gives (not a product formulation)
  out.push_back({"newton-euler(double)",
                 [](const FourBar& m, double t1, double w1) -> Result {
                   const auto p = reference::ref_position<double>(m, t1);
                   if (!p) return Unexpected(DynamicsError{DynamicsError::Kind::kAssembly, t1, ""});
                   const RefSample<double> r = reference::ref_forward<double>(m, *p, w1);
                   DynamicsSample s;
                   s.state.theta1 = t1;
                   s.state.theta2 = p->theta2;
                   s.state.theta3 = p->theta3;
                   s.state.alpha1 = r.alpha1;
                   s.RA0 = Vec2(r.RA0x, r.RA0y);
                   s.RA3 = Vec2(r.RA3x, r.RA3y);
                   return s;
                 },
                 [](const FourBar& m, double t1, double w1, double a1) -> Result {
                   const auto p = reference::ref_position<double>(m, t1);
                   if (!p) return Unexpected(DynamicsError{DynamicsError::Kind::kAssembly, t1, ""});
                   const RefSample<double> r = reference::ref_inverse<double>(m, *p, w1, a1);
                   DynamicsSample s;
                   s.state.theta1 = t1;
                   s.state.theta2 = p->theta2;
                   s.state.theta3 = p->theta3;
                   s.state.alpha1 = a1;
                   s.tau = r.tau;
                   s.RA0 = Vec2(r.RA0x, r.RA0y);
                   s.RA3 = Vec2(r.RA3x, r.RA3y);
                   return s;
                 }});
  return out;
}

// ---------------------------------------------------------------------------------------------
// outcomes and errors

enum class Status { kOk, kAssembly, kSingular, kNonFinite, kSilentNonFinite };
const char* to_text(Status s) {
  switch (s) {
    case Status::kOk: return "ok";
    case Status::kAssembly: return "kAssembly";
    case Status::kSingular: return "kSingular";
    case Status::kNonFinite: return "kNonFinite";
    case Status::kSilentNonFinite: return "SILENT-NaN";
  }
  return "?";
}

Status status_of(const Result& r) {
  if (!r) {
    switch (r.error().kind) {
      case DynamicsError::Kind::kAssembly: return Status::kAssembly;
      case DynamicsError::Kind::kSingular: return Status::kSingular;
      case DynamicsError::Kind::kNonFinite: return Status::kNonFinite;
    }
  }
  const DynamicsSample& s = *r;
  const bool finite = std::isfinite(s.state.alpha1) && std::isfinite(s.tau) &&
                      s.RA0.allFinite() && s.RA3.allFinite();
  return finite ? Status::kOk : Status::kSilentNonFinite;
}

struct Errors {
  double main = 0;  // |x - x_ref| / |x_ref|, x = alpha1 (forward) or tau (inverse)
  double R = 0;     // max(|dRA0|, |dRA3|) / max(|RA0_ref|, |RA3_ref|)
};

ld hypot_ld(ld x, ld y) { return std::sqrt(x * x + y * y); }

Errors errors_of(const DynamicsSample& s, const RefSample<ld>& r, bool inverse) {
  Errors e;
  const ld x = inverse ? ld(s.tau) : ld(s.state.alpha1);
  const ld xr = inverse ? r.tau : r.alpha1;
  e.main = static_cast<double>(std::abs(x - xr) / (xr != 0 ? std::abs(xr) : ld(1)));
  const ld d0 = hypot_ld(ld(s.RA0.x()) - r.RA0x, ld(s.RA0.y()) - r.RA0y);
  const ld d3 = hypot_ld(ld(s.RA3.x()) - r.RA3x, ld(s.RA3.y()) - r.RA3y);
  const ld scale = std::max(hypot_ld(r.RA0x, r.RA0y), hypot_ld(r.RA3x, r.RA3y));
  e.R = static_cast<double>(std::max(d0, d3) / (scale > 0 ? scale : ld(1)));
  return e;
}

std::string sci(double x, int digits = 1) {
  char buf[32];
  if (x == 0) return "0";
  std::snprintf(buf, sizeof buf, "%.*e", digits, x);
  return buf;
}
std::string num(ld x) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.10Lg", x);
  return buf;
}

// ---------------------------------------------------------------------------------------------
// linkages

// loads and gravity so that no output vanishes identically at rest
FourBar with_loads(const FourBar& m) { return samples::with_paper_loads(m, Vec2(0.0, -9.81)); }
FourBar folding_rocker() { return with_loads(samples::folding_rocker()); }

struct Limit {
  const char* name;
  FourBar model;
  ld theta_lim;  // [rad], long double
  int inside;    // +1 if assemblable for theta1 > theta_lim, -1 if below
};

std::vector<Limit> limits() {
  std::vector<Limit> out;
  {
    const FourBar m = with_loads(samples::triple_rocker());
    const ld t = reference::limit_angle(m, ld(m.coupler.length) + ld(m.rocker.length));
    out.push_back({"triple-rocker (l23 -> l2+l3)", m, t, -1});
  }
  {
    const FourBar m = folding_rocker();
    const ld t = reference::limit_angle(m, std::abs(ld(m.coupler.length) - ld(m.rocker.length)));
    out.push_back({"folding-rocker (l23 -> |l2-l3|)", m, t, +1});
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// conditioning indicators, recomputed here from the paper's equations (long double)

template <class T>
using V2 = Eigen::Matrix<T, 2, 1>;
V2<ld> vld(const Vec2& v) { return {ld(v.x()), ld(v.y())}; }
V2<ld> rot(const V2<ld>& v) { return {-v.y(), v.x()}; }
V2<ld> dir(ld t) { return {std::cos(t), std::sin(t)}; }

struct Conditioning {
  double cond5 = 0;      // 2-norm condition of the opened loop's 5x5 matrix (eqs. 22, 27)
  double kappa_mm = 0;   // cancellation factor of the mass-matrix reduced equation's dot product
  double kappa_red = 0;  // same for the Θ-reduced equation in the link angles (complex masses)
};

Conditioning conditioning(const FourBar& m, const RefSample<ld>& r, bool inverse) {
  const std::array<ld, 3> th{r.pose.theta1, r.pose.theta2, r.pose.theta3};
  const std::array<ld, 3> Th{1, r.dtheta2_dtheta1, r.dtheta3_dtheta1},
      om{r.omega1, r.omega2, r.omega3}, al{r.alpha1, r.alpha2, r.alpha3};
  std::array<V2<ld>, 3> lv;
  for (int k = 0; k < 3; ++k) lv[k] = ld(link(m, k + 1).length) * dir(th[k]);
  Conditioning c;

  // opened loop: [M D; Dᵀ 0] with the constant-diagonal mass matrix of eq. 22 and D of eq. 24
  {
    const Pose pose{double(th[0]), double(th[1]), double(th[2])};
    const OpenedLoopVectors a = opened_loop_vectors(m, pose);
    const double mt = total_mass(m);
    const Link &L1 = m.crank, &L2 = m.coupler, &L3 = m.rocker;
    Mat5 K = Mat5::Zero();
    K(0, 0) = L1.inertia + L1.mass * (L1.e * L1.e + L1.f * L1.f) +
              (L2.mass + L3.mass) * L1.length * L1.length;
    K(1, 1) = L2.inertia + L2.mass * (L2.e * L2.e + L2.f * L2.f) + L3.mass * L2.length * L2.length;
    K(2, 2) = L3.inertia + L3.mass * (L3.e * L3.e + L3.f * L3.f);
    const Vec2 l1 = L1.length * unit(pose.theta1), l2 = L2.length * unit(pose.theta2),
               l3 = L3.length * unit(pose.theta3);
    K(0, 1) = K(1, 0) = -mt * l1.dot(a.a21);
    K(0, 2) = K(2, 0) = -mt * l1.dot(a.a32);
    K(1, 2) = K(2, 1) = -mt * l2.dot(a.a32);
    const std::array<Vec2, 3> lvd{l1, l2, l3};
    for (int j = 0; j < 3; ++j) {
      K.block<1, 2>(j, 3) = perp(lvd[j]).transpose();
      K.block<2, 1>(3, j) = perp(lvd[j]);
    }
    if (inverse) {  // theta1'' known, tau unknown: its column is -e1 (tau enters Q1)
      K.col(0).setZero();
      K(0, 0) = -1;
    }
    // dynamic size: GCC 12 warns falsely (maybe-uninitialized) on the fixed-size SVD
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd{Eigen::MatrixXd(K)};
    const Eigen::VectorXd sv = svd.singularValues();
    c.cond5 = sv(0) / sv(sv.size() - 1);
  }

  // joint accelerations and centre-of-mass accelerations of the reference state
  const V2<ld> A1 = lv[0], A2 = lv[0] + lv[1];
  const V2<ld> aA1 = al[0] * rot(lv[0]) - om[0] * om[0] * lv[0];
  const V2<ld> aA2 = aA1 + al[1] * rot(lv[1]) - om[1] * om[1] * lv[1];
  const V2<ld> g = vld(m.loads.gravity);

  // mass matrix: the reduced equation Jᵀ(M r̈ - F) = tau over the moving joints; forward uses
  // its right-hand side at alpha1 = 0 (the numerator of alpha1)
  {
    const Mat4 M = system_mass_matrices(m).M;
    const std::array<Vec2, 4> nodes{Vec2(0, 0), Vec2(double(A1.x()), double(A1.y())),
                                    Vec2(double(A2.x()), double(A2.y())),
                                    Vec2(m.frame_length, 0)};
    Eigen::Matrix<double, 8, 1> F = Eigen::Matrix<double, 8, 1>::Zero();
    for (int k = 1; k <= 3; ++k) {
      const Link& l = link(m, k);
      const LinkLoad& q = link_load(m, k);
      const Vec2 p = nodes[k - 1], qq = p + l.length * unit(double(th[k - 1]));
      F.segment<4>(2 * (k - 1)) +=
          link_nodal_forces(l, q.force + l.mass * m.loads.gravity, q.moment, p, qq);
    }
    const V2<ld> J1 = rot(lv[0]), J2 = J1 + r.dtheta2_dtheta1 * rot(lv[1]);
    Eigen::Matrix<ld, 4, 1> J, acc;
    J << J1.x(), J1.y(), J2.x(), J2.y();
    // r̈ at the state's alpha1 (inverse) or at alpha1 = 0 (forward numerator)
    const ld a1 = inverse ? r.alpha1 : 0;
    const V2<ld> bA1 = a1 * rot(lv[0]) - om[0] * om[0] * lv[0];
    const V2<ld> bA2 =
        bA1 + (r.dtheta2_dtheta1 * a1 + r.gamma2) * rot(lv[1]) - om[1] * om[1] * lv[1];
    acc << bA1.x(), bA1.y(), bA2.x(), bA2.y();
    const Eigen::Matrix<ld, 4, 1> res = M.cast<ld>() * acc - F.segment<4>(2).cast<ld>();
    ld sum = 0, sum_abs = 0;
    for (int i = 0; i < 4; ++i) {
      sum += J(i) * res(i);
      sum_abs += std::abs(J(i) * res(i));
    }
    c.kappa_mm = static_cast<double>(sum_abs / std::abs(sum));
  }

  // Θ-reduction of the opened loop's link equations E_j = generalized force of coordinate
  // theta_j (link j about its first joint, the distal links translated): Σ Θj Ej = tau
  {
    const ld a1 = inverse ? r.alpha1 : 0;
    const std::array<ld, 3> alk{a1, r.dtheta2_dtheta1 * a1 + r.gamma2,
                                r.dtheta3_dtheta1 * a1 + r.gamma3};
    std::array<V2<ld>, 4> p, ap;
    p[0] = V2<ld>::Zero();
    ap[0] = V2<ld>::Zero();
    for (int k = 0; k < 3; ++k) {
      p[k + 1] = p[k] + lv[k];
      ap[k + 1] = ap[k] + alk[k] * rot(lv[k]) - om[k] * om[k] * lv[k];
    }
    std::array<V2<ld>, 3> cm, force;  // centre of mass and (applied - inertia) force
    std::array<ld, 3> moment{};
    for (int k = 0; k < 3; ++k) {
      const Link& l = link(m, k + 1);
      const LinkLoad& q = link_load(m, k + 1);
      const V2<ld> u = dir(th[k]);
      const V2<ld> rho = ld(l.e) * u + ld(l.f) * rot(u);
      cm[k] = p[k] + rho;
      const V2<ld> acm = ap[k] + alk[k] * rot(rho) - om[k] * om[k] * rho;
      force[k] = vld(q.force) + ld(l.mass) * (g - acm);
      moment[k] = ld(q.moment) - ld(l.inertia) * alk[k];
    }
    ld sum = 0, sum_abs = 0;
    for (int j = 0; j < 3; ++j) {
      ld E = moment[j] + rot(cm[j] - p[j]).dot(force[j]);
      for (int k = j + 1; k < 3; ++k) E += rot(lv[j]).dot(force[k]);
      sum += Th[j] * E;
      sum_abs += std::abs(Th[j] * E);
    }
    c.kappa_red = static_cast<double>(sum_abs / std::abs(sum));
  }
  (void)aA2;
  return c;
}

// ---------------------------------------------------------------------------------------------
// 1. the reference against the double referee on ordinary states

void check_reference(std::ostream& csv) {
  std::printf("## 1. Long-double reference against the double referee\n\n");
  csv << "linkage,theta1,rel_diff_forward,rel_diff_inverse,rel_diff_ref_double_vs_ld\n";
  double worst_ne = 0, worst_self = 0;
  std::vector<double> all_ne;
  int states = 0;
  std::mt19937_64 rng(20240611);
  std::vector<std::pair<std::string, FourBar>> models{{"paper", samples::paper_fourbar()},
                                                      {"double-crank", samples::double_crank()}};
  for (int i = 0; i < 20; ++i) models.push_back({"random" + std::to_string(i),
                                                 samples::random_crank_rocker(rng)});
  for (const auto& [name, m] : models) {
    for (int i = 0; i < 36; ++i) {
      const double t1 = 2 * std::numbers::pi * i / 36 + 0.01;
      const auto pl = reference::ref_position<ld>(m, t1);
      if (!pl) continue;
      const double w1 = 1.7, a1 = -0.6;
      const RefSample<ld> rf = reference::ref_forward<ld>(m, *pl, w1);
      const RefSample<ld> ri = reference::ref_inverse<ld>(m, *pl, w1, a1);
      const DynamicsSample nf = reference::newton_euler_forward(m, t1, w1);
      const DynamicsSample ni = reference::newton_euler_inverse(m, t1, w1, a1);
      // sizes: forces by the largest reaction, alpha1 and tau by their own size (>= 1)
      auto diff = [](const DynamicsSample& s, const RefSample<ld>& r, bool inv) {
        const Errors e = errors_of(s, r, inv);
        return std::max(e.main, e.R);
      };
      const double df = diff(nf, rf, false), di = diff(ni, ri, true);
      const auto pd = reference::ref_position<double>(m, t1);
      const RefSample<double> rd = reference::ref_forward<double>(m, *pd, w1);
      DynamicsSample sd;
      sd.state.alpha1 = rd.alpha1;
      sd.RA0 = Vec2(rd.RA0x, rd.RA0y);
      sd.RA3 = Vec2(rd.RA3x, rd.RA3y);
      const double ds = diff(sd, rf, false);
      worst_ne = std::max({worst_ne, df, di});
      all_ne.push_back(std::max(df, di));
      worst_self = std::max(worst_self, ds);
      ++states;
      char line[160];
      std::snprintf(line, sizeof line, "%s,%.17g,%.3e,%.3e,%.3e\n", name.c_str(), t1, df, di, ds);
      csv << line;
    }
  }
  std::sort(all_ne.begin(), all_ne.end());
  std::printf("| states | referee (double) vs long double: median | max | "
              "same algorithm in double vs long double: max |\n|---|---|---|---|\n");
  std::printf("| %d (paper, double crank, 20 random crank-rockers x 36 angles; fwd + inv) | %s | "
              "%s | %s |\n\n",
              states, sci(all_ne[all_ne.size() / 2]).c_str(), sci(worst_ne).c_str(),
              sci(worst_self).c_str());
}

// ---------------------------------------------------------------------------------------------
// 2. approach to a limit position

struct Case {
  const char* name;
  bool inverse;
  // crank rate [rad/s] and acceleration [rad/s^2] from the reference pose's Θ3
  std::function<double(ld dtheta3_dtheta1)> omega1;
  double alpha1;
};

std::vector<Case> cases() {
  return {
      {"fwd-rest", false, [](ld) { return 0.0; }, 0},
      {"fwd-crank-rate", false, [](ld) { return 1.0; }, 0},
      {"fwd-rocker-rate", false, [](ld T3) { return static_cast<double>(1 / T3); }, 0},
      {"inv-crank-rate", true, [](ld) { return 1.0; }, 0.5},
      {"inv-rest", true, [](ld) { return 0.0; }, 0.5},
  };
}

std::vector<double> distances() {
  std::vector<double> d;
  for (int k = 2; k <= 30; ++k) d.push_back(std::pow(10.0, -0.5 * k));
  return d;
}

void singular_study(const std::vector<Method>& ms, const std::filesystem::path& out) {
  for (const auto& entry : std::filesystem::directory_iterator(out)) {
    if (entry.path().extension() == ".dat") std::filesystem::remove(entry.path());
  }
  std::ofstream err(out / "singular_errors.csv"), cond(out / "singular_conditioning.csv");
  err << "linkage,case,d,sin_mu,method,status,err_main,err_R,err_main_at_pose,err_R_at_pose\n";
  cond << "linkage,case,d,sin_mu,Theta3,ref_main,ref_RA0,ref_RA3,cond5,kappa_mm,kappa_red,"
          "ne_rcond\n";
  std::printf("## 2. Approach to a limit position\n\n");
  bool first_linkage = true;
  for (const Limit& L : limits()) {
    std::printf("### %s: theta1_limit = %s rad\n\n", L.name, num(L.theta_lim).c_str());
    for (const Case& c : cases()) {
      std::printf("#### %s (%s)\n\n", L.name, c.name);
      std::printf("| d [rad] | sin mu | |Theta3| | |%s| ref | |RA| ref | cond 5x5 | kappa mm | "
                  "kappa red |",
                  c.inverse ? "tau" : "alpha1");
      for (const Method& m : ms) std::printf(" %s err(%s / R) |", m.name, c.inverse ? "tau" : "a1");
      std::printf("\n|---|---|---|---|---|---|---|---|");
      for (size_t i = 0; i < ms.size(); ++i) std::printf("---|");
      std::printf("\n");
      for (double d : distances()) {
        const double t1 = static_cast<double>(L.theta_lim + ld(L.inside) * ld(d));
        const ld d_true = (ld(t1) - L.theta_lim) * ld(L.inside);
        const auto pose = reference::ref_position<ld>(L.model, ld(t1));
        if (!pose || d_true <= 0) continue;
        // Θ3 of the pose: a throw-away forward solve at rest
        const ld T3 = reference::ref_forward<ld>(L.model, *pose, 0).dtheta3_dtheta1;
        const double w1 = c.omega1(T3), a1 = c.alpha1;
        const RefSample<ld> ref = c.inverse ? reference::ref_inverse<ld>(L.model, *pose, w1, a1)
                                            : reference::ref_forward<ld>(L.model, *pose, w1);
        const Conditioning k = conditioning(L.model, ref, c.inverse);
        const ld main_ref = c.inverse ? ref.tau : ref.alpha1;
        const ld ra0 = hypot_ld(ref.RA0x, ref.RA0y), ra3 = hypot_ld(ref.RA3x, ref.RA3y);
        char line[400];
        std::snprintf(line, sizeof line, "%s,%s,%.6Le,%.6Le,%.6Le,%.6Le,%.6Le,%.6Le,%.3e,%.3e,%.3e,%.3Le\n",
                      L.name, c.name, d_true, std::abs(pose->sin_mu), std::abs(T3),
                      std::abs(main_ref), ra0, ra3, k.cond5, k.kappa_mm, k.kappa_red,
                      ref.lu_rcond);
        cond << line;
        std::printf("| %s | %s | %s | %s | %s | %s | %s | %s |", sci(double(d_true)).c_str(),
                    sci(double(std::abs(pose->sin_mu))).c_str(), sci(double(std::abs(T3))).c_str(),
                    sci(double(std::abs(main_ref))).c_str(),
                    sci(double(std::max(ra0, ra3))).c_str(), sci(k.cond5).c_str(),
                    sci(k.kappa_mm).c_str(), sci(k.kappa_red).c_str());
        for (const Method& m : ms) {
          const Result r = c.inverse ? m.inverse(L.model, t1, w1, a1) : m.forward(L.model, t1, w1);
          const Status st = status_of(r);
          Errors e{NAN, NAN}, ep{NAN, NAN};
          if (st == Status::kOk) {
            e = errors_of(*r, ref, c.inverse);
            // the dynamics stage alone: the reference at the formulation's own (double) pose
            const RefPose<ld> p = reference::ref_pose_from_angles<ld>(
                ld(t1), ld(r->state.theta2), ld(r->state.theta3));
            const RefSample<ld> refp = c.inverse ? reference::ref_inverse<ld>(L.model, p, w1, a1)
                                                 : reference::ref_forward<ld>(L.model, p, w1);
            ep = errors_of(*r, refp, c.inverse);
            std::printf(" %s / %s |", sci(e.main).c_str(), sci(e.R).c_str());
          } else {
            std::printf(" %s |", to_text(st));
          }
          std::snprintf(line, sizeof line, "%s,%s,%.6Le,%.6Le,%s,%s,%.3e,%.3e,%.3e,%.3e\n",
                        L.name, c.name, d_true, std::abs(pose->sin_mu), m.name, to_text(st),
                        e.main, e.R, ep.main, ep.R);
          err << line;
          if (first_linkage && st == Status::kOk) {
            // one whitespace-separated file per case and formulation, for gnuplot
            std::ofstream dat(out / (std::string("chart_") + c.name + "_" + m.name + ".dat"),
                              std::ios::app);
            std::snprintf(line, sizeof line, "%.6Le %.6Le %.3e %.3e %.3e %.3e\n", d_true,
                          std::abs(pose->sin_mu), std::max(e.main, 1e-17), std::max(e.R, 1e-17),
                          std::max(ep.main, 1e-17), std::max(ep.R, 1e-17));
            dat << line;
          }
        }
        std::printf("\n");
      }
      std::printf("\n");
    }
    first_linkage = false;
  }
}

// what each formulation returns on the doubles nearest the limit
void at_limit_study(const std::vector<Method>& ms, const std::filesystem::path& out) {
  std::ofstream csv(out / "at_limit.csv");
  csv << "linkage,ulps,theta1,d,core_sin_mu,method,forward_status,forward_err,inverse_status,"
         "inverse_err\n";
  std::printf("## 3. At the limit: the doubles nearest theta1_limit\n\n");
  std::printf("Offsets in ulps towards the assemblable side (negative: beyond the limit). "
              "Forward at omega1 = 1 rad/s, inverse at omega1 = 1 rad/s, alpha1 = 0.5 rad/s^2. "
              "`core sin mu` is sin(theta3 - theta2) of core::solve_position.\n\n");
  for (const Limit& L : limits()) {
    std::printf("### %s\n\n| ulps | d [rad] | core sin mu |", L.name);
    for (const Method& m : ms) std::printf(" %s fwd | %s inv |", m.name, m.name);
    std::printf("\n|---|---|---|");
    for (size_t i = 0; i < ms.size(); ++i) std::printf("---|---|");
    std::printf("\n");
    const double t0 = static_cast<double>(L.theta_lim);
    const double toward = L.inside > 0 ? 10.0 : -10.0, away = -toward;
    for (int u = -3; u <= 12; ++u) {
      double t1 = t0;
      for (int i = 0; i < std::abs(u); ++i) t1 = std::nextafter(t1, u > 0 ? toward : away);
      const ld d = (ld(t1) - L.theta_lim) * ld(L.inside);
      const auto cp = solve_position(L.model, t1);
      const double core_sin = cp ? std::sin(cp->theta3 - cp->theta2) : NAN;
      const auto pose = reference::ref_position<ld>(L.model, ld(t1));
      std::printf("| %+d | %s | %s |", u, sci(double(d), 2).c_str(),
                  cp ? sci(core_sin, 2).c_str() : "no pose");
      for (const Method& m : ms) {
        const Result f = m.forward(L.model, t1, 1.0);
        const Result v = m.inverse(L.model, t1, 1.0, 0.5);
        const Status sf = status_of(f), sv = status_of(v);
        double ef = NAN, ev = NAN;
        if (pose && sf == Status::kOk)
          ef = errors_of(*f, reference::ref_forward<ld>(L.model, *pose, 1.0), false).main;
        if (pose && sv == Status::kOk)
          ev = errors_of(*v, reference::ref_inverse<ld>(L.model, *pose, 1.0, 0.5), true).main;
        auto cell = [](Status s, double e) {
          return s == Status::kOk ? "ok, err " + sci(e) : std::string(to_text(s));
        };
        std::printf(" %s | %s |", cell(sf, ef).c_str(), cell(sv, ev).c_str());
        char line[300];
        std::snprintf(line, sizeof line, "%s,%d,%.17g,%.3Le,%.3e,%s,%s,%.3e,%s,%.3e\n", L.name,
                      u, t1, d, core_sin, m.name, to_text(sf), ef, to_text(sv), ev);
        csv << line;
      }
      std::printf("\n");
    }
    std::printf("\n");
  }
}

// ---------------------------------------------------------------------------------------------
// 4. vanishing masses, zero inertia, centre of mass on a joint

struct MassOutcome {
  double err_fwd = 0, err_inv = 0, err_R = 0;  // worst over the states (ok ones)
  int ok = 0, errors = 0, silent = 0;          // counts over forward + inverse evaluations
  std::string first_error;
};

MassOutcome run_states(const Method& method, const FourBar& m) {
  MassOutcome o;
  for (int i = 0; i < 12; ++i) {
    const double t1 = 2 * std::numbers::pi * i / 12 + 0.1;
    const double w1 = 1.3, a1 = 0.5;
    const auto pose = reference::ref_position<ld>(m, ld(t1));
    if (!pose) continue;
    for (bool inv : {false, true}) {
      const Result r = inv ? method.inverse(m, t1, w1, a1) : method.forward(m, t1, w1);
      const Status st = status_of(r);
      if (st == Status::kOk) {
        const RefSample<ld> ref = inv ? reference::ref_inverse<ld>(m, *pose, w1, a1)
                                      : reference::ref_forward<ld>(m, *pose, w1);
        const Errors e = errors_of(*r, ref, inv);
        (inv ? o.err_inv : o.err_fwd) = std::max(inv ? o.err_inv : o.err_fwd, e.main);
        o.err_R = std::max(o.err_R, e.R);
        ++o.ok;
      } else if (st == Status::kSilentNonFinite) {
        ++o.silent;
      } else {
        ++o.errors;
        if (o.first_error.empty()) o.first_error = r.error().what();
      }
    }
  }
  return o;
}

std::string outcome_cell(const MassOutcome& o) {
  if (o.silent > 0) return "**SILENT NaN x" + std::to_string(o.silent) + "**";
  if (o.ok == 0) return "error (all)";
  std::string s = sci(std::max({o.err_fwd, o.err_inv, o.err_R}));
  if (o.errors > 0) s += " (+" + std::to_string(o.errors) + " errors)";
  return s;
}

void mass_study(const std::vector<Method>& ms, const std::filesystem::path& out) {
  std::ofstream csv(out / "masses.csv");
  csv << "variant,link,value,method,ok,errors,silent,err_alpha1,err_tau,err_R,first_error\n";
  std::printf("## 4. Vanishing masses, zero inertia, centre of mass on a joint (paper four-bar)\n\n");
  std::printf("Worst relative error over 12 crank angles x (forward at omega1 = 1.3 rad/s, inverse "
              "at alpha1 = 0.5 rad/s^2): max of alpha1, tau and reactions (relative to the larger "
              "reaction). m_tot = %.1f kg nominal.\n\n",
              total_mass(samples::paper_fourbar()));
  const std::vector<double> masses{1e-1,  1e-2,   1e-3,   1e-4,
                                   1e-6,  1e-8,   1e-12,  1e-16,
                                   1e-100, 1e-300, std::numeric_limits<double>::denorm_min()};
  auto emit = [&](const char* variant, int k, double value, const FourBar& m) {
    for (const Method& meth : ms) {
      const MassOutcome o = run_states(meth, m);
      std::printf(" %s |", outcome_cell(o).c_str());
      std::string fe = o.first_error;
      std::replace(fe.begin(), fe.end(), ',', ';');
      char line[600];
      std::snprintf(line, sizeof line, "%s,%d,%.3e,%s,%d,%d,%d,%.3e,%.3e,%.3e,\"%s\"\n", variant, k,
                    value, meth.name, o.ok, o.errors, o.silent, o.err_fwd, o.err_inv, o.err_R,
                    fe.c_str());
      csv << line;
    }
    std::printf("\n");
  };
  auto header = [&](const char* first) {
    std::printf("| %s |", first);
    for (const Method& m : ms) std::printf(" %s |", m.name);
    std::printf("\n|---|");
    for (size_t i = 0; i < ms.size(); ++i) std::printf("---|");
    std::printf("\n");
  };
  for (bool zero_inertia : {false, true}) {
    for (int k = 1; k <= 3; ++k) {
      std::printf("### m%d -> 0%s\n\n", k, zero_inertia ? " with I" : " (I kept)");
      header(zero_inertia ? "m_k [kg], I_k = 0" : "m_k [kg]");
      for (double mk : masses) {
        FourBar m = samples::paper_fourbar();
        Link& l = k == 1 ? m.crank : (k == 2 ? m.coupler : m.rocker);
        l.mass = mk;
        if (zero_inertia) l.inertia = 0;
        m = make_fourbar(m);
        std::printf("| %s |", sci(mk).c_str());
        emit(zero_inertia ? "mass_and_inertia" : "mass", k, mk, m);
      }
      std::printf("\n");
    }
  }
  std::printf("### Zero inertia and centre of mass on a joint (nominal masses)\n\n");
  header("variant");
  for (int k = 1; k <= 3; ++k) {
    struct V {
      const char* name;
      std::function<void(Link&)> apply;
    };
    const std::vector<V> vs{{"I = 0", [](Link& l) { l.inertia = 0; }},
                            {"e = f = 0 (on first joint)", [](Link& l) { l.e = l.f = 0; }},
                            {"e = l, f = 0 (on second joint)", [](Link& l) { l.e = l.length; l.f = 0; }},
                            {"on first joint and I = 0", [](Link& l) { l.e = l.f = 0; l.inertia = 0; }},
                            {"on second joint and I = 0",
                             [](Link& l) { l.e = l.length; l.f = 0; l.inertia = 0; }}};
    for (const V& v : vs) {
      FourBar m = samples::paper_fourbar();
      v.apply(k == 1 ? m.crank : (k == 2 ? m.coupler : m.rocker));
      m = make_fourbar(m);
      std::printf("| %s: %s |", link_name(k), v.name);
      emit(v.name, k, 0, m);
    }
  }
  std::printf("\n");
}

// the constant K of the law err = K eps m_tot / m_k over random linkages (loads and gravity on)
void mass_law_study(const std::vector<Method>& ms, const std::filesystem::path& out) {
  std::ofstream csv(out / "mass_law.csv");
  csv << "model,link,ratio,method,K_alpha1,K_tau,K_R\n";
  std::printf("### Growth constant K in err = K eps m_tot / m_k (40 random crank-rockers with loads "
              "and gravity, m_k = 1e-6 m_tot, 12 angles each)\n\n| link |");
  for (const Method& m : ms) std::printf(" %s K(alpha1, tau / R) |", m.name);
  std::printf("\n|---|");
  for (size_t i = 0; i < ms.size(); ++i) std::printf("---|");
  std::printf("\n");
  constexpr double ratio = 1e-6;
  for (int k = 1; k <= 3; ++k) {
    std::vector<std::array<double, 2>> worst(ms.size(), {0.0, 0.0});
    std::mt19937_64 rng(7 + k);
    for (int i = 0; i < 40; ++i) {
      FourBar m = samples::random_crank_rocker(rng);
      Link& l = k == 1 ? m.crank : (k == 2 ? m.coupler : m.rocker);
      l.mass = ratio * (total_mass(m) - l.mass) / (1 - ratio);
      m = make_fourbar(m);
      const double scale = kEps / ratio;
      for (size_t j = 0; j < ms.size(); ++j) {
        const MassOutcome o = run_states(ms[j], m);
        worst[j][0] = std::max({worst[j][0], o.err_fwd / scale, o.err_inv / scale});
        worst[j][1] = std::max(worst[j][1], o.err_R / scale);
        char line[200];
        std::snprintf(line, sizeof line, "%d,%d,%.1e,%s,%.3e,%.3e,%.3e\n", i, k, ratio,
                      ms[j].name, o.err_fwd / scale, o.err_inv / scale, o.err_R / scale);
        csv << line;
      }
    }
    std::printf("| m%d |", k);
    for (const auto& w : worst) std::printf(" %s / %s |", sci(w[0]).c_str(), sci(w[1]).c_str());
    std::printf("\n");
  }
  std::printf("\nK << 1 means the error does not grow as the mass vanishes (it is the ordinary round-off, ~1e-12 relative, divided by eps m_tot / m_k = 2.2e-10).\n\n");
}

// ---------------------------------------------------------------------------------------------
// charts

void charts(const std::vector<Method>& ms, const std::filesystem::path& out,
            const std::filesystem::path& svg_dir) {
  std::filesystem::create_directories(svg_dir);
  const std::filesystem::path gp = out / "failure.gp";
  std::ofstream g(gp);
  g << "set datafile separator ','\n"
       "set terminal svg size 960,420 dynamic font 'sans,11' background rgb 'white'\n"
       "set logscale xy\nset grid\nset format x '10^{%L}'\nset format y '10^{%L}'\n"
       "set key top right font 'sans,9'\n"
       "eps = 2.220446e-16\n";
  g << "set terminal svg size 1200,440 dynamic font 'sans,11' background rgb 'white'\n";
  g << "set output '" << (svg_dir / "failure-singular.svg").string() << "'\n";
  g << "set datafile separator whitespace\n";
  g << "set multiplot layout 1,3 title 'Triple rocker approaching its limit position "
       "(|A1A3| -> l2 + l3), crank at 1 rad/s: relative error against the long-double "
       "reference'\n";
  struct Panel {
    const char* file_case;
    const char* title;
    int column;  // 3: total alpha1/tau, 4: total reactions, 5/6: at the formulation's pose
  };
  const Panel panels[3] = {
      {"fwd-crank-rate", "total error of alpha1 (forward); all coincide", 3},
      {"inv-crank-rate", "dynamics stage only: tau (inverse)", 5},
      {"fwd-crank-rate", "dynamics stage only: reactions (forward)", 6}};
  for (const Panel& p : panels) {
    g << "set title '" << p.title << "'\nset xlabel 'd = theta1_{limit} - theta1 [rad]'\n"
      << "set ylabel 'relative error'\nset yrange [1e-17:10]\nset xrange [5e-16:0.2]\n";
    g << "plot ";
    int lt = 1;
    for (const Method& m : ms) {
      g << "'" << (out / (std::string("chart_") + p.file_case + "_" + m.name + ".dat")).string()
        << "' using 1:" << p.column << " with linespoints lt " << lt++
        << " pt 7 ps 0.5 lw 1.5 title '" << m.name << "', \\\n     ";
    }
    g << "eps/x lt 0 lw 1.5 dt 2 title 'eps/d ~ eps/sin^2 mu', \\\n"
      << "     eps/sqrt(x) lt 0 lw 1 dt 3 title 'eps/sqrt(d) ~ eps/sin mu'\n";
  }
  g << "unset multiplot\n";

  // masses: worst error against m_k / m_tot for each link
  g << "set terminal svg size 960,380 dynamic font 'sans,11' background rgb 'white'\n";
  g << "set output '" << (svg_dir / "failure-masses.svg").string() << "'\n";
  g << "set datafile separator ','\nunset logscale x\nset format x '%g'\n";
  g << "set multiplot layout 1,3 title 'Worst relative error when one link mass vanishes "
       "(paper four-bar, m_{tot} = 7.3 kg, inertia kept); capped at 10^{2}'\n"
       "set xlabel 'log_{10}(m_k / kg)'\nset yrange [1e-17:1e2]\nset xrange [-330:0]\n";
  for (int k = 1; k <= 3; ++k) {
    g << "set title 'm" << k << " -> 0'\nplot ";
    bool first = true;
    int lt = 1;
    for (const Method& m : ms) {
      if (!first) g << ", \\\n     ";
      first = false;
      g << "'" << (out / "masses.csv").string() << "' using ((strcol(1) eq 'mass' && $2 == " << k
        << " && strcol(4) eq '" << m.name
        << "' && $5 > 0) ? log10($3) : 1/0):(($8>$9?($8>$10?$8:$10):($9>$10?$9:$10)) > 0 ? "
           "(($8>$9?($8>$10?$8:$10):($9>$10?$9:$10)) < 100 ? ($8>$9?($8>$10?$8:$10):($9>$10?$9:$10)) : 100) : 1e-17) with points lt "
        << lt++ << " pt 7 ps 0.6 lw 2 title '" << m.name << "'";
    }
    g << "\n";
  }
  g << "unset multiplot\n";
  g.close();
  const std::string cmd = "gnuplot '" + gp.string() + "'";
  if (std::system(cmd.c_str()) != 0) std::fprintf(stderr, "gnuplot failed: %s\n", cmd.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  std::filesystem::path out = "build/failure-domains";
  std::filesystem::path svg = std::filesystem::path(BD_SOURCE_DIR) / "docs" / "figures";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--svg" && i + 1 < argc) {
      svg = argv[++i];
    } else if (a == "-h" || a == "--help") {
      std::printf("usage: failure_domains [OUT_DIR] [--svg DIR]\n");
      return 0;
    } else {
      out = a;
    }
  }
  std::filesystem::create_directories(out);
  const std::vector<Method> ms = methods();
  std::printf("# Failure domains of the four-bar formulations\n\nFormulations:");
  for (const Method& m : ms) std::printf(" %s", m.name);
  std::printf("\n\n");
  {
    std::ofstream csv(out / "reference_check.csv");
    check_reference(csv);
  }
  singular_study(ms, out);
  at_limit_study(ms, out);
  mass_study(ms, out);
  mass_law_study(ms, out);
  charts(ms, out, svg);
  std::printf("CSVs in %s, charts in %s\n", out.string().c_str(), svg.string().c_str());
  return 0;
}
