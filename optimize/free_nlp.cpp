// The program in a free scene: every evaluation is a forward simulation of the design
// (core::simulate_free), without gradients; a design whose simulation fails evaluates to
// +infinity. The last simulation is kept, so the objective and the constraints at the same x
// simulate once.
#include <limits>
#include <mutex>

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
  FreeNlp(const DesignProblem& problem, CounterweightVariablesAs as) : NlpProgram(problem, as) {
    set_up_constraints();
  }

  bool has_gradients() const override { return false; }
  double objective(const VectorXd& x, VectorXd* grad) const override;
  core::Trajectory trajectory(const VectorXd& x) const override { return simulate(design(x)); }
  core::Metrics metrics(const VectorXd& x) const override;

 private:
  void metric_inequalities(const VectorXd& x, const Inertial& in, VectorXd& c,
                           MatrixXd* jac) const override;
  double reaction_metric(const VectorXd& x, Metric m) const override {
    return value(metrics(x), m);
  }

  // the last simulation
  mutable std::mutex cache_mutex_;
  mutable VectorXd cached_x_;
  mutable core::Metrics cached_metrics_;
};

core::Metrics FreeNlp::metrics(const VectorXd& x) const {
  const std::lock_guard<std::mutex> lock(cache_mutex_);
  if (cached_x_.size() == x.size() && cached_x_ == x) return cached_metrics_;
  const core::Trajectory t = trajectory(x);
  cached_metrics_ = t.ok() ? core::metrics(t) : infinite_metrics();
  cached_x_ = x;
  return cached_metrics_;
}

// linear form: an RMS smoothed as in driven scenes, a peak exactly (no bound variable);
// squared form: each ratio squared
double FreeNlp::objective(const VectorXd& x, VectorXd* grad) const {
  require_gradients(grad != nullptr, "objective");
  const core::Metrics v = metrics(x);
  double f = 0;
  for (Metric m : kMetrics) {
    const double w = weight_[metric_index(m)];
    if (!(w > 0)) continue;
    if (m == Metric::kAddedMass) {
      f += w * added_mass(inertial(x, false).q) / original_mass_;
    } else {
      const double r = value(v, m) / original(m);
      f += w * (!linear_ ? r * r : is_peak(m) ? r : smoothed(r * r, eps_));
    }
  }
  return f;
}

// a limit on a reaction metric: (metric / (value · original))² - 1, the peak evaluated directly
void FreeNlp::metric_inequalities(const VectorXd& x, const Inertial&, VectorXd& c,
                                  MatrixXd*) const {
  const core::Metrics v = metrics(x);
  int row = 0;
  for (const Block& b : blocks_) {
    if (b.kind == Block::Kind::kRmsLimit || b.kind == Block::Kind::kPeakLimit) {
      const double r = value(v, b.metric) / (b.value * original(b.metric));
      c(row) = r * r - 1;
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
