// The core at one instant (kinematics, inverse and forward dynamics, principal vectors) and the
// balance and optimise steps on their own, as methods of balance_design.Study.
#include <pybind11/stl.h>

#include <optional>
#include <string>
#include <vector>

#include "balance/conditions.hpp"
#include "bindings.hpp"
#include "core/fourbar/dynamics.hpp"
#include "core/fourbar/kinematics.hpp"
#include "core/fourbar/principal_vectors.hpp"
#include "core/planar/dynamics.hpp"
#include "core/planar/simulate.hpp"
#include "optimize/nlp.hpp"
#include "optimize/optimize.hpp"
#include "optimize/planar.hpp"
#include "studies/run/runner.hpp"

namespace bd::python {

namespace {

using namespace pybind11::literals;
using studies::Study;
using StudyRef = std::shared_ptr<Study>;

py::array_t<double> vec(const Vec2& v) {
  py::array_t<double> out(2);
  out.mutable_data()[0] = v.x();
  out.mutable_data()[1] = v.y();
  return out;
}

// a position, rate, ... given as one number or one per input of a planar linkage
std::vector<double> per_input(const py::object& value, std::size_t inputs, const char* what) {
  std::vector<double> out;
  if (py::hasattr(value, "__len__")) {  // a list, tuple or NumPy array
    out = value.cast<std::vector<double>>();
  } else {
    out.push_back(value.cast<double>());
  }
  if (out.size() != inputs) {
    throw InputError(std::string(what) + ": " + std::to_string(inputs) +
                     " value(s) expected, one per input of the linkage, got " +
                     std::to_string(out.size()));
  }
  return out;
}

// the four-bar formulation a method names ('auto' takes mass-matrix)
core::Formulation formulation(const std::string& method) {
  if (method == "auto") return core::Formulation::kMassMatrix;
  const std::optional<studies::Method> m = studies::method_named(method);
  const std::optional<core::Formulation> f = m ? studies::formulation_of(*m) : std::nullopt;
  if (!f) {
    throw InputError(
        "method must be auto, mass-matrix, opened-loop or complex-masses at one "
        "instant of a four-bar, got '" +
        method + "'");
  }
  return *f;
}

// a four-bar's instant as a dict with timeseries.csv's names (t left out)
py::dict fourbar_instant(const Expected<core::DynamicsSample, core::DynamicsError>& s) {
  if (!s) throw DynamicsFailure(s.error().what());
  core::Trajectory one;
  one.t = {0.0};
  one.samples = {*s};
  py::dict row;
  const core::Series table = studies::timeseries_table(one);
  for (std::size_t k = 1; k < table.width(); ++k) row[py::str(table.columns[k])] = table.at(0, k);
  return row;
}

// a planar linkage's instant as a dict with its timeseries.csv names (t left out)
py::dict planar_instant(const core::planar::Model& model, const core::planar::Instant& in) {
  core::Series table;
  table.columns = core::planar::columns(model);
  core::planar::append_row(model, in, table);
  py::dict row;
  for (std::size_t k = 1; k < table.width(); ++k) row[py::str(table.columns[k])] = table.at(0, k);
  return row;
}

void check(const Expected<bool, core::planar::PlanarError>& r) {
  if (!r) throw DynamicsFailure(r.error().detail);
}

// a planar linkage assembled at the inputs' positions, ready for the dynamics
struct Planar {
  core::planar::Model model;
  core::planar::Workspace ws;
  std::vector<double> positions;
  Planar(const Study& s, const py::object& position)
      : model(s.planar()),
        ws(model),
        positions(per_input(position, static_cast<std::size_t>(model.inputs()), "position")) {
    check(core::planar::assemble(model, ws, positions));
  }
  std::size_t inputs() const { return static_cast<std::size_t>(model.inputs()); }
};

const core::FourBar& fourbar_of(const Study& s, const char* what) {
  if (!s.is_fourbar())
    throw InputError(std::string(what) + " is a four-bar's (linkage type fourbar)");
  return s.fourbar();
}

py::dict kinematics(const Study& s, const py::object& position, const py::object& rate,
                    const py::object& acceleration) {
  if (!s.is_fourbar()) {
    Planar p(s, position);
    check(core::planar::inverse_dynamics(p.model, p.ws, 0.0, per_input(rate, p.inputs(), "rate"),
                                         per_input(acceleration, p.inputs(), "acceleration")));
    py::dict all = planar_instant(p.model, p.ws.instant), out;
    for (auto [key, value] : all) {
      const std::string name = key.cast<std::string>();
      for (const char* prefix : {"theta_", "omega_", "alpha_", "s_", "v_", "a_", "x_", "y_"}) {
        if (name.rfind(prefix, 0) == 0) out[key] = value;
      }
    }
    return out;
  }
  const core::FourBar& m = s.fourbar();
  const double theta1 = position.cast<double>();
  const auto pose = core::solve_position(m, theta1);
  if (!pose) throw DynamicsFailure(pose.error().what());
  const core::FourBarState st = core::solve_acceleration(
      m, core::solve_velocity(m, *pose, rate.cast<double>()), acceleration.cast<double>());
  const core::Joints j = core::joint_positions(m, *pose);
  py::dict out;
  const double values[] = {st.theta1, st.theta2, st.theta3, st.omega1, st.omega2,
                           st.omega3, st.alpha1, st.alpha2, st.alpha3};
  const char* names[] = {"theta1", "theta2", "theta3", "omega1", "omega2",
                         "omega3", "alpha1", "alpha2", "alpha3"};
  for (std::size_t k = 0; k < std::size(values); ++k) out[names[k]] = values[k];
  out["A0"] = vec(j.A0);
  out["A1"] = vec(j.A1);
  out["A2"] = vec(j.A2);
  out["A3"] = vec(j.A3);
  for (int k = 1; k <= 3; ++k) {
    const std::string n = std::to_string(k);
    out[py::str("G" + n)] = vec(core::centre_of_mass(m, k, *pose));
    out[py::str("G" + n + "_velocity")] = vec(core::centre_of_mass_velocity(m, k, st));
    out[py::str("G" + n + "_acceleration")] = vec(core::centre_of_mass_acceleration(m, k, st));
  }
  out["transmission_angle"] = core::transmission_angle(*pose);
  return out;
}

py::dict principal_vectors(const Study& s, double theta1) {
  const core::FourBar& m = fourbar_of(s, "principal_vectors");
  const auto pose = core::solve_position(m, theta1);
  if (!pose) throw DynamicsFailure(pose.error().what());
  const core::OpenedLoopVectors a = core::opened_loop_vectors(m, *pose);
  const core::FrameVectors b = core::frame_vectors(m, *pose);
  const core::PrincipalPoints p = core::opened_loop_principal_points(m, *pose);
  const core::FramePrincipalPoints q = core::frame_principal_points(m, *pose);
  py::dict opened, frame;
  opened["a12"] = vec(a.a12);
  opened["a21"] = vec(a.a21);
  opened["a23"] = vec(a.a23);
  opened["a32"] = vec(a.a32);
  opened["a14p"] = vec(a.a14p);
  opened["a34p"] = vec(a.a34p);
  opened["P1"] = vec(p.P1);
  opened["P2"] = vec(p.P2);
  opened["P3"] = vec(p.P3);
  frame["a14"] = vec(b.a14);
  frame["a41"] = vec(b.a41);
  frame["a43"] = vec(b.a43);
  frame["a34"] = vec(b.a34);
  frame["a12p"] = vec(b.a12p);
  frame["a32p"] = vec(b.a32p);
  frame["P1"] = vec(q.P1);
  frame["P3"] = vec(q.P3);
  frame["P4"] = vec(q.P4);
  py::dict out;
  out["opened_loop"] = opened;
  out["frame"] = frame;
  return out;
}

py::list conditions(const std::vector<balance::Condition>& list) {
  py::list out;
  for (const balance::Condition& c : list) {
    out.append(py::dict("name"_a = c.name, "meaning"_a = c.meaning, "residual"_a = c.residual,
                        "scale"_a = c.scale, "unit"_a = c.unit, "holds"_a = c.holds));
  }
  return out;
}

py::dict balance_report(const balance::BalanceReport& r) {
  py::dict out;
  out["force"] = conditions(r.force);
  out["moment"] = conditions(r.moment);
  out["force_balanced"] = r.force_balanced();
  out["moment_balanced"] = r.moment_balanced();
  return out;
}

py::object counterweight(const std::optional<balance::Counterweight>& c) {
  if (!c) return py::none();
  return py::dict("mass"_a = c->mass, "position"_a = vec(c->position), "distance"_a = c->distance,
                  "radius"_a = c->radius, "thickness"_a = c->thickness, "inertia"_a = c->inertia);
}

py::dict balanced_design(const StudyRef& s) {
  fourbar_of(*s,
             "balanced_design (a planar linkage's comes from its motion: Study.run(), "
             "Result.balanced)");
  if (!s->balance) throw InputError(s->name + ": the study has no balance section");
  const balance::BalancedDesign& b = *s->balance;
  py::dict out;
  out["crank_counterweight"] = counterweight(b.crank_counterweight);
  out["rocker_counterweight"] = counterweight(b.rocker_counterweight);
  out["added_mass"] = b.added_mass;
  out["added_inertia"] = b.added_inertia;
  out["conditions"] = balance_report(b.conditions);
  out["study"] = std::make_shared<Study>(studies::balanced_study(*s));
  return out;
}

template <class Result>
py::dict solver_dict(const Result& r, const std::vector<std::string>& names) {
  py::dict out, vars;
  out["algorithm"] = optimize::to_string(r.algorithm);
  out["termination"] = optimize::to_string(r.termination);
  out["message"] = r.message;
  out["found"] = optimize::found_design(r.termination);
  out["objective"] = r.objective;
  out["constraint_violation"] = r.constraint_violation;
  out["iterations"] = r.iterations;
  out["evaluations"] = r.evaluations;
  out["verification_error"] = r.verification_error;
  out["report"] = optimize::solver_report(r);
  for (std::size_t i = 0; i < names.size() && i < static_cast<std::size_t>(r.x.size()); ++i) {
    vars[py::str(names[i])] = r.x[static_cast<Eigen::Index>(i)];
  }
  out["variables"] = vars;
  return out;
}

py::dict optimize_step(const StudyRef& s) {
  if (!s->optimizes()) throw InputError(s->name + ": the study has no optimize section");
  if (s->is_fourbar()) {
    optimize::OptimizeResult r;
    std::vector<std::string> names;
    {
      py::gil_scoped_release unlocked;
      const optimize::DesignProblem problem = studies::design_problem(*s);
      r = optimize::optimize(problem, s->optimize->options);
      names = optimize::Nlp(problem).variable_names();
    }
    py::dict out = solver_dict(r, names);
    out["study"] = r.ok()
                       ? py::cast(std::make_shared<Study>(studies::optimized_study(*s, r.design)))
                       : py::object(py::none());
    return out;
  }
  optimize::planar::Result r;
  {
    py::gil_scoped_release unlocked;
    r = optimize::planar::optimize(studies::planar_design_problem(*s), s->planar_optimize->options);
  }
  py::dict out = solver_dict(r, r.variable_names);
  out["added_mass"] = r.added_mass;
  out["study"] =
      optimize::found_design(r.termination)
          ? py::cast(std::make_shared<Study>(studies::planar_optimized_study(*s, r.design)))
          : py::object(py::none());
  return out;
}

}  // namespace

void bind_instant(py::module_&, py::class_<Study, std::shared_ptr<Study>>& cls) {
  cls.def("kinematics", &kinematics, py::arg("position"), py::arg("rate") = 0.0,
          py::arg("acceleration") = 0.0,
          "Positions, rates and accelerations at one instant.\n\n"
          "Four-bar: position, rate, acceleration are the crank's theta1 [rad], omega1 [rad/s], "
          "alpha1 [rad/s^2]; returns theta1..alpha3, the joints A0..A3 and centres of mass "
          "G1..G3 with their velocities and accelerations ([x, y] arrays), and the "
          "transmission angle.\n"
          "Planar linkage: one value per input (a number for a single input); returns "
          "timeseries.csv's kinematic columns (theta_<link>, ..., x_<node>, y_<node>).\n"
          "Raises DynamicsError where the linkage cannot assemble.")
      .def(
          "inverse_dynamics",
          [](const Study& s, const py::object& position, const py::object& rate,
             const py::object& acceleration, const std::string& method) {
            if (s.is_fourbar()) {
              return fourbar_instant(
                  core::inverse_dynamics(s.fourbar(), position.cast<double>(), rate.cast<double>(),
                                         acceleration.cast<double>(), formulation(method)));
            }
            Planar p(s, position);
            check(core::planar::inverse_dynamics(
                p.model, p.ws, 0.0, per_input(rate, p.inputs(), "rate"),
                per_input(acceleration, p.inputs(), "acceleration")));
            return planar_instant(p.model, p.ws.instant);
          },
          py::arg("position"), py::arg("rate"), py::arg("acceleration") = 0.0,
          py::arg("method") = "auto",
          "Inverse dynamics at one instant: the drive efforts that give the inputs' "
          "accelerations, with every reaction, joint force and the shaking force and moment.\n\n"
          "Returns a dict named as timeseries.csv's columns (without t): a four-bar's theta1, "
          "..., RA0x, ..., Fshx, Fshy, Msh, tau. Four-bar: method is auto (mass-matrix), "
          "mass-matrix, opened-loop or complex-masses. Planar linkage: one value per input.\n"
          "Raises DynamicsError at a dead centre or where the linkage cannot assemble.")
      .def(
          "forward_dynamics",
          [](const Study& s, const py::object& position, const py::object& rate,
             const py::object& efforts, double t, const std::string& method) {
            if (s.is_fourbar()) {
              return fourbar_instant(core::forward_dynamics(
                  s.fourbar(), position.cast<double>(), rate.cast<double>(), formulation(method)));
            }
            Planar p(s, position);
            const std::vector<double> e = efforts.is_none()
                                              ? core::planar::efforts_at(p.model, t)
                                              : per_input(efforts, p.inputs(), "efforts");
            check(core::planar::forward_dynamics(p.model, p.ws, t,
                                                 per_input(rate, p.inputs(), "rate"), e));
            return planar_instant(p.model, p.ws.instant);
          },
          py::arg("position"), py::arg("rate"), py::arg("efforts") = py::none(), py::arg("t") = 0.0,
          py::arg("method") = "auto",
          "Forward dynamics at one instant: the accelerations under the applied loads and "
          "everything else, as inverse_dynamics() returns it.\n\n"
          "Four-bar: free motion (tau = 0) at theta1, omega1. Planar linkage: the inputs' "
          "efforts (drive torque or force, one per input; default: the study's drives at time "
          "t).")
      .def("principal_vectors", &principal_vectors, py::arg("theta1"),
           "A four-bar's principal vectors at crank angle theta1 [rad] (paper eqs. 12-13 and "
           "30-31): {'opened_loop': a12, a21, a23, a32, a14p, a34p and principal points P1..P3; "
           "'frame': a14, a41, a43, a34, a12p, a32p and P1, P3, P4}, each an [x, y] array in "
           "ground axes [m].")
      .def(
          "check_balance",
          [](const Study& s, double tolerance) {
            return balance_report(
                balance::check_balance(fourbar_of(s, "check_balance"), tolerance));
          },
          py::arg("relative_tolerance") = 1e-12,
          "The balance conditions of a four-bar's linkage (force: paper eq. 57; moment: "
          "Berkof's): {'force': [...], 'moment': [...], 'force_balanced', 'moment_balanced'}, "
          "each condition a dict name, meaning, residual, scale, unit, holds.")
      .def("balanced_design", &balanced_design,
           "A four-bar's balance step alone: the design its balance section synthesises "
           "(counterweights on crank and rocker, added mass and inertia, its balance "
           "conditions) and that design as a Study ('study'), without simulating either.")
      .def("optimize", &optimize_step,
           "The optimise step alone: solves the study's optimize section (NLopt or Ipopt) and "
           "returns the solver's end (algorithm, termination, message, found, objective, "
           "constraint_violation, iterations, evaluations, verification_error, report), the "
           "variables by name and the optimum as a Study ('study', None when no design was "
           "found); nothing is simulated beyond what the solver does. Releases the GIL.");
}

}  // namespace bd::python
