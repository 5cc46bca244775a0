#include "core/planar/simulate.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <utility>

#include "core/detail/sensitivity.hpp"
#include "core/input_error.hpp"
#include "core/integrators.hpp"
#include "core/number_text.hpp"
#include "core/peaks.hpp"
#include "core/planar/blocks.hpp"
#include "core/planar/system.hpp"

namespace bd::core::planar {

using detail::NodeVectors;
using detail::System;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

constexpr double kTwoPi = 6.28318530717958647692;
constexpr long long kMaxSamples = 100'000'000;

const char* unit_of(const Input& in) { return in.kind == Input::Kind::kAngle ? "rad" : "m"; }

std::string state_text(const Model& model, double t, const std::vector<double>& z) {
  std::string s = "t = " + text::digits(t, 10) + " s";
  for (std::size_t k = 0; k < z.size(); ++k) {
    const Input& in = model.linkage().inputs[k];
    s += ", " + in.name + " = " + text::digits(z[k], 10) + " " + unit_of(in);
  }
  return s;
}

SimulationStatus status_of(const PlanarError& e) {
  switch (e.kind) {
    case PlanarError::Kind::kAssembly:
      return SimulationStatus::kAssemblyFailed;
    case PlanarError::Kind::kSingular:
      return SimulationStatus::kSingular;
    case PlanarError::Kind::kMobility:
    case PlanarError::Kind::kNonFinite:
      break;
  }
  return SimulationStatus::kIntegratorFailed;
}

void fail(Trajectory& out, const PlanarError& e, double t) {
  out.status = status_of(e);
  out.message = e.detail + " (t = " + text::digits(t, 10) + " s)";
}

// checks the scene's counts against the model and assembles the start; ws then holds it
std::vector<double> start_of(const Model& model, Workspace& ws, const std::vector<double>& start,
                             const char* scene) {
  const int dof = model.inputs();
  if (const int m = mobility(model); m != dof) {
    throw InputError(FieldError{"linkage.inputs", -1,
                                ": the linkage has " + std::to_string(m) + " degree" +
                                    (m == 1 ? "" : "s") + " of freedom and " + std::to_string(dof) +
                                    " input" + (dof == 1 ? "" : "s") +
                                    "; give one input per degree of freedom"});
  }
  std::vector<double> z = start.empty() ? drawn_inputs(model) : start;
  if (static_cast<int>(z.size()) != dof) {
    throw InputError(FieldError{std::string(scene) + ".start", -1,
                                "must give " + std::to_string(dof) +
                                    " values (one per input), got " + std::to_string(z.size())});
  }
  for (double v : z) {
    if (!std::isfinite(v))
      throw InputError(FieldError{std::string(scene) + ".start", -1, "must be finite"});
  }
  if (auto ok = assemble(model, ws, z); !ok) {
    throw InputError(FieldError{std::string(scene) + ".start", -1,
                                ": " + ok.error().detail + " (the start of the scene)"});
  }
  return z;
}

void check_count(const std::vector<double>& v, int dof, const char* field, const char* meaning) {
  if (static_cast<int>(v.size()) != dof) {
    throw InputError(FieldError{field, -1,
                                "must give " + std::to_string(dof) + " " + meaning +
                                    " (one per input), got " + std::to_string(v.size())});
  }
  for (double x : v) {
    if (!std::isfinite(x)) throw InputError(FieldError{field, -1, "must be finite"});
  }
}

}  // namespace

const char* to_string(Route r) { return r == Route::kDae ? "dae" : "reduced"; }

// ---------------------------------------------------------------------------------------------
// the table

std::vector<std::string> columns(const Model& model) {
  const Linkage& l = model.linkage();
  std::vector<std::string> c = {"t"};
  for (const Link& link : l.links) {
    for (const char* p : {"theta_", "omega_", "alpha_"}) c.push_back(p + link.name);
  }
  for (const Slider& s : l.sliders) {
    for (const char* p : {"s_", "v_", "a_"}) c.push_back(p + s.name);
  }
  for (const Node& n : l.nodes) {
    if (n.ground) continue;
    c.push_back("x_" + n.name);
    c.push_back("y_" + n.name);
  }
  auto pair = [&](const std::string& name) {
    c.push_back(name + "x");
    c.push_back(name + "y");
  };
  for (int g : model.ground_nodes()) pair("R" + l.nodes[static_cast<std::size_t>(g)].name);
  for (int s : model.frame_guides()) pair("R" + l.sliders[static_cast<std::size_t>(s)].name);
  for (const BalanceShaft& b : l.shafts) pair("R" + b.name);
  for (int k : model.frame_springs()) {
    const Spring& sp = l.springs[static_cast<std::size_t>(k)];
    const int anchor = l.nodes[static_cast<std::size_t>(sp.a)].ground ? sp.a : sp.b;
    pair("R" + l.nodes[static_cast<std::size_t>(anchor)].name + "_" + sp.name);
  }
  for (int k : model.frame_drives()) {
    const Input& in = l.inputs[static_cast<std::size_t>(k)];
    pair("R" + l.sliders[static_cast<std::size_t>(in.slider)].name + "_drive");
  }
  for (const JointForce& j : model.joints()) pair("F" + j.name);
  for (int k : model.link_guides())
    pair("F" + l.sliders[static_cast<std::size_t>(k)].name + "_guide");
  c.insert(c.end(), {"Fshx", "Fshy", "Msh"});
  if (l.inputs.size() == 1) {
    c.push_back("tau");
  } else {
    for (const Input& in : l.inputs) c.push_back("tau_" + in.name);
  }
  c.insert(c.end(), {"Fshx_inertial", "Fshy_inertial", "Msh_inertial", "Fshx_static",
                     "Fshy_static", "Msh_static"});
  return c;
}

void append_row(const Model& model, const Instant& in, Series& table) {
  const Linkage& l = model.linkage();
  const System& s = model.system();
  std::vector<double>& v = table.values;
  // the row's width (columns() names every value below), then every value written in place (a
  // vector's insert per value costs more than the values)
  const std::size_t width = table.width();
  const std::size_t start = v.size();
  v.resize(start + width);
  double* o = v.data() + start;
  auto put = [&o](double value) { *o++ = value; };
  auto put2 = [&o](const Vec2& value) {
    *o++ = value.x();
    *o++ = value.y();
  };
  put(in.t);
  for (std::size_t k = 0; k < l.links.size(); ++k) {
    put(in.angle[k]);
    put(in.omega[k]);
    put(in.alpha[k]);
  }
  for (std::size_t k = 0; k < l.sliders.size(); ++k) {
    put(in.slide[k]);
    put(in.slide_rate[k]);
    put(in.slide_acceleration[k]);
  }
  for (int i : s.moving) put2(in.x[static_cast<std::size_t>(i)]);
  for (const Vec2& r : in.ground_reaction) put2(r);
  for (const Vec2& r : in.guide_reaction) put2(r);
  for (const Vec2& r : in.shaft_reaction) put2(r);
  for (const Vec2& r : in.spring_reaction) put2(r);
  for (const Vec2& r : in.drive_reaction) put2(r);
  for (const Vec2& f : in.joint_force) put2(f);
  for (const Vec2& f : in.guide_force) put2(f);
  put2(in.Fsh);
  put(in.Msh);
  for (double e : in.effort) put(e);
  put2(in.Fsh_inertial);
  put(in.Msh_inertial);
  put2(in.Fsh_static);
  put(in.Msh_static);
  assert(o == v.data() + start + width);
}

