#include "optimize/planar.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <numbers>
#include <optional>
#include <set>
#include <stdexcept>

#include "core/input_error.hpp"
#include "core/number_text.hpp"
#include "optimize/convex_solve.hpp"
#include "optimize/detail/local_maxima.hpp"
#include "optimize/detail/peak_exchange.hpp"
#include "optimize/epsilon_front.hpp"
#include "optimize/nlopt_driver.hpp"
#include "optimize/relaxation.hpp"

namespace bd::optimize::planar {

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;
namespace bp = balance::planar;
using P = bp::Parameters;
using Param = LinkParameterVariable::Parameter;

Problem field(const std::string& name, int index, const std::string& message) {
  return FieldError{name, index, message};
}

double disc_inertia_per_mass2(const CounterweightVariables& c) {  // I = m² / (2 ρ π t)
  return c.shape == balance::CounterweightShape::kDisc
             ? 1.0 / (2 * c.density * std::numbers::pi * c.thickness)
             : 0.0;
}

const char* parameter_text(Param p) {
  switch (p) {
    case Param::kMass:
      return "mass";
    case Param::kE:
      return "e";
    case Param::kF:
      return "f";
    case Param::kInertia:
      return "inertia";
  }
  return "?";
}

}  // namespace

Problem DesignProblem::validate() const {
  const cp::Linkage& l = original;
  const int links = static_cast<int>(l.links.size());
  const std::vector<cp::ColumnMetric> table = cp::metric_table(cp::Model(l));
  auto metric = [&](const std::string& name) -> const cp::ColumnMetric* {
    for (const cp::ColumnMetric& m : table)
      if (m.name == name) return &m;
    return nullptr;
  };
  std::string names;
  for (const cp::ColumnMetric& m : table) names += (names.empty() ? "" : ", ") + m.name;
  if (counterweights.empty() && link_parameters.empty())
    return field("", -1, "no design variable: give counterweights or link parameters");
  std::map<int, std::pair<const char*, int>> moved;  // link -> the first variable moving its
                                                     // centre of mass (list, index)
  std::set<int> with_cw;
  for (std::size_t i = 0; i < counterweights.size(); ++i) {
    const CounterweightVariables& c = counterweights[i];
    const int k = static_cast<int>(i);
    if (c.link < 0 || c.link >= links) return field("counterweights", k, ": not a link");
    if (!with_cw.insert(c.link).second)
      return field("counterweights", k, ": a second counterweight on the link");
    if (!(std::isfinite(c.mass_max) && c.mass_max > 0))
      return field("counterweights", k,
                   ".mass_max must be > 0 kg, got " + text::shortest(c.mass_max));
    if (!(std::isfinite(c.distance_max) && c.distance_max > 0))
      return field("counterweights", k,
                   ".distance_max must be > 0 m, got " + text::shortest(c.distance_max));
    if (c.shape == balance::CounterweightShape::kDisc &&
        !(c.thickness > 0 && c.density > 0 && std::isfinite(c.thickness) &&
          std::isfinite(c.density)))
      return field("counterweights", k, ": a disc needs thickness > 0 m and density > 0 kg/m^3");
    moved.try_emplace(c.link, "counterweights", k);
  }
  std::set<std::pair<int, int>> seen;
  for (std::size_t i = 0; i < link_parameters.size(); ++i) {
    const LinkParameterVariable& v = link_parameters[i];
    const int k = static_cast<int>(i);
    if (v.link < 0 || v.link >= links) return field("link_parameters", k, ": not a link");
    const std::string what = "(" + l.links[static_cast<std::size_t>(v.link)].name + "." +
                             parameter_text(v.parameter) + ")";
    if (!seen.insert({v.link, static_cast<int>(v.parameter)}).second)
      return field("link_parameters", k, ": " + what + " is a variable twice");
    if (!(std::isfinite(v.lower) && std::isfinite(v.upper) && v.lower <= v.upper))
      return field("link_parameters", k, ": " + what + " needs finite bounds, lower <= upper");
    if (v.parameter == Param::kMass && !(v.lower > 0))
      return field("link_parameters", k, ": " + what + ".lower must be > 0 kg");
    if (v.parameter == Param::kInertia && !(v.lower >= 0))
      return field("link_parameters", k, ": " + what + ".lower must be >= 0 kg m²");
    // mass too: the regressor's columns move the centre of mass one parameter at a time
    if (v.parameter != Param::kInertia) moved.try_emplace(v.link, "link_parameters", k);
  }
  for (const cp::LinkLoad& load : l.loads.link_loads) {
    const auto it = moved.find(load.link);
    if (it != moved.end() && load.force.norm() > 0) {
      return field(it->second.first, it->second.second,
                   ": link " + l.links[static_cast<std::size_t>(load.link)].name +
                       " carries a force at its centre of mass, which this variable moves (the "
                       "outputs are then not linear in the masses); apply the force at a node to "
                       "optimise this link");
    }
  }
  if (objective.empty()) return field("objective", -1, ": give at least one term");
  bool positive = false;
  for (std::size_t i = 0; i < objective.size(); ++i) {
    const Term& t = objective[i];
    const int k = static_cast<int>(i);
    if (!(std::isfinite(t.weight) && t.weight >= 0))
      return field("objective", k, ".weight must be >= 0, got " + text::shortest(t.weight));
    positive = positive || t.weight > 0;
    if (t.metric == "added_mass") continue;
    if (!metric(t.metric))
      return field("objective", k,
                   ": no metric " + t.metric + " (metrics: " + names + ", added_mass)");
  }
  if (!positive) return field("objective", -1, ": at least one weight must be > 0");
  for (std::size_t i = 0; i < limits.size(); ++i) {
    const Limit& lim = limits[i];
    const int k = static_cast<int>(i);
    if (!std::isfinite(lim.value))
      return field("limits", k, ".value must be finite, got " + text::shortest(lim.value));
    if (lim.metric == "added_mass") {
      // counterweights add mass; only a link's own mass variable can take some away
      double least = 0;
      for (const LinkParameterVariable& v : link_parameters) {
        if (v.parameter == Param::kMass)
          least += v.lower - l.links[static_cast<std::size_t>(v.link)].mass;
      }
      if (lim.value < least - 1e-12 * cp::total_mass(l))
        return field("limits", k,
                     ": added_mass <= " + text::shortest(lim.value) +
                         " kg cannot be met: the least the variables allow is " +
                         text::digits(least, 6) +
                         " kg (a counterweight's mass is >= 0; only a link's own mass, within "
                         "its bounds, can take mass away)");
      continue;
    }
    if (!metric(lim.metric))
      return field("limits", k,
                   ": no metric " + lim.metric + " (metrics: " + names + ", added_mass)");
    if (!(lim.value > 0))
      return field(
          "limits", k,
          ".value must be > 0 (a fraction of the original), got " + text::shortest(lim.value));
  }
  if (!(smoothing > 0 && smoothing <= 0.1))
    return field("smoothing", -1, "must be in (0, 0.1], got " + text::shortest(smoothing));
  const bool driven = std::holds_alternative<cp::DrivenScene>(scene);
  for (std::size_t i = 0; i < peak_times.size(); ++i) {
    if (!driven || !std::isfinite(peak_times[i]))
      return field("peak_times", static_cast<int>(i),
                   driven ? " must be finite, got " + text::shortest(peak_times[i])
                          : ": only a driven scene takes added instants");
  }
  return std::nullopt;
}

// ---------------------------------------------------------------------------------------------

// a free scene's simulation at x: its metrics (table order; +inf when it failed) and, when it
// was a run with sensitivities, their gradients (table rows x n; zero where it failed)
struct PlanarNlp::Evaluation {
  VectorXd x;
  std::vector<double> metrics;
  MatrixXd gradient;
};

struct PlanarNlp::Impl {
  DesignProblem p;
  bool free{};     // a free scene: metrics by simulation, no regressor
  bool moments{};  // counterweights as (m, p = m r): CounterweightVariablesAs::kMassMoments
  bool relaxed{};  // and their inertias relaxed: CounterweightVariablesAs::kRelaxation
  std::vector<detail::RelaxedCounterweight> relaxed_cw;  // kRelaxation: their variables
  // a free scene's last simulation
  mutable std::mutex cache_mutex;
  mutable Evaluation cached;
  std::vector<int> sensitivity_parameters;  // free scenes: the entries of q the design varies
  // free scenes with resolve_peaks: the peak metrics the objective or a limit reads (table
  // indices; the others keep their largest samples), and those rows of the table
  std::vector<std::size_t> read_peaks;
  std::vector<cp::ColumnMetric> read_table;
  int nq{}, samples{};
  int instants{};  // rows of the regressor: the samples, then p.peak_times (peaks only)
  VectorXd q0;
  double mass0{}, length{};
  std::vector<cp::ColumnMetric> table;
  std::vector<double> original;
  // per output column used by a metric: y = base + B (q - q0), instants x nq
  std::map<std::string, std::pair<VectorXd, MatrixXd>> outputs;
  std::vector<double> times;  // of the instants
  // variables
  int n{};
  VectorXd lower, upper;
  std::vector<std::string> variable_names, constraint_names;
  std::vector<int> cw_var, param_var;
  std::map<int, std::array<int, 4>> link_vars;  // link -> variable of its m, e, f, I (or -1)
  std::vector<int> cw_pivot;
  std::vector<Vec2> cw_pivot_in_link, cw_away;
  // objective weights per metric (table order) and on added_mass
  std::vector<double> weight;
  double added_weight{};
  // a peak in the objective: its bound variable t (the metric's unit), per metric or -1
  std::vector<int> bound_var;
  int design_n{};  // the design's own variables, before the bound variables
  // constraints
  MatrixXd balance_rows;  // r x nq: U_rᵀ Z / (M0 L)
  VectorXd balance_offset;
  struct Row {
    enum class Kind { kEnvelope, kRmsLimit, kPeakLimit, kPeakBound, kAddedMass, kRelaxation } kind{};
    int index{};   // counterweight, or metric
    int sample{};  // peak limits
    double value{};
  };
  std::vector<Row> rows;

