#include "optimize/nlp.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <mutex>
#include <numbers>
#include <stdexcept>
#include <variant>

#include "core/input_error.hpp"
#include "core/fourbar/kinematics.hpp"
#include "core/number_text.hpp"

namespace bd::optimize {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Layout of q = (π, ρ, 1): per link k = 1, 2, 3 at 4(k-1): m, m e, m f, J = I + m|s̄|² about the
// first joint; the counter-rotation inertias; the links' centres of mass (e, f) where the
// applied forces act; the constant 1 (the column y0 of the regressor).
constexpr int kQ = 21;
constexpr int kCrankDisc = 12, kRockerDisc = 13;
constexpr int kOne = 20;
constexpr int link_base(int k) { return 4 * (k - 1); }
constexpr int rho_base(int k) { return 14 + 2 * (k - 1); }
using VecQ = Eigen::Matrix<double, kQ, 1>;

// Outputs of one sample: RA0x, RA0y, RA3x, RA3y, Fshx, Fshy, Msh, tau.
constexpr int kOutputs = 8;
using Vec8 = Eigen::Matrix<double, kOutputs, 1>;

// Output groups of the metrics: their first row and row count.
enum Group { kFsh, kMsh, kTau, kRA0, kRA3, kGroups };
constexpr int kGroupFirst[kGroups] = {4, 6, 7, 0, 2};
constexpr int kGroupRows[kGroups] = {2, 1, 1, 2, 2};

// the output group of a reaction metric's quantity
int group_of(Metric m) {
  if (m == Metric::kAddedMass) return -1;
  switch (info(m).quantity) {
    case core::Quantity::kShakingForce:
      return kFsh;
    case core::Quantity::kShakingMoment:
      return kMsh;
    case core::Quantity::kDriveTorque:
      return kTau;
    case core::Quantity::kReactionA0:
      return kRA0;
    case core::Quantity::kReactionA3:
      return kRA3;
  }
  return -1;
}

std::size_t metric_index(Metric m) { return static_cast<std::size_t>(m); }

const char* parameter_name(LinkParameterVariable::Parameter p) {
  switch (p) {
    case LinkParameterVariable::Parameter::kMass:
      return "mass [kg]";
    case LinkParameterVariable::Parameter::kE:
      return "e [m]";
    case LinkParameterVariable::Parameter::kF:
      return "f [m]";
    case LinkParameterVariable::Parameter::kInertia:
      return "inertia [kg m^2]";
  }
  return "?";
}

core::Metrics infinite_metrics() {
  core::Metrics m;
  for (const core::MetricInfo& info : core::kMetricTable) m.*info.field = kInf;
  return m;
}

// sqrt(r2 + eps²) for r2 = r² >= 0: the linear form's smoothed magnitude
double smoothed(double r2, double eps) { return std::sqrt(r2 + eps * eps); }

// The outputs of one dynamics sample.
Vec8 outputs(const core::DynamicsSample& s) {
  Vec8 y;
  y << s.RA0.x(), s.RA0.y(), s.RA3.x(), s.RA3.y(), s.Fsh.x(), s.Fsh.y(), s.Msh, s.tau;
  return y;
}

}  // namespace

struct Nlp::Impl {
  // q(x) and its Jacobian ∂q/∂x (kQ x n; empty unless asked for)
  struct Inertial {
    VecQ q = VecQ::Zero();
    Eigen::MatrixXd B;
  };
  // a run of inequality constraints of one kind
  struct Block {
    enum class Kind { kEnvelope, kRmsLimit, kPeakLimit, kAddedMassLimit, kPeakBound } kind{};
    int index{};        // counterweight (envelope), group (metric blocks)
    Metric metric{};    // limits and peak bounds
    double value{};     // the limit's value
    int bound_var{-1};  // peak bound: the variable t
    int count{};        // constraints in the block
  };

  DesignProblem problem;
  bool driven{};
  int n_design{}, n{};
  Eigen::VectorXd lower, upper;
  std::vector<std::string> variable_names, constraint_names;
  std::vector<int> cw_var;     // first variable (the mass) of each counterweight
  std::vector<int> param_var;  // the variable of each link parameter

  core::Metrics original_metrics;
  double original_mass{};
  bool linear{};                                     // ObjectiveForm::kLinear
  double eps{};                                      // its smoothing
  std::array<double, std::size(kMetrics)> weight{};  // aggregated objective weights
  std::array<int, std::size(kMetrics)> bound_var{};  // -1 unless a peak objective term

  // driven scenes: samples, their crank angles and the regressor per output group
  int samples{};
  std::vector<double> theta1;
  std::array<Eigen::MatrixXd, kGroups> A;  // (rows·samples) x kQ, sample-major
  std::array<Eigen::MatrixXd, kGroups> R;  // R of a QR of A: |A q| = |R q|

  // constraints
  int n_eq{}, n_ineq{};
  std::vector<Block> blocks;
  Eigen::Matrix<double, 4, kQ> balance = Eigen::Matrix<double, 4, kQ>::Zero();

  // free scenes: the last simulation
  mutable std::mutex cache_mutex;
  mutable Eigen::VectorXd cached_x;
  mutable core::Metrics cached_metrics;

  explicit Impl(const DesignProblem& p);
  void set_up_variables();
  void build_regressor();
  void set_up_constraints();
  void check_normalisers() const;
  void bound_peaks();