// ---------------------------------------------------------------------------------------------
// driven

namespace {

// A driven scene's sample times: turns of the first angle input that moves, or the duration.
struct DrivenTimes {
  bool by_duration{};
  double period{};  // of one turn [s]
  double duration{};
  int samples{};  // per turn, or in all
  long long rows{};
  double at(long long i) const {
    return by_duration ? duration * static_cast<double>(i) / static_cast<double>(rows - 1)
                       : period * static_cast<double>(i) / samples;
  }
};

DrivenTimes driven_times(const Model& model, const DrivenScene& scene) {
  check_count(scene.speeds, model.inputs(), "scene.speeds", "speeds");
  if (scene.samples < 1) {
    throw InputError(
        FieldError{"scene.samples", -1, "must be >= 1, got " + std::to_string(scene.samples)});
  }
  DrivenTimes d;
  for (std::size_t k = 0; k < model.linkage().inputs.size(); ++k) {
    if (model.linkage().inputs[k].kind == Input::Kind::kAngle && scene.speeds[k] != 0) {
      d.period = kTwoPi / std::abs(scene.speeds[k]);
      break;
    }
  }
  d.by_duration = scene.duration > 0;
  d.duration = scene.duration;
  d.samples = scene.samples;
  if (!d.by_duration && !(d.period > 0)) {
    throw InputError(FieldError{"scene.duration", -1,
                                ": the scene needs a duration (no angle input turns, so there are "
                                "no revolutions to count)"});
  }
  if (!d.by_duration && scene.revolutions < 1) {
    throw InputError(FieldError{"scene.revolutions", -1, "must be >= 1"});
  }
  d.rows =
      d.by_duration ? scene.samples : static_cast<long long>(scene.samples) * scene.revolutions;
  if (d.rows > kMaxSamples || (d.by_duration && d.rows < 2)) {
    throw InputError(FieldError{"scene.samples", -1, "must be between 2 and 1e8 in all"});
  }
  return d;
}

// A limit position a driven sweep steps over. A dyad's or guide's closure margin (the square of
// its node's distance from the line dividing its branches, detail::place_by_blocks()) is 0 where
// the linkage stops turning; a linkage a hair short of turning fully does not close over an input
// range narrower than the samples' step, which the blocks' closed forms, holding each branch, step
// across. With the margins of `block` at three consecutive samples (inputs za, zm, zb at times
// ta, tm, tb) whose middle one is the least, and the parabola through them dipping well below it
// (a minimum near 0 between the samples; a minimum of the margin well above 0 lies within the
// samples' spread, so the parabola stays near them), the least margin over [ta, tb] is found by
// resolved_peak() on the placed positions. Returns the time where the linkage does not close, if
// any.
std::optional<double> limit_between(const Model& model, const Workspace& ws, std::size_t block,
                                    const std::array<double, 3>& t,
                                    const std::array<double, 3>& margin,
                                    const std::vector<double>& za, const std::vector<double>& zb) {
  const double b = (margin[2] - margin[0]) / 2, c = (margin[0] + margin[2]) / 2 - margin[1];
  if (!(c > 0) || !(margin[1] - b * b / (4 * c) < 0.5 * margin[1])) return std::nullopt;
  Workspace probe = ws;
  std::vector<double> z(za.size());
  const QuantityAt negative_margin = [&](double at) {
    const double s = (at - t[0]) / (t[2] - t[0]);
    for (std::size_t k = 0; k < z.size(); ++k) z[k] = za[k] + s * (zb[k] - za[k]);
    probe.block_margin[block] = std::numeric_limits<double>::quiet_NaN();
    detail::place_by_blocks(model, probe, probe.instant.x, z);  // the margin, placed or not
    return -probe.block_margin[block];
  };
  const std::array<double, 3> x = {-margin[0], -margin[1], -margin[2]};
  const Peak least = resolved_peak(t, x, 0.0, negative_margin);
  if (!(least.value > 0)) return std::nullopt;
  return least.t;
}

}  // namespace