  // "at t = 0.25 s", or for an added instant "near a resolved peak, t = 0.2513 s"
  std::string instant_words(int s) const {
    const std::string t = text::digits(times[static_cast<std::size_t>(s)], s < samples ? 6 : 9);
    return (s < samples ? "at t = " : "near a resolved peak, t = ") + t + " s";
  }
  void build_regressor(bool checks_only);
  void set_up_variables();
  void set_up_constraints();
  void check_balance_reachable(const MatrixXd& Z, const VectorXd& z0,
                               const bp::Kinematics& k) const;
  void balance_conditions(const cp::Trajectory& base);
  // q at x and its Jacobian; `positions`: the counterweights' variables read as positions
  // whatever the program's (the start's force-balance step works in positions)
  void q_of(const VectorXd& x, VectorXd& q, MatrixXd* J, bool positions = false) const;
  const cp::ColumnMetric& metric(int k) const { return table[static_cast<std::size_t>(k)]; }
  int metric_index(const std::string& name) const {
    for (std::size_t k = 0; k < table.size(); ++k)
      if (table[k].name == name) return static_cast<int>(k);
    return -1;
  }
  // the columns' values at q, and their Jacobians B J when J is given
  struct Columns {
    std::vector<VectorXd> y;
    std::vector<MatrixXd> dy;
  };
  Columns columns(int k, const VectorXd& q, const MatrixXd* J) const {
    Columns c;
    for (const std::string& name : metric(k).columns) {
      const auto& [base, B] = outputs.at(name);
      c.y.push_back(base + B * (q - q0));
      if (J) c.dy.push_back(B * *J);
    }
    return c;
  }
  double rms2(const Columns& c, VectorXd* grad) const {
    double s = 0;
    if (grad) grad->setZero(n);
    for (std::size_t i = 0; i < c.y.size(); ++i) {  // over the samples, not the added instants
      s += c.y[i].head(samples).squaredNorm();
      if (grad) *grad += 2.0 * c.dy[i].topRows(samples).transpose() * c.y[i].head(samples);
    }
    if (grad) *grad /= samples;
    return s / samples;
  }
  // the magnitude of metric k's columns at q at each instant
  std::vector<double> magnitudes(int k, const VectorXd& q) const {
    const Columns c = columns(k, q, nullptr);
    std::vector<double> v(static_cast<std::size_t>(instants));
    for (int s = 0; s < instants; ++s) {
      double s2 = 0;
      for (const VectorXd& y : c.y) s2 += y[s] * y[s];
      v[static_cast<std::size_t>(s)] = std::sqrt(s2);
    }
    return v;
  }
  // the largest magnitude over the instants of metric k's columns at q
  double peak(int k, const VectorXd& q) const {
    const std::vector<double> v = magnitudes(k, q);
    return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end());
  }
  // a bound on each |q_j - q0_j| over the variables' box (counterweights within their
  // envelopes, link parameters within their bounds)
  VectorXd q_spread() const;
  double added(const VectorXd& q, const MatrixXd* J, VectorXd* grad) const {
    double a = 0;
    if (grad) grad->setZero(n);
    for (std::size_t k = 0; k < p.original.links.size(); ++k) {
      const int i = P::link_mass(static_cast<int>(k));
      a += q[i] - q0[i];
      if (grad) *grad += J->row(i).transpose();
    }
    return a;
  }
};

void PlanarNlp::Impl::build_regressor(bool checks_only) {
  const cp::Linkage& l = p.original;
  std::set<std::string> used;
  for (const cp::ColumnMetric& m : table)
    for (const std::string& c : m.columns) used.insert(c);
  // a design's run: its table's samples, then its rows at the added instants (p.peak_times)
  struct Run {
    cp::Trajectory trajectory;
    std::vector<std::vector<double>> added;  // per added instant, the whole row
    std::vector<double> column(const std::string& name) const {
      std::vector<double> v = trajectory.table.column_values(name);
      const auto c = static_cast<std::size_t>(trajectory.table.column(name));
      for (const std::vector<double>& row : added) v.push_back(row[c]);
      return v;
    }
  };
  auto run = [&](const VectorXd& q, const char* what) {
    const cp::Model model(cp::make_linkage(cp::with_mass_parameters(l, q.data())));
    const cp::DrivenScene& scene = std::get<cp::DrivenScene>(p.scene);
    Run r{cp::simulate_driven(model, scene), {}};
    if (!r.trajectory.ok()) {
      throw InputError(std::string(what) + " cannot run in the scene: " + r.trajectory.message);
    }
    cp::DrivenRows at(model, scene, r.trajectory);
    for (const double s : p.peak_times) {
      const double* row = at.at(s);
      if (!row) {
        throw InputError(std::string(what) + " cannot be evaluated at t = " + text::digits(s, 9) +
                         " s, an instant added for a peak");
      }
      r.added.emplace_back(row, row + r.trajectory.table.width());
    }
    return r;
  };
  const Run base =
      free ? Run{cp::simulate_free(cp::Model(l), std::get<cp::FreeScene>(p.scene), p.simulate), {}}
           : run(q0, "the original design");
  if (free && !base.trajectory.ok())
    throw InputError("the original design cannot run in the scene: " + base.trajectory.message);
  samples = static_cast<int>(base.trajectory.table.rows());
  instants = samples + static_cast<int>(base.added.size());
  times = base.column("t");
  // the normalisers: the original's metrics, its peaks resolved between the samples when the
  // optimiser resolves the design's
  original = !p.resolve_peaks ? cp::metric_values(table, base.trajectory.table)
             : free           ? cp::metric_values(cp::Model(l), p.simulate, table, base.trajectory)
                    : cp::metric_values(cp::Model(l), std::get<cp::DrivenScene>(p.scene), table,
                                        base.trajectory);
  if (free) {  // the balance conditions come from the configurations the original passes through
    balance_conditions(base.trajectory);
    return;
  }
  for (const std::string& c : used) {
    const std::vector<double> v = base.column(c);
    outputs[c] = {Eigen::Map<const VectorXd>(v.data(), static_cast<Eigen::Index>(v.size())),
                  MatrixXd::Zero(instants, nq)};
  }
  for (std::size_t k = 0; k < l.links.size(); ++k) {
    if (q0[P::link_mass(static_cast<int>(k))] <= 0) {
      throw InputError("link " + l.links[k].name +
                       " has no mass: give it one to optimise the linkage");
    }
  }
  if (checks_only) {
    balance_conditions(base.trajectory);
    return;
  }
  // one column per parameter: the outputs are affine in q, so a difference is exact (to
  // round-off); a link's J is raised with its first moments so that its inertia stays >= 0
  for (int i = 0; i < nq; ++i) {
    VectorXd lo = q0, hi = q0;
    double step = 1.0;
    const int k = i < 4 * static_cast<int>(l.links.size()) ? i / 4 : -1;
    if (k >= 0) {
      const double m = std::max(q0[P::link_mass(k)], 1e-6 * mass0);
      const double L = cp::element_length(l, k);
      const int which = i - 4 * k;
      step = which == 0 ? m : which == 3 ? m * L * L : m * L;
      const double lift = which == 1 || which == 2 ? 4 * m * L * L : 0.0;
      lo[P::link_J(k)] += lift;
      hi[P::link_J(k)] += lift;
    } else {
      step = std::max(q0[i], 1e-3 * mass0);
    }
    hi[i] += step;
    const Run a = run(lo, "a perturbed design"), b = run(hi, "a perturbed design");
    for (auto& [name, out] : outputs) {
      const std::vector<double> ya = a.column(name), yb = b.column(name);
      for (int s = 0; s < instants; ++s)
        out.second(s, i) =
            (yb[static_cast<std::size_t>(s)] - ya[static_cast<std::size_t>(s)]) / step;
    }
  }
  balance_conditions(base.trajectory);
}

// the force-balance conditions: the momentum per unit input rate, in its independent rows
void PlanarNlp::Impl::balance_conditions(const cp::Trajectory& base) {
  const cp::Linkage& l = p.original;
  if (p.force_balance) {
    const cp::Model model(l);
    const bp::InputSeries in = bp::input_series(model, base.table);
    const auto k = bp::kinematics(model, in.values, in.rates, in.accelerations);
    if (!k) throw InputError("the original's motion cannot be evaluated: " + k.error().detail);
    const MatrixXd Z = bp::momentum_regressor(l, *k);
    const VectorXd z0 = bp::shaft_series(l, *k).momentum;
    MatrixXd S = Z;  // columns scaled to one unit for the rank
    for (std::size_t j = 0; j < l.links.size(); ++j) {
      S.col(P::link_me(static_cast<int>(j))) *= length;
      S.col(P::link_mf(static_cast<int>(j))) *= length;
      S.col(P::link_J(static_cast<int>(j))) *= length * length;
    }
    Eigen::JacobiSVD<MatrixXd> svd(S, Eigen::ComputeThinU);
    svd.setThreshold(1e-10);
    const MatrixXd U = svd.matrixU().leftCols(svd.rank());
    balance_rows = U.transpose() * Z / (mass0 * length);
    balance_offset = U.transpose() * z0 / (mass0 * length);
    check_balance_reachable(Z, z0, *k);
  }
}

// Full force balance asks the momentum Z q + z0 to vanish, and the variables move q only in
// the mass and first moments of the links they act on: if no such move cancels it (whatever
// the bounds), say so now, in the balance layer's words where they apply, rather than let the
// solver report a violated condition.
void PlanarNlp::Impl::check_balance_reachable(const MatrixXd& Z, const VectorXd& z0,
                                              const bp::Kinematics& k) const {
  const cp::Linkage& l = p.original;
  std::set<int> links;
  for (const CounterweightVariables& c : p.counterweights) links.insert(c.link);
  for (const LinkParameterVariable& v : p.link_parameters)
    if (v.parameter != Param::kInertia) links.insert(v.link);
  std::vector<int> cols;
  for (int i : links) cols.insert(cols.end(), {P::link_mass(i), P::link_me(i), P::link_mf(i)});
  MatrixXd A(Z.rows(), static_cast<Eigen::Index>(cols.size()));
  for (std::size_t j = 0; j < cols.size(); ++j)
    A.col(static_cast<Eigen::Index>(j)) = Z.col(cols[j]);
  const VectorXd b = Z * q0 + z0;
  const VectorXd left = b - A * A.completeOrthogonalDecomposition().solve(b);
  if (!(left.norm() > 1e-8 * b.norm())) return;
  std::string names;
  for (int i : links)
    names += (names.empty() ? "" : ", ") + l.links[static_cast<std::size_t>(i)].name;
  std::string why = "full force balance is out of reach with variables on " + names + ": " +
                    text::digits(100 * left.norm() / b.norm(), 3) +
                    " % of the original's linear momentum is left whatever they are";
  if (p.link_parameters.empty()) {  // the balance layer names what is left
    std::vector<bp::LinkCounterweightSpec> specs;
    for (const CounterweightVariables& c : p.counterweights) {
      bp::LinkCounterweightSpec spec{c.link, {}};
      const int pivot = bp::counterweight_pivot(l, c.link);
      if (!l.nodes[static_cast<std::size_t>(pivot)].ground) spec.spec.mass = c.mass_max;
      specs.push_back(spec);
    }
    try {
      const bp::ForceBalance fb = bp::force_balance(l, k, specs);
      if (!fb.full && !fb.message.empty()) why = fb.message;
    } catch (const InputError&) {
      // the generic words stand
    }
  }
  throw InputError(FieldError{"force_balance", -1, ": " + why});
}