  void check_size(const Eigen::VectorXd& x) const;
  Inertial inertial(const Eigen::VectorXd& x, bool with_jacobian) const;
  core::FourBar design(const Eigen::VectorXd& x) const;
  std::vector<PlacedCounterweight> counterweights(const Eigen::VectorXd& x) const;
  core::FourBar model_at(const VecQ& q, double th1, double th2, double th3) const;
  Vec8 sample_outputs(const VecQ& q, double th1, double th2, double th3) const;
  core::Metrics free_metrics(const Eigen::VectorXd& x) const;
  core::Trajectory driven_trajectory(const VecQ& q) const;
  core::Trajectory free_trajectory(const Eigen::VectorXd& x) const;
  double rms_squared(int g, const VecQ& q) const;
  double peak(int g, const VecQ& q) const;
  double added_mass(const VecQ& q) const;
  double metric(const Eigen::VectorXd& x, Metric m) const;
  double normaliser(Metric m) const;
};

// ---------------------------------------------------------------------------------------------
// set-up

Nlp::Impl::Impl(const DesignProblem& p) : problem(p) {
  if (const Problem e = problem.validate()) {
    throw InputError("invalid design problem: " + e->text());
  }
  problem.original = core::make_fourbar(problem.original);
  driven = std::holds_alternative<core::DrivenScene>(problem.scene);
  original_mass = core::total_mass(problem.original);
  linear = problem.objective_form == ObjectiveForm::kLinear;
  eps = problem.smoothing;
  bound_var.fill(-1);
  for (const Term& t : problem.objective) weight[metric_index(t.metric)] += t.weight;

  // the original's metrics, by core's own simulation (the normalisers)
  core::SimulateOptions options;
  options.formulation = problem.formulation;
  options.tolerance = problem.tolerance;
  const core::Trajectory trajectory =
      driven ? core::simulate_driven(problem.original, std::get<core::DrivenScene>(problem.scene),
                                     options)
             : core::simulate_free(problem.original, std::get<core::FreeScene>(problem.scene),
                                   options);
  if (!trajectory.ok()) {
    throw InputError(FieldError{"", -1,
                                std::string("the original design cannot be evaluated in the ") +
                                    (driven ? "driven" : "free") +
                                    " scene: " + trajectory.message});
  }
  original_metrics = core::metrics(trajectory);
  check_normalisers();

  set_up_variables();
  if (driven) build_regressor();
  set_up_constraints();
  if (driven) bound_peaks();
}

void Nlp::Impl::check_normalisers() const {
  const core::Metrics& o = original_metrics;
  const double force = std::max({o.RA0_max, o.RA3_max, o.Fsh_max});
  const double moment = std::max({o.tau_max, o.Msh_max, force * problem.original.frame_length});
  auto check = [&](Metric m, const char* list, std::size_t i) {
    if (m == Metric::kAddedMass) return;
    const double v = value(o, m), scale = is_moment(m) ? moment : force;
    if (!(v > 1e-10 * scale)) {
      throw InputError(FieldError{list, static_cast<int>(i),
                                  std::string(": the original design's ") + to_string(m) +
                                      " is " + text::digits(v, 6) + " " + metric_unit(m) +
                                      ", too small to normalise by (it is already minimal)"});
    }
  };
  for (std::size_t i = 0; i < problem.objective.size(); ++i) {
    const Term& t = problem.objective[i];
    if (t.weight > 0) check(t.metric, "objective", i);
  }
  for (std::size_t i = 0; i < problem.limits.size(); ++i) {
    check(problem.limits[i].metric, "limits", i);
  }
}

void Nlp::Impl::set_up_variables() {
  std::vector<double> lo, hi;
  auto add = [&](double l, double h, std::string name) {
    lo.push_back(l);
    hi.push_back(h);
    variable_names.push_back(std::move(name));
    return static_cast<int>(lo.size()) - 1;
  };
  for (const CounterweightVariables& c : problem.counterweights) {
    const std::string name = std::string(core::link_name(c.link)) + " counterweight ";
    const double d = c.distance_max;
    cw_var.push_back(add(0.0, c.mass_max, name + "mass [kg]"));
    const char* pivot = c.link == 1 ? "A0" : "A3";
    add(-d, d, name + "x from " + pivot + " in link axes [m]");
    add(-d, d, name + "y from " + pivot + " in link axes [m]");
  }
  for (const LinkParameterVariable& v : problem.link_parameters) {
    param_var.push_back(
        add(v.lower, v.upper,
            std::string(core::link_name(v.link)) + " " + parameter_name(v.parameter)));
  }
  n_design = static_cast<int>(lo.size());
  if (driven) {
    for (Metric m : kMetrics) {
      if (is_peak(m) && weight[metric_index(m)] > 0) {
        bound_var[metric_index(m)] =
            add(0.0, kInf, std::string("bound on ") + to_string(m) + " [" + metric_unit(m) + "]");
      }
    }
  }
  n = static_cast<int>(lo.size());
  lower = Eigen::Map<Eigen::VectorXd>(lo.data(), n);
  upper = Eigen::Map<Eigen::VectorXd>(hi.data(), n);
}

