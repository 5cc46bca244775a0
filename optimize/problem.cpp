#include "optimize/problem.hpp"

#include <cmath>
#include <cstdio>
#include <set>
#include <utility>

#include "core/input_error.hpp"
#include "core/number_text.hpp"

namespace bd::optimize {

namespace {

// "<what> must be <expected> <unit>, got <value>"
std::string must_be(const std::string& what, const char* expected, const char* unit, double v) {
  return what + " must be " + expected + (unit[0] != '\0' ? " " : "") + unit + ", got " +
         text::exact(v);
}

const char* parameter_name(LinkParameterVariable::Parameter p) {
  switch (p) {
    case LinkParameterVariable::Parameter::kMass:
      return "mass";
    case LinkParameterVariable::Parameter::kE:
      return "e";
    case LinkParameterVariable::Parameter::kF:
      return "f";
    case LinkParameterVariable::Parameter::kInertia:
      return "inertia";
  }
  return "?";
}

const char* parameter_unit(LinkParameterVariable::Parameter p) {
  switch (p) {
    case LinkParameterVariable::Parameter::kMass:
      return "kg";
    case LinkParameterVariable::Parameter::kE:
    case LinkParameterVariable::Parameter::kF:
      return "m";
    case LinkParameterVariable::Parameter::kInertia:
      return "kg m^2";
  }
  return "";
}

std::string check_scene(const core::FreeScene& s) {
  if (!(std::isfinite(s.duration) && s.duration > 0)) {
    return must_be("scene.duration", "> 0", "s", s.duration);
  }
  if (s.samples < 2) return must_be("scene.samples", ">= 2", "", s.samples);
  if (!std::isfinite(s.theta1)) return must_be("scene.theta1", "finite", "rad", s.theta1);
  if (!std::isfinite(s.omega1)) return must_be("scene.omega1", "finite", "rad/s", s.omega1);
  return "";
}

std::string check_scene(const core::DrivenScene& s) {
  if (!(std::isfinite(s.omega1) && s.omega1 != 0)) {
    return must_be("scene.omega1", "finite and != 0", "rad/s", s.omega1);
  }
  if (s.revolutions < 1) return must_be("scene.revolutions", ">= 1", "", s.revolutions);
  if (s.samples < 1) return must_be("scene.samples", ">= 1", "", s.samples);
  if (!std::isfinite(s.theta1)) return must_be("scene.theta1", "finite", "rad", s.theta1);
  return "";
}

bool is_torque(Metric m) {
  return m != Metric::kAddedMass && info(m).quantity == core::Quantity::kDriveTorque;
}

}  // namespace

const core::MetricInfo& info(Metric m) { return core::kMetricTable[static_cast<std::size_t>(m)]; }

const char* to_string(Metric m) { return m == Metric::kAddedMass ? "added_mass" : info(m).name; }

std::optional<Metric> metric_named(const std::string& name) {
  for (Metric m : kMetrics) {
    if (name == to_string(m)) return m;
  }
  return std::nullopt;
}

const char* metric_unit(Metric m) { return m == Metric::kAddedMass ? "kg" : info(m).unit; }

bool is_moment(Metric m) { return std::string_view(metric_unit(m)) == "N m"; }

double value(const core::Metrics& metrics, Metric m) { return metrics.*info(m).field; }

bool is_peak(Metric m) {
  return m != Metric::kAddedMass && info(m).statistic == core::Statistic::kMax;
}

const char* to_string(ObjectiveForm f) {
  switch (f) {
    case ObjectiveForm::kLinear:
      return "linear";
    case ObjectiveForm::kSquared:
      return "squared";
  }
  return "?";
}

std::optional<ObjectiveForm> objective_form_named(const std::string& name) {
  for (ObjectiveForm f : {ObjectiveForm::kLinear, ObjectiveForm::kSquared}) {
    if (name == to_string(f)) return f;
  }
  return std::nullopt;
}

std::string DesignProblem::validate() const {
  // the original design
  try {
    (void)core::make_fourbar(original);
  } catch (const InputError& e) {
    return std::string("original design: ") + e.what();
  }

  // scene and evaluation
  if (const std::string e = std::visit([](const auto& s) { return check_scene(s); }, scene);
      !e.empty()) {
    return e;
  }
  if (formulation != core::Formulation::kMassMatrix &&
      formulation != core::Formulation::kOpenedLoop &&
      formulation != core::Formulation::kComplexMasses) {
    return "formulation must be mass-matrix, opened-loop or complex-masses";
  }
  if (std::holds_alternative<core::FreeScene>(scene) &&
      !(std::isfinite(tolerance) && tolerance > 0)) {
    return must_be("tolerance", "> 0", "", tolerance);
  }

  // variables
  if (counterweights.empty() && link_parameters.empty()) {
    return "no design variables: give at least one counterweight or link parameter";
  }
  int on_link[4] = {-1, -1, -1, -1};
  for (std::size_t i = 0; i < counterweights.size(); ++i) {
    const CounterweightVariables& c = counterweights[i];
    const std::string name = "counterweights[" + std::to_string(i) + "]";
    if (c.link != 1 && c.link != 3) {
      return name + ".link must be 1 (crank) or 3 (rocker), got " + std::to_string(c.link);
    }
    if (on_link[c.link] >= 0) {
      return name + ": a second counterweight on the " + core::link_name(c.link) +
             " (counterweights[" + std::to_string(on_link[c.link]) +
             "] is there already); at most one per link";
    }
    on_link[c.link] = static_cast<int>(i);
    if (!(std::isfinite(c.mass_max) && c.mass_max > 0)) {
      return must_be(name + ".mass_max", "> 0", "kg", c.mass_max);
    }
    if (!(std::isfinite(c.distance_max) && c.distance_max > 0)) {
      return must_be(name + ".distance_max", "> 0", "m", c.distance_max);
    }
    if (c.shape != balance::CounterweightShape::kPoint &&
        c.shape != balance::CounterweightShape::kDisc) {
      return name + ".shape must be point or disc";
    }
    if (c.shape == balance::CounterweightShape::kDisc) {
      if (!(std::isfinite(c.thickness) && c.thickness > 0)) {
        return must_be(name + ".thickness", "> 0", "m", c.thickness);
      }
      if (!(std::isfinite(c.density) && c.density > 0)) {
        return must_be(name + ".density", "> 0", "kg/m^3", c.density);
      }
    }
  }
  std::set<std::pair<int, int>> seen;
  for (std::size_t i = 0; i < link_parameters.size(); ++i) {
    const LinkParameterVariable& v = link_parameters[i];
    const std::string name = "link_parameters[" + std::to_string(i) + "]";
    if (v.link < 1 || v.link > 3) {
      return name + ".link must be 1, 2 or 3, got " + std::to_string(v.link);
    }
    using P = LinkParameterVariable::Parameter;
    if (v.parameter != P::kMass && v.parameter != P::kE && v.parameter != P::kF &&
        v.parameter != P::kInertia) {
      return name + ".parameter must be mass, e, f or inertia";
    }
    const std::string what =
        name + " (" + core::link_name(v.link) + "." + parameter_name(v.parameter) + ")";
    if (!seen.insert({v.link, static_cast<int>(v.parameter)}).second) {
      return what + " appears twice";
    }
    const char* unit = parameter_unit(v.parameter);
    if (!std::isfinite(v.lower)) return must_be(what + ".lower", "finite", unit, v.lower);
    if (!std::isfinite(v.upper)) return must_be(what + ".upper", "finite", unit, v.upper);
    if (v.parameter == P::kMass && !(v.lower > 0)) {
      // the link keeps a mass (core needs m > 0 and the centre of mass m e / m is then defined)
      return must_be(what + ".lower", "> 0", unit, v.lower);
    }
    if (v.parameter == P::kInertia && !(v.lower >= 0)) {
      return must_be(what + ".lower", ">= 0", unit, v.lower);
    }
    if (!(v.upper >= v.lower)) {
      return what + ".upper must be >= lower = " + text::exact(v.lower) + " " + unit + ", got " +
             text::exact(v.upper);
    }
  }

  // objective and limits
  if (objective.empty()) return "objective: give at least one term";
  const bool free_scene = std::holds_alternative<core::FreeScene>(scene);
  bool positive = false;
  for (std::size_t i = 0; i < objective.size(); ++i) {
    const Term& t = objective[i];
    const std::string name = "objective[" + std::to_string(i) + "]";
    if (!metric_named(to_string(t.metric))) return name + ".metric is not a known metric";
    if (!(std::isfinite(t.weight) && t.weight >= 0)) {
      return must_be(name + ".weight (" + to_string(t.metric) + ")", ">= 0", "", t.weight);
    }
    positive = positive || t.weight > 0;
    if (t.weight > 0 && free_scene && is_torque(t.metric)) {
      return name + ": " + to_string(t.metric) + " is 0 in a free scene (no drive torque)";
    }
  }
  if (!positive) return "objective: at least one term needs a weight > 0, all are 0";
  if (objective_form != ObjectiveForm::kLinear && objective_form != ObjectiveForm::kSquared) {
    return "objective_form must be linear or squared";
  }
  if (!(smoothing > 0 && smoothing <= 0.1)) {
    return must_be("smoothing", "in (0, 0.1]", "", smoothing);
  }
  for (std::size_t i = 0; i < limits.size(); ++i) {
    const Limit& l = limits[i];
    const std::string name = "limits[" + std::to_string(i) + "]";
    if (!metric_named(to_string(l.metric))) return name + ".metric is not a known metric";
    if (free_scene && is_torque(l.metric)) {
      return name + ": " + to_string(l.metric) + " is 0 in a free scene (no drive torque)";
    }
    const std::string what = name + ".value (" + to_string(l.metric) + ")";
    if (l.metric == Metric::kAddedMass) {
      // kg; may be 0 or negative (redistribute or remove mass)
      if (!std::isfinite(l.value)) return must_be(what, "finite", "kg", l.value);
    } else if (!(std::isfinite(l.value) && l.value > 0)) {
      return must_be(what, "> 0 (a fraction of the original)", "", l.value);
    }
  }
  return "";
}

}  // namespace bd::optimize