void PlanarNlp::Impl::set_up_variables() {
  const cp::Linkage& l = p.original;
  auto add = [&](double lo, double hi, std::string name) {
    lower.conservativeResize(n + 1);
    upper.conservativeResize(n + 1);
    lower[n] = lo;
    upper[n] = hi;
    variable_names.push_back(std::move(name));
    return n++;
  };
  for (const CounterweightVariables& c : p.counterweights) {
    const std::string name = l.links[static_cast<std::size_t>(c.link)].name;
    const int pv = bp::counterweight_pivot(l, c.link);
    cw_pivot.push_back(pv);
    cw_pivot_in_link.push_back(
        bp::in_link_axes(l, c.link, l.nodes[static_cast<std::size_t>(pv)].position));
    // away from the link's other node (its second, or its first when the pivot is the second)
    const auto& nodes = l.links[static_cast<std::size_t>(c.link)].nodes;
    const int other = nodes[0] == pv ? nodes[1] : nodes[0];
    const Vec2 d = bp::in_link_axes(l, c.link, l.nodes[static_cast<std::size_t>(other)].position) -
                   cw_pivot_in_link.back();
    cw_away.push_back(-d.normalized());
    const std::string from = " from " + l.nodes[static_cast<std::size_t>(pv)].name;
    cw_var.push_back(add(0.0, c.mass_max, name + " counterweight mass [kg]"));
    if (moments) {
      const double pmax = c.mass_max * c.distance_max;
      const std::string about = " about " + l.nodes[static_cast<std::size_t>(pv)].name;
      add(-pmax, pmax, name + " counterweight mass moment x" + about + " in link axes [kg m]");
      add(-pmax, pmax, name + " counterweight mass moment y" + about + " in link axes [kg m]");
      continue;
    }
    add(-c.distance_max, c.distance_max, name + " counterweight x" + from + " in link axes [m]");
    add(-c.distance_max, c.distance_max, name + " counterweight y" + from + " in link axes [m]");
  }
  for (const LinkParameterVariable& v : p.link_parameters) {
    const char* unit = v.parameter == Param::kMass      ? " [kg]"
                       : v.parameter == Param::kInertia ? " [kg m²]"
                                                        : " [m]";
    param_var.push_back(add(
        v.lower, v.upper,
        l.links[static_cast<std::size_t>(v.link)].name + " " + parameter_text(v.parameter) + unit));
    auto [it, _] = link_vars.try_emplace(v.link, std::array<int, 4>{-1, -1, -1, -1});
    it->second[static_cast<std::size_t>(v.parameter)] = param_var.back();
  }
  design_n = n;
  // kRelaxation: each counterweight's inertia about its pivot (and a disc's own), relaxed
  for (std::size_t c = 0; relaxed && c < p.counterweights.size(); ++c) {
    const CounterweightVariables& cw = p.counterweights[c];
    const std::string name = l.links[static_cast<std::size_t>(cw.link)].name + " counterweight ";
    detail::RelaxedCounterweight r;
    r.mass = cw_var[c];
    r.mass_max = cw.mass_max;
    r.distance_max = cw.distance_max;
    r.w = add(0.0, r.w_max(), name + "inertia of its mass about its pivot (relaxed) [kg m²]");
    if (cw.shape == balance::CounterweightShape::kDisc) {
      r.disc_a = disc_inertia_per_mass2(cw);
      r.s = add(0.0, r.s_max(), name + "own inertia (relaxed) [kg m²]");
    }
    relaxed_cw.push_back(r);
  }
  // a bound variable t per peak of the objective, |y_s| <= t at every sample. Boxed in
  // [-t_max, t_max], t_max above the peak of any design in the box (the regressor's rows
  // against the spread of the parameters): with a lower bound at 0, SLSQP's subproblems put t on
  // it at infeasible iterates and stop early (as the four-bar's, docs/performance.md)
  bound_var.assign(table.size(), -1);
  const VectorXd spread = q_spread();
  for (std::size_t k = 0; k < table.size(); ++k) {
    if (free || !(weight[k] > 0) || table[k].statistic != core::Statistic::kMax) continue;
    double worst = 0;
    for (int i = 0; i < instants; ++i) {
      double sum = 0;
      for (const std::string& c : table[k].columns) {
        const auto& [base, B] = outputs.at(c);
        sum += std::abs(base[i]) + B.row(i).cwiseAbs().dot(spread);
      }
      worst = std::max(worst, sum);
    }
    // in units of the original's value, as the objective's terms
    const double t_max = std::hypot(worst / original[k], p.smoothing) * (1 + 1e-9);
    bound_var[k] = add(-t_max, t_max, "bound on " + table[k].name + " / original");
  }
}

VectorXd PlanarNlp::Impl::q_spread() const {
  const cp::Linkage& l = p.original;
  VectorXd spread = VectorXd::Zero(nq);
  // a link's own parameters: their largest magnitudes within the bounds
  for (const auto& [i, var] : link_vars) {
    const cp::Link& link = l.links[static_cast<std::size_t>(i)];
    double big[4] = {link.mass, std::abs(link.e), std::abs(link.f), link.inertia};
    for (const LinkParameterVariable& v : p.link_parameters) {
      if (v.link == i) {
        big[static_cast<std::size_t>(v.parameter)] = std::max(std::abs(v.lower), std::abs(v.upper));
      }
    }
    const double m = big[0], e = big[1], f = big[2], I = big[3];
    spread[P::link_mass(i)] = m + std::abs(q0[P::link_mass(i)]);
    spread[P::link_me(i)] = m * e + std::abs(q0[P::link_me(i)]);
    spread[P::link_mf(i)] = m * f + std::abs(q0[P::link_mf(i)]);
    spread[P::link_J(i)] = I + m * (e * e + f * f) + std::abs(q0[P::link_J(i)]);
  }
  // counterweights: a mass up to mass_max within distance_max of the pivot
  for (std::size_t c = 0; c < p.counterweights.size(); ++c) {
    const CounterweightVariables& cw = p.counterweights[c];
    const int k = cw.link;
    const double r = cw_pivot_in_link[c].norm() + cw.distance_max, mc = cw.mass_max;
    spread[P::link_mass(k)] += mc;
    spread[P::link_me(k)] += mc * r;
    spread[P::link_mf(k)] += mc * r;
    spread[P::link_J(k)] += mc * r * r + disc_inertia_per_mass2(cw) * mc * mc;
  }
  return spread;
}

void PlanarNlp::Impl::set_up_constraints() {
  for (Eigen::Index r = 0; r < balance_rows.rows(); ++r)
    constraint_names.push_back("force balance, condition " + std::to_string(r + 1));
  for (std::size_t k = 0; k < table.size(); ++k) {
    if (bound_var[k] < 0) continue;
    for (int s = 0; s < instants; ++s) {
      rows.push_back({Row::Kind::kPeakBound, static_cast<int>(k), s, 0.0});
      constraint_names.push_back("|" + table[k].name + "| " + instant_words(s) + " <= bound on " +
                                 table[k].name);
    }
  }
  for (std::size_t c = 0; c < p.counterweights.size(); ++c) {
    rows.push_back({Row::Kind::kEnvelope, static_cast<int>(c), 0, 0.0});
    constraint_names.push_back(
        p.original.links[static_cast<std::size_t>(p.counterweights[c].link)].name +
        " counterweight within distance_max = " +
        text::digits(p.counterweights[c].distance_max, 6) + " m of its pivot");
    if (!relaxed) continue;
    const detail::RelaxedCounterweight& r = relaxed_cw[c];
    for (std::string& name : r.row_names(
             p.original.links[static_cast<std::size_t>(p.counterweights[c].link)].name +
             " counterweight")) {
      rows.push_back({Row::Kind::kRelaxation, static_cast<int>(c), 0, 0.0});
      constraint_names.push_back(std::move(name));
    }
  }
  for (const Limit& lim : p.limits) {
    const std::string what = lim.metric + " <= " + text::digits(lim.value, 6);
    if (lim.metric == "added_mass") {
      rows.push_back({Row::Kind::kAddedMass, -1, 0, lim.value});
      constraint_names.push_back(what + " kg");
      continue;
    }
    const int k = metric_index(lim.metric);
    if (metric(k).statistic == core::Statistic::kRms) {
      rows.push_back({Row::Kind::kRmsLimit, k, 0, lim.value});
      constraint_names.push_back(what + " x original");
    } else {
      for (int s = 0; s < (free ? 1 : instants); ++s) {
        rows.push_back({Row::Kind::kPeakLimit, k, free ? -1 : s, lim.value});
        constraint_names.push_back(free ? what + " x original"
                                        : what + " x original " + instant_words(s));
      }
    }
  }
}