Trajectory simulate_driven(const Model& model, const DrivenScene& scene) {
  const int dof = model.inputs();
  const DrivenTimes times = driven_times(model, scene);
  const long long rows = times.rows;
  Workspace ws(model);
  const std::vector<double> start = start_of(model, ws, scene.start, "scene");

  Trajectory out;
  out.table.columns = columns(model);
  out.table.values.reserve(static_cast<std::size_t>(rows) * out.table.width());
  const std::vector<double> zero(static_cast<std::size_t>(dof), 0.0);
  std::vector<double> z(static_cast<std::size_t>(dof));
  // the last two samples' positions, velocities and accelerations
  std::vector<Vec2> guess = ws.instant.x, previous = ws.instant.x, v_previous = ws.instant.v,
                    a_previous = ws.instant.a;
  std::vector<double> z_previous = start, z_step(z.size());
  const System& system = model.system();
  // the sign of the constraints' and inputs' determinant tells the assembly branch: it changes
  // only through a singular position, where the branches meet
  auto branch = [&ws]() { return ws.lu.determinant() < 0 ? -1 : 1; };
  const int drawn_branch = branch();
  // the positions block by block where the linkage allows (core/planar/blocks.hpp): closed forms
  // for its dyads, cranks, guides and further nodes need no guess; the general route below takes
  // any sample they cannot answer to round-off (a dead centre near)
  detail::prime_blocks(model, ws);
  const bool closed = system.blocks.usable && system.blocks.closed;
  // the dyads' and guides' closure margins at the last two samples the blocks placed (`older`
  // at t_2, `last` at t_prev), how many samples in a row they placed, for limit_between()
  std::vector<std::size_t> closing;
  for (std::size_t k = 0; k < system.blocks.blocks.size(); ++k) {
    const detail::Block::Kind kind = system.blocks.blocks[k].kind;
    if (kind == detail::Block::Kind::kDyad || kind == detail::Block::Kind::kGuide)
      closing.push_back(k);
  }
  std::vector<double> older(closing.size()), last(closing.size());
  int placed_in_a_row = 0;
  double t_2 = 0;
  const auto inputs_at = [&](double at) {
    std::vector<double> z_at(z.size());
    for (std::size_t j = 0; j < z.size(); ++j) z_at[j] = start[j] + scene.speeds[j] * at;
    return z_at;
  };
  // A limit position between the last three samples the blocks placed, from their margins
  // (limit_between()): where, and the run's failure there. `placed`: how the sample at t (inputs
  // z_now, the one before at t_before) was placed; every closed form placed (well conditioned
  // or not): the margins are the sample's.
  struct Limit {
    double at;
    std::size_t node;
    std::vector<double> before, after;  // the inputs at the samples around it
    // the run's failure there, `shown` the inputs it names
    PlanarError error(const Model& m, const std::vector<double>& shown) const {
      return {PlanarError::Kind::kAssembly,
              "the linkage cannot be assembled at " + detail::inputs_text(m, shown) + ": node " +
                  m.linkage().nodes[node].name +
                  " is out of its links' reach there (a limit position between the samples at " +
                  detail::inputs_text(m, before) + " and " + detail::inputs_text(m, after) +
                  ": the input cannot turn through it)"};
    }
  };
  const auto limit_at = [&](detail::Placement placed, double t, double t_before,
                            const std::vector<double>& z_now) -> std::optional<Limit> {
    if (placed == detail::Placement::kDeclined) {
      placed_in_a_row = 0;
      return std::nullopt;
    }
    ++placed_in_a_row;
    for (std::size_t j = 0; j < closing.size(); ++j) {
      const std::array<double, 3> m = {older[j], last[j], ws.block_margin[closing[j]]};
      older[j] = m[1];
      last[j] = m[2];
      if (placed_in_a_row < 3 || m[1] > m[0] || m[1] > m[2]) continue;  // no minimum near
      const std::vector<double> z_2 = inputs_at(t_2);
      const std::optional<double> at =
          limit_between(model, ws, closing[j], {t_2, t_before, t}, m, z_2, z_now);
      if (!at) continue;
      return Limit{*at, static_cast<std::size_t>(system.blocks.blocks[closing[j]].node), z_2,
                   z_now};
    }
    t_2 = t_before;
    return std::nullopt;
  };
  double t_prev = 0;
  for (long long i = 0; i < rows; ++i) {
    const double t = times.at(i);
    for (std::size_t k = 0; k < z.size(); ++k) z[k] = start[k] + scene.speeds[k] * t;
    const double h = t - t_prev;
    // The guess: from the second sample on, the quintic through the last two samples' positions,
    // velocities and accelerations (Hermite), extrapolated one step (the samples are evenly
    // spaced): its error is h⁶ x⁽⁶⁾ / 90, so that at 360 samples per turn the chord method
    // closes in two or three steps (2.3 on average over the paper four-bar's revolution, against
    // 6 from the third-order Taylor guess). The second sample continues the first to second
    // order. A plan of closed forms reads no guess.
    if (i > 0) {
      const Instant& at = ws.instant;
      if (i == 1 && !closed) {
        for (int n : system.moving) {
          const std::size_t k = static_cast<std::size_t>(n);
          guess[k] = at.x[k] + h * (at.v[k] + h / 2 * at.a[k]);
        }
      } else if (!closed) {
        // p(1) = 32 p0 - 31 p1 - 16 p0' - 14 p1' + 4 p0'' - 2 p1'' in the step s = (t - t0)/h,
        // p' = h v, p'' = h² a (index 0 the last sample, 1 the one before), written as
        // p0 + 31 (p0 - p1) so that the large coefficients act on a difference
        for (int n : system.moving) {
          const std::size_t k = static_cast<std::size_t>(n);
          const Vec2 dx = at.x[k] - previous[k];
          const Vec2 dv = -16 * at.v[k] - 14 * v_previous[k];
          const Vec2 da = 4 * at.a[k] - 2 * a_previous[k];
          guess[k] = at.x[k] + (31 * dx + h * (dv + h * da));
        }
      }
      // the last sample's vectors become the previous ones by a swap, not a copy: the solve
      // and the dynamics below write every entry of the instant's before reading it
      std::swap(previous, ws.instant.x);
      std::swap(v_previous, ws.instant.v);
      std::swap(a_previous, ws.instant.a);
    }
    Expected<bool, PlanarError> ok = true;
    const detail::Placement placed = detail::place_by_blocks(model, ws, guess, z);
    if (const std::optional<Limit> limit = limit_at(placed, t, t_prev, z)) {
      // the motion ends at the limit: a sample past it goes
      if (limit->at < t_prev) out.table.values.resize(out.table.values.size() - out.table.width());
      fail(out, limit->error(model, inputs_at(limit->at)), limit->at);
      return out;
    }
    if (placed != detail::Placement::kPlaced) {
      if (placed == detail::Placement::kIllConditioned) {
        // near a dead centre the closed forms still place every node on the linkage's branch,
        // where a prediction from the last samples, whose rates grow without bound there, may
        // land on the other one: the general route starts from them
        guess = ws.instant.x;
      } else if (closed && i > 0) {  // the general route needs a guess: the last sample's
        for (int n : system.moving) {
          const std::size_t k = static_cast<std::size_t>(n);
          guess[k] = previous[k] + h * (v_previous[k] + h / 2 * a_previous[k]);
        }
      }
      ok = solve_position(model, ws, guess, z, PositionRoute::kGeneral);
      if (ok && i > 0 && branch() != drawn_branch) {
        // near a singular position the prediction can overshoot onto another branch (the rates
        // grow without bound there): continue from the previous sample's positions in small
        // steps
        constexpr int kSubsteps = 16;
        guess = previous;
        for (int j = 1; j <= kSubsteps && ok; ++j) {
          for (std::size_t k = 0; k < z.size(); ++k)
            z_step[k] = z_previous[k] + (z[k] - z_previous[k]) * j / kSubsteps;
          ok = solve_position(model, ws, guess, z_step, PositionRoute::kGeneral);
          guess = ws.instant.x;
        }
        // a driven input follows its branch: a position found only on the other one lies past
        // a singular position the steps could not resolve
        if (ok && branch() != drawn_branch) {
          ok = Unexpected<PlanarError>(PlanarError{
              PlanarError::Kind::kSingular,
              "singular position between " + detail::inputs_text(model, z_previous) + " and " +
                  detail::inputs_text(model, z) +
                  " (the assembly cannot be followed on its branch: a dead centre or limit "
                  "position too near to resolve)"});
        }
      }
      if (ok) detail::prime_blocks(model, ws);
    }
    if (ok) ok = inverse_dynamics(model, ws, t, scene.speeds, zero);
    std::swap(z_previous, z);  // z is written whole at the next sample
    ++out.rhs_evaluations;
    if (!ok) {
      fail(out, ok.error(), t);
      return out;
    }
    append_row(model, ws.instant, out.table);
    t_prev = t;
  }
  // A periodic run (one input turning, whole turns): the samples' windows around its end and its
  // start (the last sample, the period's end, which is the start, and the second sample) are
  // searched too, the motion continued past the end at the end's and the second sample's inputs;
  // a limit there stops the run as one between samples does.
  int moving = 0;
  bool turning = false;
  for (std::size_t k = 0; k < z.size(); ++k) {
    if (scene.speeds[k] == 0) continue;
    ++moving;
    turning = model.linkage().inputs[k].kind == Input::Kind::kAngle;
  }
  if (!times.by_duration && moving == 1 && turning && rows >= 2) {
    const double end = times.at(rows);  // the period's end: the start again
    for (const double t : {end, times.at(rows + 1)}) {
      const std::vector<double> z_now = inputs_at(t);
      const detail::Placement placed = detail::place_by_blocks(model, ws, guess, z_now);
      const std::optional<Limit> limit = limit_at(placed, t, t_prev, z_now);
      t_prev = t;
      if (!limit) continue;
      // past the end is after the start: the motion stops right after its first sample
      const double at = limit->at > end ? limit->at - end : limit->at;
      if (limit->at > end) {
        out.table.values.resize(out.table.width());
      } else if (limit->at < times.at(rows - 1)) {
        out.table.values.resize(out.table.values.size() - out.table.width());
      }
      fail(out, limit->error(model, inputs_at(at)), at);
      return out;
    }
  }
  out.status = SimulationStatus::kCompleted;
  out.message = "completed";
  return out;
}

// ---------------------------------------------------------------------------------------------
// free motion

