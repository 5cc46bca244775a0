// The program in a driven scene: the reactions, torque, shaking force and moment of every sample
// are affine in q (optimize/nlp.hpp), so a regressor computed once from core's inverse dynamics
// gives every metric, and its exact gradient through ∂q/∂x.
#include <Eigen/QR>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <variant>

#include "core/fourbar/kinematics.hpp"
#include "core/input_error.hpp"
#include "core/number_text.hpp"
#include "optimize/detail/local_maxima.hpp"
#include "optimize/nlp_program.hpp"

namespace bd::optimize::detail {

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

// Outputs of one sample: RA0x, RA0y, RA3x, RA3y, Fshx, Fshy, Msh (the inertial parts, which the
// metrics take), tau, and the total Fshx, Fshy, Msh (weights and loads included).
constexpr int kOutputs = 11;
using VecOut = Eigen::Matrix<double, kOutputs, 1>;

// Output groups of the metrics, and of the total shaking force and moment: their first row and
// row count.
enum Group { kFsh, kMsh, kTau, kRA0, kRA3, kFshTotal, kMshTotal, kGroups };
constexpr int kGroupFirst[kGroups] = {4, 6, 7, 0, 2, 8, 10};
constexpr int kGroupRows[kGroups] = {2, 1, 1, 2, 2, 2, 1};

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

// The outputs of one dynamics sample.
VecOut outputs(const core::DynamicsSample& s) {
  VecOut y;
  y << s.RA0.x(), s.RA0.y(), s.RA3.x(), s.RA3.y(), s.Fsh_inertial.x(), s.Fsh_inertial.y(),
      s.Msh_inertial, s.tau, s.Fsh.x(), s.Fsh.y(), s.Msh;
  return y;
}

// The outputs y = A q of each group and, for a Jacobian, A ∂q/∂x, each computed on first use.
class GroupOutputs {
 public:
  GroupOutputs(const std::array<MatrixXd, kGroups>& A, const Inertial& in, bool jacobian)
      : A_(A), in_(in), jacobian_(jacobian) {}
  const VectorXd& y(int g) {
    compute(g);
    return y_[g];
  }
  const MatrixXd& AB(int g) {
    compute(g);
    return AB_[g];
  }

 private:
  void compute(int g) {
    if (y_[g].size() != 0) return;
    y_[g] = A_[g] * in_.q;
    if (jacobian_) AB_[g] = A_[g] * in_.B;
  }
  const std::array<MatrixXd, kGroups>& A_;
  const Inertial& in_;
  bool jacobian_;
  std::array<VectorXd, kGroups> y_;
  std::array<MatrixXd, kGroups> AB_;
};

class DrivenNlp final : public NlpProgram {
 public:
  DrivenNlp(const DesignProblem& problem, CounterweightVariablesAs as);

  bool has_gradients() const override { return true; }
  std::string why_not_convex() const override;
  double objective(const VectorXd& x, VectorXd* grad) const override;
  core::Trajectory trajectory(const VectorXd& x) const override {
    return trajectory_of(inertial(x, false).q);
  }
  std::vector<double> peak_instants(const VectorXd& x, double within) const override;
  core::Metrics metrics(const VectorXd& x) const override {
    const VecQ q = inertial(x, false).q;
    core::Metrics m = core::metrics(trajectory_of(q));
    // the peaks over the samples and the problem's peak angles, as the program bounds them
    if (instants_ > samples_) {
      for (const core::MetricInfo& info : core::kMetricTable) {
        if (info.statistic != core::Statistic::kMax) continue;
        const auto metric = metric_named(info.name);
        if (metric) m.*info.field = peak(group_of(*metric), q);
      }
    }
    return m;
  }

 private:
  std::vector<std::string> peak_limit_names(const std::string& name) const override;
  void start_extra_variables(VectorXd& x) const override;
  void metric_inequalities(const VectorXd& x, const Inertial& in, VectorXd& c,
                           MatrixXd* jac) const override;
  double reaction_metric(const VectorXd& x, Metric m) const override;