// The regressor. y_i = A_i q is exact because the motion is prescribed: the kinematics does not
// depend on the masses, and the equations for the torque and the reactions are linear in the
// inertial parameters, in the loads and, through the moment F̄k × (c̄k - joint), in the point ρ
// where each applied force acts. Column j is y(q0 + e_j) - y(q0) at a base q0 (unit masses at the
// first joints, unit inertias): a difference quotient with step 1, exact up to round-off. The
// base keeps masses > 0; core's inverse dynamics accepts any inertia. ρ may differ from the
// model's centre of mass m e / m only in these column evaluations: there the applied force is
// moved to ρ by adding its moment to the link's load (at the sample's link angle).
void Nlp::Impl::build_regressor() {
  const core::DrivenScene& scene = std::get<core::DrivenScene>(problem.scene);
  const core::CounterRotations& discs = problem.original.counter_rotations;
  const int per_revolution = scene.samples;
  samples = per_revolution * scene.revolutions;
  // the instants of core::simulate_driven, operation for operation
  const double period = 2.0 * std::numbers::pi / std::abs(scene.omega1);
  theta1.resize(static_cast<std::size_t>(samples));
  for (int i = 0; i < samples; ++i) {
    const double t = period * static_cast<double>(i) / static_cast<double>(per_revolution);
    theta1[static_cast<std::size_t>(i)] = scene.theta1 + scene.omega1 * t;
  }

  // the base and the columns that can be non-zero
  VecQ q0 = VecQ::Zero();
  for (int k = 1; k <= 3; ++k) {
    q0(link_base(k)) = 1.0;
    q0(link_base(k) + 3) = 1.0;
  }
  q0(kCrankDisc) = discs.crank.inertia > 0 ? 1.0 : 0.0;
  q0(kRockerDisc) = discs.rocker.inertia > 0 ? 1.0 : 0.0;
  q0(kOne) = 1.0;
  std::vector<int> columns;
  for (int j = 0; j < 12; ++j) columns.push_back(j);
  if (discs.crank.inertia > 0) columns.push_back(kCrankDisc);
  if (discs.rocker.inertia > 0) columns.push_back(kRockerDisc);
  for (int k = 1; k <= 3; ++k) {
    if (core::link_load(problem.original, k).force != Vec2(0, 0)) {
      columns.push_back(rho_base(k));
      columns.push_back(rho_base(k) + 1);
    }
  }

  Eigen::MatrixXd Y = Eigen::MatrixXd::Zero(kOutputs * samples, kQ);
  for (int i = 0; i < samples; ++i) {
    // the link angles (the same for every q)
    const double th1 = theta1[static_cast<std::size_t>(i)];
    const auto pose = core::solve_position(problem.original, th1);
    if (!pose) throw InputError("the driven scene cannot be evaluated: " + pose.error().what());
    const Vec8 y0 = sample_outputs(q0, th1, pose->theta2, pose->theta3);
    Vec8 affine = y0;
    for (int j : columns) {
      VecQ qj = q0;
      qj(j) += 1.0;
      const Vec8 yj = sample_outputs(qj, th1, pose->theta2, pose->theta3);
      Y.block<kOutputs, 1>(kOutputs * i, j) = yj - y0;
      affine -= (yj - y0) * q0(j);
    }
    Y.block<kOutputs, 1>(kOutputs * i, kOne) = affine;
  }

  // per output group: its rows, and R of their QR (|A q|² = |R q|² as a sum of squares, so an
  // RMS never comes out negative and stays accurate near 0)
  for (int g = 0; g < kGroups; ++g) {
    const int rows = kGroupRows[g];
    A[g].resize(rows * samples, kQ);
    for (int i = 0; i < samples; ++i) {
      A[g].middleRows(rows * i, rows) = Y.middleRows(kOutputs * i + kGroupFirst[g], rows);
    }
    const Eigen::HouseholderQR<Eigen::MatrixXd> qr(A[g]);
    const int r = std::min<int>(static_cast<int>(A[g].rows()), kQ);
    R[g] = qr.matrixQR().topRows(r).triangularView<Eigen::Upper>();
  }
}

// The model whose inertial parameters are π = q(0..13), with each applied force moved from the
// model's centre of mass to ρ = q(14..19) by its moment at link angles th1, th2, th3.
core::FourBar Nlp::Impl::model_at(const VecQ& q, double th1, double th2, double th3) const {
  core::FourBar m = problem.original;
  core::Link* links[3] = {&m.crank, &m.coupler, &m.rocker};
  core::LinkLoad* loads[3] = {&m.loads.crank, &m.loads.coupler, &m.loads.rocker};
  const double angles[3] = {th1, th2, th3};
  for (int k = 1; k <= 3; ++k) {
    core::Link& l = *links[k - 1];
    const int b = link_base(k);
    l.mass = q(b);
    l.e = q(b + 1) / l.mass;
    l.f = q(b + 2) / l.mass;
    l.inertia = q(b + 3) - l.mass * (l.e * l.e + l.f * l.f);
    core::LinkLoad& load = *loads[k - 1];
    if (load.force != Vec2(0, 0)) {
      const Vec2 u = unit(angles[k - 1]);
      const Vec2 d = (q(rho_base(k)) - l.e) * u + (q(rho_base(k) + 1) - l.f) * perp(u);
      load.moment += cross(d, load.force);
    }
  }
  m.counter_rotations.crank.inertia = q(kCrankDisc);
  m.counter_rotations.rocker.inertia = q(kRockerDisc);
  return m;
}

// The outputs for q at crank angle th1 with the sample's link angles th2, th3 (for moving the
// applied forces to ρ).
Vec8 Nlp::Impl::sample_outputs(const VecQ& q, double th1, double th2, double th3) const {
  const core::DrivenScene& scene = std::get<core::DrivenScene>(problem.scene);
  const auto s = core::inverse_dynamics(model_at(q, th1, th2, th3), th1, scene.omega1, 0.0,
                                        problem.formulation);
  if (!s) throw InputError("the driven scene cannot be evaluated: " + s.error().what());
  return outputs(*s);
}