namespace {

// what the integrator's callbacks share
struct Motion {
  const Model* model{};
  Workspace* ws{};
  Route route{};
  double baumgarte{};
  int dof{};
  long evaluations{};
  bool failed{};
  PlanarError error;
  double error_t{};
  double root_sign = 1;     // the sign of the normalised determinant at the start
  std::vector<Vec2> cache;  // positions of the last successful evaluation (Newton's guess)
  std::vector<double> z, zd, efforts;  // scratch: the inputs, their rates, the drives' efforts
  std::vector<double> sample_angle;    // reduced route: the link angles of the last sample
  // forward sensitivities: the model's mass parameters π are read from `parameters` (which
  // CVODES perturbs for its difference quotients) at every evaluation; `applied` are the ones
  // the model (`varied`, the same as `model`) has
  Model* varied{};
  const double* parameters{};
  std::vector<double> applied;
  // dae route scratch
  MatrixXd kkt;
  VectorXd kkt_rhs, kkt_solution, rate_residual;
  std::vector<Vec2> none;  // no input targets: the structural rows only
  detail::SmallLu kkt_lu;
};

// the normalised determinant of the factorised constraints and inputs at ws
double normalised_determinant(const Model& model, Workspace& ws) {
  double d = ws.by_blocks ? detail::block_determinant(model, ws) : ws.lu.determinant();
  for (Eigen::Index r = 0; r < ws.G.rows(); ++r) d /= ws.G.row(r).norm();
  return d;
}

// reduced route: y = (z, ż)
Expected<bool, PlanarError> reduced_state(Motion& m, double t, const double* y) {
  const int dof = m.dof;
  m.z.assign(y, y + dof);
  m.zd.assign(y + dof, y + 2 * dof);
  if (m.varied != nullptr &&
      !std::equal(m.applied.begin(), m.applied.end(), m.parameters)) {
    m.applied.assign(m.parameters, m.parameters + m.applied.size());
    m.varied->set_mass_parameters(m.parameters);
  }
  efforts_at(*m.model, t, m.efforts);
  auto ok = solve_position(*m.model, *m.ws, m.cache, m.z);
  if (ok) ok = forward_dynamics(*m.model, *m.ws, t, m.zd, m.efforts);
  if (ok) m.cache = m.ws->instant.x;
  return ok;
}

int reduced_rhs(sunrealtype t, N_Vector y, N_Vector ydot, void* data) {
  Motion& m = *static_cast<Motion*>(data);
  ++m.evaluations;
  const double* yv = N_VGetArrayPointer(y);
  const auto ok = reduced_state(m, t, yv);
  if (!ok) {
    m.failed = true;
    m.error = ok.error();
    m.error_t = t;
    return 1;  // recoverable: the integrator tries a smaller step
  }
  double* d = N_VGetArrayPointer(ydot);
  for (int k = 0; k < m.dof; ++k) {
    d[k] = yv[m.dof + k];
    d[m.dof + k] = m.ws->instant.input_acceleration[static_cast<std::size_t>(k)];
  }
  return 0;
}

int reduced_root(sunrealtype, N_Vector y, sunrealtype* g, void* data) {
  Motion& m = *static_cast<Motion*>(data);
  const double* yv = N_VGetArrayPointer(y);
  m.z.assign(yv, yv + m.dof);
  if (!solve_position(*m.model, *m.ws, m.cache, m.z)) {
    g[0] = -1;  // beyond a limit: the root lies before
    return 0;
  }
  g[0] = m.root_sign * normalised_determinant(*m.model, *m.ws) - kLimitDeterminant;
  return 0;
}

// dae route: y = (q, q̇); the accelerations and the structural multipliers from
//   [M  -Gᵀ] [q̈]   [F                        ]
//   [G   0 ] [λ ] = [-γ - 2α G q̇ - α² g(q)    ]
Expected<bool, PlanarError> dae_accelerations(Motion& m, double t, const double* y,
                                              bool stabilise) {
  const System& s = m.model->system();
  Workspace& ws = *m.ws;
  const int n = s.n, r = s.structural_rows;
  ws.q = Eigen::Map<const VectorXd>(y, n);
  ws.qd = Eigen::Map<const VectorXd>(y + n, n);
  detail::nodes_from_q(s, ws.q, ws.instant.x);
  detail::node_rates_from(s, ws.qd, ws.instant.v);
  detail::constraint_jacobian(s, ws.instant.x, r, ws.G);
  detail::constraint_bias(s, ws.instant.x, ws.instant.v, r, ws.gamma);
  efforts_at(*m.model, t, m.efforts);
  detail::applied_forces(s, ws.instant.x, ws.instant.v, &m.efforts, ws.F);
  m.kkt.setZero(n + r, n + r);
  m.kkt.topLeftCorner(n, n) = s.M;
  m.kkt.topRightCorner(n, r) = -ws.G.transpose();
  m.kkt.bottomLeftCorner(r, n) = ws.G;
  m.kkt_rhs.resize(n + r);
  m.kkt_rhs.head(n) = ws.F;
  m.kkt_rhs.tail(r) = -ws.gamma;
  if (stabilise && m.baumgarte > 0) {
    detail::constraint_values(s, ws.instant.x, m.none, ws.g);
    const double a = m.baumgarte;
    m.rate_residual.noalias() = ws.G * ws.qd;
    m.kkt_rhs.tail(r) -= 2 * a * m.rate_residual + a * a * ws.g.head(r);
  }
  m.kkt_lu.compute(m.kkt);
  if (!(m.kkt_lu.rcond() > 1e-12)) {
    return Unexpected<PlanarError>(PlanarError{
        PlanarError::Kind::kSingular,
        "the constraints lose rank (a lock-up or a branch point): the linkage cannot move on"});
  }
  m.kkt_lu.solve(m.kkt_rhs, m.kkt_solution);
  ws.qdd = m.kkt_solution.head(n);
  ws.lambda.setZero(s.rows);
  ws.lambda.head(r) = m.kkt_solution.tail(r);
  if (!ws.qdd.allFinite()) {
    return Unexpected<PlanarError>(
        PlanarError{PlanarError::Kind::kNonFinite, "non-finite accelerations"});
  }
  return true;
}

// Keeps the link angles continuous through every evaluation: the dae route integrates node
// coordinates, not angles, and its samples may lie further apart than half a turn of a link, so
// continuing the angles from one sample to the next would lose whole turns. Consecutive
// evaluations of the integrator are a fraction of a step apart.
void continue_angles(const System& s, Instant& in) {
  for (std::size_t k = 0; k < s.elements.size(); ++k) {
    const System::ElementRow& e = s.elements[k];
    const Vec2 d = in.x[static_cast<std::size_t>(e.q)] - in.x[static_cast<std::size_t>(e.p)];
    const double a = std::atan2(d.y(), d.x());
    in.angle[k] = a + kTwoPi * std::round((in.angle[k] - a) / kTwoPi);
  }
}

int dae_rhs(sunrealtype t, N_Vector y, N_Vector ydot, void* data) {
  Motion& m = *static_cast<Motion*>(data);
  ++m.evaluations;
  const auto ok = dae_accelerations(m, t, N_VGetArrayPointer(y), true);
  if (!ok) {
    m.failed = true;
    m.error = ok.error();
    m.error_t = t;
    return 1;
  }
  continue_angles(m.model->system(), m.ws->instant);
  const int n = m.model->system().n;
  double* d = N_VGetArrayPointer(ydot);
  const double* yv = N_VGetArrayPointer(y);
  for (int k = 0; k < n; ++k) {
    d[k] = yv[n + k];
    d[n + k] = m.ws->qdd[k];
  }
  return 0;
}

// projects (q, q̇) onto g(q) = 0 and G q̇ = 0 (Newton with the least-norm step)
void project(const Model& model, Workspace& ws, double* y) {
  const System& s = model.system();
  const int n = s.n, r = s.structural_rows;
  Eigen::Map<VectorXd> q(y, n), qd(y + n, n);
  const std::vector<Vec2> none;
  for (int it = 0; it < 4; ++it) {
    detail::nodes_from_q(s, q, ws.instant.x);
    detail::constraint_values(s, ws.instant.x, none, ws.g);
    detail::constraint_jacobian(s, ws.instant.x, r, ws.G);
    const MatrixXd GGt = ws.G * ws.G.transpose();
    const VectorXd step = ws.G.transpose() * GGt.partialPivLu().solve(-ws.g.head(r));
    q += step;
    if (step.cwiseAbs().maxCoeff() <= 1e-15 * model.length_scale()) break;
  }
  detail::nodes_from_q(s, q, ws.instant.x);
  detail::constraint_jacobian(s, ws.instant.x, r, ws.G);
  const MatrixXd GGt = ws.G * ws.G.transpose();
  qd -= ws.G.transpose() * GGt.partialPivLu().solve(ws.G * qd);
}

// the outputs at a dae state (projected): the inputs read off the nodes, forces from the
// multipliers of the saddle-point system and the given efforts
Expected<bool, PlanarError> dae_instant(Motion& m, double t, const double* y) {
  auto ok = dae_accelerations(m, t, y, false);
  if (!ok) return ok;
  const Model& model = *m.model;
  const System& s = model.system();
  Workspace& ws = *m.ws;
  Instant& in = ws.instant;
  in.t = t;
  detail::node_rates_from(s, ws.qdd, in.a);
  efforts_at(model, t, m.efforts);
  for (const System::InputRow& ir : s.inputs) {
    const std::size_t k = static_cast<std::size_t>(ir.input);
    in.effort[k] = m.efforts[k];
    ws.lambda[ir.row] = ir.angle ? m.efforts[k] / ir.length : m.efforts[k];
    // the angle inputs as the nodes give them, continuing their links' angles (the outputs take
    // an input link's angle from its input)
    if (ir.angle) {
      const std::size_t link = static_cast<std::size_t>(model.linkage().inputs[k].link);
      in.input[k] = detail::input_angle(s, ir, in.x, in.angle[link]);
    }
  }
  detail::finish_outputs(model, ws);
  // the inputs' rates and accelerations (and the slides) as the nodes give them
  for (const System::InputRow& ir : s.inputs) {
    const std::size_t k = static_cast<std::size_t>(ir.input);
    const Input& input = model.linkage().inputs[k];
    if (ir.angle) {
      const std::size_t link = static_cast<std::size_t>(input.link);
      in.input_rate[k] = in.omega[link];
      in.input_acceleration[k] = in.alpha[link];
    } else {
      const std::size_t sl = static_cast<std::size_t>(input.slider);
      in.input[k] = in.slide[sl];
      in.input_rate[k] = in.slide_rate[sl];
      in.input_acceleration[k] = in.slide_acceleration[sl];
    }
  }
  return true;
}

// the outcome of one advance, as the trajectory's status; false when the run stops. `where()`
// says where a limit position was reached (written only then).
template <class Where>
bool advance_ok(Trajectory& out, const Motion& m, integrators::Integration& integration,
                integrators::Integration::Outcome outcome, const SimulateOptions& options,
                Where where) {
  using Outcome = integrators::Integration::Outcome;
  if (outcome == Outcome::kReached) return true;
  const std::string at = "t = " + text::digits(integration.t(), 10) + " s";
  if (outcome == Outcome::kMaxSteps) {
    out.status = SimulationStatus::kIntegratorFailed;
    out.message = "integrator stopped at " + at +
                  ": max_steps = " + std::to_string(options.max_steps) + " reached";
  } else if (outcome == Outcome::kRoot) {
    out.status = SimulationStatus::kSingular;
    out.message = "limit position reached at " + where() +
                  ": the inputs stop describing the motion there (following every joint's "
                  "coordinates, method truss-dae, goes through it)";
  } else if (m.failed && m.route == Route::kReduced &&
             m.error.kind == PlanarError::Kind::kAssembly) {
    // an explicit Runge-Kutta stage beyond a limit position (it cannot retry a shorter step):
    // the linkage does not close there
    out.status = SimulationStatus::kSingular;
    out.message = "limit position reached after " + at + ": a step beyond it cannot close the " +
                  "linkage (" + m.error.detail +
                  "); following every joint's coordinates, method "
                  "truss-dae, goes through it";
  } else if (m.failed) {
    out.status = status_of(m.error);
    out.message = m.error.detail + " (a step ahead of " + at + " reached it)";
  } else {
    out.status = SimulationStatus::kIntegratorFailed;
    out.message = "integrator failed at " + at + ": " + integration.failure();
  }
  return false;
}

// the integration of y' = rhs(t, y) from y0 over [0, t_end] as the options ask
integrators::Problem free_problem(const SimulateOptions& options, const std::vector<double>& y0,
                                  double t_end, Motion& m, integrators::RhsFn rhs) {
  integrators::Problem problem;
  problem.integrator = options.integrator;
  problem.y0 = y0;
  problem.absolute_tolerance.assign(y0.size(), options.absolute_tolerance);
  problem.tolerance = options.tolerance;
  problem.t_end = t_end;
  problem.max_steps = options.max_steps;
  problem.user_data = &m;
  problem.rhs = rhs;
  return problem;
}

// a trajectory with the model's columns, `state_size` numbers of state per sample, and room for
// the scene's samples
Trajectory empty_table(const Model& model, const FreeScene& scene, std::size_t state_size) {
  Trajectory out;
  out.table.columns = columns(model);
  out.table.values.reserve(static_cast<std::size_t>(scene.samples) * out.table.width());
  out.state_size = state_size;
  out.states.reserve(static_cast<std::size_t>(scene.samples) * state_size);
  out.steps_to.reserve(static_cast<std::size_t>(scene.samples));
  return out;
}

// what the integrator's callbacks share, for a route
Motion motion(const Model& model, Workspace& ws, Route route, const SimulateOptions& options) {
  Motion m;
  m.model = &model;
  m.ws = &ws;
  m.dof = model.inputs();
  m.route = route;
  m.baumgarte = options.baumgarte;
  return m;
}

double output_time(const FreeScene& scene, std::size_t j) {
  const std::size_t last = static_cast<std::size_t>(scene.samples - 1);
  return j == last ? scene.duration
                   : scene.duration * static_cast<double>(j) / static_cast<double>(last);
}

// A free run that stops short of its end: where the integration had reached (past the last
// sample), and the motion there where it can be evaluated (`evaluate(true)`: the instant at the
// integration's state, as a sample's but for the sensitivities): the end of its peaks' search.
template <class Evaluate>
void keep_stop(const Model& model, Motion& m, const integrators::Integration& integration,
               Trajectory& out, Evaluate& evaluate) {
  out.stop_time = integration.t();
  const std::size_t rows = out.table.rows();
  if (rows == 0 || !(out.stop_time > out.table.at(rows - 1, 0))) return;
  m.failed = false;
  ++m.evaluations;
  if (!evaluate(true) || m.failed) return;
  Series row;
  row.columns = out.table.columns;
  append_row(model, m.ws->instant, row);
  out.stop_row = std::move(row.values);
  out.stop_state.assign(integration.y(), integration.y() + out.state_size);
}

// The samples after the first: the integration advanced to each output time, the instant there
// evaluated by `evaluate(false)` and appended to the table, until the end or a failure (every
// sample before it kept). `where()` names a limit position reached.
template <class Where, class Evaluate>
void sample_run(const Model& model, Motion& m, integrators::Integration& integration,
                const FreeScene& scene, const SimulateOptions& options, Trajectory& out,
                Where where, Evaluate evaluate) {
  out.status = SimulationStatus::kCompleted;
  out.message = "completed";
  out.steps_to.assign(out.table.rows(), 0);
  for (std::size_t j = 1; j < static_cast<std::size_t>(scene.samples); ++j) {
    m.failed = false;
    const auto outcome = integration.advance(output_time(scene, j));
    if (!advance_ok(out, m, integration, outcome, options, where)) {
      keep_stop(model, m, integration, out, evaluate);
      break;
    }
    ++m.evaluations;
    const auto ok = evaluate(false);
    if (!ok) {
      fail(out, ok.error(), integration.t());
      keep_stop(model, m, integration, out, evaluate);
      break;
    }
    append_row(model, m.ws->instant, out.table);
    out.states.insert(out.states.end(), integration.y(), integration.y() + out.state_size);
    out.steps_to.push_back(integration.steps());
  }
  out.steps = integration.steps();
  out.rhs_evaluations = m.evaluations;
}

// What free_reduced() takes and gives for forward sensitivities (simulate_free_sensitivities()).
struct StateSensitivities {
  Model* model{};                 // the run's model, its mass parameters set from `parameters`
  std::vector<int> which;         // the entries of π differentiated
  std::vector<double> scales;     // their typical magnitudes, > 0 (CVODES' pbar)
  double tolerance{};             // relative, of the sensitivities' error test
  std::vector<double> parameters; // π, the model's; CVODES perturbs them in place
  std::vector<Series> derivative; // per entry of `which`: the samples' derivatives
  // per sample, per entry of `which`, the integrator's d(z, ż)/dπ_j (FreeSensitivities::state)
  std::vector<double> state;
};

// the integrator's sensitivities d(z, ż)/dπ_j at its time appended to sens.state (zeros:
// `integration` null, the start)
void keep_state_derivatives(StateSensitivities& sens, std::size_t size,
                            const integrators::Integration* integration) {
  for (std::size_t j = 0; j < sens.which.size(); ++j) {
    if (integration == nullptr) {
      sens.state.insert(sens.state.end(), size, 0.0);
      continue;
    }
    const double* d = integration->sensitivity(static_cast<int>(j));
    sens.state.insert(sens.state.end(), d, d + size);
  }
}

// A sample of the reduced route at (t, y): the dynamics there, the link angles continued from
// `angles` (a sample's continue the last sample's, not the last evaluation's, which may lie a
// step ahead, up to a turn or more of a crank at loose tolerance), an angle input's the
// integrated value itself.
Expected<bool, PlanarError> reduced_sample(Motion& m, double t, const double* y,
                                           const std::vector<double>& angles) {
  Workspace& ws = *m.ws;
  ws.instant.angle = angles;
  auto ok = reduced_state(m, t, y);
  if (!ok) return ok;
  const std::vector<Input>& inputs = m.model->linkage().inputs;
  for (std::size_t k = 0; k < inputs.size(); ++k) {
    if (inputs[k].kind == Input::Kind::kAngle)
      ws.instant.angle[static_cast<std::size_t>(inputs[k].link)] = y[k];
  }
  return ok;
}

// Appends to each sens.derivative[j] the derivative of the sample at (t, y) along (s_j, e_j):
// the sample moved by ±h along it (h = kSensitivityStep times the parameter's scale), its rows
// differenced. `integration` gives s_j (null: s_j = 0, the start). Leaves ws.instant at a moved
// sample.
Expected<bool, PlanarError> sample_derivatives(const Model& model, Motion& m,
                                               StateSensitivities& sens, double t, const double* y,
                                               const integrators::Integration* integration,
                                               const std::vector<double>& angles, Series& scratch) {
  const std::size_t n = 2 * static_cast<std::size_t>(m.dof);
  std::vector<double> moved(n);
  for (std::size_t j = 0; j < sens.which.size(); ++j) {
    const double h = core::detail::kSensitivityStep * sens.scales[j];
    const double* d = integration != nullptr ? integration->sensitivity(static_cast<int>(j)) : nullptr;
    double& parameter = sens.parameters[static_cast<std::size_t>(sens.which[j])];
    const double nominal = parameter;
    scratch.values.clear();
    for (const double step : {h, -h}) {
      for (std::size_t i = 0; i < n; ++i) moved[i] = y[i] + (d != nullptr ? step * d[i] : 0.0);
      parameter = nominal + step;
      const auto ok = reduced_sample(m, t, moved.data(), angles);
      parameter = nominal;
      if (!ok) return ok;
      append_row(model, m.ws->instant, scratch);
    }
    const std::size_t w = scratch.width();
    std::vector<double>& out = sens.derivative[j].values;
    for (std::size_t c = 0; c < w; ++c)
      out.push_back((scratch.values[c] - scratch.values[w + c]) / (2 * h));
  }
  return true;
}

Trajectory free_reduced(const Model& model, Workspace& ws, const FreeScene& scene,
                        const std::vector<double>& start, const std::vector<double>& rates,
                        const SimulateOptions& options, StateSensitivities* sens) {
  const int dof = model.inputs();
  Trajectory out = empty_table(model, scene, 2 * static_cast<std::size_t>(dof));
  Motion m = motion(model, ws, Route::kReduced, options);
  m.cache = ws.instant.x;
  std::vector<double> y0 = start;
  y0.insert(y0.end(), rates.begin(), rates.end());
  Series scratch;  // sensitivities: the rows of the moved samples
  if (sens != nullptr) {
    m.varied = sens->model;
    m.parameters = sens->parameters.data();
    m.applied = sens->parameters;
    scratch.columns = out.table.columns;
    sens->derivative.assign(sens->which.size(), Series{out.table.columns, {}});
    for (Series& d : sens->derivative) d.values.reserve(out.table.values.capacity());
  }
  const std::vector<double> drawn_angles = ws.instant.angle;
  Expected<bool, PlanarError> first = true;
  if (sens != nullptr) {
    first = sample_derivatives(model, m, *sens, 0.0, y0.data(), nullptr, drawn_angles, scratch);
    ws.instant.angle = drawn_angles;
    m.cache = ws.instant.x;
  }
  ++m.evaluations;
  if (first) first = reduced_state(m, 0.0, y0.data());
  if (sens != nullptr) keep_state_derivatives(*sens, y0.size(), nullptr);
  if (first && std::abs(normalised_determinant(model, ws)) <= kLimitDeterminant) {
    first = Unexpected<PlanarError>(
        PlanarError{PlanarError::Kind::kSingular, "the start is a limit position of the inputs"});
  }
  if (!first) {
    fail(out, first.error(), 0.0);
    out.rhs_evaluations = m.evaluations;
    return out;
  }
  m.root_sign = normalised_determinant(model, ws) > 0 ? 1.0 : -1.0;
  append_row(model, ws.instant, out.table);
  out.states.insert(out.states.end(), y0.begin(), y0.end());

  integrators::Problem problem = free_problem(options, y0, scene.duration, m, reduced_rhs);
  problem.root = reduced_root;
  if (sens != nullptr) {
    problem.sensitivities = {
        sens->parameters.data(), sens->which, sens->scales, sens->tolerance, {}};
  }
  integrators::Integration integration(problem);
  const auto where = [&] {
    return state_text(model, integration.t(),
                      std::vector<double>(integration.y(), integration.y() + dof));
  };
  m.sample_angle = ws.instant.angle;
  sample_run(model, m, integration, scene, options, out, where, [&](bool at_stop) {
    if (sens != nullptr && !at_stop) {
      if (auto ok = sample_derivatives(model, m, *sens, integration.t(), integration.y(),
                                       &integration, m.sample_angle, scratch);
          !ok) {
        return ok;
      }
      keep_state_derivatives(*sens, y0.size(), &integration);
    }
    auto ok = reduced_sample(m, integration.t(), integration.y(), m.sample_angle);
    if (ok) m.sample_angle = ws.instant.angle;
    return ok;
  });
  return out;
}

Trajectory free_dae(const Model& model, Workspace& ws, const FreeScene& scene,
                    const std::vector<double>& start, const std::vector<double>& rates,
                    const SimulateOptions& options) {
  const System& s = model.system();
  Trajectory out = empty_table(model, scene, 2 * static_cast<std::size_t>(s.n));
  Motion m = motion(model, ws, Route::kDae, options);
  // the start: positions assembled, velocities from the inputs' rates
  if (auto ok = inverse_dynamics(model, ws, 0.0, rates, std::vector<double>(rates.size(), 0.0));
      !ok) {
    fail(out, ok.error(), 0.0);
    return out;
  }
  (void)start;
  std::vector<double> y0(static_cast<std::size_t>(2 * s.n));
  const VectorXd q0 = detail::q_from_nodes(s, ws.instant.x),
                 qd0 = detail::q_from_nodes(s, ws.instant.v);
  for (int k = 0; k < s.n; ++k) {
    y0[static_cast<std::size_t>(k)] = q0[k];
    y0[static_cast<std::size_t>(s.n + k)] = qd0[k];
  }
  ++m.evaluations;
  if (auto ok = dae_instant(m, 0.0, y0.data()); !ok) {
    fail(out, ok.error(), 0.0);
    return out;
  }
  append_row(model, ws.instant, out.table);
  out.states.insert(out.states.end(), y0.begin(), y0.end());

  const integrators::Problem problem = free_problem(options, y0, scene.duration, m, dae_rhs);
  integrators::Integration integration(problem);
  std::vector<double> y(y0.size());
  const auto where = [&] { return "t = " + text::digits(integration.t(), 10) + " s"; };
  sample_run(model, m, integration, scene, options, out, where, [&](bool /*at_stop*/) {
    y.assign(integration.y(), integration.y() + y0.size());
    project(model, ws, y.data());
    return dae_instant(m, integration.t(), y.data());
  });
  return out;
}

}  // namespace

