// Nlp: the program of the problem's scene (optimize/nlp_program.hpp), behind one interface.
#include "optimize/nlp.hpp"

#include <string>
#include <variant>

#include "core/input_error.hpp"
#include "optimize/nlp_program.hpp"

namespace bd::optimize {

namespace {

std::unique_ptr<detail::NlpProgram> program_for(const DesignProblem& problem,
                                                CounterweightVariablesAs as) {
  if (std::holds_alternative<core::DrivenScene>(problem.scene)) {
    return detail::make_driven_nlp(problem, as);
  }
  return detail::make_free_nlp(problem, as);
}

}  // namespace

Nlp::Nlp(const DesignProblem& problem, CounterweightVariablesAs as)
    : program_(program_for(problem, as)) {}
Nlp::~Nlp() = default;

int Nlp::n() const { return program_->n(); }
int Nlp::n_eq() const { return program_->n_eq(); }
int Nlp::n_ineq() const { return program_->n_ineq(); }
const Eigen::VectorXd& Nlp::lower() const { return program_->lower(); }
const Eigen::VectorXd& Nlp::upper() const { return program_->upper(); }
const std::vector<std::string>& Nlp::variable_names() const { return program_->variable_names(); }
const std::vector<std::string>& Nlp::constraint_names() const {
  return program_->constraint_names();
}
std::string Nlp::constraint_text(int i, const Eigen::VectorXd& x) const {
  return program_->constraint_text(i, x);
}
bool Nlp::has_gradients() const { return program_->has_gradients(); }
bool Nlp::free_scene() const { return program_->free_scene(); }
std::string Nlp::why_not_convex() const { return program_->why_not_convex(); }
Eigen::VectorXd Nlp::from_positions(const Eigen::VectorXd& x) const {
  return program_->start_at(program_->from_positions(x));
}
Eigen::VectorXd Nlp::to_positions(const Eigen::VectorXd& x) const {
  return at(x).to_positions(x);
}
Eigen::VectorXd Nlp::within_envelopes(const Eigen::VectorXd& x) const {
  return from_positions(to_positions(x));
}
Eigen::VectorXd Nlp::without_vanishing_counterweights(const Eigen::VectorXd& x,
                                                      double fraction) const {
  return at(x).without_vanishing_counterweights(x, fraction);
}
std::vector<int> Nlp::vanishing_counterweight_variables(const Eigen::VectorXd& x,
                                                       double fraction) const {
  return at(x).vanishing_counterweight_variables(x, fraction);
}
Eigen::VectorXd Nlp::start(bool original) const { return program_->start(original); }
Eigen::VectorXd Nlp::start_scaled(double fraction) const {
  return program_->start_scaled(fraction);
}
Eigen::VectorXd Nlp::start_at(const Eigen::VectorXd& design) const {
  return program_->start_at(design);
}

const detail::NlpProgram& Nlp::at(const Eigen::VectorXd& x) const {
  if (x.size() != program_->n()) {
    throw InputError("design vector has " + std::to_string(x.size()) + " entries; expected " +
                     std::to_string(program_->n()));
  }
  return *program_;
}

double Nlp::objective(const Eigen::VectorXd& x, Eigen::VectorXd* grad) const {
  return at(x).objective(x, grad);
}

void Nlp::equalities(const Eigen::VectorXd& x, Eigen::VectorXd& c, Eigen::MatrixXd* jac) const {
  at(x).equalities(x, c, jac);
}

void Nlp::inequalities(const Eigen::VectorXd& x, Eigen::VectorXd& c, Eigen::MatrixXd* jac) const {
  at(x).inequalities(x, c, jac);
}

void Nlp::first_order_inequalities(const Eigen::VectorXd& x, const Eigen::VectorXd& g,
                                   Eigen::VectorXd& c, Eigen::MatrixXd& jac) const {
  at(x).first_order_inequalities(x, g, c, jac);
}

core::FourBar Nlp::design(const Eigen::VectorXd& x) const { return at(x).design(x); }

std::vector<PlacedCounterweight> Nlp::counterweights(const Eigen::VectorXd& x) const {
  return at(x).counterweights(x);
}

core::Metrics Nlp::metrics(const Eigen::VectorXd& x) const { return at(x).metrics(x); }

core::Trajectory Nlp::trajectory(const Eigen::VectorXd& x) const { return at(x).trajectory(x); }

double Nlp::metric(const Eigen::VectorXd& x, Metric m) const { return at(x).metric(x, m); }

double Nlp::original(Metric m) const { return program_->original(m); }
std::vector<int> Nlp::counterweight_mass_variables() const { return program_->cw_var(); }
std::vector<double> Nlp::counterweight_reach() const { return program_->counterweight_reach(); }

std::vector<double> Nlp::peak_instants(const Eigen::VectorXd& x, double within) const {
  return at(x).peak_instants(x, within);
}

}  // namespace bd::optimize