void Nlp::Impl::set_up_constraints() {
  // force balance (eq. 57) in q, over the original total mass:
  // crank m1 s̄1/l1 + m2 (1 - s̄2/l2), rocker m2 s̄2/l2 + m3 (1 - s̄3/l3)
  if (problem.force_balance) {
    const double l1 = problem.original.crank.length, l2 = problem.original.coupler.length,
                 l3 = problem.original.rocker.length;
    const int b1 = link_base(1), b2 = link_base(2), b3 = link_base(3);
    balance(0, b1 + 1) = 1 / l1;
    balance(0, b2) = 1;
    balance(0, b2 + 1) = -1 / l2;
    balance(1, b1 + 2) = 1 / l1;
    balance(1, b2 + 2) = -1 / l2;
    balance(2, b2 + 1) = 1 / l2;
    balance(2, b3) = 1;
    balance(2, b3 + 1) = -1 / l3;
    balance(3, b2 + 2) = 1 / l2;
    balance(3, b3 + 2) = -1 / l3;
    balance /= original_mass;
    n_eq = 4;
    for (const char* side : {"crank", "rocker"}) {
      for (const char* part : {"real", "imaginary"}) {
        constraint_names.push_back(std::string("force balance, ") + side + " side (" + part +
                                   " part)");
      }
    }
  }

  auto at_sample = [this](int i) {
    return " at sample " + std::to_string(i) +
           " (theta1 = " + text::digits(theta1[static_cast<std::size_t>(i)], 6) + " rad)";
  };
  // envelopes
  for (std::size_t c = 0; c < problem.counterweights.size(); ++c) {
    const CounterweightVariables& cw = problem.counterweights[c];
    blocks.push_back({Block::Kind::kEnvelope, static_cast<int>(c), Metric::kAddedMass, 0.0, -1, 1});
    constraint_names.push_back(
        std::string(core::link_name(cw.link)) + " counterweight within distance_max = " +
        text::digits(cw.distance_max, 6) + " m of " + (cw.link == 1 ? "A0" : "A3"));
  }
  // limits
  for (const Limit& l : problem.limits) {
    Block b{Block::Kind::kRmsLimit, group_of(l.metric), l.metric, l.value, -1, 1};
    const std::string name = std::string(to_string(l.metric)) + " <= " + text::digits(l.value, 6) +
                             (l.metric == Metric::kAddedMass ? " kg" : " x original");
    if (l.metric == Metric::kAddedMass) {
      b.kind = Block::Kind::kAddedMassLimit;
      constraint_names.push_back(name);
    } else if (is_peak(l.metric) && driven) {
      b.kind = Block::Kind::kPeakLimit;
      b.count = samples;
      for (int i = 0; i < samples; ++i) constraint_names.push_back(name + at_sample(i));
    } else {
      b.kind = is_peak(l.metric) ? Block::Kind::kPeakLimit : Block::Kind::kRmsLimit;
      constraint_names.push_back(name);
    }
    blocks.push_back(b);
  }
  // peak bounds of the objective (driven scenes)
  for (Metric m : kMetrics) {
    const int t = bound_var[metric_index(m)];
    if (t < 0) continue;
    blocks.push_back({Block::Kind::kPeakBound, group_of(m), m, 0.0, t, samples});
    for (int i = 0; i < samples; ++i) {
      constraint_names.push_back(std::string("|") + to_string(m) + "| sample" + at_sample(i) +
                                 " <= bound on " + to_string(m));
    }
  }
  n_ineq = 0;
  for (const Block& b : blocks) n_ineq += b.count;
}

// t_max for each bound variable: max over samples of Σ_rows Σ_j |A_ij| qmax_j with qmax_j a
// bound of |q_j| over the variable box (the centre of mass is a convex combination of the link's
// and the counterweight's), so no design in the box has a larger peak (linear form: a larger
// smoothed peak sqrt(peak² + δ²)).
void Nlp::Impl::bound_peaks() {
  VecQ qmax = VecQ::Zero();
  for (int k = 1; k <= 3; ++k) {
    const core::Link& l = core::link(problem.original, k);
    double m_hi = l.mass, e_max = std::abs(l.e), f_max = std::abs(l.f), I_hi = l.inertia;
    for (std::size_t i = 0; i < problem.link_parameters.size(); ++i) {
      const LinkParameterVariable& v = problem.link_parameters[i];
      if (v.link != k) continue;
      const double a = std::max(std::abs(v.lower), std::abs(v.upper));
      switch (v.parameter) {
        case LinkParameterVariable::Parameter::kMass:
          m_hi = v.upper;
          break;
        case LinkParameterVariable::Parameter::kE:
          e_max = a;
          break;
        case LinkParameterVariable::Parameter::kF:
          f_max = a;
          break;
        case LinkParameterVariable::Parameter::kInertia:
          I_hi = v.upper;
          break;
      }
    }
    double mc = 0, rx = 0, ry = 0, Ic = 0;
    for (const CounterweightVariables& c : problem.counterweights) {
      if (c.link != k) continue;
      mc = c.mass_max;
      rx = (k == 3 ? l.length : 0.0) + c.distance_max;
      ry = c.distance_max;
      if (c.shape == balance::CounterweightShape::kDisc) {
        Ic = mc * mc / (2 * c.density * std::numbers::pi * c.thickness);
      }
    }
    const int b = link_base(k);
    qmax(b) = m_hi + mc;
    qmax(b + 1) = m_hi * e_max + mc * rx;
    qmax(b + 2) = m_hi * f_max + mc * ry;
    qmax(b + 3) = I_hi + m_hi * (e_max * e_max + f_max * f_max) + Ic + mc * (rx * rx + ry * ry);
    qmax(rho_base(k)) = std::max(e_max, rx);
    qmax(rho_base(k) + 1) = std::max(f_max, ry);
  }
  qmax(kCrankDisc) = problem.original.counter_rotations.crank.inertia;
  qmax(kRockerDisc) = problem.original.counter_rotations.rocker.inertia;
  qmax(kOne) = 1.0;
  for (Metric m : kMetrics) {
    const int t = bound_var[metric_index(m)];
    if (t < 0) continue;
    const int g = group_of(m), rows = kGroupRows[g];
    const Eigen::VectorXd row_bounds = A[g].cwiseAbs() * qmax;
    double worst = 0;
    for (int i = 0; i < samples; ++i)
      worst = std::max(worst, row_bounds.segment(rows * i, rows).sum());
    if (linear) worst = std::hypot(worst, eps * normaliser(m));  // t >= sqrt(|y_i|² + δ²)
    upper(t) = worst * (1 + 1e-9) + std::numeric_limits<double>::min();  // round-off margin
    // Linear form: t is kept above sqrt(|y_i|² + δ²) > 0 by its constraints alone, and boxed in
    // [-t_max, t_max]. With a lower bound at 0 (or δ), SLSQP's quadratic subproblems put t on
    // that bound at infeasible iterates, twice running at the same objective, and NLopt's
    // SLSQP then stops on ftol_rel (it tests f at every iterate once any feasible point was
    // seen): measured on min Fsh_max, stopped after 12 evaluations at 0.35 x the original.
    if (linear) lower(t) = -upper(t);
  }
}

