#include "optimize/problem.hpp"

#include <cmath>
#include <cstdio>
#include <set>
#include <utility>

#include "core/input_error.hpp"
#include "core/number_text.hpp"

namespace bd::optimize {

namespace {

// {field, "must be <expected> <unit>, got <value>"}
FieldError must_be(std::string field, const char* expected, const char* unit, double v) {
  return {std::move(field), -1,
          std::string("must be ") + expected + (unit[0] != '\0' ? " " : "") + unit + ", got " +
              text::exact(v)};
}

// the path of one field of element i of a list field, e.g. "counterweights[1].link"
std::string element(const char* list, std::size_t i, const char* field) {
  return std::string(list) + "[" + std::to_string(i) + "]." + field;
}

// {list, i, message}: element i of a list field as a whole
FieldError at(const char* list, std::size_t i, std::string message) {
  return {list, static_cast<int>(i), std::move(message)};
}

Problem check_scene(const core::FreeScene& s) {
  if (!(std::isfinite(s.duration) && s.duration > 0)) {
    return must_be("scene.duration", "> 0", "s", s.duration);
  }
  if (s.samples < 2) return must_be("scene.samples", ">= 2", "", s.samples);
  if (!std::isfinite(s.theta1)) return must_be("scene.theta1", "finite", "rad", s.theta1);
  if (!std::isfinite(s.omega1)) return must_be("scene.omega1", "finite", "rad/s", s.omega1);
  return std::nullopt;
}

Problem check_scene(const core::DrivenScene& s) {
  if (!(std::isfinite(s.omega1) && s.omega1 != 0)) {
    return must_be("scene.omega1", "finite and != 0", "rad/s", s.omega1);
  }
  if (s.revolutions < 1) return must_be("scene.revolutions", ">= 1", "", s.revolutions);
  if (s.samples < 1) return must_be("scene.samples", ">= 1", "", s.samples);
  if (!std::isfinite(s.theta1)) return must_be("scene.theta1", "finite", "rad", s.theta1);
  return std::nullopt;
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

core::MetricMask resolved_peak_rows(const DesignProblem& problem) {
  core::MetricMask rows{};
  if (!problem.resolve_peaks) return rows;
  for (const Term& t : problem.objective) {
    if (t.weight > 0 && is_peak(t.metric)) rows[static_cast<std::size_t>(t.metric)] = true;
  }
  for (const Limit& l : problem.limits) {
    if (is_peak(l.metric)) rows[static_cast<std::size_t>(l.metric)] = true;
  }
  return rows;
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
      return "kg m²";
  }
  return "";
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

// ---------------------------------------------------------------------------------------------
// validate(), part by part: each returns the first problem of its part

namespace {

Problem check_original_and_scene(const DesignProblem& p) {
  try {
    (void)core::make_fourbar(p.original);
  } catch (const InputError& e) {
    return FieldError{"original", -1, std::string("design: ") + e.what()};
  }
  if (Problem e = std::visit([](const auto& s) { return check_scene(s); }, p.scene)) return e;
  if (p.formulation != core::Formulation::kMassMatrix &&
      p.formulation != core::Formulation::kOpenedLoop &&
      p.formulation != core::Formulation::kComplexMasses) {
    return FieldError{"formulation", -1, "must be mass-matrix, opened-loop or complex-masses"};
  }
  if (std::holds_alternative<core::FreeScene>(p.scene) &&
      !(std::isfinite(p.tolerance) && p.tolerance > 0)) {
    return must_be("tolerance", "> 0", "", p.tolerance);
  }
  return std::nullopt;
}

Problem check_counterweights(const std::vector<CounterweightVariables>& counterweights) {
  int on_link[4] = {-1, -1, -1, -1};
  for (std::size_t i = 0; i < counterweights.size(); ++i) {
    const CounterweightVariables& c = counterweights[i];
    auto field = [i](const char* name) { return element("counterweights", i, name); };
    if (c.link != 1 && c.link != 3) {
      return FieldError{field("link"), -1,
                        "must be 1 (crank) or 3 (rocker), got " + std::to_string(c.link)};
    }
    if (on_link[c.link] >= 0) {
      return at("counterweights", i,
                std::string(": a second counterweight on the ") + core::link_name(c.link) +
                    " (counterweights[" + std::to_string(on_link[c.link]) +
                    "] is there already); at most one per link");
    }
    on_link[c.link] = static_cast<int>(i);
    if (!(std::isfinite(c.mass_max) && c.mass_max > 0)) {
      return must_be(field("mass_max"), "> 0", "kg", c.mass_max);
    }
    if (!(std::isfinite(c.distance_max) && c.distance_max > 0)) {
      return must_be(field("distance_max"), "> 0", "m", c.distance_max);
    }
    if (c.shape != balance::CounterweightShape::kPoint &&
        c.shape != balance::CounterweightShape::kDisc) {
      return FieldError{field("shape"), -1, "must be point or disc"};
    }
    if (c.shape == balance::CounterweightShape::kDisc) {
      if (!(std::isfinite(c.thickness) && c.thickness > 0)) {
        return must_be(field("thickness"), "> 0", "m", c.thickness);
      }
      if (!(std::isfinite(c.density) && c.density > 0)) {
        return must_be(field("density"), "> 0", "kg/m^3", c.density);
      }
    }
  }
  return std::nullopt;
}

// the bounds of link parameter i, named "(coupler.mass).lower" after the element
Problem check_bounds(const LinkParameterVariable& v, std::size_t i, const std::string& what) {
  using P = LinkParameterVariable::Parameter;
  const char* unit = parameter_unit(v.parameter);
  auto bound_must_be = [&](const char* bound, const char* expected, double value) {
    FieldError e = must_be("", expected, unit, value);
    return at("link_parameters", i, what + "." + bound + " " + e.message);
  };
  if (!std::isfinite(v.lower)) return bound_must_be("lower", "finite", v.lower);
  if (!std::isfinite(v.upper)) return bound_must_be("upper", "finite", v.upper);
  if (v.parameter == P::kMass && !(v.lower > 0)) {
    // the link keeps a mass (core needs m > 0 and the centre of mass m e / m is then defined)
    return bound_must_be("lower", "> 0", v.lower);
  }
  if (v.parameter == P::kInertia && !(v.lower >= 0)) {
    return bound_must_be("lower", ">= 0", v.lower);
  }
  if (!(v.upper >= v.lower)) {
    return at("link_parameters", i,
              what + ".upper must be >= lower = " + text::exact(v.lower) + " " + unit + ", got " +
                  text::exact(v.upper));
  }
  return std::nullopt;
}

Problem check_link_parameters(const std::vector<LinkParameterVariable>& link_parameters) {
  std::set<std::pair<int, int>> seen;
  for (std::size_t i = 0; i < link_parameters.size(); ++i) {
    const LinkParameterVariable& v = link_parameters[i];
    if (v.link < 1 || v.link > 3) {
      return FieldError{element("link_parameters", i, "link"), -1,
                        "must be 1, 2 or 3, got " + std::to_string(v.link)};
    }
    using P = LinkParameterVariable::Parameter;
    if (v.parameter != P::kMass && v.parameter != P::kE && v.parameter != P::kF &&
        v.parameter != P::kInertia) {
      return FieldError{element("link_parameters", i, "parameter"), -1,
                        "must be mass, e, f or inertia"};
    }
    // "(coupler.mass)": the element's message reads on from "link_parameters[i]"
    const std::string what =
        std::string("(") + core::link_name(v.link) + "." + parameter_name(v.parameter) + ")";
    if (!seen.insert({v.link, static_cast<int>(v.parameter)}).second) {
      return at("link_parameters", i, what + " appears twice");
    }
    if (Problem e = check_bounds(v, i, what)) return e;
  }
  return std::nullopt;
}

// the error with the metric it is about before its message: "(tau_max) must be > 0 ..."
FieldError noting(Metric m, FieldError e) {
  e.message = std::string("(") + to_string(m) + ") " + e.message;
  return e;
}

// ": tau_rms is 0 in a free scene (no drive torque)" for element i of `list`
FieldError no_torque(const char* list, std::size_t i, Metric m) {
  return at(list, i, std::string(": ") + to_string(m) + " is 0 in a free scene (no drive torque)");
}

Problem check_objective(const DesignProblem& p) {
  if (p.objective.empty()) return FieldError{"objective", -1, ": give at least one term"};
  const bool free_scene = std::holds_alternative<core::FreeScene>(p.scene);
  bool positive = false;
  for (std::size_t i = 0; i < p.objective.size(); ++i) {
    const Term& t = p.objective[i];
    if (!metric_named(to_string(t.metric))) {
      return FieldError{element("objective", i, "metric"), -1, "is not a known metric"};
    }
    if (!(std::isfinite(t.weight) && t.weight >= 0)) {
      return noting(t.metric, must_be(element("objective", i, "weight"), ">= 0", "", t.weight));
    }
    positive = positive || t.weight > 0;
    if (t.weight > 0 && free_scene && is_torque(t.metric))
      return no_torque("objective", i, t.metric);
  }
  if (!positive) {
    return FieldError{"objective", -1, ": at least one term needs a weight > 0, all are 0"};
  }
  if (p.objective_form != ObjectiveForm::kLinear && p.objective_form != ObjectiveForm::kSquared) {
    return FieldError{"objective_form", -1, "must be linear or squared"};
  }
  if (!(p.smoothing > 0 && p.smoothing <= 0.1)) {
    return must_be("smoothing", "in (0, 0.1]", "", p.smoothing);
  }
  return std::nullopt;
}

Problem check_limits(const DesignProblem& p) {
  const bool free_scene = std::holds_alternative<core::FreeScene>(p.scene);
  for (std::size_t i = 0; i < p.limits.size(); ++i) {
    const Limit& l = p.limits[i];
    if (!metric_named(to_string(l.metric))) {
      return FieldError{element("limits", i, "metric"), -1, "is not a known metric"};
    }
    if (free_scene && is_torque(l.metric)) return no_torque("limits", i, l.metric);
    const std::string value = element("limits", i, "value");
    if (l.metric == Metric::kAddedMass) {
      // kg; may be 0 or negative (redistribute or remove mass)
      if (!std::isfinite(l.value)) return noting(l.metric, must_be(value, "finite", "kg", l.value));
    } else if (!(std::isfinite(l.value) && l.value > 0)) {
      return noting(l.metric, must_be(value, "> 0 (a fraction of the original)", "", l.value));
    }
  }
  return std::nullopt;
}

}  // namespace

Problem DesignProblem::validate() const {
  if (Problem e = check_original_and_scene(*this)) return e;
  for (std::size_t i = 0; i < peak_angles.size(); ++i) {
    if (!std::holds_alternative<core::DrivenScene>(scene)) {
      return FieldError{"peak_angles", static_cast<int>(i),
                        ": crank angles for the peaks are for driven scenes only"};
    }
    if (!std::isfinite(peak_angles[i])) {
      return FieldError{"peak_angles", static_cast<int>(i),
                        "must be finite rad, got " + text::digits(peak_angles[i], 6)};
    }
  }
  if (counterweights.empty() && link_parameters.empty()) {
    return FieldError{"", -1,
                      "no design variables: give at least one counterweight or link parameter"};
  }
  if (Problem e = check_counterweights(counterweights)) return e;
  if (Problem e = check_link_parameters(link_parameters)) return e;
  if (Problem e = check_objective(*this)) return e;
  return check_limits(*this);
}

}  // namespace bd::optimize
