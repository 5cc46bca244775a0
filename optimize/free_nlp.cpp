// The program in a free scene: every evaluation is a forward simulation of the design
// (core::simulate_free); a design whose simulation fails evaluates to +infinity. With the
// reduced equation in theta1 (formulations mass-matrix and complex-masses) the gradients come
// from the forward sensitivities of the same simulation (core/fourbar/sensitivity.hpp: CVODES
// integrates dy/dp for the links' mass parameters p, and each metric's gradient follows from the
// samples' derivatives), chained with ∂p/∂x from the inertial parameters q(x):
//   m = q_b, e = q_b+1 / m, f = q_b+2 / m, I = J - m (e² + f²) with J = q_b+3,
// so dm = dq_b, de = (dq_b+1 - e dq_b) / m, df = (dq_b+2 - f dq_b) / m,
// dI = dJ - 2 e dq_b+1 - 2 f dq_b+2 + (e² + f²) dq_b.
// On the opened loop's DAE (formulation opened-loop) there are no gradients: derivative-free
// methods only. The last evaluation is kept, so the objective and the constraints at the same x
// simulate once: a plain simulation when no derivative is asked for, the sensitivity run (its
// metrics and their gradients) when one is.
#include <limits>
#include <mutex>

#include "core/fourbar/sensitivity.hpp"
#include "optimize/nlp_program.hpp"

namespace bd::optimize::detail {

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

core::Metrics infinite_metrics() {
  core::Metrics m;
  for (const core::MetricInfo& info : core::kMetricTable) {
    m.*info.field = std::numeric_limits<double>::infinity();
  }
  return m;
}

class FreeNlp final : public NlpProgram {
 public:
  FreeNlp(const DesignProblem& problem, CounterweightVariablesAs as);

  bool has_gradients() const override {
    return problem_.formulation != core::Formulation::kOpenedLoop;
  }
  double objective(const VectorXd& x, VectorXd* grad) const override;
  core::Trajectory trajectory(const VectorXd& x) const override { return simulate(design(x)); }
  core::Metrics metrics(const VectorXd& x) const override { return evaluate(x, false).metrics; }

 private:
  // the metrics at x and, when asked for, their gradients d(metric)/dx (rows in
  // core::kMetricTable's order; zero where the simulation failed)
  struct Evaluation {
    VectorXd x;
    core::Metrics metrics;
    MatrixXd gradient;  // core::kMetricCount x n(), or empty
  };
  Evaluation evaluate(const VectorXd& x, bool with_gradient) const;
  // ∂p/∂x for the sensitivity parameters (4 per varied link) at x
  MatrixXd parameter_jacobian(const VectorXd& x) const;
  // d(metric)/dx of a reaction metric (a row of the table)
  static auto gradient_row(const Evaluation& e, Metric m) {
    return e.gradient.row(static_cast<Eigen::Index>(metric_index(m)));
  }

  void metric_inequalities(const VectorXd& x, const Inertial& in, VectorXd& c,
                           MatrixXd* jac) const override;
  double reaction_metric(const VectorXd& x, Metric m) const override {
    return value(metrics(x), m);
  }

  // with resolve_peaks, the peaks the objective or a limit reads (core::kMetricTable's order):
  // resolved between the samples (the others are their largest samples)
  core::MetricMask read_peaks_ = resolved_peak_rows(problem_);
  std::vector<core::LinkParameter> parameters_;  // every mass parameter of each varied link
  std::vector<int> varied_links_;                // their links, in order