// ---------------------------------------------------------------------------------------------
// the design at x

void Nlp::Impl::check_size(const Eigen::VectorXd& x) const {
  if (x.size() != n) {
    throw InputError("design vector has " + std::to_string(x.size()) + " entries; expected " +
                     std::to_string(n));
  }
}

Nlp::Impl::Inertial Nlp::Impl::inertial(const Eigen::VectorXd& x, bool with_jacobian) const {
  Inertial out;
  if (with_jacobian) out.B = Eigen::MatrixXd::Zero(kQ, n);
  for (int k = 1; k <= 3; ++k) {
    // the link's own parameters, with their variables
    core::Link l = core::link(problem.original, k);
    int vm = -1, ve = -1, vf = -1, vi = -1;
    for (std::size_t i = 0; i < problem.link_parameters.size(); ++i) {
      const LinkParameterVariable& v = problem.link_parameters[i];
      if (v.link != k) continue;
      const int j = param_var[i];
      switch (v.parameter) {
        case LinkParameterVariable::Parameter::kMass:
          l.mass = x(j);
          vm = j;
          break;
        case LinkParameterVariable::Parameter::kE:
          l.e = x(j);
          ve = j;
          break;
        case LinkParameterVariable::Parameter::kF:
          l.f = x(j);
          vf = j;
          break;
        case LinkParameterVariable::Parameter::kInertia:
          l.inertia = x(j);
          vi = j;
          break;
      }
    }
    const int b = link_base(k);
    double M = l.mass, Mx = l.mass * l.e, My = l.mass * l.f;
    double J = l.inertia + l.mass * (l.e * l.e + l.f * l.f);
    if (with_jacobian) {
      auto dM = out.B.row(b), dMx = out.B.row(b + 1), dMy = out.B.row(b + 2), dJ = out.B.row(b + 3);
      if (vm >= 0) {
        dM(vm) += 1;
        dMx(vm) += l.e;
        dMy(vm) += l.f;
        dJ(vm) += l.e * l.e + l.f * l.f;
      }
      if (ve >= 0) {
        dMx(ve) += l.mass;
        dJ(ve) += 2 * l.mass * l.e;
      }
      if (vf >= 0) {
        dMy(vf) += l.mass;
        dJ(vf) += 2 * l.mass * l.f;
      }
      if (vi >= 0) dJ(vi) += 1;
    }
    // its counterweight: mass mc at r (link axes from the first joint), own inertia Ic(mc)
    for (std::size_t c = 0; c < problem.counterweights.size(); ++c) {
      const CounterweightVariables& cw = problem.counterweights[c];
      if (cw.link != k) continue;
      const int j = cw_var[c];
      const double mc = x(j), rx = x(j + 1) + (k == 3 ? l.length : 0.0), ry = x(j + 2);
      double Ic = 0, dIc = 0;
      if (cw.shape == balance::CounterweightShape::kDisc) {
        const double area_density = cw.density * std::numbers::pi * cw.thickness;  // m/r²
        Ic = mc * mc / (2 * area_density);
        dIc = mc / area_density;
      }
      M += mc;
      Mx += mc * rx;
      My += mc * ry;
      J += Ic + mc * (rx * rx + ry * ry);
      if (with_jacobian) {
        auto dM = out.B.row(b), dMx = out.B.row(b + 1), dMy = out.B.row(b + 2),
             dJ = out.B.row(b + 3);
        dM(j) += 1;
        dMx(j) += rx;
        dMy(j) += ry;
        dJ(j) += dIc + rx * rx + ry * ry;
        dMx(j + 1) += mc;
        dJ(j + 1) += 2 * mc * rx;
        dMy(j + 2) += mc;
        dJ(j + 2) += 2 * mc * ry;
      }
    }
    out.q(b) = M;
    out.q(b + 1) = Mx;
    out.q(b + 2) = My;
    out.q(b + 3) = J;
    // the centre of mass, where the applied force acts
    const int r = rho_base(k);
    out.q(r) = Mx / M;
    out.q(r + 1) = My / M;
    if (with_jacobian) {
      out.B.row(r) = (out.B.row(b + 1) - out.q(r) * out.B.row(b)) / M;
      out.B.row(r + 1) = (out.B.row(b + 2) - out.q(r + 1) * out.B.row(b)) / M;
    }
  }
  out.q(kCrankDisc) = problem.original.counter_rotations.crank.inertia;
  out.q(kRockerDisc) = problem.original.counter_rotations.rocker.inertia;
  out.q(kOne) = 1.0;
  return out;
}