namespace {

// simulate_free()'s checks of the scene and options; the start assembled in ws; the rates
std::vector<double> free_rates(const Model& model, const FreeScene& scene,
                               const SimulateOptions& options) {
  const int dof = model.inputs();
  if (!(scene.duration > 0) || !std::isfinite(scene.duration)) {
    throw InputError(
        FieldError{"scene.duration", -1, "must be > 0 s, got " + text::shortest(scene.duration)});
  }
  if (scene.samples < 2 || scene.samples > kMaxSamples) {
    throw InputError(FieldError{"scene.samples", -1,
                                "must be between 2 and 1e8, got " + std::to_string(scene.samples)});
  }
  if (!(options.tolerance > 0 && options.tolerance < 1)) {
    throw InputError(FieldError{"tolerance", -1,
                                "must be > 0 and < 1, got " + text::shortest(options.tolerance)});
  }
  if (options.integrator == Integrator::kIda) {
    throw InputError(FieldError{"integrator", -1, ": ida is not available for planar linkages"});
  }
  const std::vector<double> rates =
      scene.rates.empty() ? std::vector<double>(static_cast<std::size_t>(dof), 0.0) : scene.rates;
  check_count(rates, dof, "scene.rates", "rates");
  return rates;
}

// the typical magnitude of mass parameter i (simulate_free_sensitivities())
double parameter_scale(const Linkage& l, int i) {
  const int links = static_cast<int>(l.links.size());
  if (i >= 4 * links) return l.point_masses[static_cast<std::size_t>(i - 4 * links)].mass;
  const int k = i / 4;
  const double m = l.links[static_cast<std::size_t>(k)].mass > 0
                       ? l.links[static_cast<std::size_t>(k)].mass
                       : total_mass(l);
  const double length = element_length(l, k);
  const int kind = i - 4 * k;
  return kind == 0 ? m : kind == 3 ? m * length * length : m * length;
}

// the sensitivities' set-up for `parameters` (checked) of `varied`, a copy of the run's model
// that the run's right-hand side sets the mass parameters of
StateSensitivities sensitivity_setup(Model& varied, const std::vector<int>& parameters,
                                     const SimulateOptions& options) {
  StateSensitivities sens;
  sens.model = &varied;
  for (const int i : parameters) {
    sens.which.push_back(i);
    sens.scales.push_back(parameter_scale(varied.linkage(), i));
  }
  sens.tolerance = std::max(options.tolerance, core::detail::kSensitivityTolerance);
  sens.parameters = mass_parameters(varied.linkage());
  return sens;
}

}  // namespace