  mutable std::mutex cache_mutex_;
  mutable Evaluation cached_;
};

FreeNlp::FreeNlp(const DesignProblem& problem, CounterweightVariablesAs as)
    : NlpProgram(problem, as) {
  set_up_constraints();
  for (int k = 1; k <= 3; ++k) {
    bool varied = false;
    for (const CounterweightVariables& c : problem_.counterweights) varied |= c.link == k;
    for (const LinkParameterVariable& v : problem_.link_parameters) varied |= v.link == k;
    if (!varied) continue;
    varied_links_.push_back(k);
    for (auto kind : {core::LinkParameter::Kind::kMass, core::LinkParameter::Kind::kE,
                      core::LinkParameter::Kind::kF, core::LinkParameter::Kind::kInertia}) {
      parameters_.push_back({k, kind});
    }
  }
}

MatrixXd FreeNlp::parameter_jacobian(const VectorXd& x) const {
  const Inertial in = inertial(x, true);
  MatrixXd P(static_cast<Eigen::Index>(parameters_.size()), n_);
  for (std::size_t i = 0; i < varied_links_.size(); ++i) {
    const int b = link_base(varied_links_[i]);
    const auto r = static_cast<Eigen::Index>(4 * i);
    const double m = in.q(b), e = in.q(b + 1) / m, f = in.q(b + 2) / m;
    P.row(r) = in.B.row(b);
    P.row(r + 1) = (in.B.row(b + 1) - e * in.B.row(b)) / m;
    P.row(r + 2) = (in.B.row(b + 2) - f * in.B.row(b)) / m;
    P.row(r + 3) = in.B.row(b + 3) - 2 * e * in.B.row(b + 1) - 2 * f * in.B.row(b + 2) +
                   (e * e + f * f) * in.B.row(b);
  }
  return P;
}

FreeNlp::Evaluation FreeNlp::evaluate(const VectorXd& x, bool with_gradient) const {
  const std::lock_guard<std::mutex> lock(cache_mutex_);
  if (cached_.x.size() == x.size() && cached_.x == x &&
      (!with_gradient || cached_.gradient.size() != 0)) {
    return cached_;
  }
  Evaluation e;
  e.x = x;
  const core::SimulateOptions options = simulate_options();
  const core::FourBar model = design(x);
  // the peaks the problem reads resolved (none without resolve_peaks: read_peaks_ is then all
  // false, and these are the samples' metrics and gradients)
  if (!with_gradient) {
    const core::Trajectory t = simulate(model);
    e.metrics = t.ok() ? core::metrics(model, t, options, &read_peaks_) : infinite_metrics();
  } else {
    const core::FreeSensitivities run = core::simulate_free_sensitivities(
        model, std::get<core::FreeScene>(problem_.scene), parameters_, options);
    e.gradient = MatrixXd::Zero(static_cast<Eigen::Index>(core::kMetricCount), n_);
    if (!run.trajectory.ok()) {
      e.metrics = infinite_metrics();
    } else {
      core::PeakList peaks;
      e.metrics = core::metrics(model, run.trajectory, options, &read_peaks_, &peaks);
      // the others' peaks as metric_gradients(run) takes them: at their largest samples
      for (std::size_t k = 0; k < core::kMetricCount; ++k) {
        if (!read_peaks_[k]) peaks.table[k] = core::Peak{};
      }
      e.gradient = core::metric_gradients(model, run, options, peaks) * parameter_jacobian(x);
    }
  }
  cached_ = e;
  return e;
}

// linear form: an RMS smoothed as in driven scenes, a peak exactly (no bound variable);
// squared form: each ratio squared
double FreeNlp::objective(const VectorXd& x, VectorXd* grad) const {
  require_gradients(grad != nullptr, "objective");
  const Evaluation e = evaluate(x, grad != nullptr);
  if (grad) grad->setZero(n_);
  double f = 0;
  for (Metric m : kMetrics) {
    const double w = weight_[metric_index(m)];
    if (!(w > 0)) continue;
    if (m == Metric::kAddedMass) {
      const Inertial in = inertial(x, grad != nullptr);
      f += w * added_mass(in.q) / original_mass_;
      if (grad) {
        for (int k = 1; k <= 3; ++k)
          *grad += w * in.B.row(link_base(k)).transpose() / original_mass_;
      }
      continue;
    }
    const double r = value(e.metrics, m) / original(m);
    // the term and its derivative with respect to r
    double term = 0, dterm = 0;
    if (!linear_) {
      term = r * r, dterm = 2 * r;
    } else if (is_peak(m)) {
      term = r, dterm = 1;
    } else {
      term = smoothed(r * r, eps_), dterm = r / term;
    }
    f += w * term;
    if (grad) *grad += w * dterm / original(m) * gradient_row(e, m).transpose();
  }
  return f;
}

// a limit on a reaction metric: (metric / (value · original))² - 1, the peak evaluated directly
void FreeNlp::metric_inequalities(const VectorXd& x, const Inertial&, VectorXd& c,
                                  MatrixXd* jac) const {
  const Evaluation e = evaluate(x, jac != nullptr);
  int row = 0;
  for (const Block& b : blocks_) {
    if (b.kind == Block::Kind::kRmsLimit || b.kind == Block::Kind::kPeakLimit) {
      const double scale = b.value * original(b.metric), r = value(e.metrics, b.metric) / scale;
      c(row) = r * r - 1;
      if (jac) jac->row(row) = 2 * r / scale * gradient_row(e, b.metric);
    }
    row += b.count;
  }
}

}  // namespace

std::unique_ptr<NlpProgram> make_free_nlp(const DesignProblem& problem,
                                          CounterweightVariablesAs as) {
  return std::make_unique<FreeNlp>(problem, as);
}

}  // namespace bd::optimize::detail