void PlanarNlp::Impl::q_of(const VectorXd& x, VectorXd& q, MatrixXd* J, bool positions) const {
  const cp::Linkage& l = p.original;
  q = q0;
  if (J) J->setZero(nq, n);
  // link parameters: the link's (m, e, f, I) with the variables' values, as π
  for (const auto& [k, var] : link_vars) {
    const cp::Link& link = l.links[static_cast<std::size_t>(k)];
    const double m = var[0] >= 0 ? x[var[0]] : link.mass, e = var[1] >= 0 ? x[var[1]] : link.e,
                 f = var[2] >= 0 ? x[var[2]] : link.f, I = var[3] >= 0 ? x[var[3]] : link.inertia;
    q[P::link_mass(k)] = m;
    q[P::link_me(k)] = m * e;
    q[P::link_mf(k)] = m * f;
    q[P::link_J(k)] = I + m * (e * e + f * f);
    if (!J) continue;
    if (var[0] >= 0) {
      (*J)(P::link_mass(k), var[0]) = 1;
      (*J)(P::link_me(k), var[0]) = e;
      (*J)(P::link_mf(k), var[0]) = f;
      (*J)(P::link_J(k), var[0]) = e * e + f * f;
    }
    if (var[1] >= 0) {
      (*J)(P::link_me(k), var[1]) = m;
      (*J)(P::link_J(k), var[1]) = 2 * m * e;
    }
    if (var[2] >= 0) {
      (*J)(P::link_mf(k), var[2]) = m;
      (*J)(P::link_J(k), var[2]) = 2 * m * f;
    }
    if (var[3] >= 0) (*J)(P::link_J(k), var[3]) = 1;
  }
  // counterweights: a mass at the pivot + (x, y), and a disc's own inertia
  for (std::size_t c = 0; c < p.counterweights.size(); ++c) {
    const int k = p.counterweights[c].link, v = cw_var[c];
    const double mc = x[v];
    const double a = disc_inertia_per_mass2(p.counterweights[c]);
    if (moments && !positions) {
      // the first moment about the link's first node, p + m (pivot), and J = |that|² / m
      const Vec2 o = cw_pivot_in_link[c], M = Vec2(x[v + 1], x[v + 2]) + mc * o;
      const double Jc = mc > 0 ? M.squaredNorm() / mc : 0.0;
      q[P::link_mass(k)] += mc;
      q[P::link_me(k)] += M.x();
      q[P::link_mf(k)] += M.y();
      if (J) {
        (*J)(P::link_mass(k), v) += 1;
        (*J)(P::link_me(k), v) += o.x();
        (*J)(P::link_mf(k), v) += o.y();
        (*J)(P::link_me(k), v + 1) += 1;
        (*J)(P::link_mf(k), v + 2) += 1;
      }
      if (relaxed) {
        // |p + m o|² / m = w + 2 p·o + m |o|² with w >= |p|² / m relaxed, and s for a disc's
        // own inertia
        const detail::RelaxedCounterweight& rc = relaxed_cw[c];
        const Vec2 pc(x[v + 1], x[v + 2]);
        q[P::link_J(k)] += x[rc.w] + 2 * pc.dot(o) + mc * o.squaredNorm() +
                           (rc.s >= 0 ? x[rc.s] : 0.0);
        if (!J) continue;
        (*J)(P::link_J(k), rc.w) += 1;
        (*J)(P::link_J(k), v) += o.squaredNorm();
        (*J)(P::link_J(k), v + 1) += 2 * o.x();
        (*J)(P::link_J(k), v + 2) += 2 * o.y();
        if (rc.s >= 0) (*J)(P::link_J(k), rc.s) += 1;
        continue;
      }
      q[P::link_J(k)] += Jc + a * mc * mc;
      if (!J) continue;
      (*J)(P::link_J(k), v) += 2 * a * mc;
      if (mc > 0) {
        (*J)(P::link_J(k), v) += 2 * M.dot(o) / mc - Jc / mc;
        (*J)(P::link_J(k), v + 1) += 2 * M.x() / mc;
        (*J)(P::link_J(k), v + 2) += 2 * M.y() / mc;
      }
      continue;
    }
    const Vec2 r = cw_pivot_in_link[c] + Vec2(x[v + 1], x[v + 2]);
    q[P::link_mass(k)] += mc;
    q[P::link_me(k)] += mc * r.x();
    q[P::link_mf(k)] += mc * r.y();
    q[P::link_J(k)] += mc * r.squaredNorm() + a * mc * mc;
    if (!J) continue;
    (*J)(P::link_mass(k), v) += 1;
    (*J)(P::link_me(k), v) += r.x();
    (*J)(P::link_mf(k), v) += r.y();
    (*J)(P::link_J(k), v) += r.squaredNorm() + 2 * a * mc;
    (*J)(P::link_me(k), v + 1) += mc;
    (*J)(P::link_J(k), v + 1) += 2 * mc * r.x();
    (*J)(P::link_mf(k), v + 2) += mc;
    (*J)(P::link_J(k), v + 2) += 2 * mc * r.y();
  }
}

PlanarNlp::PlanarNlp(const DesignProblem& problem, CounterweightVariablesAs as)
    : PlanarNlp(problem, as, false) {}

void PlanarNlp::check(const DesignProblem& problem) {
  const PlanarNlp checked(problem, CounterweightVariablesAs::kPositions, true);
}

PlanarNlp::PlanarNlp(const DesignProblem& problem, CounterweightVariablesAs as, bool checks_only)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.p = problem;
  m.moments = as == CounterweightVariablesAs::kMassMoments ||
              as == CounterweightVariablesAs::kRelaxation;
  m.relaxed = as == CounterweightVariablesAs::kRelaxation;
  m.p.original = cp::make_linkage(problem.original);
  m.free = std::holds_alternative<cp::FreeScene>(problem.scene);
  if (const Problem e = m.p.validate()) throw InputError("invalid design problem: " + e->text());
  const cp::Linkage& l = m.p.original;
  m.nq = P::count(l);
  m.q0 = P::of(l);
  m.mass0 = cp::total_mass(l);
  for (std::size_t k = 0; k < l.links.size(); ++k)
    m.length = std::max(m.length, cp::element_length(l, static_cast<int>(k)));
  m.table = cp::metric_table(cp::Model(l));
  m.build_regressor(checks_only);
  // the normalisers: the original's value of each metric in the objective or a limit
  m.weight.assign(m.table.size(), 0.0);
  auto normaliser = [&](const std::string& name, const char* list, int index) {
    const int k = m.metric_index(name);
    double scale = 0;
    for (std::size_t j = 0; j < m.table.size(); ++j)
      if (m.table[j].unit == m.metric(k).unit) scale = std::max(scale, m.original[j]);
    if (!(m.original[static_cast<std::size_t>(k)] > 1e-10 * scale)) {
      throw InputError(FieldError{list, index,
                                  ": the original design's " + name + " is " +
                                      text::digits(m.original[static_cast<std::size_t>(k)], 3) +
                                      " " + m.metric(k).unit +
                                      ", too small to normalise by (it is already minimal)"});
    }
    return k;
  };
  for (std::size_t i = 0; i < m.p.objective.size(); ++i) {
    const Term& t = m.p.objective[i];
    if (t.metric == "added_mass") {
      m.added_weight += t.weight;
    } else if (t.weight > 0) {
      m.weight[static_cast<std::size_t>(normaliser(t.metric, "objective", static_cast<int>(i)))] +=
          t.weight;
    }
  }
  for (std::size_t i = 0; i < m.p.limits.size(); ++i)
    if (m.p.limits[i].metric != "added_mass")
      normaliser(m.p.limits[i].metric, "limits", static_cast<int>(i));
  m.set_up_variables();
  m.set_up_constraints();
  if (m.free) {  // the sensitivities' parameters: every mass parameter of each varied link
    std::set<int> varied;
    for (const CounterweightVariables& c : m.p.counterweights) varied.insert(c.link);
    for (const LinkParameterVariable& v : m.p.link_parameters) varied.insert(v.link);
    for (int k : varied)
      m.sensitivity_parameters.insert(m.sensitivity_parameters.end(),
                                      {P::link_mass(k), P::link_me(k), P::link_mf(k), P::link_J(k)});
  }
  if (m.free && m.p.resolve_peaks) {
    std::vector<bool> read(m.table.size(), false);
    for (std::size_t k = 0; k < m.table.size(); ++k) read[k] = m.weight[k] > 0;
    for (const Impl::Row& row : m.rows) {
      if (row.kind == Impl::Row::Kind::kPeakLimit) read[static_cast<std::size_t>(row.index)] = true;
    }
    for (std::size_t k = 0; k < m.table.size(); ++k) {
      if (!read[k] || m.table[k].statistic != core::Statistic::kMax) continue;
      m.read_peaks.push_back(k);
      m.read_table.push_back(m.table[k]);
    }
  }
}

PlanarNlp::~PlanarNlp() = default;

bool PlanarNlp::free_scene() const { return impl_->free; }

bool PlanarNlp::has_gradients() const {
  const cp::SimulateOptions& o = impl_->p.simulate;
  return !impl_->free || (o.route == cp::Route::kReduced &&
                          (o.integrator == core::Integrator::kCvodeAdams ||
                           o.integrator == core::Integrator::kCvodeBdf));
}

// A free scene: the metrics of the design at x simulated and, with `gradient`, their gradients
// from the same run's forward sensitivities (core/planar/simulate.hpp) with respect to the
// varied links' mass parameters q, chained with ∂q/∂x. The last evaluation is kept, so the
// objective and the constraints at the same x simulate once: a plain simulation when no
// derivative is asked for, the run with sensitivities when one is. A failed simulation gives
// +inf (gradient 0).
PlanarNlp::Evaluation PlanarNlp::simulated(const VectorXd& x, bool gradient) const {
  const Impl& m = *impl_;
  const std::lock_guard<std::mutex> lock(m.cache_mutex);
  if (m.cached.x.size() == x.size() && m.cached.x == x &&
      (!gradient || m.cached.gradient.size() != 0)) {
    return m.cached;
  }
  Evaluation e;
  e.x = x;
  const cp::Model model(design(x));
  const cp::FreeScene& scene = std::get<cp::FreeScene>(m.p.scene);
  const std::vector<double> failed(m.table.size(), std::numeric_limits<double>::infinity());
  // the others' peaks' value 0 in `peaks`: their gradients stay their largest samples'
  auto values = [&](const cp::Trajectory& t, std::vector<core::Peak>* peaks) {
    return free_run_metrics(model, t, m.p.simulate, peaks);
  };
  if (!gradient) {
    const cp::Trajectory t = cp::simulate_free(model, scene, m.p.simulate);
    e.metrics = t.ok() ? values(t, nullptr) : failed;
  } else {
    const cp::FreeSensitivities run =
        cp::simulate_free_sensitivities(model, scene, m.sensitivity_parameters, m.p.simulate);
    e.gradient = MatrixXd::Zero(static_cast<Eigen::Index>(m.table.size()), m.n);
    e.metrics = failed;
    if (run.trajectory.ok()) {
      std::vector<core::Peak> peaks;
      e.metrics = values(run.trajectory, &peaks);
      VectorXd q;
      MatrixXd J;
      m.q_of(x, q, &J);
      MatrixXd dq(static_cast<Eigen::Index>(m.sensitivity_parameters.size()), m.n);
      for (std::size_t j = 0; j < m.sensitivity_parameters.size(); ++j)
        dq.row(static_cast<Eigen::Index>(j)) = J.row(m.sensitivity_parameters[j]);
      // the peaks not read (every one without resolve_peaks) at their largest samples
      e.gradient = cp::metric_gradients(model, m.p.simulate, m.table, run, peaks) * dq;
    }
  }
  m.cached = e;
  return e;
}