Trajectory simulate_free(const Model& model, const FreeScene& scene,
                         const SimulateOptions& options) {
  const std::vector<double> rates = free_rates(model, scene, options);
  Workspace ws(model);
  const std::vector<double> start = start_of(model, ws, scene.start, "scene");
  return options.route == Route::kDae
             ? free_dae(model, ws, scene, start, rates, options)
             : free_reduced(model, ws, scene, start, rates, options, nullptr);
}

namespace {

// the state of a run whose row (of run.table's columns) is `row` and integrator state `y`
FreeState free_state_of(const Model& model, const Trajectory& run, std::span<const double> row,
                        std::span<const double> y) {
  const Linkage& l = model.linkage();
  const auto value = [&](const std::string& column) {
    return row[static_cast<std::size_t>(run.table.column(column))];
  };
  FreeState out;
  out.t = value("t");
  out.y.assign(y.begin(), y.end());
  out.angle.reserve(l.links.size());
  for (const Link& link : l.links) out.angle.push_back(value("theta_" + link.name));
  out.x.reserve(l.nodes.size());
  for (const Node& n : l.nodes) {
    out.x.push_back(n.ground ? n.position : Vec2(value("x_" + n.name), value("y_" + n.name)));
  }
  return out;
}

}  // namespace

FreeState free_state(const Model& model, const Trajectory& run, std::size_t i) {
  std::span<const double> y;
  if (run.state_size > 0 && (i + 1) * run.state_size <= run.states.size()) {
    y = std::span<const double>(run.states).subspan(i * run.state_size, run.state_size);
  }
  return free_state_of(model, run, run.table.row(i), y);
}