std::vector<PlacedCounterweight> Nlp::Impl::counterweights(const Eigen::VectorXd& x) const {
  std::vector<PlacedCounterweight> out;
  for (std::size_t c = 0; c < problem.counterweights.size(); ++c) {
    const CounterweightVariables& cw = problem.counterweights[c];
    const int j = cw_var[c];
    balance::Counterweight w;
    w.mass = x(j);
    w.position = Vec2(x(j + 1), x(j + 2));
    w.distance = w.position.norm();
    if (cw.shape == balance::CounterweightShape::kDisc) {
      w.radius = std::sqrt(w.mass / (cw.density * std::numbers::pi * cw.thickness));
      w.thickness = cw.thickness;
      w.inertia = 0.5 * w.mass * w.radius * w.radius;
    }
    out.push_back({cw.link, w});
  }
  return out;
}

core::FourBar Nlp::Impl::design(const Eigen::VectorXd& x) const {
  core::FourBar m = problem.original;
  core::Link* links[3] = {&m.crank, &m.coupler, &m.rocker};
  for (std::size_t i = 0; i < problem.link_parameters.size(); ++i) {
    const LinkParameterVariable& v = problem.link_parameters[i];
    core::Link& l = *links[v.link - 1];
    const double value = x(param_var[i]);
    switch (v.parameter) {
      case LinkParameterVariable::Parameter::kMass:
        l.mass = value;
        break;
      case LinkParameterVariable::Parameter::kE:
        l.e = value;
        break;
      case LinkParameterVariable::Parameter::kF:
        l.f = value;
        break;
      case LinkParameterVariable::Parameter::kInertia:
        l.inertia = value;
        break;
    }
  }
  for (const PlacedCounterweight& c : counterweights(x)) {
    core::Link& l = *links[c.link - 1];
    l = balance::merged(l, c.counterweight, c.link == 3);
  }
  return core::make_fourbar(m);
}

// ---------------------------------------------------------------------------------------------
// metrics

double Nlp::Impl::rms_squared(int g, const VecQ& q) const {
  return (R[g] * q).squaredNorm() / samples;
}

double Nlp::Impl::peak(int g, const VecQ& q) const {
  const Eigen::VectorXd y = A[g] * q;
  const int rows = kGroupRows[g];
  double worst = 0;
  for (int i = 0; i < samples; ++i) {
    worst = std::max(worst, rows == 1 ? std::abs(y(i)) : y.segment(rows * i, rows).norm());
  }
  return worst;
}

double Nlp::Impl::added_mass(const VecQ& q) const {
  return q(link_base(1)) + q(link_base(2)) + q(link_base(3)) - original_mass;
}

core::Trajectory Nlp::Impl::driven_trajectory(const VecQ& q) const {
  // every sample's outputs from the regressor, at the instants of core::simulate_driven
  const core::DrivenScene& scene = std::get<core::DrivenScene>(problem.scene);
  const double period = 2.0 * std::numbers::pi / std::abs(scene.omega1);
  core::Trajectory t;
  t.samples.resize(static_cast<std::size_t>(samples));
  t.t.resize(static_cast<std::size_t>(samples));
  std::array<Eigen::VectorXd, kGroups> y;
  for (int g = 0; g < kGroups; ++g) y[g] = A[g] * q;
  for (int i = 0; i < samples; ++i) {
    const auto j = static_cast<std::size_t>(i);
    t.t[j] = period * static_cast<double>(i) / static_cast<double>(scene.samples);
    core::DynamicsSample& s = t.samples[j];
    s.state.theta1 = theta1[j];
    s.state.omega1 = scene.omega1;
    s.RA0 = y[kRA0].segment<2>(2 * i);
    s.RA3 = y[kRA3].segment<2>(2 * i);
    s.Fsh = y[kFsh].segment<2>(2 * i);
    s.Msh = y[kMsh](i);
    s.tau = y[kTau](i);
  }
  t.status = core::SimulationStatus::kCompleted;
  t.message = "completed (regressor)";
  return t;
}

core::Trajectory Nlp::Impl::free_trajectory(const Eigen::VectorXd& x) const {
  core::SimulateOptions options;
  options.formulation = problem.formulation;
  options.tolerance = problem.tolerance;
  return core::simulate_free(design(x), std::get<core::FreeScene>(problem.scene), options);
}

core::Metrics Nlp::Impl::free_metrics(const Eigen::VectorXd& x) const {
  const std::lock_guard<std::mutex> lock(cache_mutex);
  if (cached_x.size() == x.size() && cached_x == x) return cached_metrics;
  const core::Trajectory t = free_trajectory(x);
  cached_metrics = t.ok() ? core::metrics(t) : infinite_metrics();
  cached_x = x;
  return cached_metrics;
}

double Nlp::Impl::metric(const Eigen::VectorXd& x, Metric m) const {
  if (m == Metric::kAddedMass) return added_mass(inertial(x, false).q);
  if (!driven) return value(free_metrics(x), m);
  const VecQ q = inertial(x, false).q;
  return is_peak(m) ? peak(group_of(m), q) : std::sqrt(rms_squared(group_of(m), q));
}

double Nlp::Impl::normaliser(Metric m) const {
  return m == Metric::kAddedMass ? original_mass : value(original_metrics, m);
}

// ---------------------------------------------------------------------------------------------
// the public interface

Nlp::Nlp(const DesignProblem& problem) : impl_(std::make_unique<Impl>(problem)) {}
Nlp::~Nlp() = default;