std::vector<double> PlanarNlp::free_run_metrics(const cp::Model& model, const cp::Trajectory& run,
                                                const cp::SimulateOptions& options,
                                                std::vector<core::Peak>* peaks) const {
  const Impl& m = *impl_;
  std::vector<double> v = cp::metric_values(m.table, run.table);
  if (peaks) peaks->assign(m.table.size(), core::Peak{});
  if (m.read_peaks.empty()) return v;
  std::vector<core::Peak> at;
  const std::vector<double> r = cp::metric_values(model, options, m.read_table, run, &at);
  for (std::size_t i = 0; i < m.read_peaks.size(); ++i) {
    v[m.read_peaks[i]] = r[i];
    if (peaks) (*peaks)[m.read_peaks[i]] = at[i];
  }
  return v;
}

int PlanarNlp::n() const { return impl_->n; }
int PlanarNlp::design_variables() const { return impl_->design_n; }
int PlanarNlp::n_eq() const { return static_cast<int>(impl_->balance_rows.rows()); }
int PlanarNlp::n_ineq() const { return static_cast<int>(impl_->rows.size()); }
const VectorXd& PlanarNlp::lower() const { return impl_->lower; }
const VectorXd& PlanarNlp::upper() const { return impl_->upper; }
const std::vector<std::string>& PlanarNlp::variable_names() const { return impl_->variable_names; }
const std::vector<std::string>& PlanarNlp::constraint_names() const {
  return impl_->constraint_names;
}
const std::vector<cp::ColumnMetric>& PlanarNlp::metric_table() const { return impl_->table; }
const std::vector<double>& PlanarNlp::original_metrics() const { return impl_->original; }

double PlanarNlp::objective(const VectorXd& x, VectorXd* grad) const {
  const Impl& m = *impl_;
  if (m.free) {  // RMS smoothed as in driven scenes, a peak exactly (no bound variable)
    if (grad && !has_gradients())
      throw std::logic_error("PlanarNlp: this free scene's route has no gradients");
    const Evaluation e = simulated(x, grad != nullptr);
    double f = 0;
    if (grad) grad->setZero(m.n);
    for (std::size_t k = 0; k < m.table.size(); ++k) {
      if (!(m.weight[k] > 0)) continue;
      const double r = e.metrics[k] / m.original[k];
      const bool peak = m.table[k].statistic == core::Statistic::kMax;
      const double term = peak ? r : std::sqrt(r * r + m.p.smoothing * m.p.smoothing);
      f += m.weight[k] * term;
      // d(term)/dr: 1 for a peak, r / term for a smoothed RMS
      if (grad && std::isfinite(r)) {
        *grad += m.weight[k] * (peak ? 1.0 : r / term) / m.original[k] *
                 e.gradient.row(static_cast<Eigen::Index>(k)).transpose();
      }
    }
    VectorXd q;
    MatrixXd J;
    VectorXd g;
    m.q_of(x, q, grad ? &J : nullptr);
    if (m.added_weight > 0) {
      f += m.added_weight * m.added(q, grad ? &J : nullptr, grad ? &g : nullptr) / m.mass0;
      if (grad) *grad += m.added_weight / m.mass0 * g;
    }
    return f;
  }
  VectorXd q;
  MatrixXd J;
  m.q_of(x, q, grad ? &J : nullptr);
  double f = 0;
  if (grad) grad->setZero(m.n);
  VectorXd g;
  for (std::size_t k = 0; k < m.table.size(); ++k) {
    if (m.weight[k] == 0) continue;
    const double o = m.original[k];
    if (const int t = m.bound_var[k]; t >= 0) {  // a peak: its bound variable
      f += m.weight[k] * x[t];
      if (grad) (*grad)[t] += m.weight[k];
      continue;
    }
    const double r2 =
        m.rms2(m.columns(static_cast<int>(k), q, grad ? &J : nullptr), grad ? &g : nullptr) /
        (o * o);
    const double s = std::sqrt(r2 + m.p.smoothing * m.p.smoothing);
    f += m.weight[k] * s;
    if (grad) *grad += m.weight[k] / (2 * s * o * o) * g;
  }
  if (m.added_weight > 0) {
    f += m.added_weight * m.added(q, grad ? &J : nullptr, grad ? &g : nullptr) / m.mass0;
    if (grad) *grad += m.added_weight / m.mass0 * g;
  }
  return f;
}

void PlanarNlp::equalities(const VectorXd& x, VectorXd& c, MatrixXd* jac) const {
  const Impl& m = *impl_;
  VectorXd q;
  MatrixXd J;
  m.q_of(x, q, jac ? &J : nullptr);
  c = m.balance_rows * q + m.balance_offset;
  if (jac) *jac = m.balance_rows * J;
}

void PlanarNlp::inequalities(const VectorXd& x, VectorXd& c, MatrixXd* jac) const {
  const Impl& m = *impl_;
  VectorXd q;
  MatrixXd J;
  m.q_of(x, q, jac ? &J : nullptr);
  c.resize(static_cast<Eigen::Index>(m.rows.size()));
  if (jac) jac->setZero(static_cast<Eigen::Index>(m.rows.size()), m.n);
  if (m.free && jac && !has_gradients())
    throw std::logic_error("PlanarNlp: this free scene's route has no gradients");
  const Evaluation simulated_metrics =
      m.free ? simulated(x, jac != nullptr) : Evaluation{};
  // a free scene's limit: (metric / bound)² - 1 from the simulation, a peak over all samples,
  // and its gradient 2 ratio / bound · d(metric)/dx
  auto free_limit = [&](const Impl::Row& row, Eigen::Index r) {
    const auto k = static_cast<std::size_t>(row.index);
    const double bound = row.value * m.original[k], ratio = simulated_metrics.metrics[k] / bound;
    if (jac && std::isfinite(ratio)) {
      jac->row(r) = 2 * ratio / bound * simulated_metrics.gradient.row(static_cast<Eigen::Index>(k));
    }
    return ratio * ratio - 1;
  };
  std::map<int, Impl::Columns> cache;  // per metric
  auto columns = [&](int k) -> const Impl::Columns& {
    auto it = cache.find(k);
    if (it == cache.end()) it = cache.emplace(k, m.columns(k, q, jac ? &J : nullptr)).first;
    return it->second;
  };
  VectorXd g;
  for (std::size_t i = 0; i < m.rows.size(); ++i) {
    const Impl::Row& row = m.rows[i];
    const Eigen::Index r = static_cast<Eigen::Index>(i);
    switch (row.kind) {
      case Impl::Row::Kind::kEnvelope: {
        const int v = m.cw_var[static_cast<std::size_t>(row.index)];
        const double d = m.p.counterweights[static_cast<std::size_t>(row.index)].distance_max;
        if (m.moments) {
          // the smoothed cone (sqrt(|p|² + δ²) - δ) / (mass_max d) - m / mass_max
          const double mmax = m.p.counterweights[static_cast<std::size_t>(row.index)].mass_max;
          const double pmax = mmax * d, ux = x[v + 1] / pmax, uy = x[v + 2] / pmax;
          const double norm = std::sqrt(ux * ux + uy * uy + kConeSmoothing * kConeSmoothing);
          c[r] = norm - kConeSmoothing - x[v] / mmax;
          if (jac) {
            (*jac)(r, v) = -1 / mmax;
            (*jac)(r, v + 1) = ux / norm / pmax;
            (*jac)(r, v + 2) = uy / norm / pmax;
          }
          break;
        }
        c[r] = (x[v + 1] * x[v + 1] + x[v + 2] * x[v + 2]) / (d * d) - 1;
        if (jac) {
          (*jac)(r, v + 1) = 2 * x[v + 1] / (d * d);
          (*jac)(r, v + 2) = 2 * x[v + 2] / (d * d);
        }
        break;
      }
      case Impl::Row::Kind::kRelaxation:
        // the counterweight's rows, filled at its first
        if (i == 0 || m.rows[i - 1].kind != row.kind || m.rows[i - 1].index != row.index) {
          m.relaxed_cw[static_cast<std::size_t>(row.index)].fill(x, r, c, jac);
        }
        break;
      case Impl::Row::Kind::kAddedMass:
        c[r] = (m.added(q, jac ? &J : nullptr, jac ? &g : nullptr) - row.value) / m.mass0;
        if (jac) jac->row(r) = g.transpose() / m.mass0;
        break;
      case Impl::Row::Kind::kRmsLimit: {
        if (m.free) {
          c[r] = free_limit(row, r);
          break;
        }
        const double bound = row.value * m.original[static_cast<std::size_t>(row.index)];
        c[r] = m.rms2(columns(row.index), jac ? &g : nullptr) / (bound * bound) - 1;
        if (jac) jac->row(r) = g.transpose() / (bound * bound);
        break;
      }
      case Impl::Row::Kind::kPeakBound: {
        // sqrt(|y_s|² / o² + ε²) - t: linear in t, its gradient never vanishes
        const auto k = static_cast<std::size_t>(row.index);
        const double o = m.original[k], eps = m.p.smoothing;
        const int t = m.bound_var[k];
        const Impl::Columns& y = columns(row.index);
        double s2 = 0;
        for (std::size_t j = 0; j < y.y.size(); ++j) s2 += y.y[j][row.sample] * y.y[j][row.sample];
        const double root = std::sqrt(s2 / (o * o) + eps * eps);
        c[r] = root - x[t];
        if (jac) {
          for (std::size_t j = 0; j < y.y.size(); ++j)
            jac->row(r) += y.y[j][row.sample] * y.dy[j].row(row.sample) / (root * o * o);
          (*jac)(r, t) = -1;
        }
        break;
      }
      case Impl::Row::Kind::kPeakLimit: {
        if (m.free) {
          c[r] = free_limit(row, r);
          break;
        }
        const double bound = row.value * m.original[static_cast<std::size_t>(row.index)];
        const Impl::Columns& y = columns(row.index);
        double s2 = 0;
        for (std::size_t j = 0; j < y.y.size(); ++j) {
          const double yi = y.y[j][row.sample];
          s2 += yi * yi;
          if (jac) jac->row(r) += 2 * yi * y.dy[j].row(row.sample) / (bound * bound);
        }
        c[r] = s2 / (bound * bound) - 1;
        break;
      }
    }
  }
}

