#pragma once
/// Internal to bd_optimize: a program with some of its variables held at given values, as a
/// program in the others. Used to go on from a solver's end with the counterweights it left
/// vanishing put on their cone's apex and kept there (optimize.cpp, ensure_first_order();
/// convex_solve.hpp, tight_bound()): at the apex a cone has no gradient and the direction of a
/// vanishing mass moment is round-off, so a gradient method turns there with the round-off,
/// where with those variables fixed the rest of the problem is smooth and it converges in a few
/// steps. Whether the apex is right for them is then the whole program's first-order check.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "optimize/program.hpp"

namespace bd::optimize::detail {

class FixedVariables final : public Program {
 public:
  /// `base` with the variables `fixed` (indices into its x) held at their values in `at`.
  FixedVariables(const Program& base, const std::vector<int>& fixed, const Eigen::VectorXd& at)
      : base_(base), full_(at) {
    std::vector<bool> is_fixed(static_cast<std::size_t>(base.n()), false);
    for (int j : fixed) is_fixed[static_cast<std::size_t>(j)] = true;
    for (int j = 0; j < base.n(); ++j) {
      if (!is_fixed[static_cast<std::size_t>(j)]) free_.push_back(j);
    }
    lower_ = reduce(base.lower());
    upper_ = reduce(base.upper());
    for (int j : free_) names_.push_back(base.variable_names()[static_cast<std::size_t>(j)]);
  }

  /// The free variables of a whole x, and a whole x from the free ones (the fixed at their
  /// values).
  Eigen::VectorXd reduce(const Eigen::VectorXd& x) const {
    Eigen::VectorXd out(static_cast<Eigen::Index>(free_.size()));
    for (std::size_t k = 0; k < free_.size(); ++k) out[static_cast<Eigen::Index>(k)] = x[free_[k]];
    return out;
  }
  Eigen::VectorXd expand(const Eigen::VectorXd& y) const {
    Eigen::VectorXd out = full_;
    for (std::size_t k = 0; k < free_.size(); ++k) out[free_[k]] = y[static_cast<Eigen::Index>(k)];
    return out;
  }

  int n() const override { return static_cast<int>(free_.size()); }
  int n_eq() const override { return base_.n_eq(); }
  int n_ineq() const override { return base_.n_ineq(); }
  const Eigen::VectorXd& lower() const override { return lower_; }
  const Eigen::VectorXd& upper() const override { return upper_; }
  const std::vector<std::string>& variable_names() const override { return names_; }
  const std::vector<std::string>& constraint_names() const override {
    return base_.constraint_names();
  }
  bool has_gradients() const override { return base_.has_gradients(); }
  double objective(const Eigen::VectorXd& y, Eigen::VectorXd* grad) const override {
    if (grad == nullptr) return base_.objective(expand(y), nullptr);
    Eigen::VectorXd g(base_.n());
    const double f = base_.objective(expand(y), &g);
    *grad = reduce(g);
    return f;
  }
  void equalities(const Eigen::VectorXd& y, Eigen::VectorXd& c,
                  Eigen::MatrixXd* jac) const override {
    rows(y, c, jac, [&](const Eigen::VectorXd& x, Eigen::VectorXd& cc, Eigen::MatrixXd* j) {
      base_.equalities(x, cc, j);
    });
  }
  void inequalities(const Eigen::VectorXd& y, Eigen::VectorXd& c,
                    Eigen::MatrixXd* jac) const override {
    rows(y, c, jac, [&](const Eigen::VectorXd& x, Eigen::VectorXd& cc, Eigen::MatrixXd* j) {
      base_.inequalities(x, cc, j);
    });
  }
  void first_order_inequalities(const Eigen::VectorXd& y, const Eigen::VectorXd& g,
                                Eigen::VectorXd& c, Eigen::MatrixXd& jac) const override {
    // the whole gradient, with zeros for the fixed variables (whose cones are on their apex)
    Eigen::VectorXd whole = Eigen::VectorXd::Zero(base_.n());
    for (std::size_t k = 0; k < free_.size(); ++k) {
      whole[free_[k]] = g[static_cast<Eigen::Index>(k)];
    }
    rows(y, c, &jac, [&](const Eigen::VectorXd& x, Eigen::VectorXd& cc, Eigen::MatrixXd* j) {
      base_.first_order_inequalities(x, whole, cc, *j);
    });
  }
  void polish(Eigen::VectorXd& y) const override {
    Eigen::VectorXd x = expand(y);
    base_.polish(x);
    y = reduce(x);
  }
  std::string constraint_text(int i, const Eigen::VectorXd& y) const override {
    return base_.constraint_text(i, expand(y));
  }

 private:
  template <class Rows>
  void rows(const Eigen::VectorXd& y, Eigen::VectorXd& c, Eigen::MatrixXd* jac,
            Rows&& of) const {
    if (jac == nullptr) {
      of(expand(y), c, nullptr);
      return;
    }
    Eigen::MatrixXd whole;
    of(expand(y), c, &whole);
    jac->resize(whole.rows(), n());
    for (std::size_t k = 0; k < free_.size(); ++k) {
      jac->col(static_cast<Eigen::Index>(k)) = whole.col(free_[k]);
    }
  }

  const Program& base_;
  Eigen::VectorXd full_;
  std::vector<int> free_;
  Eigen::VectorXd lower_, upper_;
  std::vector<std::string> names_;
};

}  // namespace bd::optimize::detail