  void add_bound_variables();
  void add_peak_bounds();
  std::string at_sample(int i) const;
  void build_regressor();
  std::vector<int> regressor_columns() const;
  void factor(const MatrixXd& Y);
  VecQ box_bounds() const;
  void bound_peaks();
  core::FourBar model_at(const VecQ& q, double th1, double th2, double th3) const;
  VecOut sample_outputs(const VecQ& q, double th1, double th2, double th3) const;
  core::Trajectory trajectory_of(const VecQ& q) const;
  double rms_squared(int g, const VecQ& q) const;
  std::vector<double> magnitudes(int g, const VecQ& q) const;  // per instant
  double peak(int g, const VecQ& q) const;
  void rms_limit(const Block& b, const Inertial& in, int row, VectorXd& c, MatrixXd* jac) const;
  void smoothed_peak_bound(const Block& b, const VectorXd& x, GroupOutputs& groups, int row,
                           VectorXd& c, MatrixXd* jac) const;
  void squared_peak_rows(const Block& b, const VectorXd& x, GroupOutputs& groups, int row,
                         VectorXd& c, MatrixXd* jac) const;

  const core::DrivenScene& scene() const { return std::get<core::DrivenScene>(problem_.scene); }

  std::array<int, std::size(kMetrics)> bound_var_{};  // -1 unless a peak objective term
  int samples_{};   // the scene's samples: the RMS metrics' instants
  int instants_{};  // the peaks': the samples, then the problem's peak angles
  std::vector<double> theta1_;       // the crank angle of each instant
  std::array<MatrixXd, kGroups> A_;  // (rows·instants) x kQ, instant-major
  std::array<MatrixXd, kGroups> R_;  // R of a QR of the samples' rows of A: |A q| = |R q|
};

// ---------------------------------------------------------------------------------------------
// set-up

DrivenNlp::DrivenNlp(const DesignProblem& problem, CounterweightVariablesAs as)
    : NlpProgram(problem, as) {
  add_bound_variables();
  build_regressor();
  set_up_constraints();
  add_peak_bounds();
  bound_peaks();
}

std::string DrivenNlp::why_not_convex() const {
  // the metrics the program reads: the objective's (weight > 0) and the limits'
  std::vector<Metric> used;
  for (const Term& t : problem_.objective) {
    if (t.weight > 0 && t.metric != Metric::kAddedMass) used.push_back(t.metric);
    if (t.weight > 0 && is_peak(t.metric) && !linear_) {
      return std::string("the squared objective form bounds the peak ") + to_string(t.metric) +
             " by |y|² <= t², which is not convex in t (the linear form is)";
    }
  }
  for (const Limit& l : problem_.limits) {
    if (l.metric != Metric::kAddedMass) used.push_back(l.metric);
  }
  const std::vector<std::pair<int, std::string>> varying = non_affine_parameters();
  for (Metric m : used) {
    const MatrixXd& A = A_[static_cast<std::size_t>(group_of(m))];
    const double scale = A.cwiseAbs().maxCoeff();
    for (const auto& [i, why] : varying) {
      if (A.col(i).cwiseAbs().maxCoeff() > 1e-9 * scale) {
        return std::string(to_string(m)) + " depends on " + why;
      }
    }
  }
  return "";
}

// one bound variable t per peak metric of the objective, its upper bound set by bound_peaks()
void DrivenNlp::add_bound_variables() {
  bound_var_.fill(-1);
  for (Metric m : kMetrics) {
    if (is_peak(m) && weight_[metric_index(m)] > 0) {
      bound_var_[metric_index(m)] =
          add_variable(0.0, std::numeric_limits<double>::infinity(),
                       std::string("bound on ") + to_string(m) + " [" + metric_unit(m) + "]");
    }
  }
}

std::string DrivenNlp::at_sample(int i) const {
  const std::string angle =
      "theta1 = " + text::digits(theta1_[static_cast<std::size_t>(i)], 6) + " rad";
  if (i >= samples_) return " near a resolved peak (" + angle + ")";
  return " at sample " + std::to_string(i) + " (" + angle + ")";
}

std::vector<std::string> DrivenNlp::peak_limit_names(const std::string& name) const {
  std::vector<std::string> names;
  for (int i = 0; i < instants_; ++i) names.push_back(name + at_sample(i));
  return names;
}

// the peak bounds of the objective: |y_i| <= t at every sample
void DrivenNlp::add_peak_bounds() {
  for (Metric m : kMetrics) {
    const int t = bound_var_[metric_index(m)];
    if (t < 0) continue;
    std::vector<std::string> names;
    for (int i = 0; i < instants_; ++i) {
      names.push_back(std::string("|") + to_string(m) + "|" + at_sample(i) + " <= bound on " +
                      to_string(m));
    }
    add_block({Block::Kind::kPeakBound, -1, m, 0.0, t, instants_}, std::move(names));
  }
}

// The regressor. y_i = A_i q is exact because the motion is prescribed: the kinematics does not
// depend on the masses, and the equations for the torque and the reactions are linear in the
// inertial parameters, in the loads and, through the moment F̄k × (c̄k - joint), in the point ρ
// where each applied force acts. Column j is y(q0 + e_j) - y(q0) at a base q0 (unit masses at the
// first joints, unit inertias): a difference quotient with step 1, exact up to round-off. The
// base keeps masses > 0; core's inverse dynamics accepts any inertia. ρ may differ from the
// model's centre of mass m e / m only in these column evaluations: there the applied force is
// moved to ρ by adding its moment to the link's load (at the sample's link angle).
void DrivenNlp::build_regressor() {
  const int per_revolution = scene().samples;
  samples_ = per_revolution * scene().revolutions;
  // the instants of core::simulate_driven, operation for operation
  theta1_.resize(static_cast<std::size_t>(samples_));
  for (int i = 0; i < samples_; ++i) {
    theta1_[static_cast<std::size_t>(i)] =
        scene().theta1 + scene().omega1 * core::driven_sample_time(scene(), i);
  }
  theta1_.insert(theta1_.end(), problem_.peak_angles.begin(), problem_.peak_angles.end());
  instants_ = static_cast<int>(theta1_.size());

  // the base
  const core::CounterRotations& discs = problem_.original.counter_rotations;
  VecQ q0 = VecQ::Zero();
  for (int k = 1; k <= 3; ++k) {
    q0(link_base(k)) = 1.0;
    q0(link_base(k) + 3) = 1.0;
  }
  q0(kCrankDisc) = discs.crank.inertia > 0 ? 1.0 : 0.0;
  q0(kRockerDisc) = discs.rocker.inertia > 0 ? 1.0 : 0.0;
  q0(kOne) = 1.0;
  const std::vector<int> columns = regressor_columns();

  MatrixXd Y = MatrixXd::Zero(kOutputs * instants_, kQ);
  for (int i = 0; i < instants_; ++i) {
    // the link angles (the same for every q)
    const double th1 = theta1_[static_cast<std::size_t>(i)];
    const auto pose = core::solve_position(problem_.original, th1);
    if (!pose) throw InputError("the driven scene cannot be evaluated: " + pose.error().what());
    const VecOut y0 = sample_outputs(q0, th1, pose->theta2, pose->theta3);
    VecOut affine = y0;
    for (int j : columns) {
      VecQ qj = q0;
      qj(j) += 1.0;
      const VecOut yj = sample_outputs(qj, th1, pose->theta2, pose->theta3);
      Y.block<kOutputs, 1>(kOutputs * i, j) = yj - y0;
      affine -= (yj - y0) * q0(j);
    }
    Y.block<kOutputs, 1>(kOutputs * i, kOne) = affine;
  }
  factor(Y);
}

// the columns of the regressor that can be non-zero (besides y0's)
std::vector<int> DrivenNlp::regressor_columns() const {
  const core::CounterRotations& discs = problem_.original.counter_rotations;
  std::vector<int> columns;
  for (int j = 0; j < 12; ++j) columns.push_back(j);
  if (discs.crank.inertia > 0) columns.push_back(kCrankDisc);
  if (discs.rocker.inertia > 0) columns.push_back(kRockerDisc);
  for (int k = 1; k <= 3; ++k) {
    if (core::link_load(problem_.original, k).force != Vec2(0, 0)) {
      columns.push_back(rho_base(k));
      columns.push_back(rho_base(k) + 1);
    }
  }
  return columns;
}

// per output group: its rows of the instants' outputs Y, and R of a QR of the samples' rows
// (|A q|² = |R q|² as a sum of squares, so an RMS never comes out negative and stays accurate
// near 0)
void DrivenNlp::factor(const MatrixXd& Y) {
  for (int g = 0; g < kGroups; ++g) {
    const int rows = kGroupRows[g];
    A_[g].resize(rows * instants_, kQ);
    for (int i = 0; i < instants_; ++i) {
      A_[g].middleRows(rows * i, rows) = Y.middleRows(kOutputs * i + kGroupFirst[g], rows);
    }
    const Eigen::HouseholderQR<MatrixXd> qr(A_[g].topRows(rows * samples_));
    const int r = std::min<int>(rows * samples_, kQ);
    R_[g] = qr.matrixQR().topRows(r).triangularView<Eigen::Upper>();
  }
}

// The model whose inertial parameters are π = q(0..13), with each applied force moved from the
// model's centre of mass to ρ = q(14..19) by its moment at link angles th1, th2, th3.
core::FourBar DrivenNlp::model_at(const VecQ& q, double th1, double th2, double th3) const {
  core::FourBar m = problem_.original;
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
VecOut DrivenNlp::sample_outputs(const VecQ& q, double th1, double th2, double th3) const {
  const auto s = core::inverse_dynamics(model_at(q, th1, th2, th3), th1, scene().omega1, 0.0,
                                        problem_.formulation);
  if (!s) throw InputError("the driven scene cannot be evaluated: " + s.error().what());
  return outputs(*s);
}

// A bound of |q_j| over the variable box (the centre of mass is a convex combination of the
// link's and the counterweight's).
VecQ DrivenNlp::box_bounds() const {
  VecQ qmax = VecQ::Zero();
  for (int k = 1; k <= 3; ++k) {
    const core::Link& l = core::link(problem_.original, k);
    double m_hi = l.mass, e_max = std::abs(l.e), f_max = std::abs(l.f), I_hi = l.inertia;
    for (const LinkParameterVariable& v : problem_.link_parameters) {
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
    for (const CounterweightVariables& c : problem_.counterweights) {
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
  qmax(kCrankDisc) = problem_.original.counter_rotations.crank.inertia;
  qmax(kRockerDisc) = problem_.original.counter_rotations.rocker.inertia;
  qmax(kOne) = 1.0;
  return qmax;
}

// t_max for each bound variable: max over instants of Σ_rows Σ_j |A_ij| qmax_j with qmax the
// box_bounds(), so no design in the box has a larger peak (linear form: a larger smoothed peak
// sqrt(peak² + δ²)).
void DrivenNlp::bound_peaks() {
  const VecQ qmax = box_bounds();
  for (Metric m : kMetrics) {
    const int t = bound_var_[metric_index(m)];
    if (t < 0) continue;
    const int g = group_of(m), rows = kGroupRows[g];
    const VectorXd row_bounds = A_[g].cwiseAbs() * qmax;
    double worst = 0;
    for (int i = 0; i < instants_; ++i)
      worst = std::max(worst, row_bounds.segment(rows * i, rows).sum());
    if (linear_) worst = std::hypot(worst, eps_ * original(m));  // t >= sqrt(|y_i|² + δ²)
    upper_(t) = worst * (1 + 1e-9) + std::numeric_limits<double>::min();  // round-off margin
    // Linear form: t is kept above sqrt(|y_i|² + δ²) > 0 by its constraints alone, and boxed in
    // [-t_max, t_max]. With a lower bound at 0 (or δ), SLSQP's quadratic subproblems put t on
    // that bound at infeasible iterates, twice running at the same objective, and NLopt's
    // SLSQP then stops on ftol_rel (it tests f at every iterate once any feasible point was
    // seen), far from the optimum (docs/performance.md, "The objective's form").
    if (linear_) lower_(t) = -upper_(t);
  }
}

// ---------------------------------------------------------------------------------------------
// evaluation

double DrivenNlp::rms_squared(int g, const VecQ& q) const {
  return (R_[g] * q).squaredNorm() / samples_;
}

std::vector<double> DrivenNlp::magnitudes(int g, const VecQ& q) const {
  const VectorXd y = A_[g] * q;
  const int rows = kGroupRows[g];
  std::vector<double> v(static_cast<std::size_t>(instants_));
  for (int i = 0; i < instants_; ++i) {
    v[static_cast<std::size_t>(i)] = rows == 1 ? std::abs(y(i)) : y.segment(rows * i, rows).norm();
  }
  return v;
}

double DrivenNlp::peak(int g, const VecQ& q) const {
  const std::vector<double> v = magnitudes(g, q);
  return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end());
}

std::vector<double> DrivenNlp::peak_instants(const VectorXd& x, double within) const {
  std::vector<Metric> used;
  for (const Term& t : problem_.objective) {
    if (t.weight > 0 && is_peak(t.metric)) used.push_back(t.metric);
  }
  for (const Limit& l : problem_.limits) {
    if (is_peak(l.metric)) used.push_back(l.metric);
  }
  std::vector<double> out;
  if (instants_ == samples_) return out;
  const VecQ q = inertial(x, false).q;
  for (const Metric m : used) {
    detail::add_local_maxima(theta1_, magnitudes(group_of(m), q),
                             static_cast<std::size_t>(samples_), within * original(m), out);
  }
  return out;
}

double DrivenNlp::reaction_metric(const VectorXd& x, Metric m) const {
  const VecQ q = inertial(x, false).q;
  return is_peak(m) ? peak(group_of(m), q) : std::sqrt(rms_squared(group_of(m), q));
}

// every sample's outputs from the regressor, at the instants of core::simulate_driven (the
// problem's peak angles are not samples)
core::Trajectory DrivenNlp::trajectory_of(const VecQ& q) const {
  core::Trajectory t;
  t.samples.resize(static_cast<std::size_t>(samples_));
  t.t.resize(static_cast<std::size_t>(samples_));
  std::array<VectorXd, kGroups> y;
  for (int g = 0; g < kGroups; ++g) y[g] = A_[g].topRows(kGroupRows[g] * samples_) * q;
  for (int i = 0; i < samples_; ++i) {
    const auto j = static_cast<std::size_t>(i);
    t.t[j] = core::driven_sample_time(scene(), i);
    core::DynamicsSample& s = t.samples[j];
    s.state.theta1 = theta1_[j];
    s.state.omega1 = scene().omega1;
    s.RA0 = y[kRA0].segment<2>(2 * i);
    s.RA3 = y[kRA3].segment<2>(2 * i);
    s.Fsh_inertial = y[kFsh].segment<2>(2 * i);
    s.Msh_inertial = y[kMsh](i);
    s.Fsh = y[kFshTotal].segment<2>(2 * i);
    s.Msh = y[kMshTotal](i);
    s.tau = y[kTau](i);
  }
  t.status = core::SimulationStatus::kCompleted;
  t.message = "completed (regressor)";
  return t;
}

// each bound variable a hair above its (smoothed) peak at the start design, so that its
// constraints survive the round-off of sqrt
void DrivenNlp::start_extra_variables(VectorXd& x) const {
  const VecQ q = inertial(x, false).q;
  for (Metric m : kMetrics) {
    const int t = bound_var_[metric_index(m)];
    if (t < 0) continue;
    double p = peak(group_of(m), q);
    if (linear_) p = std::hypot(p, eps_ * original(m));
    x(t) = std::min(p * (1 + 1e-12), upper_(t));
  }
}

double DrivenNlp::objective(const VectorXd& x, VectorXd* grad) const {
  const Inertial in = inertial(x, grad != nullptr);
  double f = 0;
  Eigen::RowVectorXd dq;  // ∂f/∂q
  if (grad) {
    grad->setZero(n_);
    dq.setZero(kQ);
  }
  for (Metric m : kMetrics) {
    const double w = weight_[metric_index(m)];
    if (!(w > 0)) continue;
    const double o = original(m);
    if (m == Metric::kAddedMass) {
      f += w * added_mass(in.q) / o;
      if (grad) {
        for (int k = 1; k <= 3; ++k) dq(link_base(k)) += w / o;
      }
    } else if (is_peak(m)) {
      const int t = bound_var_[metric_index(m)];
      if (linear_) {
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
      const VectorXd Rq = R_[g] * in.q;
      const double r2 = Rq.squaredNorm() / (samples_ * o * o);
      double dr2 = w;  // ∂term/∂r²
      if (linear_) {
        f += w * smoothed(r2, eps_);
        dr2 = w / (2 * std::sqrt(r2 + eps_ * eps_));
      } else {
        f += w * r2;
      }
      if (grad) dq += (2 * dr2 / (samples_ * o * o)) * Rq.transpose() * R_[g];
    }
  }
  if (grad) grad->head(n_) += (dq * in.B).transpose();
  return f;
}

void DrivenNlp::metric_inequalities(const VectorXd& x, const Inertial& in, VectorXd& c,
                                    MatrixXd* jac) const {
  GroupOutputs groups(A_, in, jac != nullptr);
  int row = 0;
  for (const Block& b : blocks_) {
    switch (b.kind) {
      case Block::Kind::kRmsLimit:
        rms_limit(b, in, row, c, jac);
        break;
      case Block::Kind::kPeakBound:
        if (linear_) {
          smoothed_peak_bound(b, x, groups, row, c, jac);
        } else {
          squared_peak_rows(b, x, groups, row, c, jac);
        }
        break;
      case Block::Kind::kPeakLimit:
        squared_peak_rows(b, x, groups, row, c, jac);
        break;
      case Block::Kind::kEnvelope:
      case Block::Kind::kAddedMassLimit:
      case Block::Kind::kRelaxation:
        break;
    }
    row += b.count;
  }
}

// (RMS / limit)² - 1 = |R q|² / (N limit²) - 1
void DrivenNlp::rms_limit(const Block& b, const Inertial& in, int row, VectorXd& c,
                          MatrixXd* jac) const {
  const double limit = b.value * original(b.metric);
  const int g = group_of(b.metric);
  const VectorXd Rq = R_[g] * in.q;
  const double scale = 1 / (samples_ * limit * limit);
  c(row) = scale * Rq.squaredNorm() - 1;
  if (jac) jac->row(row) = 2 * scale * (Rq.transpose() * R_[g]) * in.B;
}

// (sqrt(|y_i|² + δ²) - t) / o with δ = ε o: linear in t, so its gradient never vanishes
// (|y_i|² - t² has none at y_i = 0, t = 0: a force-balanced optimum)
void DrivenNlp::smoothed_peak_bound(const Block& b, const VectorXd& x, GroupOutputs& groups,
                                    int row, VectorXd& c, MatrixXd* jac) const {
  const double o = original(b.metric);
  const double delta = eps_ * o, t = x(b.bound_var);
  const int g = group_of(b.metric), rows = kGroupRows[g];
  for (int i = 0; i < b.count; ++i) {
    const auto yi = groups.y(g).segment(rows * i, rows);
    const double n2 = yi.squaredNorm(), root = std::sqrt(n2 + delta * delta);
    c(row + i) = (root - t) / o;
    if (jac) {
      jac->row(row + i) = yi.transpose() * groups.AB(g).middleRows(rows * i, rows) / (root * o);
      (*jac)(row + i, b.bound_var) = -1 / o;
    }
  }
}

// (|y_i|² - t²) / s² at every sample: a peak limit (t = s = its value times the original's) or,
// in the squared form, a peak bound (t the variable, s the original's value)
void DrivenNlp::squared_peak_rows(const Block& b, const VectorXd& x, GroupOutputs& groups, int row,
                                  VectorXd& c, MatrixXd* jac) const {
  const bool limit = b.kind == Block::Kind::kPeakLimit;
  const double o = original(b.metric);
  const double s = limit ? b.value * o : o;  // the scale of the bound
  const double t = limit ? s : x(b.bound_var);
  const int g = group_of(b.metric), rows = kGroupRows[g];
  for (int i = 0; i < b.count; ++i) {
    const auto yi = groups.y(g).segment(rows * i, rows);
    c(row + i) = (yi.squaredNorm() - t * t) / (s * s);
    if (jac) {
      jac->row(row + i) = 2 * yi.transpose() * groups.AB(g).middleRows(rows * i, rows) / (s * s);
      if (!limit) (*jac)(row + i, b.bound_var) = -2 * t / (s * s);
    }
  }
}

}  // namespace

std::unique_ptr<NlpProgram> make_driven_nlp(const DesignProblem& problem,
                                            CounterweightVariablesAs as) {
  return std::make_unique<DrivenNlp>(problem, as);
}

}  // namespace bd::optimize::detail