std::string PlanarNlp::constraint_text(int i, const VectorXd& x) const {
  const Impl& m = *impl_;
  VectorXd q;
  m.q_of(x, q, nullptr);
  if (i < n_eq()) {  // the momentum conditions, against the original's imbalance
    const double now = (m.balance_rows * q + m.balance_offset).norm();
    const double was = (m.balance_rows * m.q0 + m.balance_offset).norm();
    return "the linear momentum left in the balance conditions is " +
           text::digits(was > 0 ? now / was : 0.0, 3) + " of the original's";
  }
  const Impl::Row& row = m.rows[static_cast<std::size_t>(i - n_eq())];
  switch (row.kind) {
    case Impl::Row::Kind::kEnvelope: {
      const int v = m.cw_var[static_cast<std::size_t>(row.index)];
      const double distance =
          m.moments ? (x[v] > 0 ? x.segment<2>(v + 1).norm() / x[v] : 0.0)
                    : x.segment<2>(v + 1).norm();
      return "the counterweight's centre is " + text::digits(distance, 6) +
             " m from its pivot, at most " +
             text::digits(m.p.counterweights[static_cast<std::size_t>(row.index)].distance_max, 6) +
             " m";
    }
    case Impl::Row::Kind::kAddedMass:
      return "the added mass is " + text::digits(m.added(q, nullptr, nullptr), 6) +
             " kg, at most " + text::digits(row.value, 6) + " kg";
    case Impl::Row::Kind::kRmsLimit: {
      const auto k = static_cast<std::size_t>(row.index);
      const double value =
          m.free ? simulated(x, false).metrics[k] : std::sqrt(m.rms2(m.columns(row.index, q, nullptr), nullptr));
      return m.table[k].name + " is " + text::digits(value, 6) + " " + m.table[k].unit + " = " +
             text::digits(value / m.original[k], 4) + " x the original's, at most " +
             text::digits(row.value, 6) + " x";
    }
    case Impl::Row::Kind::kPeakLimit: {
      const auto k = static_cast<std::size_t>(row.index);
      if (m.free) {
        const double value = simulated(x, false).metrics[k];
        return m.table[k].name + " is " + text::digits(value, 6) + " " + m.table[k].unit + " = " +
               text::digits(value / m.original[k], 4) + " x the original's, at most " +
               text::digits(row.value, 6) + " x";
      }
      const Impl::Columns c = m.columns(row.index, q, nullptr);
      double s2 = 0;
      for (const VectorXd& y : c.y) s2 += y[row.sample] * y[row.sample];
      return "|" + m.table[k].name + "| there is " + text::digits(std::sqrt(s2), 6) + " " +
             m.table[k].unit + " = " + text::digits(std::sqrt(s2) / m.original[k], 4) +
             " x the original's peak, at most " + text::digits(row.value, 6) + " x";
    }
    case Impl::Row::Kind::kPeakBound:
    case Impl::Row::Kind::kRelaxation:
      break;
  }
  return {};
}

void PlanarNlp::polish(VectorXd& x) const {
  const Impl& m = *impl_;
  VectorXd q;
  m.q_of(x, q, nullptr);
  for (std::size_t k = 0; k < m.table.size(); ++k) {
    const int t = m.bound_var[k];
    if (t < 0) continue;
    x[t] = std::hypot(m.peak(static_cast<int>(k), q) / m.original[k], m.p.smoothing);
  }
}

VectorXd PlanarNlp::start(bool original) const {
  VectorXd x = positions_start(original);
  if (impl_->moments) {
    for (int v : impl_->cw_var) x.segment<2>(v + 1) *= x[v];
  }
  set_bound_variables(x);
  return x;
}

VectorXd PlanarNlp::start_scaled(double fraction) const {
  VectorXd x = start();
  for (int v : impl_->cw_var) {
    x[v] *= fraction;
    if (impl_->moments) x.segment<2>(v + 1) *= fraction;
  }
  set_bound_variables(x);
  return x;
}

VectorXd PlanarNlp::from_positions(const VectorXd& x) const {
  VectorXd z = x;
  if (impl_->moments) {
    for (int v : impl_->cw_var) {
      if (v + 2 < z.size()) z.segment<2>(v + 1) *= z[v];
    }
  }
  return start_at(z);
}

VectorXd PlanarNlp::to_positions(const VectorXd& x) const {
  const Impl& m = *impl_;
  VectorXd out = x.head(m.design_n);
  if (!m.moments) return out;
  for (std::size_t c = 0; c < m.cw_var.size(); ++c) {
    const int v = m.cw_var[c];
    out.segment<2>(v + 1) = detail::position_of(x[v], Vec2(x[v + 1], x[v + 2]),
                                                m.p.counterweights[c].distance_max);
  }
  return out;
}

std::vector<int> PlanarNlp::vanishing_counterweight_variables(const VectorXd& x,
                                                              double fraction) const {
  if (!impl_->moments) return {};
  return detail::vanishing_counterweight_variables(x, impl_->cw_var, impl_->p.counterweights,
                                                   fraction);
}

VectorXd PlanarNlp::without_vanishing_counterweights(const VectorXd& x, double fraction) const {
  const Impl& m = *impl_;
  VectorXd out = x;
  for (int j : vanishing_counterweight_variables(x, fraction)) out[j] = 0;
  for (const detail::RelaxedCounterweight& r : m.relaxed_cw) r.set_tight(out);
  return out;
}

void PlanarNlp::first_order_inequalities(const VectorXd& x, const VectorXd& g, VectorXd& c,
                                         MatrixXd& jac) const {
  const Impl& m = *impl_;
  inequalities(x, c, &jac);
  if (!m.moments) return;
  for (std::size_t i = 0; i < m.rows.size(); ++i) {
    const Impl::Row& row = m.rows[i];
    if (row.kind != Impl::Row::Kind::kEnvelope) continue;
    const CounterweightVariables& cw = m.p.counterweights[static_cast<std::size_t>(row.index)];
    detail::cone_first_order_row(x, g, m.cw_var[static_cast<std::size_t>(row.index)],
                                 cw.mass_max, cw.distance_max, static_cast<Eigen::Index>(i), c,
                                 jac);
  }
}

std::string PlanarNlp::why_not_convex() const {
  const Impl& m = *impl_;
  if (m.free) return "a free scene: the motion, and with it every reaction, depends on the design";
  // the entries of q that are not affine in the variables, and why
  std::vector<std::pair<int, std::string>> varying;
  for (std::size_t k = 0; k < m.p.original.links.size(); ++k) {
    const int link = static_cast<int>(k);
    bool mass = false, offset = false, counterweight = false;
    for (const LinkParameterVariable& v : m.p.link_parameters) {
      if (v.link != link) continue;
      mass = mass || v.parameter == Param::kMass;
      offset = offset || v.parameter == Param::kE || v.parameter == Param::kF;
    }
    for (const CounterweightVariables& c : m.p.counterweights) {
      counterweight = counterweight || c.link == link;
    }
    const std::string name = "the " + m.p.original.links[k].name + "'s ";
    if (counterweight && !m.relaxed) {
      varying.emplace_back(P::link_J(link),
                           name + "inertia about its first node, which varies with the square of "
                                  "its counterweight's position");
    } else if (offset) {
      varying.emplace_back(P::link_J(link), name + "inertia about its first node, which varies "
                                                   "with the square of its e or f");
    }
    if (mass && offset) {
      for (int i : {P::link_me(link), P::link_mf(link)}) {
        varying.emplace_back(i, name + "first moments, its mass times e or f, both varied");
      }
    }
  }
  std::vector<int> used;
  for (std::size_t k = 0; k < m.table.size(); ++k) {
    if (m.weight[k] > 0) used.push_back(static_cast<int>(k));
  }
  for (const Limit& l : m.p.limits) {
    if (l.metric != "added_mass") used.push_back(m.metric_index(l.metric));
  }
  for (int k : used) {
    for (const std::string& column : m.metric(k).columns) {
      const MatrixXd& B = m.outputs.at(column).second;
      const double scale = B.cwiseAbs().maxCoeff();
      for (const auto& [i, why] : varying) {
        if (B.col(i).cwiseAbs().maxCoeff() > 1e-9 * scale) {
          return m.metric(k).name + " depends on " + why;
        }
      }
    }
  }
  return "";
}

VectorXd PlanarNlp::positions_start(bool original) const {
  const Impl& m = *impl_;
  VectorXd x = VectorXd::Zero(m.n);
  for (std::size_t c = 0; c < m.p.counterweights.size(); ++c) {
    const CounterweightVariables& cw = m.p.counterweights[c];
    const int v = m.cw_var[c];
    x[v] = original ? 0.0 : cw.mass_max / 2;
    x.segment<2>(v + 1) = cw.distance_max / 2 * m.cw_away[c];
  }
  for (std::size_t i = 0; i < m.p.link_parameters.size(); ++i) {
    const LinkParameterVariable& v = m.p.link_parameters[i];
    const cp::Link& link = m.p.original.links[static_cast<std::size_t>(v.link)];
    const double value = v.parameter == Param::kMass ? link.mass
                         : v.parameter == Param::kE  ? link.e
                         : v.parameter == Param::kF  ? link.f
                                                     : link.inertia;
    x[m.param_var[i]] = std::clamp(value, v.lower, v.upper);
  }
  // with force balance asked for, the counterweights moved onto the balance conditions: for
  // fixed masses the conditions are linear in the positions, so a least-norm step meets them;
  // a position outside its envelope then takes more mass (same mass moment, up to mass_max) and
  // the step is repeated. A start that meets the equalities is what SLSQP needs to find a
  // feasible design at all on some linkages.
  if (!original && n_eq() > 0 && !m.p.counterweights.empty()) {
    for (int pass = 0; pass < 4; ++pass) {
      // the balance conditions in the positions, whatever the program's variables
      VectorXd q, c;
      MatrixXd dq, jac;
      m.q_of(x, q, &dq, true);
      c = m.balance_rows * q + m.balance_offset;
      jac = m.balance_rows * dq;
      MatrixXd J(jac.rows(), 2 * static_cast<Eigen::Index>(m.p.counterweights.size()));
      for (std::size_t k = 0; k < m.p.counterweights.size(); ++k)
        J.middleCols(2 * static_cast<Eigen::Index>(k), 2) = jac.middleCols(m.cw_var[k] + 1, 2);
      const VectorXd step = J.completeOrthogonalDecomposition().solve(c);
      bool moved_mass = false;
      for (std::size_t k = 0; k < m.p.counterweights.size(); ++k) {
        const CounterweightVariables& cw = m.p.counterweights[k];
        const int v = m.cw_var[k];
        x.segment<2>(v + 1) -= step.segment<2>(2 * static_cast<Eigen::Index>(k));
        const double r = x.segment<2>(v + 1).norm(), fit = 0.9 * cw.distance_max;
        if (r > fit && x[v] > 0) {  // the same mass moment, further in, with more mass
          const double mass = std::min(cw.mass_max, x[v] * r / fit);
          x.segment<2>(v + 1) *= x[v] / mass;
          x[v] = mass;
          moved_mass = true;
        }
        if (x.segment<2>(v + 1).norm() > cw.distance_max)
          x.segment<2>(v + 1) *= cw.distance_max / x.segment<2>(v + 1).norm();
      }
      if (!moved_mass) break;
    }
  }
  return x;
}