int Nlp::n() const { return impl_->n; }
int Nlp::n_eq() const { return impl_->n_eq; }
int Nlp::n_ineq() const { return impl_->n_ineq; }
const Eigen::VectorXd& Nlp::lower() const { return impl_->lower; }
const Eigen::VectorXd& Nlp::upper() const { return impl_->upper; }
const std::vector<std::string>& Nlp::variable_names() const { return impl_->variable_names; }
const std::vector<std::string>& Nlp::constraint_names() const { return impl_->constraint_names; }
bool Nlp::has_gradients() const { return impl_->driven; }

Eigen::VectorXd Nlp::start() const {
  const Impl& p = *impl_;
  Eigen::VectorXd x = Eigen::VectorXd::Zero(p.n);
  for (std::size_t c = 0; c < p.problem.counterweights.size(); ++c) {
    const CounterweightVariables& cw = p.problem.counterweights[c];
    const int j = p.cw_var[c];
    x(j) = cw.mass_max / 2;
    x(j + 1) = (cw.link == 1 ? -0.5 : 0.5) * cw.distance_max;
  }
  for (std::size_t i = 0; i < p.problem.link_parameters.size(); ++i) {
    const LinkParameterVariable& v = p.problem.link_parameters[i];
    const core::Link& l = core::link(p.problem.original, v.link);
    double value = 0;
    switch (v.parameter) {
      case LinkParameterVariable::Parameter::kMass:
        value = l.mass;
        break;
      case LinkParameterVariable::Parameter::kE:
        value = l.e;
        break;
      case LinkParameterVariable::Parameter::kF:
        value = l.f;
        break;
      case LinkParameterVariable::Parameter::kInertia:
        value = l.inertia;
        break;
    }
    x(p.param_var[i]) = std::clamp(value, v.lower, v.upper);
  }
  if (p.driven) {
    const VecQ q = p.inertial(x, false).q;
    for (Metric m : kMetrics) {
      const int t = p.bound_var[metric_index(m)];
      // a hair above the (smoothed) peak, so that its constraints survive the round-off of sqrt
      if (t < 0) continue;
      double peak = p.peak(group_of(m), q);
      if (p.linear) peak = std::hypot(peak, p.eps * p.normaliser(m));
      x(t) = std::min(peak * (1 + 1e-12), p.upper(t));
    }
  }
  return x;
}

double Nlp::objective(const Eigen::VectorXd& x, Eigen::VectorXd* grad) const {
  const Impl& p = *impl_;
  p.check_size(x);
  if (grad && !p.driven) {
    throw std::logic_error(
        "Nlp::objective: no gradients in a free scene (has_gradients() is false)");
  }
  if (!p.driven) {
    const core::Metrics v = p.free_metrics(x);
    double f = 0;
    for (Metric m : kMetrics) {
      const double w = p.weight[metric_index(m)];
      if (!(w > 0)) continue;
      if (m == Metric::kAddedMass) {
        f += w * p.added_mass(p.inertial(x, false).q) / p.original_mass;
      } else {
        const double r = value(v, m) / p.normaliser(m);
        // linear: an RMS smoothed as in driven scenes, a peak exactly (no bound variable)
        f += w * (!p.linear ? r * r : is_peak(m) ? r : smoothed(r * r, p.eps));
      }
    }
    return f;
  }

  const Impl::Inertial in = p.inertial(x, grad != nullptr);
  double f = 0;
  Eigen::RowVectorXd dq;  // ∂f/∂q
  if (grad) {
    grad->setZero(p.n);
    dq.setZero(kQ);
  }
  for (Metric m : kMetrics) {
    const double w = p.weight[metric_index(m)];
    if (!(w > 0)) continue;
    const double o = p.normaliser(m);
    if (m == Metric::kAddedMass) {
      f += w * p.added_mass(in.q) / o;
      if (grad) {
        for (int k = 1; k <= 3; ++k) dq(link_base(k)) += w / o;
      }
    } else if (is_peak(m)) {
      const int t = p.bound_var[metric_index(m)];
      if (p.linear) {
        f += w * x(t) / o;
        if (grad) (*grad)(t) += w / o;
      } else {
        f += w * (x(t) / o) * (x(t) / o);
        if (grad) (*grad)(t) += 2 * w * x(t) / (o * o);
      }
    } else {
      // r² = |R q|² / (N o²); the term is w r² (squared) or w sqrt(r² + ε²) (linear), whose
      // derivative in r² is w / (2 sqrt(r² + ε²))
      const int g = group_of(m);
      const Eigen::VectorXd Rq = p.R[g] * in.q;
      const double r2 = Rq.squaredNorm() / (p.samples * o * o);
      double dr2 = w;  // ∂term/∂r²
      if (p.linear) {
        f += w * smoothed(r2, p.eps);
        dr2 = w / (2 * std::sqrt(r2 + p.eps * p.eps));
      } else {
        f += w * r2;
      }
      if (grad) dq += (2 * dr2 / (p.samples * o * o)) * Rq.transpose() * p.R[g];
    }
  }
  if (grad) grad->head(p.n) += (dq * in.B).transpose();
  return f;
}

void Nlp::equalities(const Eigen::VectorXd& x, Eigen::VectorXd& c, Eigen::MatrixXd* jac) const {
  const Impl& p = *impl_;
  p.check_size(x);
  if (jac && !p.driven) {
    throw std::logic_error(
        "Nlp::equalities: no gradients in a free scene (has_gradients() is false)");
  }
  c.resize(p.n_eq);
  if (jac) jac->setZero(p.n_eq, p.n);
  if (p.n_eq == 0) return;
  const Impl::Inertial in = p.inertial(x, jac != nullptr);
  c = p.balance * in.q;
  if (jac) *jac = p.balance * in.B;
}