std::optional<FreeState> free_stop_state(const Model& model, const Trajectory& run) {
  if (run.stop_row.size() != run.table.width() || run.stop_state.size() != run.state_size ||
      run.state_size == 0) {
    return std::nullopt;
  }
  return free_state_of(model, run, run.stop_row, run.stop_state);
}

namespace {

// A continuation of a free run from `from` to t: the workspace at the state's angles and positions
// (every evaluation continues the last), on the reduced route the side of the limit determinant
// the run keeps (as the run takes it at its start), and the integration's problem from from.t
// (m's route). None where the state cannot be evaluated.
std::optional<integrators::Problem> continuation(Motion& m, const FreeState& from, double t,
                                                 const SimulateOptions& options) {
  Workspace& ws = *m.ws;
  ws.instant.angle = from.angle;
  ws.instant.x = from.x;
  m.cache = from.x;
  const bool dae = m.route == Route::kDae;
  if (!dae) {
    ++m.evaluations;
    if (!reduced_state(m, from.t, from.y.data())) return std::nullopt;
    m.root_sign = normalised_determinant(*m.model, ws) > 0 ? 1.0 : -1.0;
  }
  integrators::Problem problem = free_problem(options, from.y, t, m, dae ? dae_rhs : reduced_rhs);
  problem.t0 = from.t;
  if (!dae) problem.root = reduced_root;
  return problem;
}

}  // namespace

