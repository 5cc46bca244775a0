// What the driven and the free program share: set-up, variables, q(x), the design at x, the
// force-balance equalities, the envelopes and the added-mass limits.
#include "optimize/nlp_program.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <variant>

#include "core/input_error.hpp"
#include "core/number_text.hpp"
#include "optimize/convex_solve.hpp"

namespace bd::optimize::detail {

double& parameter(core::Link& link, LinkParameterVariable::Parameter p) {
  switch (p) {
    case LinkParameterVariable::Parameter::kMass:
      return link.mass;
    case LinkParameterVariable::Parameter::kE:
      return link.e;
    case LinkParameterVariable::Parameter::kF:
      return link.f;
    case LinkParameterVariable::Parameter::kInertia:
      break;
  }
  return link.inertia;
}

// ---------------------------------------------------------------------------------------------
// set-up

NlpProgram::NlpProgram(const DesignProblem& p, CounterweightVariablesAs as)
    : problem_(p),
      moments_(as == CounterweightVariablesAs::kMassMoments ||
               as == CounterweightVariablesAs::kRelaxation),
      relaxed_(as == CounterweightVariablesAs::kRelaxation) {
  if (const Problem e = problem_.validate()) {
    throw InputError("invalid design problem: " + e->text());
  }
  problem_.original = core::make_fourbar(problem_.original);
  original_mass_ = core::total_mass(problem_.original);
  linear_ = problem_.objective_form == ObjectiveForm::kLinear;
  eps_ = problem_.smoothing;
  for (const Term& t : problem_.objective) weight_[metric_index(t.metric)] += t.weight;

  // the original's metrics, by core's own simulation (the normalisers)
  const core::Trajectory trajectory = simulate(problem_.original);
  if (!trajectory.ok()) {
    const bool driven = std::holds_alternative<core::DrivenScene>(problem_.scene);
    throw InputError(FieldError{"", -1,
                                std::string("the original design cannot be evaluated in the ") +
                                    (driven ? "driven" : "free") +
                                    " scene: " + trajectory.message});
  }
  // with resolve_peaks, the peaks resolved between the samples, as the exchange steps bound a
  // driven optimum's (optimize()) and a free scene's program evaluates them: a limit's
  // "x original" is then the motion's peak
  const auto* driven = std::get_if<core::DrivenScene>(&problem_.scene);
  original_metrics_ = !problem_.resolve_peaks ? core::metrics(trajectory)
                      : driven ? core::metrics(problem_.original, *driven, trajectory,
                                               problem_.formulation, nullptr)
                               : core::metrics(problem_.original, trajectory, simulate_options());
  check_normalisers();
  set_up_design_variables();
}

core::SimulateOptions NlpProgram::simulate_options() const {
  core::SimulateOptions options;
  options.formulation = problem_.formulation;
  options.tolerance = problem_.tolerance;
  return options;
}

core::Trajectory NlpProgram::simulate(const core::FourBar& model) const {
  const core::SimulateOptions options = simulate_options();
  if (const auto* driven = std::get_if<core::DrivenScene>(&problem_.scene)) {
    return core::simulate_driven(model, *driven, options);
  }
  return core::simulate_free(model, std::get<core::FreeScene>(problem_.scene), options);
}

void NlpProgram::check_normalisers() const {
  const core::Metrics& o = original_metrics_;
  const double force = std::max({o.RA0_max, o.RA3_max, o.Fsh_max});
  const double moment = std::max({o.tau_max, o.Msh_max, force * problem_.original.frame_length});
  auto check = [&](Metric m, const char* list, std::size_t i) {
    if (m == Metric::kAddedMass) return;
    const double v = value(o, m), scale = is_moment(m) ? moment : force;
    if (!(v > 1e-10 * scale)) {
      throw InputError(FieldError{list, static_cast<int>(i),
                                  std::string(": the original design's ") + to_string(m) + " is " +
                                      text::digits(v, 6) + " " + metric_unit(m) +
                                      ", too small to normalise by (it is already minimal)"});
    }
  };
  for (std::size_t i = 0; i < problem_.objective.size(); ++i) {
    const Term& t = problem_.objective[i];
    if (t.weight > 0) check(t.metric, "objective", i);
  }
  for (std::size_t i = 0; i < problem_.limits.size(); ++i) {
    check(problem_.limits[i].metric, "limits", i);
  }
}

int NlpProgram::add_variable(double lower, double upper, std::string name) {
  lower_.conservativeResize(n_ + 1);
  upper_.conservativeResize(n_ + 1);
  lower_(n_) = lower;
  upper_(n_) = upper;
  variable_names_.push_back(std::move(name));
  return n_++;
}

void NlpProgram::set_up_design_variables() {
  for (const CounterweightVariables& c : problem_.counterweights) {
    const std::string name = std::string(core::link_name(c.link)) + " counterweight ";
    const double d = c.distance_max;
    cw_var_.push_back(add_variable(0.0, c.mass_max, name + "mass [kg]"));
    const char* pivot = c.link == 1 ? "A0" : "A3";
    if (moments_) {
      const double p = c.mass_max * d;
      add_variable(-p, p, name + "mass moment x about " + pivot + " in link axes [kg m]");
      add_variable(-p, p, name + "mass moment y about " + pivot + " in link axes [kg m]");
      continue;
    }
    add_variable(-d, d, name + "x from " + pivot + " in link axes [m]");
    add_variable(-d, d, name + "y from " + pivot + " in link axes [m]");
  }
  for (const LinkParameterVariable& v : problem_.link_parameters) {
    param_var_.push_back(add_variable(v.lower, v.upper,
                                      std::string(core::link_name(v.link)) + " " +
                                          parameter_name(v.parameter) + " [" +
                                          parameter_unit(v.parameter) + "]"));
  }
  if (!relaxed_) return;
  for (std::size_t c = 0; c < problem_.counterweights.size(); ++c) {
    const CounterweightVariables& cw = problem_.counterweights[c];
    RelaxedCounterweight r;
    r.mass = cw_var_[c];
    r.mass_max = cw.mass_max;
    r.distance_max = cw.distance_max;
    const std::string name = std::string(core::link_name(cw.link)) + " counterweight ";
    const char* pivot = cw.link == 1 ? "A0" : "A3";
    r.w = add_variable(0.0, r.w_max(),
                       name + "inertia of its mass about " + pivot + " (relaxed) [kg m²]");
    if (cw.shape == balance::CounterweightShape::kDisc) {
      r.disc_a = 1 / (2 * cw.density * std::numbers::pi * cw.thickness);
      r.s = add_variable(0.0, r.s_max(), name + "own inertia (relaxed) [kg m²]");
    }
    relaxed_cw_.push_back(r);
  }
}

void NlpProgram::set_relaxed_variables(Eigen::VectorXd& x) const {
  for (const RelaxedCounterweight& r : relaxed_cw_) r.set_tight(x);
}

// force balance (eq. 57) in q, over the original total mass:
// crank m1 s̄1/l1 + m2 (1 - s̄2/l2), rocker m2 s̄2/l2 + m3 (1 - s̄3/l3)
void NlpProgram::set_up_force_balance() {
  const double l1 = problem_.original.crank.length, l2 = problem_.original.coupler.length,
               l3 = problem_.original.rocker.length;
  const int b1 = link_base(1), b2 = link_base(2), b3 = link_base(3);
  balance_(0, b1 + 1) = 1 / l1;
  balance_(0, b2) = 1;
  balance_(0, b2 + 1) = -1 / l2;
  balance_(1, b1 + 2) = 1 / l1;
  balance_(1, b2 + 2) = -1 / l2;
  balance_(2, b2 + 1) = 1 / l2;
  balance_(2, b3) = 1;
  balance_(2, b3 + 1) = -1 / l3;
  balance_(3, b2 + 2) = 1 / l2;
  balance_(3, b3 + 2) = -1 / l3;
  balance_ /= original_mass_;
  n_eq_ = 4;
  for (const char* side : {"crank", "rocker"}) {
    for (const char* part : {"real", "imaginary"}) {
      constraint_names_.push_back(std::string("force balance, ") + side + " side (" + part +
                                  " part)");
    }
  }
}

void NlpProgram::set_up_constraints() {
  if (problem_.force_balance) set_up_force_balance();
  // envelopes
  for (std::size_t c = 0; c < problem_.counterweights.size(); ++c) {
    const CounterweightVariables& cw = problem_.counterweights[c];
    add_block({Block::Kind::kEnvelope, static_cast<int>(c), Metric::kAddedMass, 0.0, -1, 1},
              {std::string(core::link_name(cw.link)) + " counterweight within distance_max = " +
               text::digits(cw.distance_max, 6) + " m of " + (cw.link == 1 ? "A0" : "A3")});
    if (relaxed_) {
      const RelaxedCounterweight& r = relaxed_cw_[c];
      add_block({Block::Kind::kRelaxation, static_cast<int>(c), Metric::kAddedMass, 0.0, -1,
                 r.rows()},
                r.row_names(std::string(core::link_name(cw.link)) + " counterweight"));
    }
  }
  // limits
  for (const Limit& l : problem_.limits) {
    Block b{Block::Kind::kRmsLimit, -1, l.metric, l.value, -1, 1};
    const std::string name = std::string(to_string(l.metric)) + " <= " + text::digits(l.value, 6) +
                             (l.metric == Metric::kAddedMass ? " kg" : " x original");
    if (l.metric == Metric::kAddedMass) {
      b.kind = Block::Kind::kAddedMassLimit;
      add_block(b, {name});
    } else if (is_peak(l.metric)) {
      b.kind = Block::Kind::kPeakLimit;
      std::vector<std::string> names = peak_limit_names(name);
      b.count = static_cast<int>(names.size());
      add_block(b, std::move(names));
    } else {
      add_block(b, {name});
    }
  }
}

void NlpProgram::add_block(const Block& block, std::vector<std::string> names) {
  blocks_.push_back(block);
  for (std::string& name : names) constraint_names_.push_back(std::move(name));
  n_ineq_ += block.count;
}

std::vector<std::string> NlpProgram::peak_limit_names(const std::string& name) const {
  return {name};
}

void NlpProgram::start_extra_variables(Eigen::VectorXd&) const {}

// ---------------------------------------------------------------------------------------------
// mass-moment variables

Eigen::VectorXd NlpProgram::from_positions(const Eigen::VectorXd& x) const {
  Eigen::VectorXd z = x;
  if (!moments_) return z;
  for (int j : cw_var_) {
    if (j + 2 >= z.size()) break;
    z(j + 1) *= z(j);
    z(j + 2) *= z(j);
  }
  return z;
}

Eigen::VectorXd NlpProgram::to_positions(const Eigen::VectorXd& x) const {
  Eigen::VectorXd out = x.head(static_cast<Eigen::Index>(3 * cw_var_.size() + param_var_.size()));
  if (!moments_) return out;
  for (std::size_t c = 0; c < cw_var_.size(); ++c) {
    const int j = cw_var_[c];
    out.segment<2>(j + 1) = position_of(x(j), Vec2(x(j + 1), x(j + 2)),
                                    problem_.counterweights[c].distance_max);
  }
  return out;
}

std::vector<int> NlpProgram::vanishing_counterweight_variables(const Eigen::VectorXd& x,
                                                               double fraction) const {
  if (!moments_) return {};
  return detail::vanishing_counterweight_variables(x, cw_var_, problem_.counterweights, fraction);
}

Eigen::VectorXd NlpProgram::without_vanishing_counterweights(const Eigen::VectorXd& x,
                                                             double fraction) const {
  Eigen::VectorXd out = x;
  for (int j : vanishing_counterweight_variables(x, fraction)) out(j) = 0;
  set_relaxed_variables(out);
  return out;
}

std::string NlpProgram::why_not_convex() const {
  return "a free scene: the motion, and with it every reaction, depends on the design";
}

std::vector<std::pair<int, std::string>> NlpProgram::non_affine_parameters() const {
  std::vector<std::pair<int, std::string>> out;
  for (int k = 1; k <= 3; ++k) {
    const std::string name = core::link_name(k);
    bool mass = false, offset = false, counterweight = false;
    for (const LinkParameterVariable& v : problem_.link_parameters) {
      if (v.link != k) continue;
      mass = mass || v.parameter == LinkParameterVariable::Parameter::kMass;
      offset = offset || v.parameter == LinkParameterVariable::Parameter::kE ||
               v.parameter == LinkParameterVariable::Parameter::kF;
    }
    for (const CounterweightVariables& c : problem_.counterweights) {
      counterweight = counterweight || c.link == k;
    }
    const int b = link_base(k), r = rho_base(k);
    const std::string joint = k == 3 ? "A3" : k == 1 ? "A0" : "A1";
    if (counterweight && !relaxed_) {
      out.emplace_back(b + 3, "the " + name + "'s inertia about " + joint +
                                  ", which varies with the square of its counterweight's position");
    } else if (offset) {
      out.emplace_back(b + 3, "the " + name + "'s inertia about " + joint +
                                  ", which varies with the square of its e or f");
    }
    if (mass && offset) {
      for (int i : {b + 1, b + 2}) {
        out.emplace_back(i, "the " + name + "'s first moments, its mass times e or f, both "
                                            "varied");
      }
    }
    if (mass || counterweight) {
      for (int i : {r, r + 1}) {
        out.emplace_back(i, "the " + name + "'s centre of mass, where its applied force acts, "
                                            "which moves with its mass");
      }
    }
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// the design at x

// The link's own parameters at x as q(b..b+3) = (m, m e, m f, J) and, when asked for, their
// rows of ∂q/∂x; returns the link with its variables set.
core::Link NlpProgram::add_link(int k, const Eigen::VectorXd& x, Inertial& out,
                                bool with_jacobian) const {
  core::Link l = core::link(problem_.original, k);
  int var[4] = {-1, -1, -1, -1};  // the variable of each parameter, in Parameter's order
  for (std::size_t i = 0; i < problem_.link_parameters.size(); ++i) {
    const LinkParameterVariable& v = problem_.link_parameters[i];
    if (v.link != k) continue;
    parameter(l, v.parameter) = x(param_var_[i]);
    var[static_cast<int>(v.parameter)] = param_var_[i];
  }
  const int vm = var[0], ve = var[1], vf = var[2], vi = var[3];
  const int b = link_base(k);
  out.q(b) = l.mass;
  out.q(b + 1) = l.mass * l.e;
  out.q(b + 2) = l.mass * l.f;
  out.q(b + 3) = l.inertia + l.mass * (l.e * l.e + l.f * l.f);
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
  return l;
}

// The link's counterweight (if any) added to q(b..b+3): mass mc at r (link axes from the first
// joint), own inertia Ic(mc).
void NlpProgram::add_counterweight(int k, const core::Link& l, const Eigen::VectorXd& x,
                                   Inertial& out, bool with_jacobian) const {
  const int b = link_base(k);
  for (std::size_t c = 0; c < problem_.counterweights.size(); ++c) {
    const CounterweightVariables& cw = problem_.counterweights[c];
    if (cw.link != k) continue;
    const int j = cw_var_[c];
    const double mc = x(j);
    double Ic = 0, dIc = 0;
    if (cw.shape == balance::CounterweightShape::kDisc) {
      const double area_density = cw.density * std::numbers::pi * cw.thickness;  // m/r²
      Ic = mc * mc / (2 * area_density);
      dIc = mc / area_density;
    }
    if (moments_) {
      // mass moment about the link's first joint: p + m (pivot), the pivot at (l3, 0) for the
      // rocker; J = |that|² / m (0 without mass)
      const double off = k == 3 ? l.length : 0.0, Mx = x(j + 1) + mc * off, My = x(j + 2);
      const double J = mc > 0 ? (Mx * Mx + My * My) / mc : 0.0;
      out.q(b) += mc;
      out.q(b + 1) += Mx;
      out.q(b + 2) += My;
      if (relaxed_) {
        // |p + m o|² / m = w + 2 p·o + m |o|² with w >= |p|² / m relaxed, and s for a disc's Ic
        const RelaxedCounterweight& r = relaxed_cw_[c];
        out.q(b + 3) += x(r.w) + 2 * x(j + 1) * off + mc * off * off + (r.s >= 0 ? x(r.s) : 0.0);
        if (with_jacobian) {
          out.B(b, j) += 1;
          out.B(b + 1, j) += off;
          out.B(b + 1, j + 1) += 1;
          out.B(b + 2, j + 2) += 1;
          out.B(b + 3, r.w) += 1;
          out.B(b + 3, j + 1) += 2 * off;
          out.B(b + 3, j) += off * off;
          if (r.s >= 0) out.B(b + 3, r.s) += 1;
        }
        continue;
      }
      out.q(b + 3) += Ic + J;
      if (with_jacobian) {
        auto dM = out.B.row(b), dMx = out.B.row(b + 1), dMy = out.B.row(b + 2);
        auto dJ = out.B.row(b + 3);
        dM(j) += 1;
        dMx(j) += off;
        dMx(j + 1) += 1;
        dMy(j + 2) += 1;
        dJ(j) += dIc;
        if (mc > 0) {
          dJ(j) += 2 * Mx * off / mc - J / mc;
          dJ(j + 1) += 2 * Mx / mc;
          dJ(j + 2) += 2 * My / mc;
        }
      }
      continue;
    }
    const double rx = x(j + 1) + (k == 3 ? l.length : 0.0), ry = x(j + 2);
    out.q(b) += mc;
    out.q(b + 1) += mc * rx;
    out.q(b + 2) += mc * ry;
    out.q(b + 3) += Ic + mc * (rx * rx + ry * ry);
    if (with_jacobian) {
      auto dM = out.B.row(b), dMx = out.B.row(b + 1), dMy = out.B.row(b + 2), dJ = out.B.row(b + 3);
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
}

Inertial NlpProgram::inertial(const Eigen::VectorXd& x, bool with_jacobian) const {
  Inertial out;
  if (with_jacobian) out.B = Eigen::MatrixXd::Zero(kQ, n_);
  for (int k = 1; k <= 3; ++k) {
    const core::Link l = add_link(k, x, out, with_jacobian);
    add_counterweight(k, l, x, out, with_jacobian);
    // the centre of mass, where the applied force acts
    const int b = link_base(k), r = rho_base(k);
    const double M = out.q(b);
    out.q(r) = out.q(b + 1) / M;
    out.q(r + 1) = out.q(b + 2) / M;
    if (with_jacobian) {
      out.B.row(r) = (out.B.row(b + 1) - out.q(r) * out.B.row(b)) / M;
      out.B.row(r + 1) = (out.B.row(b + 2) - out.q(r + 1) * out.B.row(b)) / M;
    }
  }
  out.q(kCrankDisc) = problem_.original.counter_rotations.crank.inertia;
  out.q(kRockerDisc) = problem_.original.counter_rotations.rocker.inertia;
  out.q(kOne) = 1.0;
  return out;
}

std::vector<PlacedCounterweight> NlpProgram::counterweights(const Eigen::VectorXd& x) const {
  std::vector<PlacedCounterweight> out;
  for (std::size_t c = 0; c < problem_.counterweights.size(); ++c) {
    const CounterweightVariables& cw = problem_.counterweights[c];
    const int j = cw_var_[c];
    balance::Counterweight w;
    w.mass = x(j);
    w.position = Vec2(x(j + 1), x(j + 2));
    if (moments_) w.position = position_of(w.mass, w.position, cw.distance_max);
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

core::FourBar NlpProgram::design(const Eigen::VectorXd& x) const {
  core::FourBar m = problem_.original;
  core::Link* links[3] = {&m.crank, &m.coupler, &m.rocker};
  for (std::size_t i = 0; i < problem_.link_parameters.size(); ++i) {
    const LinkParameterVariable& v = problem_.link_parameters[i];
    parameter(*links[v.link - 1], v.parameter) = x(param_var_[i]);
  }
  for (const PlacedCounterweight& c : counterweights(x)) {
    core::Link& l = *links[c.link - 1];
    l = balance::merged(l, c.counterweight, c.link == 3);
  }
  return core::make_fourbar(m);
}

double NlpProgram::added_mass(const VecQ& q) const {
  return q(link_base(1)) + q(link_base(2)) + q(link_base(3)) - original_mass_;
}

double NlpProgram::metric(const Eigen::VectorXd& x, Metric m) const {
  if (m == Metric::kAddedMass) return added_mass(inertial(x, false).q);
  return reaction_metric(x, m);
}

double NlpProgram::original(Metric m) const {
  return m == Metric::kAddedMass ? original_mass_ : value(original_metrics_, m);
}

// ---------------------------------------------------------------------------------------------
// the program

void NlpProgram::require_gradients(bool asked, const char* function) const {
  if (asked && !has_gradients()) {
    throw std::logic_error(std::string("Nlp::") + function +
                           ": no gradients in a free scene (has_gradients() is false)");
  }
}

Eigen::VectorXd NlpProgram::start(bool original) const {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n_);
  for (std::size_t c = 0; c < problem_.counterweights.size(); ++c) {
    const CounterweightVariables& cw = problem_.counterweights[c];
    const int j = cw_var_[c];
    x(j) = original ? 0.0 : cw.mass_max / 2;
    x(j + 1) = (cw.link == 1 ? -0.5 : 0.5) * cw.distance_max * (moments_ ? x(j) : 1.0);
  }
  for (std::size_t i = 0; i < problem_.link_parameters.size(); ++i) {
    const LinkParameterVariable& v = problem_.link_parameters[i];
    core::Link l = core::link(problem_.original, v.link);
    x(param_var_[i]) = std::clamp(parameter(l, v.parameter), v.lower, v.upper);
  }
  set_relaxed_variables(x);
  start_extra_variables(x);
  return x;
}

Eigen::VectorXd NlpProgram::start_scaled(double fraction) const {
  Eigen::VectorXd x = start();
  for (int j : cw_var_) {
    x(j) *= fraction;
    if (moments_) x.segment<2>(j + 1) *= fraction;
  }
  set_relaxed_variables(x);
  start_extra_variables(x);
  return x;
}

Eigen::VectorXd NlpProgram::start_at(const Eigen::VectorXd& design) const {
  Eigen::VectorXd x = start();
  const int k = static_cast<int>(
      std::min<std::size_t>(3 * cw_var_.size() + param_var_.size(), std::size_t(design.size())));
  x.head(k) = design.head(k).cwiseMax(lower_.head(k)).cwiseMin(upper_.head(k));
  set_relaxed_variables(x);
  start_extra_variables(x);
  return x;
}

bool NlpProgram::sized(int m, Eigen::VectorXd& c, Eigen::MatrixXd* jac,
                       const char* function) const {
  require_gradients(jac != nullptr, function);
  c.resize(m);
  if (jac) jac->setZero(m, n_);
  return m > 0;
}

void NlpProgram::equalities(const Eigen::VectorXd& x, Eigen::VectorXd& c,
                            Eigen::MatrixXd* jac) const {
  if (!sized(n_eq_, c, jac, "equalities")) return;
  const Inertial in = inertial(x, jac != nullptr);
  c = balance_ * in.q;
  if (jac) *jac = balance_ * in.B;
}

void NlpProgram::inequalities(const Eigen::VectorXd& x, Eigen::VectorXd& c,
                              Eigen::MatrixXd* jac) const {
  if (!sized(n_ineq_, c, jac, "inequalities")) return;
  const Inertial in = inertial(x, jac != nullptr);
  metric_inequalities(x, in, c, jac);
  int row = 0;
  for (const Block& b : blocks_) {
    if (b.kind == Block::Kind::kEnvelope) {
      // (x² + y²) / distance_max² - 1
      const auto i = static_cast<std::size_t>(b.counterweight);
      const int j = cw_var_[i];
      const double d2 =
          problem_.counterweights[i].distance_max * problem_.counterweights[i].distance_max;
      if (moments_) {
        // the smoothed cone (sqrt(|p|² + δ²) - δ) / (mass_max d) - m / mass_max
        const double mmax = problem_.counterweights[i].mass_max, pmax = mmax * std::sqrt(d2);
        const double ux = x(j + 1) / pmax, uy = x(j + 2) / pmax;
        const double delta = kConeSmoothing, norm = std::sqrt(ux * ux + uy * uy + delta * delta);
        c(row) = norm - delta - x(j) / mmax;
        if (jac) {
          (*jac)(row, j) = -1 / mmax;
          (*jac)(row, j + 1) = ux / norm / pmax;
          (*jac)(row, j + 2) = uy / norm / pmax;
        }
        row += b.count;
        continue;
      }
      c(row) = (x(j + 1) * x(j + 1) + x(j + 2) * x(j + 2)) / d2 - 1;
      if (jac) {
        (*jac)(row, j + 1) = 2 * x(j + 1) / d2;
        (*jac)(row, j + 2) = 2 * x(j + 2) / d2;
      }
    } else if (b.kind == Block::Kind::kRelaxation) {
      relaxed_cw_[static_cast<std::size_t>(b.counterweight)].fill(x, row, c, jac);
    } else if (b.kind == Block::Kind::kAddedMassLimit) {
      c(row) = (added_mass(in.q) - b.value) / original_mass_;
      if (jac) {
        for (int k = 1; k <= 3; ++k) jac->row(row) += in.B.row(link_base(k)) / original_mass_;
      }
    }
    row += b.count;
  }
}

std::string NlpProgram::constraint_text(int i, const Eigen::VectorXd& x) const {
  if (i < 0 || i >= n_eq_ + n_ineq_) return {};
  const Inertial in = inertial(x, false);
  if (i < n_eq_) {  // a force-balance condition (eq. 57), in kg over the original's total mass
    const Eigen::VectorXd c = balance_ * in.q;
    return "the condition is off by " + text::digits(c(i) * original_mass_, 6) + " kg (" +
           text::digits(std::abs(c(i)), 3) + " of the original's total mass)";
  }
  int row = n_eq_;
  for (const Block& b : blocks_) {
    if (i >= row + b.count) {
      row += b.count;
      continue;
    }
    switch (b.kind) {
      case Block::Kind::kEnvelope: {
        const auto k = static_cast<std::size_t>(b.counterweight);
        const int j = cw_var_[k];
        double distance = std::hypot(x(j + 1), x(j + 2));
        if (moments_) distance = x(j) > 0 ? distance / x(j) : 0.0;
        return "the counterweight's centre is " + text::digits(distance, 6) +
               " m from its pivot, at most " +
               text::digits(problem_.counterweights[k].distance_max, 6) + " m";
      }
      case Block::Kind::kAddedMassLimit:
        return "the added mass is " + text::digits(added_mass(in.q), 6) + " kg, at most " +
               text::digits(b.value, 6) + " kg";
      case Block::Kind::kRmsLimit:
      case Block::Kind::kPeakLimit: {
        const double value = metric(x, b.metric), was = original(b.metric);
        return std::string(to_string(b.metric)) + " is " + text::digits(value, 6) + " " +
               metric_unit(b.metric) + " = " + text::digits(was > 0 ? value / was : 0.0, 4) +
               " x the original's, at most " + text::digits(b.value, 6) + " x";
      }
      case Block::Kind::kPeakBound:
      case Block::Kind::kRelaxation:
        return {};
    }
  }
  return {};
}

void NlpProgram::first_order_inequalities(const Eigen::VectorXd& x, const Eigen::VectorXd& g,
                                          Eigen::VectorXd& c, Eigen::MatrixXd& jac) const {
  inequalities(x, c, &jac);
  if (!moments_) return;
  int row = 0;
  for (const Block& b : blocks_) {
    if (b.kind == Block::Kind::kEnvelope) {
      const auto i = static_cast<std::size_t>(b.counterweight);
      const int j = cw_var_[i];
      cone_first_order_row(x, g, j, problem_.counterweights[i].mass_max,
                           problem_.counterweights[i].distance_max, row, c, jac);
    }
    row += b.count;
  }
}

}  // namespace bd::optimize::detail