// each bound variable a hair above its smoothed peak at the design of x
void PlanarNlp::set_bound_variables(VectorXd& x) const {
  const Impl& m = *impl_;
  for (const detail::RelaxedCounterweight& r : m.relaxed_cw) r.set_tight(x);
  VectorXd q;
  m.q_of(x, q, nullptr);
  for (std::size_t k = 0; k < m.table.size(); ++k) {
    const int t = m.bound_var[k];
    if (t < 0) continue;
    const double peak = std::hypot(m.peak(static_cast<int>(k), q) / m.original[k], m.p.smoothing);
    x[t] = std::min(peak * (1 + 1e-12), m.upper[t]);
  }
}

VectorXd PlanarNlp::start_at(const VectorXd& design) const {
  const Impl& m = *impl_;
  VectorXd x = start(true);
  const Eigen::Index k = std::min<Eigen::Index>(m.design_n, design.size());
  x.head(k) = design.head(k).cwiseMax(m.lower.head(k)).cwiseMin(m.upper.head(k));
  set_bound_variables(x);
  return x;
}

std::vector<bp::LinkCounterweight> PlanarNlp::counterweights(const VectorXd& x) const {
  const Impl& m = *impl_;
  std::vector<bp::LinkCounterweight> out;
  for (std::size_t c = 0; c < m.p.counterweights.size(); ++c) {
    const CounterweightVariables& cw = m.p.counterweights[c];
    const int v = m.cw_var[c];
    balance::Counterweight w;
    w.mass = x[v];
    w.position = Vec2(x[v + 1], x[v + 2]);
    if (m.moments) w.position = detail::position_of(w.mass, w.position, cw.distance_max);
    w.distance = w.position.norm();
    if (cw.shape == balance::CounterweightShape::kDisc) {
      w.thickness = cw.thickness;
      w.radius = std::sqrt(w.mass / (cw.density * std::numbers::pi * cw.thickness));
    }
    w.inertia = disc_inertia_per_mass2(cw) * w.mass * w.mass;
    out.push_back({cw.link, m.cw_pivot[c], w});
  }
  return out;
}

cp::Linkage PlanarNlp::design(const VectorXd& x) const {
  const Impl& m = *impl_;
  cp::Linkage d = m.p.original;
  VectorXd q;
  m.q_of(x, q, nullptr);
  // the links' own parameters, then each counterweight merged in (parallel axes)
  for (std::size_t i = 0; i < m.p.link_parameters.size(); ++i) {
    const LinkParameterVariable& v = m.p.link_parameters[i];
    cp::Link& link = d.links[static_cast<std::size_t>(v.link)];
    const double value = x[m.param_var[i]];
    (v.parameter == Param::kMass ? link.mass
     : v.parameter == Param::kE  ? link.e
     : v.parameter == Param::kF  ? link.f
                                 : link.inertia) = value;
  }
  const std::vector<bp::LinkCounterweight> cws = counterweights(x);
  for (std::size_t c = 0; c < cws.size(); ++c) {
    if (cws[c].counterweight.mass <= 0) continue;
    cp::Link& link = d.links[static_cast<std::size_t>(cws[c].link)];
    link = bp::merged(link, cws[c].counterweight,
                      m.cw_pivot_in_link[c] + cws[c].counterweight.position);
  }
  return cp::make_linkage(d);
}

std::vector<double> PlanarNlp::metrics(const VectorXd& x) const {
  const Impl& m = *impl_;
  if (m.free) return simulated(x, false).metrics;
  VectorXd q;
  m.q_of(x, q, nullptr);
  std::vector<double> out;
  for (std::size_t k = 0; k < m.table.size(); ++k) {
    if (m.metric(static_cast<int>(k)).statistic == core::Statistic::kRms) {
      out.push_back(std::sqrt(m.rms2(m.columns(static_cast<int>(k), q, nullptr), nullptr)));
    } else {
      out.push_back(m.peak(static_cast<int>(k), q));
    }
  }
  return out;
}

std::vector<int> PlanarNlp::counterweight_mass_variables() const { return impl_->cw_var; }
std::vector<double> PlanarNlp::counterweight_reach() const {
  std::vector<double> out;
  if (impl_->moments) return out;
  for (const CounterweightVariables& c : impl_->p.counterweights) out.push_back(c.distance_max);
  return out;
}

std::vector<double> PlanarNlp::peak_instants(const VectorXd& x, double within) const {
  const Impl& m = *impl_;
  std::vector<double> out;
  if (m.free || m.instants == m.samples) return out;
  VectorXd q;
  m.q_of(x, q, nullptr);
  for (std::size_t k = 0; k < m.table.size(); ++k) {
    if (m.table[k].statistic != core::Statistic::kMax) continue;
    const bool limited = std::any_of(m.p.limits.begin(), m.p.limits.end(),
                                     [&](const Limit& l) { return l.metric == m.table[k].name; });
    if (!(m.weight[k] > 0) && !limited) continue;
    detail::add_local_maxima(m.times, m.magnitudes(static_cast<int>(k), q),
                             static_cast<std::size_t>(m.samples), within * m.original[k], out);
  }
  return out;
}

double PlanarNlp::added_mass(const VectorXd& x) const {
  VectorXd q;
  impl_->q_of(x, q, nullptr);
  return impl_->added(q, nullptr, nullptr);
}

namespace {

// the largest relative difference between two evaluations of the metrics, each against the
// larger of the two and 1e-4 of the largest metric of its unit (a metric that vanishes by
// cancellation is known only to the round-off of its terms)
double verification_error(const std::vector<cp::ColumnMetric>& table, const std::vector<double>& a,
                          const std::vector<double>& b) {
  std::map<std::string, double> scale;
  for (std::size_t k = 0; k < table.size(); ++k)
    scale[table[k].unit] = std::max({scale[table[k].unit], std::abs(a[k]), std::abs(b[k])});
  double worst = 0;
  for (std::size_t k = 0; k < table.size(); ++k) {
    const double s = std::max({std::abs(a[k]), std::abs(b[k]), 1e-4 * scale[table[k].unit]});
    if (s == 0) continue;
    const double e = std::abs(a[k] - b[k]) / s;
    if (!std::isfinite(e)) return std::numeric_limits<double>::infinity();
    worst = std::max(worst, e);
  }
  return worst;
}

}  // namespace

std::string Result::brief_report() const {
  std::string s = solver_report(*this);
  if (!peak_times.empty()) {
    s +=
        ", peaks bounded at " + std::to_string(peak_times.size()) + " instants besides the samples";
  }
  if (verified.empty()) return s + ", not verified";
  s += ", verified by simulating it to " + text::digits(verification_error, 2);
  if (!std::isnan(inertial_error)) {
    s += ", its inertial shaking force and moment by the bodies' accelerations to " +
         text::digits(inertial_error, 2);
  }
  return s;
}

Problem check_algorithm(const DesignProblem& problem, const OptimizeOptions& options) {
  // a free scene's gradients come from the reduced route's forward sensitivities (CVODES)
  std::string without;
  if (std::holds_alternative<cp::FreeScene>(problem.scene)) {
    const cp::SimulateOptions& o = problem.simulate;
    if (o.route != cp::Route::kReduced) {
      without = "a free scene on the dae route";
    } else if (o.integrator != core::Integrator::kCvodeAdams &&
               o.integrator != core::Integrator::kCvodeBdf) {
      without = std::string("a free scene integrated by ") + core::to_string(o.integrator);
    }
  }
  return optimize::check_algorithm(options, without,
                                   "the reduced route integrated by cvode-adams or cvode-bdf",
                                   problem.force_balance);
}

namespace {

// A second route for the inertial shaking force and moment of a simulated design: Newton's law
// on each body's centre of mass from the kinematics alone (the balance layer's regressors, -Σ m a
// and -dH/dt), against the engine's kinetostatic sums over the supports; the largest difference
// over the samples relative to the largest value of each (NaN when the motion cannot be
// evaluated).
double inertial_error(const cp::Linkage& design, const core::Series& table) {
  const cp::Model model(design);
  const bp::InputSeries in = bp::input_series(model, table);
  const auto k = bp::kinematics(model, in.values, in.rates, in.accelerations);
  if (!k) return std::numeric_limits<double>::quiet_NaN();
  const VectorXd q = P::of(design);
  const bp::ShaftSeries shafts = bp::shaft_series(design, *k);
  const VectorXd force = bp::shaking_force_regressor(design, *k) * q + shafts.force;
  const VectorXd moment = bp::shaking_moment_regressor(design, *k) * q + shafts.moment;
  const std::vector<double> fx = table.column_values("Fshx_inertial"),
                            fy = table.column_values("Fshy_inertial"),
                            msh = table.column_values("Msh_inertial");
  // the scales: a shaking force that vanishes by cancellation is known to the round-off of the
  // support forces it sums, its moment to that times the linkage's reach from the origin
  double f = 0, reach = 0;
  for (std::size_t c = 0; c < table.width(); ++c) {
    const std::string& name = table.columns[c];
    const bool support =
        name.size() > 1 && name[0] == 'R' && (name.back() == 'x' || name.back() == 'y');
    const bool node = name.rfind("x_", 0) == 0 || name.rfind("y_", 0) == 0;
    if (!support && !node) continue;
    for (double v : table.column_values(name))
      (support ? f : reach) = std::max(support ? f : reach, std::abs(v));
  }
  double df = 0, dm = 0, mm = 0;
  for (std::size_t i = 0; i < msh.size(); ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    df = std::max(df, std::hypot(force[2 * r] - fx[i], force[2 * r + 1] - fy[i]));
    f = std::max(f, std::hypot(fx[i], fy[i]));
    dm = std::max(dm, std::abs(moment[r] - msh[i]));
    mm = std::max(mm, std::abs(msh[i]));
  }
  mm = std::max(mm, f * reach);
  return std::max(f > 0 ? df / f : df, mm > 0 ? dm / mm : dm);
}

}  // namespace