void Nlp::inequalities(const Eigen::VectorXd& x, Eigen::VectorXd& c, Eigen::MatrixXd* jac) const {
  const Impl& p = *impl_;
  p.check_size(x);
  if (jac && !p.driven) {
    throw std::logic_error(
        "Nlp::inequalities: no gradients in a free scene (has_gradients() is false)");
  }
  c.resize(p.n_ineq);
  if (jac) jac->setZero(p.n_ineq, p.n);
  if (p.n_ineq == 0) return;
  const Impl::Inertial in = p.inertial(x, jac != nullptr);
  // per group, computed once: y = A q and, for the Jacobian, A ∂q/∂x
  std::array<Eigen::VectorXd, kGroups> y;
  std::array<Eigen::MatrixXd, kGroups> AB;
  auto outputs_of = [&](int g) {
    if (y[g].size() == 0) {
      y[g] = p.A[g] * in.q;
      if (jac) AB[g] = p.A[g] * in.B;
    }
  };
  core::Metrics free;
  if (!p.driven) free = p.free_metrics(x);

  int row = 0;
  for (const Impl::Block& b : p.blocks) {
    using Kind = Impl::Block::Kind;
    switch (b.kind) {
      case Kind::kEnvelope: {
        const CounterweightVariables& cw =
            p.problem.counterweights[static_cast<std::size_t>(b.index)];
        const int j = p.cw_var[static_cast<std::size_t>(b.index)];
        const double d2 = cw.distance_max * cw.distance_max;
        c(row) = (x(j + 1) * x(j + 1) + x(j + 2) * x(j + 2)) / d2 - 1;
        if (jac) {
          (*jac)(row, j + 1) = 2 * x(j + 1) / d2;
          (*jac)(row, j + 2) = 2 * x(j + 2) / d2;
        }
        break;
      }
      case Kind::kAddedMassLimit: {
        c(row) = (p.added_mass(in.q) - b.value) / p.original_mass;
        if (jac) {
          for (int k = 1; k <= 3; ++k) {
            jac->row(row) += in.B.row(link_base(k)) / p.original_mass;
          }
        }
        break;
      }
      case Kind::kRmsLimit: {
        const double limit = b.value * p.normaliser(b.metric);
        if (!p.driven) {
          const double r = value(free, b.metric) / limit;
          c(row) = r * r - 1;
          break;
        }
        const Eigen::VectorXd Rq = p.R[b.index] * in.q;
        const double scale = 1 / (p.samples * limit * limit);
        c(row) = scale * Rq.squaredNorm() - 1;
        if (jac) jac->row(row) = 2 * scale * (Rq.transpose() * p.R[b.index]) * in.B;
        break;
      }
      case Kind::kPeakLimit:
      case Kind::kPeakBound: {
        const double o = p.normaliser(b.metric);
        if (!p.driven) {  // a peak limit in a free scene: the peak itself
          const double r = value(free, b.metric) / (b.value * o);
          c(row) = r * r - 1;
          break;
        }
        const bool limit = b.kind == Kind::kPeakLimit;
        if (!limit && p.linear) {
          // (sqrt(|y_i|² + δ²) - t) / o with δ = ε o: linear in t, so its gradient never
          // vanishes (|y_i|² - t² has none at y_i = 0, t = 0: a force-balanced optimum)
          const double delta = p.eps * o, t = x(b.bound_var);
          const int g = b.index, rows = kGroupRows[g];
          outputs_of(g);
          for (int i = 0; i < b.count; ++i) {
            const auto yi = y[g].segment(rows * i, rows);
            const double n2 = yi.squaredNorm(), root = std::sqrt(n2 + delta * delta);
            c(row + i) = (root - t) / o;
            if (jac) {
              jac->row(row + i) = yi.transpose() * AB[g].middleRows(rows * i, rows) / (root * o);
              (*jac)(row + i, b.bound_var) = -1 / o;
            }
          }
          break;
        }
        const double s = limit ? b.value * o : o;  // the scale of the bound
        const double t = limit ? s : x(b.bound_var);
        const int g = b.index, rows = kGroupRows[g];
        outputs_of(g);
        for (int i = 0; i < b.count; ++i) {
          const auto yi = y[g].segment(rows * i, rows);
          c(row + i) = (yi.squaredNorm() - t * t) / (s * s);
          if (jac) {
            jac->row(row + i) = 2 * yi.transpose() * AB[g].middleRows(rows * i, rows) / (s * s);
            if (!limit) (*jac)(row + i, b.bound_var) = -2 * t / (s * s);
          }
        }
        break;
      }
    }
    row += b.count;
  }
}

core::FourBar Nlp::design(const Eigen::VectorXd& x) const {
  impl_->check_size(x);
  return impl_->design(x);
}

std::vector<PlacedCounterweight> Nlp::counterweights(const Eigen::VectorXd& x) const {
  impl_->check_size(x);
  return impl_->counterweights(x);
}

core::Metrics Nlp::metrics(const Eigen::VectorXd& x) const {
  impl_->check_size(x);
  if (!impl_->driven) return impl_->free_metrics(x);
  return core::metrics(impl_->driven_trajectory(impl_->inertial(x, false).q));
}

core::Trajectory Nlp::trajectory(const Eigen::VectorXd& x) const {
  impl_->check_size(x);
  if (!impl_->driven) return impl_->free_trajectory(x);
  return impl_->driven_trajectory(impl_->inertial(x, false).q);
}

double Nlp::metric(const Eigen::VectorXd& x, Metric m) const {
  impl_->check_size(x);
  return impl_->metric(x, m);
}

double Nlp::original(Metric m) const { return impl_->normaliser(m); }

}  // namespace bd::optimize