std::optional<FreeState> free_state_from(const Model& model, const SimulateOptions& options,
                                         const FreeState& from, double t, Series& row) {
  const bool dae = options.route == Route::kDae;
  const std::size_t size = 2 * static_cast<std::size_t>(dae ? model.system().n : model.inputs());
  const Linkage& l = model.linkage();
  if (!(t >= from.t) || from.y.size() != size || from.angle.size() != l.links.size() ||
      from.x.size() != l.nodes.size()) {
    return std::nullopt;
  }
  Workspace ws(model);
  Motion m = motion(model, ws, options.route, options);
  FreeState out{t, from.y, {}, {}};
  // the angles and positions continue from the state's (every evaluation continues the last)
  ws.instant.angle = from.angle;
  ws.instant.x = from.x;
  m.cache = from.x;
  if (t > from.t) {
    const std::optional<integrators::Problem> problem = continuation(m, from, t, options);
    if (!problem) return std::nullopt;
    integrators::Integration integration(*problem);
    if (integration.advance(t, true) != integrators::Integration::Outcome::kReached) {
      return std::nullopt;
    }
    out.y.assign(integration.y(), integration.y() + size);
  }
  // the instant at t as the run evaluates a sample; the angles continue the last evaluation's,
  // which lies within a step before t (the integration stops there)
  if (dae) {
    std::vector<double> y = out.y;
    project(model, ws, y.data());
    if (!dae_instant(m, t, y.data())) return std::nullopt;
  } else if (const std::vector<double> last = ws.instant.angle;
             !reduced_sample(m, t, out.y.data(), last)) {
    return std::nullopt;
  }
  append_row(model, ws.instant, row);
  out.angle = ws.instant.angle;
  out.x = ws.instant.x;
  return out;
}

FreeSensitivities simulate_free_sensitivities(const Model& model, const FreeScene& scene,
                                              const std::vector<int>& parameters,
                                              const SimulateOptions& options) {
  const std::vector<double> rates = free_rates(model, scene, options);
  if (options.route != Route::kReduced) {
    throw InputError(FieldError{"route", -1,
                                ": forward sensitivities need the reduced route (the ODE in the "
                                "inputs), got dae"});
  }
  core::detail::require_sensitivity_integrator(options.integrator);
  const Linkage& l = model.linkage();
  const int count = mass_parameter_count(l);
  std::vector<bool> seen(static_cast<std::size_t>(count), false);
  for (std::size_t j = 0; j < parameters.size(); ++j) {
    const int i = parameters[j];
    if (i < 0 || i >= count) {
      throw InputError(FieldError{"parameters", static_cast<int>(j),
                                  ": must be a mass parameter's index, 0 to " +
                                      std::to_string(count - 1) + ", got " + std::to_string(i)});
    }
    if (seen[static_cast<std::size_t>(i)]) {
      throw InputError(FieldError{"parameters", static_cast<int>(j), "is listed twice"});
    }
    seen[static_cast<std::size_t>(i)] = true;
  }
  Model varied = model;
  StateSensitivities sens = sensitivity_setup(varied, parameters, options);
  Workspace ws(varied);
  const std::vector<double> start = start_of(varied, ws, scene.start, "scene");
  FreeSensitivities out;
  out.parameters = parameters;
  out.trajectory = free_reduced(varied, ws, scene, start, rates, options, &sens);
  if (out.trajectory.ok()) {
    out.derivative = std::move(sens.derivative);
    out.state = std::move(sens.state);
  }
  return out;
}

std::optional<InstantDerivatives> free_derivatives_at(const Model& model,
                                                      const SimulateOptions& options,
                                                      const FreeSensitivities& run, double t) {
  const Trajectory& r = run.trajectory;
  const std::size_t rows = r.table.rows(), size = r.state_size, count = run.parameters.size();
  if (rows == 0 || options.route != Route::kReduced || run.derivative.size() != count ||
      size != 2 * static_cast<std::size_t>(model.inputs()) || r.states.size() != rows * size ||
      run.state.size() != rows * count * size) {
    return std::nullopt;
  }
  const std::size_t time = static_cast<std::size_t>(r.table.column("t"));
  if (!(t >= r.table.at(0, time) && t <= r.table.at(rows - 1, time))) return std::nullopt;
  // the latest sample at or before t
  std::size_t i = 0;
  while (i + 1 < rows && r.table.at(i + 1, time) <= t) ++i;
  InstantDerivatives out;
  const std::size_t width = r.table.width();
  auto row_of = [&](const Series& s) {
    return std::vector<double>(s.values.begin() + static_cast<std::ptrdiff_t>(i * width),
                               s.values.begin() + static_cast<std::ptrdiff_t>((i + 1) * width));
  };
  if (t == r.table.at(i, time)) {
    out.row = row_of(r.table);
    for (const Series& d : run.derivative) out.derivative.push_back(row_of(d));
    return out;
  }
  const FreeState from = free_state(model, r, i);
  Model varied = model;
  StateSensitivities sens = sensitivity_setup(varied, run.parameters, options);
  Workspace ws(varied);
  Motion m = motion(varied, ws, Route::kReduced, options);
  m.varied = sens.model;
  m.parameters = sens.parameters.data();
  m.applied = sens.parameters;
  std::optional<integrators::Problem> continued = continuation(m, from, t, options);
  if (!continued) return std::nullopt;
  integrators::Problem& problem = *continued;
  problem.sensitivities = {sens.parameters.data(), sens.which, sens.scales, sens.tolerance, {}};
  for (std::size_t j = 0; j < count; ++j) {
    const auto first = run.state.begin() + static_cast<std::ptrdiff_t>((i * count + j) * size);
    problem.sensitivities.initial.emplace_back(first, first + static_cast<std::ptrdiff_t>(size));
  }
  integrators::Integration integration(problem);
  if (integration.advance(t, true) != integrators::Integration::Outcome::kReached) {
    return std::nullopt;
  }
  // the derivatives, then the instant at t as the run evaluates a sample (the angles continue
  // the last evaluation's, within a step before t)
  const std::vector<double> last = ws.instant.angle;
  Series scratch{r.table.columns, {}};
  sens.derivative.assign(count, Series{r.table.columns, {}});
  if (!sample_derivatives(varied, m, sens, t, integration.y(), &integration, last, scratch) ||
      !reduced_sample(m, t, integration.y(), last)) {
    return std::nullopt;
  }
  Series row{r.table.columns, {}};
  append_row(varied, ws.instant, row);
  out.row = std::move(row.values);
  for (Series& d : sens.derivative) out.derivative.push_back(std::move(d.values));
  return out;
}

}  // namespace bd::core::planar