namespace {

// the index of metric `name` in the table, or -1
int table_index(const std::vector<cp::ColumnMetric>& table, const std::string& name) {
  for (std::size_t k = 0; k < table.size(); ++k)
    if (table[k].name == name) return static_cast<int>(k);
  return -1;
}

// The times a next round bounds the peaks at, as the four-bar's short_peak_angles()
// (optimize.cpp): for each peak metric of the objective (weight > 0) and of the limits whose
// resolved peak at the optimum (the engine's inverse dynamics between the samples) rises above
// the peak over the program's instants by more than kPeakExchangeTolerance,
// detail::add_peak_instants(). Empty in a free scene, for a design that is no result or cannot
// be run, when the instants hold the peaks, and without problem.resolve_peaks.
std::vector<double> short_peak_times(const DesignProblem& problem, const PlanarNlp& nlp,
                                     const detail::Solved& solved) {
  const auto* scene = std::get_if<cp::DrivenScene>(&problem.scene);
  if (!problem.resolve_peaks || !scene || !found_design(solved.termination)) return {};
  const std::vector<cp::ColumnMetric>& table = nlp.metric_table();
  std::vector<int> used;
  auto use = [&](const std::string& name) {
    const int k = table_index(table, name);
    if (k >= 0 && table[static_cast<std::size_t>(k)].statistic == core::Statistic::kMax)
      used.push_back(k);
  };
  for (const Term& t : problem.objective)
    if (t.weight > 0) use(t.metric);
  for (const Limit& l : problem.limits) use(l.metric);
  if (used.empty()) return {};
  const cp::Model model(nlp.design(solved.x));
  const cp::Trajectory run = cp::simulate_driven(model, *scene);
  if (!run.ok()) return {};
  std::vector<core::Peak> peaks;
  const std::vector<double> resolved = cp::metric_values(model, *scene, table, run, &peaks);
  const std::vector<double> bounded = nlp.metrics(solved.x);
  std::vector<double> instants = run.table.column_values("t");
  // a periodic run's end (its first sample's next turn) closes the last interval
  if (const double period = cp::driven_period(model, *scene, run);
      period > 0 && !instants.empty()) {
    instants.push_back(instants.front() + period);
  }
  instants.insert(instants.end(), problem.peak_times.begin(), problem.peak_times.end());
  std::sort(instants.begin(), instants.end());
  std::vector<double> added;
  for (const int k : used) {
    const auto i = static_cast<std::size_t>(k);
    // of the original's peak, as the four-bar's
    const double excess = (resolved[i] - bounded[i]) / nlp.original_metrics()[i];
    if (!(excess > detail::kPeakExchangeTolerance)) continue;
    detail::add_peak_instants(instants, peaks[i].t, excess, added);
  }
  return added;
}

// The peaks of `metrics` (the run's samples') raised to those at the added instants: what the
// program bounded, evaluated on another run of the same design (the verification's).
void add_instants_peaks(const cp::Model& model, const cp::DrivenScene& scene,
                        const cp::Trajectory& run, const std::vector<double>& times,
                        const std::vector<cp::ColumnMetric>& table, std::vector<double>& metrics) {
  if (times.empty()) return;
  cp::DrivenRows rows(model, scene, run);
  for (const double s : times) {
    const double* row = rows.at(s);
    if (!row) continue;
    for (std::size_t k = 0; k < table.size(); ++k) {
      if (table[k].statistic != core::Statistic::kMax) continue;
      double s2 = 0;
      for (const std::string& c : table[k].columns) {
        const double v = row[run.table.column(c)];
        s2 += v * v;
      }
      metrics[k] = std::max(metrics[k], std::sqrt(s2));
    }
  }
}

}  // namespace

Result optimize(const DesignProblem& problem, const OptimizeOptions& options,
                const std::vector<VectorXd>& designs) {
  if (const Problem e = options.validate()) throw InputError("optimize options: " + e->text());
  if (const Problem e = check_algorithm(problem, options)) throw InputError(*e);
  // The exchange step (problem.resolve_peaks), as the four-bar's: solve on the samples and the
  // peak times found so far; where a resolved peak of the optimum rises above what the program
  // bounded, add instants around it and solve again from that optimum
  // (detail::exchange_rounds()). A problem convex in the counterweights' masses and mass moments
  // is solved in those variables (optimize/convex_solve.hpp); the original design itself (no
  // counterweight mass) is the last start: it meets every limit of 1 or more and any
  // added-mass limit >= 0.
  return detail::exchange_rounds<PlanarNlp>(
      problem, designs, options, &DesignProblem::peak_times, "instants", short_peak_times,
      [](const PlanarNlp&) {},
      [&](const PlanarNlp& nlp, const DesignProblem& exchanged,
          const detail::ConvexAwareSolve& solve, const detail::ExchangeTotals& totals) {
        const detail::Solved& s = solve.solved;
        Result r;
        detail::set_solve_fields(r, nlp, solve, options, totals);
        if (s.termination == Termination::kInfeasible && !uses_gradients(options.algorithm) &&
            totals.evaluations >= options.max_evaluations) {
          r.message += "; the evaluation budget ran out first: raise max_evaluations";
        } else if (s.termination == Termination::kInfeasible) {
          // a local solver that finds no feasible design from its starts does not prove there is
          // none
          r.message += "; another algorithm may find one (" +
                       other_algorithms(options.algorithm,
                                        std::holds_alternative<cp::FreeScene>(problem.scene)) +
                       ")";
        }
        r.message += totals.shortfall;
        r.variable_names = nlp.variable_names();
        r.design_variables = nlp.design_variables();
        r.peak_times = exchanged.peak_times;
        r.design = nlp.design(r.x);
        r.counterweights = nlp.counterweights(r.x);
        r.metric_table = nlp.metric_table();
        r.original = nlp.original_metrics();
        r.metrics = nlp.metrics(r.x);
        r.added_mass = nlp.added_mass(r.x);
        if (!r.ok()) return r;  // no design: nothing to verify
        // the design simulated by the engine, against the regressor's evaluation (its peaks over
        // the same instants); in a free scene by the other route (dae), against the reduced route's
        // evaluations
        cp::SimulateOptions other = problem.simulate;
        other.route =
            problem.simulate.route == cp::Route::kDae ? cp::Route::kReduced : cp::Route::kDae;
        const cp::Model model(r.design);
        const auto* driven = std::get_if<cp::DrivenScene>(&problem.scene);
        const cp::Trajectory t =
            driven ? cp::simulate_driven(model, *driven)
                   : cp::simulate_free(model, std::get<cp::FreeScene>(problem.scene), other);
        if (!t.ok()) {
          r.verification_error = std::numeric_limits<double>::infinity();
          r.message += "; the optimum's simulation failed: " + t.message;
          return r;
        }
        r.verified = driven ? cp::metric_values(r.metric_table, t.table)
                            : nlp.free_run_metrics(model, t, other);
        if (driven) add_instants_peaks(model, *driven, t, r.peak_times, r.metric_table, r.verified);
        r.verification_error = verification_error(r.metric_table, r.metrics, r.verified);
        r.inertial_error = inertial_error(r.design, t.table);
        return r;
      });
}

namespace {

// a planar linkage's problems for the ε-constraint method (epsilon_front.hpp)
struct PlanarFront {
  using Problem = DesignProblem;
  using Metric = std::string;
  using Result = planar::Result;
  const DesignProblem& problem;
  const OptimizeOptions& options;
  Problem minimising(const Metric& m) const {
    DesignProblem p = problem;
    p.objective = {Term{m, 1.0}};
    return p;
  }
  static void limit(Problem& p, const Metric& m, double bound) {
    p.limits.push_back(Limit{m, bound});
  }
  Result solve(const Problem& p, const std::vector<const Result*>& warm) const {
    std::vector<VectorXd> designs;
    for (const Result* r : warm)
      if (r->ok()) designs.push_back(r->x);
    // the neighbour's design first: optimize() brings it within this point's bound towards the
    // last (the second metric's minimiser), and the solve goes on along the front from there
    return optimize(p, options, designs);
  }
  // the value of `m` at a result, in the units of a Limit on it: the fraction of the original's
  // value, or kg for added_mass
  static double value(const Result& r, const Metric& m) {
    if (m == "added_mass") return r.added_mass;
    for (std::size_t k = 0; k < r.metric_table.size(); ++k)
      if (r.metric_table[k].name == m) return r.metrics[k] / r.original[k];
    return std::numeric_limits<double>::quiet_NaN();
  }
  static bool is_mass(const Metric& m) { return m == "added_mass"; }
};

}  // namespace

std::vector<ParetoPoint> pareto_front(const DesignProblem& problem, const std::string& first,
                                      const std::string& second, int points,
                                      const OptimizeOptions& options) {
  if (points < 2)
    throw InputError("pareto_front: points must be >= 2, got " + std::to_string(points));
  if (first == second)
    throw InputError("pareto_front: the two metrics must differ, got " + first + " twice");
  if (const Problem e = options.validate()) throw InputError("optimize options: " + e->text());
  // every problem of the front is set up once here, so a metric it cannot take is reported
  // before any solve: `first` as the objective, `second` as a limit
  DesignProblem check = problem;
  check.objective = {Term{first, 1.0}};
  check.limits.push_back(Limit{second, 1.0});
  (void)PlanarNlp(check);
  // each point starts from its neighbour's design: its counterweights stay (OptimizeOptions)
  OptimizeOptions along = options;
  along.leave_out_needless_counterweights = false;
  std::vector<ParetoPoint> front;
  for (auto& [epsilon, result] :
       detail::epsilon_front(PlanarFront{problem, along}, first, second, points)) {
    front.push_back(ParetoPoint{epsilon, std::move(result)});
  }
  return front;
}

}  // namespace bd::optimize::planar
